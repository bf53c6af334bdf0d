"""Trigonometry-saving stage evaluations of an adaptive step: cos/sin of the cam angle and
theta_f are 17.7 ns of the right-hand side's 23.5 ns in contact, so a stage's are rotated from
the step's start (:func:`._physics.rotate`); the physics stays in :mod:`._physics`."""

from __future__ import annotations

import math

from numba import njit

from . import _physics as ph
from ._physics import rotate as _rotate_inline
from .layout import C_GRAV, C_INV_J, C_OMEGA


@njit(cache=True, _nrt=False, error_model="numpy")
def rotate(a, ca, sa, b):
    """:func:`._physics.rotate` compiled on its own for the DOP853 stages (inlined into every
    stage, as the RK4 steps take it, it lengthens the first compilation)."""
    return _rotate_inline(a, ca, sa, b)


@njit(cache=True, _nrt=False, error_model="numpy")
def accel_trig(tr, om, K, c, flight):
    """theta_f'' at the base ``tr`` (:func:`trig_at`): free pendulum in flight, else (1)–(3)."""
    if flight:
        return -c[C_GRAV] * c[C_INV_J] * tr[3]
    return ph.acceleration_trig(tr[1], tr[2], tr[3], tr[4], om, K, c)


@njit(cache=True, _nrt=False, error_model="numpy")
def trig_at(t, th, c):
    """(cam angle, its cos, its sin, cos th, sin th) at (t, th): a step's trigonometric base."""
    thc = ph.cam_angle(t, c)
    return (thc, math.cos(thc), math.sin(thc), math.cos(th), math.sin(th))


@njit(cache=True, _nrt=False, error_model="numpy")
def geometry_near(s_i, th_i, th, tr, c):
    """:func:`._physics.geometry` at (t + s_i, th_i), rotated from the base ``tr`` at (t, th)."""
    ct, st = rotate(th, tr[3], tr[4], th_i - th)
    cc, sc = rotate(tr[0], tr[1], tr[2], c[C_OMEGA] * s_i)
    return ph.geometry_trig(cc, sc, ct, st, c)


@njit(cache=True, _nrt=False, error_model="numpy")
def accel_stage(th_i, om_i, s_i, th, tr, K, c, flight):
    """theta_f'' at the stage (t + s_i, th_i, om_i) of a step from (t, th), its trigonometry
    rotated (:func:`rotate`) from ``tr`` = (cam angle at t, its cos, sin, cos th, sin th)."""
    ct, st = rotate(th, tr[3], tr[4], th_i - th)
    if flight:
        return -c[C_GRAV] * c[C_INV_J] * ct
    cc, sc = rotate(tr[0], tr[1], tr[2], c[C_OMEGA] * s_i)
    return ph.acceleration_trig(cc, sc, ct, st, om_i, K, c)
