"""Foundation benchmark: tumble's RK4 and DOP853 beside scipy's solve_ivp, in one run.

Prints, side by side:

1. single-body RK4 cost per step in the compiled loop (tumble) and in a
   hand-written NumPy RK4 loop (what one would write without tumble);
2. batch throughput, body-steps per second, N = 100 000 bodies on all cores;
3. the adaptive method at the same tolerance as scipy's solve_ivp(DOP853):
   wall time and maximum error against a tight scipy reference, and the ratios.

Run by hand (not a test; timings vary with the machine)::

    python benchmarks/bench_foundation.py            # full run
    python benchmarks/bench_foundation.py --quick    # smaller sizes
"""

from __future__ import annotations

import argparse
import os

import numpy as np
from scipy.integrate import solve_ivp

import tumble
from _timing import best_of
from tumble.kernels import rigid as _rigid
from tumble.integrate import _fixed, _rk4

MOMENTS = np.array([1.0, 2.0, 3.0])          # kg m², principal axes = body axes
OMEGA0 = np.array([1e-3, 1.0, 1e-3])          # rad/s: near the intermediate axis (flips)
# For the accuracy comparison, a motion far from the separatrix: near it, rounding
# differences of 1e-16 grow to 1e-9 in 100 s, and no reference can tell methods apart.
OMEGA0_ACCURACY = np.array([1.0, 0.2, 0.5])
Q0 = np.array([1.0, 0.0, 0.0, 0.0])


def euler_rhs(t, y):
    """Euler's equations + quaternion kinematics in NumPy, as a solve_ivp user would write them."""
    q, w = y[:4], y[4:]
    i1, i2, i3 = MOMENTS
    wdot = np.array([(i2 - i3) * w[1] * w[2] / i1, (i3 - i1) * w[2] * w[0] / i2, (i1 - i2) * w[0] * w[1] / i3])
    qdot = 0.5 * np.array([
        -q[1] * w[0] - q[2] * w[1] - q[3] * w[2],
        q[0] * w[0] + q[2] * w[2] - q[3] * w[1],
        q[0] * w[1] - q[1] * w[2] + q[3] * w[0],
        q[0] * w[2] + q[1] * w[1] - q[2] * w[0],
    ])
    return np.concatenate([qdot, wdot])


def numpy_rk4(y, dt, steps):
    """A hand-written RK4 loop in NumPy (the peer for the per-step cost)."""
    for k in range(steps):
        t = k * dt
        k1 = euler_rhs(t, y)
        k2 = euler_rhs(t + dt / 2, y + dt / 2 * k1)
        k3 = euler_rhs(t + dt / 2, y + dt / 2 * k2)
        k4 = euler_rhs(t + dt, y + dt * k3)
        y = y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        y[:4] /= np.linalg.norm(y[:4])
    return y


def single_body_rk4(steps):
    model = _rigid.build([tumble.RigidBody(np.diag(MOMENTS))], None)
    y = np.concatenate([Q0, OMEGA0])[None, :]
    t = np.array([0.0, steps * 1e-3])
    out, stats = np.empty((2, 1, 7)), np.zeros((1, 5))
    # the engine's entry point for one body (tumble.integrate runs a lone body on its state vector)
    _fixed.run_one(_rk4.SCHEME, model, y.copy(), t, 1e-3, out, stats)  # compile / load from cache

    def run():
        stats[:] = 0.0
        _fixed.run_one(_rk4.SCHEME, model, y.copy(), t, 1e-3, out, stats)
        return stats[0, 0]

    seconds, n = best_of(5, run)
    return seconds / n


def batch_rk4(n_bodies, steps):
    body = tumble.RigidBody(np.diag(MOMENTS))
    rng = np.random.default_rng(1)
    omega0 = OMEGA0 + 1e-2 * rng.standard_normal((n_bodies, 3))
    t = np.array([0.0, steps * 1e-3])
    tumble.simulate(body, omega0[:2], t=t, method="rk4", dt=1e-3)  # compile / load from cache
    seconds, _ = best_of(3, lambda: tumble.simulate(body, omega0, t=t, method="rk4", dt=1e-3))
    return n_bodies * steps / seconds


def adaptive_vs_scipy(t_end, rtol, atol):
    t = np.linspace(0.0, t_end, 101)
    y0 = np.concatenate([Q0, OMEGA0_ACCURACY])
    reference = solve_ivp(euler_rhs, (0.0, t_end), y0, method="DOP853", t_eval=t, rtol=2.3e-14, atol=1e-16)
    ref_w = reference.y[4:].T
    body = tumble.RigidBody(np.diag(MOMENTS))
    tumble.simulate(body, OMEGA0_ACCURACY, t=t[:3], rtol=rtol, atol=atol)  # compile / load from cache
    t_tumble, traj = best_of(5, lambda: tumble.simulate(body, OMEGA0_ACCURACY, t=t, rtol=rtol, atol=atol))
    t_scipy, sol = best_of(2, lambda: solve_ivp(euler_rhs, (0.0, t_end), y0, method="DOP853", t_eval=t,
                                                rtol=rtol, atol=atol))
    return {
        "tumble_s": t_tumble, "scipy_s": t_scipy,
        "tumble_err": np.abs(traj.omega - ref_w).max(), "scipy_err": np.abs(sol.y[4:].T - ref_w).max(),
        "tumble_steps": traj.info["n_steps"], "scipy_nfev": sol.nfev,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes (about 20 s)")
    args = parser.parse_args()
    n_bodies = 20_000 if args.quick else 100_000
    cores = len(os.sched_getaffinity(0))
    print(f"tumble {tumble.__version__}, {cores} cores; body I = diag{MOMENTS.tolist()} kg m², "
          f"omega0 = {OMEGA0.tolist()} rad/s\n")

    ns_tumble = single_body_rk4(200_000) * 1e9
    ns_numpy, _ = best_of(1, lambda: numpy_rk4(np.concatenate([Q0, OMEGA0]), 1e-3, 5_000))
    ns_numpy = ns_numpy / 5_000 * 1e9
    print("1. single-body RK4, cost per step")
    print(f"   tumble (compiled loop)        {ns_tumble:10.1f} ns")
    print(f"   hand-written NumPy RK4        {ns_numpy:10.1f} ns   ratio {ns_numpy / ns_tumble:8.0f}x\n")

    rate = batch_rk4(n_bodies, 200 if args.quick else 500)
    print(f"2. batch RK4, N = {n_bodies} bodies, all {cores} cores")
    print(f"   tumble                        {rate:10.3g} body-steps/s "
          f"({rate / cores:.3g} per core)\n")

    print(f"3. adaptive DOP853 at the same tolerance, omega0 = {OMEGA0_ACCURACY.tolist()} rad/s, t = 0..100 s, "
          "101 outputs;\n   error = max |Δω| (rad/s) against scipy DOP853 at rtol = 2.3e-14, atol = 1e-16")
    print(f"   {'rtol=atol':>10} {'tumble s':>10} {'scipy s':>10} {'speed-up':>9} {'tumble err':>11} {'scipy err':>11}")
    for tol in (1e-8, 1e-10, 1e-12):
        r = adaptive_vs_scipy(100.0, tol, tol)
        print(f"   {tol:10.0e} {r['tumble_s']:10.2e} {r['scipy_s']:10.2e} {r['scipy_s'] / r['tumble_s']:8.0f}x "
              f"{r['tumble_err']:11.2e} {r['scipy_err']:11.2e}")


if __name__ == "__main__":
    main()
