"""A dict that cannot be changed: the record of how a result was made.

A :class:`chaoscam.Trajectory` is frozen, but its ``settings`` and ``stats`` were plain dicts:
``traj.settings["seed"] = 99`` was accepted, and :func:`chaoscam.extend_trajectory` then
simulated seed 99 as if it were the same run (found by an API review). :class:`FrozenDict`
reads like a dict (``json.dumps``, ``{**d}``, ``d.get``, pickling across processes) and
refuses every change with a TypeError saying how to make a changed copy.

Imports only the standard library, so any module may use it.
"""

from __future__ import annotations

__all__ = ["FrozenDict"]


class FrozenDict(dict):
    """A read-only dict; ``{**d, key: value}`` or ``dict(d)`` gives a changeable copy."""

    def _refuse(self, *args, **kwargs):
        raise TypeError(
            "this record is read-only (it says how the result was made); copy it to change "
            "it: {**record, key: value}"
        )

    __setitem__ = __delitem__ = __ior__ = _refuse
    clear = pop = popitem = setdefault = update = _refuse

    def __reduce__(self):
        return (FrozenDict, (dict(self),))

    def __repr__(self) -> str:
        return dict.__repr__(self)
