"""One step of Dormand and Prince's explicit Runge–Kutta 8(5,3) (DOP853), and its interpolant.

Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I* (2nd ed., Springer 1993),
sec. II.10: 12 stages, order 8, error from embedded 5th- and 3rd-order solutions. Coefficients of
``scipy/integrate/_ivp/dop853_coefficients.py``, the stages written out without the zeros (the
GPU cannot allocate small arrays); for theta'' = a(t, theta, theta') the stage derivatives are
(w_i, a_i). Between a step's ends, Hermite interpolants (:func:`theta_at`, :func:`omega_at`).
"""

from __future__ import annotations

import math

from numba import njit

from ._stages import accel_stage
from .layout import C_ATOL, C_RTOL

# fmt: off
C2 = 0.05260015195876773
C3 = 0.0789002279381516
C4 = 0.1183503419072274
C5 = 0.2816496580927726
C6 = 0.3333333333333333
C7 = 0.25
C8 = 0.3076923076923077
C9 = 0.6512820512820513
C10 = 0.6
C11 = 0.8571428571428571
C12 = 1.0
A2_1 = 0.05260015195876773
A3_1 = 0.0197250569845379
A3_2 = 0.0591751709536137
A4_1 = 0.02958758547680685
A4_3 = 0.08876275643042054
A5_1 = 0.2413651341592667
A5_3 = -0.8845494793282861
A5_4 = 0.924834003261792
A6_1 = 0.037037037037037035
A6_4 = 0.17082860872947386
A6_5 = 0.12546768756682242
A7_1 = 0.037109375
A7_4 = 0.17025221101954405
A7_5 = 0.06021653898045596
A7_6 = -0.017578125
A8_1 = 0.03709200011850479
A8_4 = 0.17038392571223998
A8_5 = 0.10726203044637328
A8_6 = -0.015319437748624402
A8_7 = 0.008273789163814023
A9_1 = 0.6241109587160757
A9_4 = -3.3608926294469414
A9_5 = -0.868219346841726
A9_6 = 27.59209969944671
A9_7 = 20.154067550477894
A9_8 = -43.48988418106996
A10_1 = 0.47766253643826434
A10_4 = -2.4881146199716677
A10_5 = -0.590290826836843
A10_6 = 21.230051448181193
A10_7 = 15.279233632882423
A10_8 = -33.28821096898486
A10_9 = -0.020331201708508627
A11_1 = -0.9371424300859873
A11_4 = 5.186372428844064
A11_5 = 1.0914373489967295
A11_6 = -8.149787010746927
A11_7 = -18.52006565999696
A11_8 = 22.739487099350505
A11_9 = 2.4936055526796523
A11_10 = -3.0467644718982196
A12_1 = 2.273310147516538
A12_4 = -10.53449546673725
A12_5 = -2.0008720582248625
A12_6 = -17.9589318631188
A12_7 = 27.94888452941996
A12_8 = -2.8589982771350235
A12_9 = -8.87285693353063
A12_10 = 12.360567175794303
A12_11 = 0.6433927460157636
B1 = 0.054293734116568765
B6 = 4.450312892752409
B7 = 1.8915178993145003
B8 = -5.801203960010585
B9 = 0.3111643669578199
B10 = -0.1521609496625161
B11 = 0.20136540080403034
B12 = 0.04471061572777259
E5_1 = 0.01312004499419488
E5_6 = -1.2251564463762044
E5_7 = -0.4957589496572502
E5_8 = 1.6643771824549864
E5_9 = -0.35032884874997366
E5_10 = 0.3341791187130175
E5_11 = 0.08192320648511571
E5_12 = -0.022355307863886294
E3_1 = -0.18980075407240762
E3_6 = 4.450312892752409
E3_7 = 1.8915178993145003
E3_8 = -5.801203960010585
E3_9 = -0.4226823213237919
E3_10 = -0.1521609496625161
E3_11 = 0.20136540080403034
E3_12 = 0.02265179219836082
# fmt: on
ERROR_ORDER = 7  # the step-size controller's exponent is -1 / (ERROR_ORDER + 1)


