"""The memory layout shared by the compiled kernels and their Python drivers, the one place
where a slot gets its meaning: a float64 constants vector ``c`` (``C_*``), int64 counters
``cnt`` (``I_*``), a float64 state ``y`` (``Y_*``) and output buffers (columns ``*_NAMES``).
Status codes mirror :class:`chaoscam.kernel.Status`."""

from __future__ import annotations

# --- indices into the constants vector (built by _constants.kernel_constants) ------------
C_OMEGA = 0  # cam speed [rad/s]
C_THETA_C0 = 1  # cam phase at t = 0 [rad]
C_E = 2  # eccentricity [m]
C_XO = 3  # pivot x [m]
C_YO = 4  # pivot y [m]
C_RSUM = 5  # R + r [m]
C_RCAM = 6  # cam radius R [m]
C_RROD = 7  # rod radius r, in the slip speed [m]
C_GRAV = 8  # m g l / 2 [N m]
C_INV_J = 9  # 1 / J [1/(kg m^2)]
C_HERTZ = 10  # (pi/4) E: K_n = C_HERTZ * l_lambda for the Hertz model [Pa]
C_K_FIXED = 11  # K_n of the fractal model; 0 selects the Hertz model [N/m]
C_DAMP_SIGN = 12  # +1 Hunt–Crossley, -1 the paper's literal signs
C_BETA = 13  # impact damping factor [s/m]
C_MU_ARM = 14  # mu_f times the friction arm [m]
C_VEPS = 15  # sign regularisation speed [m/s]; 0 = exact sign
C_VMIN = 16  # least approach speed of an applied impact [m/s]
C_XI = 17  # coefficient of restitution
C_ROD_L = 18  # rod length l [m]
C_DT = 19  # grid step [s]
C_EVENT_TOL = 20  # impact-time tolerance [s]
C_PERIOD = 21  # section interval 2 pi / omega [s]
C_T_RECORD = 22  # outputs are kept from this time on (transient) [s]
C_RESAMPLE_DT = 23  # interval between line-length draws [s]; 0 = draw at impacts
C_MAX_EVENTS = 24  # impacts handled in one step before chattering hand-over
C_STRIDE = 25  # series sample every C_STRIDE steps; 0 = no series
C_FLIGHT_MERGE = 26  # most grid steps taken as one RK4 step where the gap provably stays open
C_METHOD = 27  # METHOD_RK4 (_rk4) or METHOD_ADAPTIVE (_adaptive)
C_RTOL = 28  # adaptive: relative tolerance of the step error
C_ATOL = 29  # adaptive: absolute tolerance [rad and rad/s]
C_H_MAX = 30  # adaptive: largest step [s]
C_TANGENT = 31  # integrate the tangent dynamics with the state: 1 yes, 0 no
C_V_CHATTER = 32  # approach speed below which a closing ends a complete chattering [m/s]
C_V_MICRO = 33  # approach speed below which an applied impact is flagged micro [m/s]
C_RESAMPLE_EVERY = 34  # impact resampling: 1 draws at every applied jump, 0 at macro ones
C_CALL_STEPS = 35  # most loop iterations in one compiled call, then a hand-back; 0 = no limit
N_CONSTANTS = 36

METHOD_RK4 = 0
METHOD_ADAPTIVE = 1

# --- indices into the integer counters ---------------------------------------------------
I_STEP = 0  # grid step n of the current time n dt
I_N_SERIES = 1  # rows filled in the series buffer
I_N_SECTION = 2  # rows filled in the section buffer
I_N_IMPACT = 3  # rows filled in the impact buffer
I_LAM_POS = 4  # index of the line length in use in the draws buffer
I_SECTION_K = 5  # next section index k (time k T)
I_RESAMPLE_J = 6  # next resampling index j (time j dt_l)
I_CONTACT_STEPS = 7  # recorded steps ending in contact
I_COUNTED_STEPS = 8  # recorded steps
I_CHATTER = 9  # steps where the chattering guard handed over to the compliant contact
I_SLOW_CLOSINGS = 10  # closings slower than v_min (no jump applied)
I_SAFE_STEP = 11  # the gap provably stays open until grid step I_SAFE_STEP (0 = not known)
I_SERIES_J = 12  # adaptive: index j of the next series sample (time j * stride * dt)
I_GRAZES = 13  # fixed step: crossings found inside a segment whose ends lie on one side
I_SURFACE = 14  # the point's surface flags at a hand-back (SURFACE_JUMPED | SURFACE_SETTLED)
N_COUNTERS = 15

