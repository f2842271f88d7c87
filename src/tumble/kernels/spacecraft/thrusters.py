"""On–off thrusters fired by pulse-width pulse-frequency (PWPF) modulators, one per body axis.

Thruster ``i`` exerts the torque ``τ_i`` (N·m, body axes) about the centre of
mass while it fires; it serves one body axis ``k_i`` with one sign ``σ_i`` and
fires while that axis' trigger output is ``σ_i``. Each axis ``k`` has a
modulator (Wie, *Space Vehicle Dynamics and Control*, 2nd ed., 2008, §7.5): a
first-order filter of the normalised command ``r_k = u_c,k / T_k`` (``T_k`` the
torque of the axis' thrusters) drives a Schmitt trigger with a minimum on-time::

    τ_m ḟ_k = K_m (r_k − y_k) − f_k
    y_k: 0 → ±1 when |f_k| > u_on;   ±1 → 0 when y_k f_k < u_off and the pulse is ≥ min_on_time old

The trigger outputs ``y`` and pulse start times are discrete states: they
switch in the model's projection, after every step (continuous control) or at
the sample times (zero-order hold). State slice: ``f`` (3), ``y`` (3), pulse
start times (3, s).
"""

from __future__ import annotations

import numpy as np

from tumble.kernels.spacecraft._base import SAMPLE_TOLERANCE, Actuator, Lane, Program, inline

# The modulators' block, at p:
GAIN = 0            # K_m
TIME_CONSTANT = 1   # τ_m, s
ON = 2              # u_on
OFF = 3             # u_off
MIN_ON_TIME = 4     # s
AXIS_TORQUE = 5     # T_k (3), N·m: the torque of the thrusters of axis k, half the +/− difference
HEAD = 8
# Thruster i's block at p + HEAD + STRIDE·i:
TORQUE = 0          # τ_i (3), N·m, body axes
AXIS = 3            # k_i (0, 1, 2)
SIGN = 4            # σ_i (+1 or −1)
STRIDE = 5

# State slice: filters f (3), trigger outputs y (3), pulse start times (3).
FILTER, TRIGGER, PULSE_START = 0, 3, 6
STATE_SIZE = 9


def program(torques, axis, sign, *, gain, time_constant, on, off, min_on_time, axis_torque) -> Program:
    """The thrusters' :class:`~tumble.kernels.spacecraft._base.Program`: torques (n, 3), axes and signs (n,)."""
    n = len(axis)
    table = np.column_stack([torques, axis, sign]).reshape(n, STRIDE)
    head = np.array([gain, time_constant, on, off, min_on_time, *axis_torque])
    return Program("thrusters", np.concatenate([head, table.ravel()]), count=n, state=STATE_SIZE)


def state_slices(n: int, s: int) -> dict[str, slice]:
    return {"pwpf_filter": slice(s + FILTER, s + FILTER + 3), "pwpf_output": slice(s + TRIGGER, s + TRIGGER + 3),
            "pwpf_start": slice(s + PULSE_START, s + PULSE_START + 3)}


def kernel(lane: Lane) -> Actuator:
    """The thrusters' :class:`~tumble.kernels.spacecraft._base.Actuator` for the state access ``lane``."""
    at, put = lane.at, lane.put

    @inline
    def filter_rate(d, p, s, y, j, out, k, u):
        """``ḟ_k = (K_m (u/T_k − y_k) − f_k)/τ_m``; the discrete states have zero derivative."""
        y_k, f_k = at(y, s + TRIGGER + k, j), at(y, s + FILTER + k, j)
        put(out, s + FILTER + k, j, (d[p + GAIN] * (u / d[p + AXIS_TORQUE + k] - y_k) - f_k) / d[p + TIME_CONSTANT])
        put(out, s + TRIGGER + k, j, 0.0)
        put(out, s + PULSE_START + k, j, 0.0)

    @inline
    def act(model, p, n, s, a, routed, t, y, j, out, aux, store, w1, w2, w3, cmd):
        """The filter rates ``ḟ`` (of the command when the thrusters deliver it, else of zero); returns the torque
        of the thrusters that fire."""
        d = model.data
        u1, u2, u3 = (cmd[0], cmd[1], cmd[2]) if routed else (0.0, 0.0, 0.0)
        filter_rate(d, p, s, y, j, out, 0, u1)
        filter_rate(d, p, s, y, j, out, 1, u2)
        filter_rate(d, p, s, y, j, out, 2, u3)
        t1 = t2 = t3 = 0.0
        for i in range(n):
            b = p + HEAD + STRIDE * i
            if at(y, s + TRIGGER + int(d[b + AXIS]), j) == d[b + SIGN]:
                t1 += d[b + TORQUE]
                t2 += d[b + TORQUE + 1]
                t3 += d[b + TORQUE + 2]
        return t1, t2, t3

    @inline
    def sample(model, p, n, s, t, y, j):
        """The Schmitt triggers with their minimum on-time, at the end of a step that ends at ``t``."""
        d = model.data
        for k in range(3):
            f, state, start = at(y, s + FILTER + k, j), at(y, s + TRIGGER + k, j), at(y, s + PULSE_START + k, j)
            if state == 0.0:
                if abs(f) > d[p + ON]:
                    put(y, s + TRIGGER + k, j, 1.0 if f > 0.0 else -1.0)
                    put(y, s + PULSE_START + k, j, t)
            elif state * f < d[p + OFF] and t - start >= d[p + MIN_ON_TIME] * (1.0 - SAMPLE_TOLERANCE):
                put(y, s + TRIGGER + k, j, 0.0)

    return Actuator(act, sample=sample)