@njit(cache=True, _nrt=False, error_model="numpy")
def dop853_step(th, om, a1, h, tr, K, c, flight):
    """One DOP853 step of length h from (th, om) at t, a1 = theta''(t, th, om), ``tr`` =
    ``_stages.trig_at(t, th)``, ``flight`` the free pendulum. Returns (theta, theta') at t + h
    and the error norm (<= 1: accept): the RMS of the 5th- and 3rd-order estimates combined as
    in DOP853, scaled by ``atol + rtol max(|y_start|, |y_end|)``."""
    w1 = om
    th2 = th + h * (A2_1 * w1)
    w2 = om + h * (A2_1 * a1)
    a2 = accel_stage(th2, w2, C2 * h, th, tr, K, c, flight)
    th3 = th + h * (A3_1 * w1 + A3_2 * w2)
    w3 = om + h * (A3_1 * a1 + A3_2 * a2)
    a3 = accel_stage(th3, w3, C3 * h, th, tr, K, c, flight)
    th4 = th + h * (A4_1 * w1 + A4_3 * w3)
    w4 = om + h * (A4_1 * a1 + A4_3 * a3)
    a4 = accel_stage(th4, w4, C4 * h, th, tr, K, c, flight)
    th5 = th + h * (A5_1 * w1 + A5_3 * w3 + A5_4 * w4)
    w5 = om + h * (A5_1 * a1 + A5_3 * a3 + A5_4 * a4)
    a5 = accel_stage(th5, w5, C5 * h, th, tr, K, c, flight)
    th6 = th + h * (A6_1 * w1 + A6_4 * w4 + A6_5 * w5)
    w6 = om + h * (A6_1 * a1 + A6_4 * a4 + A6_5 * a5)
    a6 = accel_stage(th6, w6, C6 * h, th, tr, K, c, flight)
    th7 = th + h * (A7_1 * w1 + A7_4 * w4 + A7_5 * w5 + A7_6 * w6)
    w7 = om + h * (A7_1 * a1 + A7_4 * a4 + A7_5 * a5 + A7_6 * a6)
    a7 = accel_stage(th7, w7, C7 * h, th, tr, K, c, flight)
    th8 = th + h * (A8_1 * w1 + A8_4 * w4 + A8_5 * w5 + A8_6 * w6 + A8_7 * w7)
    w8 = om + h * (A8_1 * a1 + A8_4 * a4 + A8_5 * a5 + A8_6 * a6 + A8_7 * a7)
    a8 = accel_stage(th8, w8, C8 * h, th, tr, K, c, flight)
    th9 = th + h * (A9_1 * w1 + A9_4 * w4 + A9_5 * w5 + A9_6 * w6 + A9_7 * w7 + A9_8 * w8)
    w9 = om + h * (A9_1 * a1 + A9_4 * a4 + A9_5 * a5 + A9_6 * a6 + A9_7 * a7 + A9_8 * a8)
    a9 = accel_stage(th9, w9, C9 * h, th, tr, K, c, flight)
    # fmt: off
    th10 = th + h * (A10_1 * w1 + A10_4 * w4 + A10_5 * w5 + A10_6 * w6 + A10_7 * w7 + A10_8 * w8
                     + A10_9 * w9)
    w10 = om + h * (A10_1 * a1 + A10_4 * a4 + A10_5 * a5 + A10_6 * a6 + A10_7 * a7 + A10_8 * a8
                    + A10_9 * a9)
    a10 = accel_stage(th10, w10, C10 * h, th, tr, K, c, flight)
    th11 = th + h * (A11_1 * w1 + A11_4 * w4 + A11_5 * w5 + A11_6 * w6 + A11_7 * w7 + A11_8 * w8
                     + A11_9 * w9 + A11_10 * w10)
    w11 = om + h * (A11_1 * a1 + A11_4 * a4 + A11_5 * a5 + A11_6 * a6 + A11_7 * a7 + A11_8 * a8
                    + A11_9 * a9 + A11_10 * a10)
    a11 = accel_stage(th11, w11, C11 * h, th, tr, K, c, flight)
    th12 = th + h * (A12_1 * w1 + A12_4 * w4 + A12_5 * w5 + A12_6 * w6 + A12_7 * w7 + A12_8 * w8
                     + A12_9 * w9 + A12_10 * w10 + A12_11 * w11)
    w12 = om + h * (A12_1 * a1 + A12_4 * a4 + A12_5 * a5 + A12_6 * a6 + A12_7 * a7 + A12_8 * a8
                    + A12_9 * a9 + A12_10 * a10 + A12_11 * a11)
    a12 = accel_stage(th12, w12, h, th, tr, K, c, flight)
    th_new = th + h * (B1 * w1 + B6 * w6 + B7 * w7 + B8 * w8 + B9 * w9 + B10 * w10 + B11 * w11
                       + B12 * w12)
    om_new = om + h * (B1 * a1 + B6 * a6 + B7 * a7 + B8 * a8 + B9 * a9 + B10 * a10 + B11 * a11
                       + B12 * a12)
    e5_th = (E5_1 * w1 + E5_6 * w6 + E5_7 * w7 + E5_8 * w8 + E5_9 * w9 + E5_10 * w10 + E5_11 * w11
             + E5_12 * w12)
    e5_om = (E5_1 * a1 + E5_6 * a6 + E5_7 * a7 + E5_8 * a8 + E5_9 * a9 + E5_10 * a10 + E5_11 * a11
             + E5_12 * a12)
    e3_th = (E3_1 * w1 + E3_6 * w6 + E3_7 * w7 + E3_8 * w8 + E3_9 * w9 + E3_10 * w10 + E3_11 * w11
             + E3_12 * w12)
    e3_om = (E3_1 * a1 + E3_6 * a6 + E3_7 * a7 + E3_8 * a8 + E3_9 * a9 + E3_10 * a10 + E3_11 * a11
             + E3_12 * a12)
    # fmt: on
    sc_th = c[C_ATOL] + c[C_RTOL] * max(abs(th), abs(th_new))
    sc_om = c[C_ATOL] + c[C_RTOL] * max(abs(om), abs(om_new))
    e5 = (e5_th / sc_th) ** 2 + (e5_om / sc_om) ** 2
    e3 = (e3_th / sc_th) ** 2 + (e3_om / sc_om) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return th_new, om_new, 0.0
    return th_new, om_new, abs(h) * e5 / math.sqrt(2.0 * (e5 + 0.01 * e3))