SURFACE_JUMPED = 1  # I_SURFACE bit: a rebound was just applied, the opening is flight's
SURFACE_SETTLED = 2  # I_SURFACE bit: a plastic closure, the point stays in contact

# --- the state vector y ----------------------------------------------------------------------
Y_THETA = 0  # theta_f [rad]
Y_OMEGA = 1  # theta_f' [rad/s]
Y_TIME = 2  # t [s] (the fixed-step kernel keeps it equal to cnt[I_STEP] * dt)
Y_STEP = 3  # adaptive: the step size to try next [s]; 0 = not known yet
Y_RECORDED = 4  # adaptive: time integrated after the transient [s]
Y_CONTACT = 5  # adaptive: of which in contact (gap <= 0) [s]
Y_EVENTS = 6  # adaptive: events so far in the grid interval Y_WINDOW (chattering guard)
Y_WINDOW = 7  # adaptive: that grid interval's index n, [n dt, (n + 1) dt)
Y_J11 = 8  # tangent: d theta(t) / d theta(t_k), t_k the last section time
Y_J21 = 9  # tangent: d theta'(t) / d theta(t_k)
Y_J12 = 10  # tangent: d theta(t) / d theta'(t_k)
Y_J22 = 11  # tangent: d theta'(t) / d theta'(t_k)
Y_DIV = 12  # tangent: integral of the divergence d theta''/d theta' since t_k [-]
Y_SIZE = 13

# --- status codes (mirrors chaoscam.kernel.Status) ---------------------------------------
OK = 0
NEED_BUFFER = 1
LEFT_REACH = 2
NON_FINITE = 3
PENETRATION = 4

# --- impact kinds (the ``kind`` column of the impact buffer) ----------------------------
IMPACT_MACRO = 0  # restitution jump with approach speed >= v_micro
IMPACT_MICRO = 1  # restitution jump slower than v_micro (inside a chattering sequence)
IMPACT_CHATTER_END = 2  # closing slower than v_chatter: the chattering's accumulation point
IMPACT_KINDS = ("macro", "micro", "chatter_end")  # the names of the codes above, in order

SECTION_NAMES = ("k", "t", "theta_f", "omega_f", "l_lambda")
# Further section columns: the stroboscopic map's Jacobian d(theta, theta')(t_k) / d(theta,
# theta')(t_k - T) and the divergence integrated over that period (NaN without the tangent).
SECTION_TANGENT_NAMES = ("j11", "j21", "j12", "j22", "div")
IMPACT_NAMES = ("t", "theta_f", "omega_before", "omega_after", "gap_rate_before", "lever_arm",
                "l_lambda", "kind")  # fmt: skip
SERIES_COLS = 4  # t, theta_f, omega_f, l_lambda
SECTION_COLS = len(SECTION_NAMES) + len(SECTION_TANGENT_NAMES)
IMPACT_COLS = len(IMPACT_NAMES)

# --- the cam angle, reduced exactly (_physics.cam_angle) ---------------------------------
# Cody & Waite's split of 2 pi into three doubles, the first two with 27 significant bits, so
# that k * TWO_PI_1 and k * TWO_PI_2 are exact for |k| < 2^26 (omega t + theta_c0 < 4e8 rad).
TWO_PI_1 = 6.283185303211212
TWO_PI_2 = 3.968374295837407e-09
TWO_PI_3 = 2.2884754904439327e-17
INV_TWO_PI = 0.15915494309189535
DEKKER_SPLIT = 134217729.0  # 2^27 + 1: splits a double into two halves of 26 bits (Dekker)

# --- the adaptive path's tangent -----------------------------------------------------------
# Largest h |A| of a tangent RK4 substep, |A| = max(sqrt|d theta''/d theta|, |d theta''/d theta'|):
# 0.02 converges the sticking period-1 multiplier at e = 0.02 m to ~2e-4 relative.
TANGENT_STEP_RATE = 0.02
