"""Control laws, compiled: torque laws, dipole laws and motor-torque laws for the wheels.

Each law is a kind of part (:data:`tumble.kernels.spacecraft.PARTS`) with a
parameter block at ``p`` in ``model.data``; the assembly in
:mod:`tumble.kernels.spacecraft` evaluates them in the right-hand side
(continuous control) or at the sample times (zero-order hold). Body axes, SI
units; ``q`` body → inertial; ``H`` the spacecraft's angular momentum
(hub, wheels, gyros, damper), N·m·s, body axes.

Torque laws (one at most), the command ``u_c`` on the hub, N·m:

* ``"pd"``, quaternion feedback (Wie, Weiss & Arapostathis, J. Guidance 12(3), 1989;
  rate limit: Wie & Lu, J. Guidance 18(6), 1995), which also serves rate damping and
  an open-loop constant torque (``C``, ``C⁻¹K`` zero, no gyroscopic term)::

      q_e = q_c* ⊗ q (w ≥ 0),  ω_c = −C⁻¹K q_e,v clipped to |ω_c| ≤ max_rate
      u_c = C (ω_c − ω) + g ω × H + u₀,  scaled so that max |u_k| ≤ max_torque

* ``"mrp"``, MRP feedback (Schaub & Junkins, *Analytical Mechanics of Space
  Systems*, §8; Basilisk's ``mrpFeedback`` with the gyroscopic term of its control
  law type 1) regulating to an inertial target, with ``σ`` the MRP of
  ``q_e = q_c* ⊗ q`` (``w ≥ 0``: the shortest rotation, ``|σ| ≤ 1``)::

      u_c = −K σ − P (ω + K_I z) + ω × H,   z = K ∫σ dt + J_ω ω   ("mrp_integral", optional)

  ``σ = q_e,v / (1 + q_e,w)`` (of the normalised quaternion). With ``V = ½ ωᵀJ_ω ω +
  2K ln(1 + σᵀσ) + ½ K_I zᵀz``, ``V̇ = −(ω + K_I z)ᵀ P (ω + K_I z) ≤ 0``
  (Basilisk's ``mrpFeedback`` documentation).
* ``"python_law"``: a Python function ``u = law(t, q, omega, wheel_speeds)``, called
  through :mod:`tumble._callback` (a few microseconds per call).

Dipole laws (summed), the dipole command ``m_c``, A·m²:

* ``"bdot"``: ``m = −k Ḃ = k ω × B`` (Stickler & Alfriend, J. Spacecraft 13(5), 1976);
* ``"dumping"``: ``m = k (h_w × B)/|B|²``, ``h_w = Σ a_i h_i`` (Sidi 1997, §7.5).

Motor-torque laws for the wheels (one at most), ``w_i`` N·m added to each wheel's motor
command (:mod:`tumble.kernels.spacecraft.wheels`):

* ``"wheel_table"``: samples ``w(t_k)``, linear or zero-order-hold interpolation, end values
  held (a constant is one sample);
* ``"wheel_python"``: ``w = law(t, q, omega, wheel_speeds)`` in Python.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, objmode

from tumble import _callback, _quat
from tumble._vec import cross, matvec_flat
from tumble.kernels.spacecraft._base import Program, inline

# "pd" block:
PD_DAMPING = 0      # C (9), N·m·s, row-major
PD_STIFFNESS = 9    # C⁻¹K (9), 1/s
PD_TARGET = 18      # q_c (4)
PD_MAX_RATE = 22    # rad/s
PD_MAX_TORQUE = 23  # N·m
PD_GYROSCOPIC = 24  # g: 1 or 0
PD_BIAS = 25        # u₀ (3), N·m
PD_SIZE = 28
# "mrp" block:
MRP_K = 0           # K, N·m
MRP_P = 1           # P (9), N·m·s, row-major
MRP_TARGET = 10     # q_c (4)
MRP_SIZE = 14
# "mrp_integral" block and state:
MRP_KI = 0          # K_I, 1/(N·m·s)
INTEGRAL = 0        # state: ∫σ dt (3), s
# "bdot", "dumping" blocks:
GAIN = 0            # k: A·m²·s/T (B-dot), 1/s (dumping)
# "python_law", "wheel_python" blocks:
SLOT = 0            # the function's slot in tumble._callback
# "wheel_table" block:
SAMPLES = 0         # number of samples n_t
PREVIOUS = 1        # 1: zero-order hold, 0: linear
TIMES = 2           # t_k (n_t), s; then the values (n_t × n_w), N·m, row-major


def pd_program(damping, stiffness, target, max_rate, max_torque, gyroscopic, bias) -> Program:
    return Program("pd", np.concatenate([np.ravel(damping), np.ravel(stiffness), target,
                                         [max_rate, max_torque, gyroscopic], bias]).astype(np.float64))


def mrp_program(k, p, target) -> Program:
    return Program("mrp", np.concatenate([[k], np.ravel(p), target]).astype(np.float64))


def mrp_integral_program(ki) -> Program:
    return Program("mrp_integral", np.array([ki], dtype=np.float64), state=3)


def gain_program(kind: str, gain: float) -> Program:
    return Program(kind, np.array([gain], dtype=np.float64))


def python_program(kind: str, slot: int) -> Program:
    return Program(kind, np.array([slot], dtype=np.float64))


def wheel_table_program(times, values, previous: bool) -> Program:
    """Samples ``values`` (n_t, n_w), N·m, at ``times`` (n_t,), s."""
    head = [len(times), 1.0 if previous else 0.0]
    return Program("wheel_table", np.concatenate([head, times, np.ravel(values)]).astype(np.float64))


def integral_slices(n: int, s: int) -> dict[str, slice]:
    return {"attitude_error_integral": slice(s + INTEGRAL, s + INTEGRAL + 3)}


@inline
def pd_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3):
    d = model.data
    o = p + PD_TARGET
    ew, ex, ey, ez = _quat.qmul(d[o], -d[o + 1], -d[o + 2], -d[o + 3], qw, qx, qy, qz)
    if ew < 0.0:
        ex, ey, ez = -ex, -ey, -ez
    c1, c2, c3 = matvec_flat(d, p + PD_STIFFNESS, -ex, -ey, -ez)
    rate = math.sqrt(c1 * c1 + c2 * c2 + c3 * c3)
    if rate > d[p + PD_MAX_RATE]:  # eigen-axis slew at the rate limit (Wie & Lu 1995)
        s = d[p + PD_MAX_RATE] / rate
        c1, c2, c3 = s * c1, s * c2, s * c3
    g1, g2, g3 = cross(w1, w2, w3, H1, H2, H3)
    u1, u2, u3 = matvec_flat(d, p + PD_DAMPING, c1 - w1, c2 - w2, c3 - w3)
    k = d[p + PD_GYROSCOPIC]
    u1, u2, u3 = u1 + k * g1 + d[p + PD_BIAS], u2 + k * g2 + d[p + PD_BIAS + 1], u3 + k * g3 + d[p + PD_BIAS + 2]
    big = max(abs(u1), abs(u2), abs(u3))
    if big > d[p + PD_MAX_TORQUE]:  # scale, keeping the direction
        s = d[p + PD_MAX_TORQUE] / big
        u1, u2, u3 = s * u1, s * u2, s * u3
    return u1, u2, u3


@inline
def attitude_error(model, p, qw, qx, qy, qz):
    """``σ``, the MRP of ``q_c* ⊗ q/|q|`` (shortest rotation, ``|σ| ≤ 1``), ``q_c`` at ``p + MRP_TARGET``."""
    d = model.data
    o = p + MRP_TARGET
    ew, ex, ey, ez = _quat.qmul(d[o], -d[o + 1], -d[o + 2], -d[o + 3], qw, qx, qy, qz)
    if ew < 0.0:
        ew, ex, ey, ez = -ew, -ex, -ey, -ez
    norm = math.sqrt(ew * ew + ex * ex + ey * ey + ez * ez)
    k = 1.0 / (norm + ew)
    return k * ex, k * ey, k * ez


@inline
def mrp_torque(model, p, qw, qx, qy, qz, w1, w2, w3, H1, H2, H3, v1, v2, v3):
    """``u_c = −K σ − P (ω + v) + ω × H`` with ``v = K_I z`` (zero without the integral term)."""
    d = model.data
    s1, s2, s3 = attitude_error(model, p, qw, qx, qy, qz)
    k = d[p + MRP_K]
    x1, x2, x3 = matvec_flat(d, p + MRP_P, w1 + v1, w2 + v2, w3 + v3)
    g1, g2, g3 = cross(w1, w2, w3, H1, H2, H3)
    return -k * s1 - x1 + g1, -k * s2 - x2 + g2, -k * s3 - x3 + g3


@njit(cache=True)
def call_python(slot, t, qw, qx, qy, qz, w1, w2, w3, speeds, size):
    """``law(t, q, omega, wheel_speeds)`` of the Python function in ``slot``: an array of ``size`` numbers.

    ``q`` is normalised here (Runge–Kutta stages leave it off the unit sphere by the local error)."""
    s = 1.0 / math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    q = np.array((qw * s, qx * s, qy * s, qz * s))
    omega = np.array((w1, w2, w3))
    out = np.empty(size)
    with objmode():
        _callback.invoke(slot, t, (q, omega, speeds), out)
    return out


@inline
def bdot_dipole(model, p, w1, w2, w3, b1, b2, b3):
    k = model.data[p + GAIN]
    m1, m2, m3 = cross(w1, w2, w3, b1, b2, b3)
    return k * m1, k * m2, k * m3


@inline
def dumping_dipole(model, p, h1, h2, h3, b1, b2, b3):
    k = model.data[p + GAIN] / (b1 * b1 + b2 * b2 + b3 * b3)
    m1, m2, m3 = cross(h1, h2, h3, b1, b2, b3)
    return k * m1, k * m2, k * m3


@inline
def wheel_table(model, p, n_w, t, i):
    """The tabulated motor torque of wheel ``i`` (of ``n_w``) at ``t`` (s), N·m."""
    d = model.data
    n = int(d[p + SAMPLES])
    t0 = p + TIMES
    v0 = t0 + n
    if t <= d[t0]:
        return d[v0 + i]
    if t >= d[t0 + n - 1]:
        return d[v0 + (n - 1) * n_w + i]
    lo, hi = 0, n - 1  # invariant: times[lo] <= t < times[hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if d[t0 + mid] <= t:
            lo = mid
        else:
            hi = mid
    value = d[v0 + lo * n_w + i]
    if d[p + PREVIOUS] != 0.0:
        return value
    f = (t - d[t0 + lo]) / (d[t0 + lo + 1] - d[t0 + lo])
    return value + f * (d[v0 + (lo + 1) * n_w + i] - value)
