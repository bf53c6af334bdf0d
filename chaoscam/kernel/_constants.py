"""The kernel's constants vector from a model and its numerics: the only bridge from the
documented settings to the compiled kernels."""

from __future__ import annotations

import math

import numpy as np

from ..model import Params, contact_angle, contact_angle_rate
from ..numerics import Numerics
from . import layout as k

CALL_STEPS = {"rk4": 1 << 21, "adaptive": 1 << 18}
"""Most loop iterations (steps) of one compiled call before it hands back to Python, as for a
full buffer (bit-identical): Ctrl-C and SIGTERM are seen only between calls; 2^21 RK4 contact
steps take ~0.4 s, 2^18 adaptive ones ~0.3 s."""


def kernel_constants(
    p: Params,
    num: Numerics,
    *,
    t_record: float = 0.0,
    stride: int = 0,
    tangent: bool = False,
) -> np.ndarray:
    """The float64 constants vector indexed by ``layout.C_*``.

    Parameters
    ----------
    p, num : Params, Numerics
        The model; the integrator and its settings.
    t_record : float
        Outputs (series, section, impacts, contact fraction) are kept from this time [s].
    stride : int
        Keep a series sample every ``stride`` grid steps; 0 keeps none.
    tangent : bool
        Integrate the tangent dynamics (RK4 on the state's stages for the fixed grid; an RK4
        step along each accepted DOP853 step on the adaptive path).
    """
    c = np.zeros(k.N_CONSTANTS)
    xo, yo = p.pivot
    c[k.C_OMEGA] = p.omega
    c[k.C_THETA_C0] = p.theta_c0
    c[k.C_E] = p.e
    c[k.C_XO] = xo
    c[k.C_YO] = yo
    c[k.C_RSUM] = p.R + p.r
    c[k.C_RCAM] = p.R
    c[k.C_RROD] = p.r
    c[k.C_GRAV] = 0.5 * p.m * p.g * p.l
    c[k.C_INV_J] = 1.0 / p.inertia
    c[k.C_HERTZ] = 0.25 * math.pi * p.E
    c[k.C_K_FIXED] = p.stiffness_at(0.0) if p.stiffness == "fractal" else 0.0
    c[k.C_DAMP_SIGN] = 1.0 if p.damping == "hunt_crossley" else -1.0
    c[k.C_BETA] = p.beta
    c[k.C_MU_ARM] = p.mu_f * p.arm
    c[k.C_VEPS] = p.v_eps
    c[k.C_VMIN] = p.v_min
    c[k.C_XI] = p.xi
    c[k.C_ROD_L] = p.l
    c[k.C_DT] = num.dt
    c[k.C_EVENT_TOL] = num.event_tol
    c[k.C_PERIOD] = p.cam_period
    c[k.C_T_RECORD] = t_record
    c[k.C_RESAMPLE_DT] = p.resample_dt if p.resample == "interval" else 0.0
    c[k.C_MAX_EVENTS] = num.max_events_per_step
    c[k.C_STRIDE] = stride
    c[k.C_FLIGHT_MERGE] = num.flight_merge
    c[k.C_METHOD] = k.METHOD_ADAPTIVE if num.integrator == "adaptive" else k.METHOD_RK4
    c[k.C_RTOL] = num.rtol
    c[k.C_ATOL] = num.atol
    c[k.C_H_MAX] = num.h_max
    c[k.C_TANGENT] = 1.0 if tangent else 0.0
    c[k.C_V_CHATTER] = p.v_chatter
    c[k.C_V_MICRO] = p.v_micro
    c[k.C_RESAMPLE_EVERY] = 1.0 if p.resample == "impact" else 0.0
    c[k.C_CALL_STEPS] = CALL_STEPS[num.integrator]
    return c


def initial_state(p: Params) -> np.ndarray:
    """The state ``y`` (slots ``layout.Y_*``) at t = 0: ``p.theta_f0``, ``p.omega_f0``, or in
    contact (theta_fc(0) and its rate) where those are None (MODEL.md, decision)."""
    y = np.zeros(k.Y_SIZE)
    y[k.Y_THETA] = float(contact_angle(p, 0.0)) if p.theta_f0 is None else p.theta_f0
    y[k.Y_OMEGA] = float(contact_angle_rate(p, 0.0)) if p.omega_f0 is None else p.omega_f0
    y[k.Y_J11] = y[k.Y_J22] = 1.0  # the tangent starts from the identity
    return y


def initial_counters() -> np.ndarray:
    """The counters (``layout.I_*``) at t = 0: section index 0 (scheduled through the transient,
    so the steps do not depend on it); series sample and resampling index 1."""
    cnt = np.zeros(k.N_COUNTERS, dtype=np.int64)
    cnt[k.I_RESAMPLE_J] = 1
    cnt[k.I_SERIES_J] = 1
    return cnt
