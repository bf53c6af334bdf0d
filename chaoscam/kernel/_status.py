"""Status codes returned by the kernels and the messages a user can act on."""

from __future__ import annotations

import enum


class Status(enum.IntEnum):
    """How a run ended. Kernels return the integer; Python maps it here."""

    OK = 0
    NEED_BUFFER = 1  # internal: a buffer is full, the driver empties it and calls again
    LEFT_REACH = 2
    NON_FINITE = 3
    PENETRATION = 4

    def __str__(self) -> str:  # print(run.status) names it, as a user reads it
        return self.name

    @property
    def message(self) -> str:
        return _MESSAGES[self]

    @property
    def label(self) -> str:
        """The regime-map label of a run that did not end normally ('' for OK)."""
        return {
            Status.OK: "",
            Status.LEFT_REACH: "left_reach",
            Status.NON_FINITE: "diverged",
            Status.PENETRATION: "diverged",
        }.get(self, "error")


_MESSAGES = {
    Status.OK: "The run reached its end time.",
    Status.NEED_BUFFER: "Internal: output buffers full; the driver continues the run.",
    Status.LEFT_REACH: (
        "The follower left the cam's reach: in contact, the contact point lay off the rod "
        "(lever arm l_1 outside (0, l)). The motion after that is not described by the model; "
        "the outputs stop there. Lower omega or e, or move the pivot (x_O, y_O)."
    ),
    Status.NON_FINITE: (
        "The state became non-finite (NaN or inf). The step is probably too large for the "
        "contact stiffness: lower dt (the contact period is 2 pi sqrt(J / (K_n l_1^2)))."
    ),
    Status.PENETRATION: (
        "The penetration exceeded the cam radius R: the rod axis passed the cam centre, which "
        "the model cannot describe. Lower dt, or check the pivot position and initial state."
    ),
}
