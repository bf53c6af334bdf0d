"""The random contact-line length l_lambda ~ Normal(mu, sigma^2), truncated to (l_min, inf).

Paper section 2.5. Decisions (shared/MODEL.md): the normal is truncated below at ``l_min`` so the
line stays positive, and the mass removed is reported; each realization is a pure function of
``(seed, index)`` through ``SeedSequence(seed, spawn_key=(index,))``, whatever the workers.
"""

from __future__ import annotations

import numpy as np

from .._util import ParameterError
from ._params import Params

__all__ = ["realization_rng", "realizations_identical", "truncated_mass", "LineLengthStream"]


def realizations_identical(p: Params, sigma=None):
    """True when every realization of ``p`` is the same run (a deterministic model):
    ``l_lambda_sigma = 0``, or ``stiffness = "fractal"``, whose K_n (15)/(17), the only place the
    line length enters the motion, does not depend on it. A sweep runs such a model once, and
    its periodic orbits can be certified by shooting. ``sigma``: an array of l_lambda_sigma
    values in place of p's (a regime map's cells): an array of answers."""
    sigma = p.l_lambda_sigma if sigma is None else np.asarray(sigma)
    return (sigma == 0.0) | (p.stiffness == "fractal")


def realization_rng(seed: int, index: int) -> np.random.Generator:
    """The generator of realization ``index`` under master ``seed`` (PCG64)."""
    if int(seed) < 0 or int(index) < 0:
        raise ParameterError(f"seed = {seed} and index = {index} must be >= 0")
    sequence = np.random.SeedSequence(int(seed), spawn_key=(int(index),))
    return np.random.Generator(np.random.PCG64(sequence))


def truncated_mass(mu: float, sigma: float, l_min: float) -> float:
    """Probability mass of Normal(mu, sigma^2) below l_min, removed by the truncation."""
    if sigma == 0.0:
        return 0.0 if mu > l_min else 1.0
    from scipy.special import ndtr  # lazily: scipy.special costs ~0.2 s to import

    return float(ndtr((l_min - mu) / sigma))


class LineLengthStream:
    """Draws of the truncated normal line length for one realization, in blocks.

    The values depend only on ``(seed, index)`` and their position in the stream, not on the
    block sizes asked for: each draw consumes exactly one uniform double. Sampling is by
    inversion of the upper tail, ``z = -Phi^-1(U Phi(-a))`` with ``a = (l_min - mu)/sigma``,
    which stays accurate when the truncation point is far in either tail.
    With ``sigma = 0`` every draw is ``mu``.
    """

    def __init__(self, p: Params, seed: int = 0, index: int = 0) -> None:
        self.mu, self.sigma, self.l_min = p.l_lambda, p.l_lambda_sigma, p.l_min
        self._rng = realization_rng(seed, index) if self.sigma > 0 else None
        if self.sigma > 0:
            self._a = (self.l_min - self.mu) / self.sigma
            from scipy.special import ndtr

            self._tail = float(ndtr(-self._a))
            if self._tail < 1e-12:
                raise ParameterError(
                    f"l_min = {self.l_min!r} m is {self._a:.1f} standard deviations above "
                    f"l_lambda = {self.mu!r} m: the truncated normal keeps no mass"
                )

    def draw(self, n: int) -> np.ndarray:
        """The next ``n`` line lengths [m]."""
        if self._rng is None:
            return np.full(n, self.mu)
        u = self._rng.random(n)
        from scipy.special import ndtri

        z = -ndtri((1.0 - u) * self._tail)  # 1 - u in (0, 1]: never ndtri(0)
        return self.mu + self.sigma * np.maximum(z, self._a)