@njit(cache=True, _nrt=False, error_model="numpy")
def theta_at(co, s):
    """theta at the fraction s of the step ``co`` = (theta0, w0, a0, theta1, w1, a1, h): the
    quintic Hermite interpolant of values, first and second derivatives (error O(h^6))."""
    th0, w0, a0, th1, w1, a1, h = co
    s2 = s * s
    s3 = s2 * s
    h3 = s3 * (10.0 - 15.0 * s + 6.0 * s2)
    h1 = s - s3 * (6.0 - 8.0 * s + 3.0 * s2)
    h2 = 0.5 * s2 * (1.0 - s) ** 3
    h4 = -s3 * (4.0 - 7.0 * s + 3.0 * s2)
    h5 = 0.5 * s3 * (1.0 - s) ** 2
    return th0 + (th1 - th0) * h3 + h * (w0 * h1 + w1 * h4) + h * h * (a0 * h2 + a1 * h5)


@njit(cache=True, _nrt=False, error_model="numpy")
def omega_at(co, s):
    """theta' at the fraction s of the step ``co``: the cubic Hermite interpolant of the
    values and first derivatives at the ends (error O(h^4))."""
    _, w0, a0, _, w1, a1, h = co
    s2 = s * s
    return (
        w0 + (w1 - w0) * s2 * (3.0 - 2.0 * s) + h * (a0 * s * (1.0 - s) ** 2 - a1 * s2 * (1.0 - s))
    )
