"""Input checks shared by the analysis functions."""

from __future__ import annotations

import numpy as np

MIN_SERIES = 16  # fewer samples than this cannot show an oscillation: too little data


def as_series(x, name: str = "x", min_size: int = 1) -> np.ndarray:
    """Return `x` as a 1-D float array; NaN or infinite values, or fewer than `min_size`
    samples, raise ValueError."""
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 1:
        arr = np.squeeze(arr)
        if arr.ndim != 1:
            raise ValueError(f"{name} must be one-dimensional, got shape {np.shape(x)}")
    if arr.size < min_size:
        raise ValueError(
            f"too little data: {name} has {arr.size} samples, at least {min_size} are needed"
        )
    if not np.all(np.isfinite(arr)):
        raise ValueError(
            f"{name} contains NaN or infinite values; remove or interpolate them first"
        )
    return arr


def as_points(points, name: str = "points", min_size: int = 1) -> np.ndarray:
    """Return section points as an (N, d) float array (1-D input becomes (N, 1)).

    NaN or infinite values, or fewer than `min_size` points, raise ValueError.
    """
    arr = np.asarray(points, dtype=float)
    if arr.ndim == 1:
        arr = arr[:, None]
    if arr.ndim != 2:
        raise ValueError(f"{name} must have shape (N,) or (N, d), got {np.shape(points)}")
    if arr.shape[0] < min_size:
        raise ValueError(
            f"too little data: {name} has {arr.shape[0]} points, at least {min_size} are needed"
        )
    if not np.all(np.isfinite(arr)):
        raise ValueError(
            f"{name} contains NaN or infinite values; remove or interpolate them first"
        )
    return arr
