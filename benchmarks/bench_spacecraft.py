"""Spacecraft benchmark: simulated seconds per wall second, tumble beside scipy's solve_ivp.

One spacecraft (total inertia with a product of inertia, four pyramid reaction wheels with
torque limits and viscous friction) under the quaternion PD law (continuous), slewing 90°
about a skewed axis: RK4 at 0.1 s steps, one core, end to end (``tumble.simulate``) and the
integration alone (``tumble.integrate.solve`` on the compiled model of ``Spacecraft.compile``).
scipy's ``solve_ivp(method="RK45")`` runs
the same equations, written below in NumPy, with its default tolerances (rtol 1e-3), and a
fixed-step RK4 loop in plain Python over the same right-hand side shows the cost of the
equations without a compiled loop. A second solve_ivp line (DOP853, rtol 1e-10, atol 1e-12)
runs the same equations to an accuracy closer to that of the RK4 run, for a comparison at
equal accuracy. Each timing is the best of several calls (``REPEATS``), since a 300 s run
of tumble takes about 2 ms and the machine may be shared. The slews run 300 s (well before the error decays
towards float64's denormal range, where any arithmetic slows down).

Run by hand (not a test)::

    python benchmarks/bench_spacecraft.py
"""

from __future__ import annotations

import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import tumble  # noqa: E402
from _timing import best_of  # noqa: E402
from tumble import attitude, integrate  # noqa: E402
from tumble.spacecraft import QuaternionPD, Spacecraft, pyramid_wheels  # noqa: E402

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
WN, ZETA = 0.2, 0.8
TARGET = attitude.from_rotvec(0.5 * np.pi * np.array([1.0, 1.0, 1.0]) / np.sqrt(3.0))
SPAN, DT = 300.0, 0.1
REPEATS = 20  # best of; tumble's runs take ~2 ms, so a few stray interruptions do not count

CRAFT = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02, max_torque=0.2, viscous=1e-4),
                   controller=QuaternionPD(WN, ZETA, target=TARGET))


def numpy_rhs(craft):
    """The spacecraft equations (see tumble.kernels.spacecraft) in NumPy: state [q, ω, h]."""
    jw = craft.rate_inertia
    jinv = np.linalg.inv(jw)
    axes = np.array([w.axis for w in craft.wheels])
    spin = np.array([w.inertia for w in craft.wheels])
    limit = np.array([w.max_torque for w in craft.wheels])
    viscous = np.array([w.viscous for w in craft.wheels])
    alloc = np.linalg.pinv(axes.T)
    k, c = QuaternionPD(WN, ZETA).gains(jw)
    p = np.linalg.solve(c, k)
    qt_conj = attitude.conjugate(TARGET)

    def rhs(t, y):
        q, w, h = y[:4], y[4:7], y[7:]
        big_h = jw @ w + axes.T @ h
        e = attitude.multiply(qt_conj, q)
        ev = e[1:] if e[0] >= 0 else -e[1:]
        u = c @ (-p @ ev - w) + np.cross(w, big_h)
        speed = h / spin - axes @ w
        hdot = np.clip(-alloc @ u, -limit, limit) - viscous * speed
        wdot = jinv @ (-axes.T @ hdot - np.cross(w, big_h))
        qdot = 0.5 * attitude.multiply(q, np.concatenate([[0.0], w]))
        return np.concatenate([qdot, wdot, hdot])

    return rhs


def main():
    t = np.linspace(0.0, SPAN, 31)
    tumble.simulate(CRAFT, [0.0, 0.0, 0.0], t=t[:2], method="rk4", dt=DT)  # compile (cached on disk)
    wall, traj = best_of(REPEATS, lambda: tumble.simulate(CRAFT, [0.0, 0.0, 0.0], t=t, method="rk4", dt=DT))
    angle = np.degrees(attitude.relative_angle(traj.q[-1], TARGET))
    print(f"tumble simulate, rk4, dt = {DT} s: {SPAN / wall:10.4g} simulated s per wall s  "
          f"({wall * 1e6 / (SPAN / DT):.2f} µs per step, set-up and outputs included; "
          f"error after {SPAN:g} s: {angle:.2e} deg)")
    model = CRAFT.compile(None, 0.0)
    y0 = CRAFT.initial_states(model, {"omega0": np.zeros((1, 3)), "q0": attitude.identity()[None],
                                      "wheel_speeds0": np.zeros((1, 4))}, 0.0)
    wall_solve, _ = best_of(REPEATS, lambda: integrate.solve(model, y0, t, method="rk4", dt=DT))
    print(f"  of which the integration:    {SPAN / wall_solve:10.4g} simulated s per wall s  "
          f"({wall_solve * 1e6 / (SPAN / DT):.2f} µs per step; set-up and outputs: "
          f"{(wall - wall_solve) * 1e3:.2f} ms per call)")

    rhs = numpy_rhs(CRAFT)
    y0 = np.concatenate([[1.0, 0.0, 0.0, 0.0], np.zeros(3), np.zeros(4)])
    wall_ivp, sol = best_of(3, lambda: solve_ivp(rhs, (0.0, SPAN), y0, method="RK45"))
    angle = np.degrees(attitude.relative_angle(attitude.normalize(sol.y[:4, -1]), TARGET))
    print(f"scipy solve_ivp RK45:             {SPAN / wall_ivp:10.4g} simulated s per wall s  "
          f"({sol.nfev} evaluations; error after {SPAN:g} s: {angle:.2e} deg)")
    wall_tight, sol = best_of(3, lambda: solve_ivp(rhs, (0.0, SPAN), y0, method="DOP853", rtol=1e-10,
                                                   atol=1e-12))
    angle = np.degrees(attitude.relative_angle(attitude.normalize(sol.y[:4, -1]), TARGET))
    print(f"scipy solve_ivp DOP853, rtol 1e-10: {SPAN / wall_tight:8.4g} simulated s per wall s  "
          f"({sol.nfev} evaluations; error after {SPAN:g} s: {angle:.2e} deg)")

    def python_rk4():
        y, h = y0.copy(), DT
        for n in range(int(SPAN / DT)):
            tn = n * h
            k1 = rhs(tn, y)
            k2 = rhs(tn + h / 2, y + h / 2 * k1)
            k3 = rhs(tn + h / 2, y + h / 2 * k2)
            k4 = rhs(tn + h, y + h * k3)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            y[:4] /= np.linalg.norm(y[:4])
        return y

    wall_py, _ = best_of(1, python_rk4)
    print(f"NumPy RK4 loop, dt = {DT} s:       {SPAN / wall_py:10.4g} simulated s per wall s")
    print(f"tumble / solve_ivp RK45: {wall_ivp / wall:.0f}x;  tumble / solve_ivp DOP853 (rtol 1e-10): "
          f"{wall_tight / wall:.0f}x;  tumble / NumPy RK4: {wall_py / wall:.0f}x")


if __name__ == "__main__":
    main()
