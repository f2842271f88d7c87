"""Exact torque-free motion: cost per evaluation and accuracy, beside dop853, in one run.

Prints the machine (CPU, cores, load average), then, side by side, each
timing as the min and median over 5 repeats of its CPU time (all threads;
the machine may be shared):

1. one body, many output times: cost per evaluation (rate + attitude) of the
   compiled free flow alone (``tumble._free_flow``: what ``method="exact"``
   runs per output time) and of ``torque_free`` end to end (with the front
   door's conversion to body axes and the Trajectory) on one core; the CPU
   time per evaluation on all cores; ``scipy.special.ellipj`` (sn, cn, dn
   only, no attitude) on as many points, the peer; and
   ``tumble.simulate(method="dop853")`` producing the same samples, with the
   error against the exact solution;
2. a batch of bodies (random inertia, rates, attitudes), one output time
   each: cost per evaluation, including each body's set-up, beside dop853
   integrating the same batch to the same time;
3. accuracy in units of eps = 2.2e-16: against an 80-bit Taylor-series
   integrator over 20 s (``|Δω| / (eps |ω|)``, attitude angle / eps); drift of
   the invariants over 10⁴ s (they are not enforced: the formulas must keep
   them); agreement of a run restarted from an intermediate state.

Run by hand (not a test; timings vary with the machine)::

    python benchmarks/bench_exact.py            # full run
    python benchmarks/bench_exact.py --quick    # smaller sizes
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numba
import numpy as np
import scipy.special
from numba import njit

import tumble
from _timing import best_of, cpu_times, machine
from tumble import _free_flow, attitude
from tumble.analytic._free import free_parameters, torque_free

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "analytic"))
from test_analytic_free import taylor_reference  # noqa: E402  (the 80-bit reference of the tests)

EPS = np.finfo(np.float64).eps
MOMENTS = np.array([1.0, 2.0, 3.0])
Q0 = attitude.normalize([0.9, 0.1, -0.3, 0.2])
CASES = {  # principal-axes initial rates, rad/s
    "major (m = 0.04)": (0.1, 0.2, 1.0),
    "minor (m = 0.19)": (1.0, 0.3, 0.2),
    "near separatrix (m1 = 2e-6)": (1e-3, 1.0, 1e-3),
    "oblate top (1, 1, 2)": (0.3, 0.2, 1.0),
    "on the separatrix (3, 4, 6)": (2.0, 0.5, 1.0),
}
OTHER_BODIES = {"oblate top (1, 1, 2)": [1.0, 1.0, 2.0], "on the separatrix (3, 4, 6)": [3.0, 4.0, 6.0]}


def body_of(case):
    return tumble.RigidBody(np.diag(OTHER_BODIES.get(case, MOMENTS)))


def motion_error(a, b):
    return max(np.abs(a.omega - b.omega).max(), attitude.relative_angle(a.q, b.q).max())


@njit
def free_flow_loop(moments, omega_p, q0, t, out):
    """The compiled free flow alone: set up once, then ``out[i] = (ω_P, q_NP)`` at each ``t[i]``."""
    motion = _free_flow._setup(moments[0], moments[1], moments[2], omega_p[0], omega_p[1], omega_p[2],
                               q0[0], q0[1], q0[2], q0[3])
    for i in range(t.shape[0]):
        x = _free_flow._evaluate(motion, t[i] - t[0])
        for c in range(7):
            out[i, c] = x[c]


def per_sample(times, n):
    """``min/median`` in ns per sample from :func:`_timing.cpu_times`' figures."""
    return f"{times[0] / n * 1e9:.0f}/{times[1] / n * 1e9:.0f}"


def single_body(n_times, span, threads):
    print(f"\n1. One body, {n_times:,} output times over {span:g} s: CPU ns per output sample, min/median of 5")
    print(f"{'case':30s} {'nome q':>7s} {'kernel 1 core':>14s} {'exact 1 core':>13s} "
          f"{f'exact {threads} cores':>14s} {'scipy ellipj':>13s} {'dop853 1e-13':>13s} {'dop853 err':>11s}")
    t = np.linspace(0.0, span, n_times)
    out = np.empty((n_times, 7))
    for case, omega in CASES.items():
        body = body_of(case)
        p = free_parameters(body.moments, omega)
        nome = np.exp(-np.pi * scipy.special.ellipk(p.m1) / scipy.special.ellipk(p.m)) if 0 < p.m < 1 else p.m
        args = (body.moments, np.array(omega, dtype=float), Q0, t, out)
        free_flow_loop(*args)
        torque_free(body, omega, Q0, t=t[:2])
        numba.set_num_threads(1)
        kernel = cpu_times(5, lambda: free_flow_loop(*args))
        serial = cpu_times(5, lambda: torque_free(body, omega, Q0, t=t))
        exact = serial[2]
        numba.set_num_threads(threads)
        parallel = cpu_times(5, lambda: torque_free(body, omega, Q0, t=t))
        u = p.lam * t
        peer = cpu_times(5, lambda: scipy.special.ellipj(u, p.m))
        numeric_time, numeric = best_of(1, lambda: tumble.simulate(body, omega, q0=Q0, t=t, rtol=1e-13, atol=1e-13))
        print(f"{case:30s} {nome:7.3f} {per_sample(kernel, n_times):>14s} {per_sample(serial, n_times):>13s} "
              f"{per_sample(parallel, n_times):>14s} {per_sample(peer, n_times):>13s} "
              f"{numeric_time / n_times * 1e9:13.0f} {motion_error(exact, numeric):11.1e}")
    print("kernel: the compiled free flow (tumble._free_flow) alone; exact: torque_free end to end; all cores:\n"
          "CPU time summed over the threads; the attitude's periodic part by the nome series where q <= 0.6,\n"
          "else by R_J (docs/exact.md); dop853: wall time, one run.")


def batch(n_bodies, threads):
    rng = np.random.default_rng(0)
    moments = np.sort(rng.uniform(1.0, 3.0, (n_bodies, 3)), axis=1)
    moments[:, 2] = np.minimum(moments[:, 2], moments[:, 0] + moments[:, 1])
    inertia = np.zeros((n_bodies, 3, 3))
    inertia[:, [0, 1, 2], [0, 1, 2]] = moments
    omega = rng.standard_normal((n_bodies, 3))
    q0 = attitude.normalize(rng.standard_normal((n_bodies, 4)))
    t = np.array([0.0, 10.0])
    body = tumble.RigidBody(np.diag(MOMENTS))
    print(f"\n2. Batch of {n_bodies:,} states at t = 0 and 10 s (CPU ns per body and output time, set-up "
          f"included; exact: min/median of 5; dop853: wall, one run)")
    print(f"{'batch':42s} {'exact 1 core':>13s} {f'exact {threads} cores':>14s} {f'dop853 {threads} cores':>15s} "
          f"{'difference':>11s}")
    for label, bodies in (("one RigidBody, N initial states", body),
                          ("N bodies given as an (N, 3, 3) inertia array", inertia)):
        torque_free(bodies if bodies is body else bodies[:2], omega[:2], q0[:2], t=t)
        numba.set_num_threads(1)
        serial = cpu_times(5, lambda: torque_free(bodies, omega, q0, t=t))
        numba.set_num_threads(threads)
        parallel = cpu_times(5, lambda: torque_free(bodies, omega, q0, t=t))
        numeric_time, numeric = best_of(
            1, lambda: tumble.simulate(bodies, omega, q0=q0, t=t, rtol=1e-13, atol=1e-13))
        samples = n_bodies * t.size
        print(f"{label:42s} {per_sample(serial, samples):>13s} {per_sample(parallel, samples):>14s} "
              f"{numeric_time / samples * 1e9:15.0f} {motion_error(serial[2], numeric):11.1e}")
    print("(an (N, 3, 3) array builds one RigidBody per member in Python, ~40 us each, for both methods)")


def accuracy():
    print("\n3. Accuracy in units of eps = 2.2e-16")
    print(f"{'case':30s} {'rate':>6s} {'angle':>7s} {'T':>5s} {'|L|':>5s} {'L_N dir':>8s} {'restart':>8s} "
          f"{'1-ulp':>8s}")
    t_ref = np.linspace(0.0, 20.0, 11)
    t_long = np.linspace(0.0, 1e4, 20001)
    for case, omega in CASES.items():
        body = body_of(case)
        exact = torque_free(body, omega, Q0, t=t_ref)
        ref_w, ref_q = taylor_reference(body.moments, omega, Q0, t_ref)
        rate_err = (np.linalg.norm(exact.omega - ref_w, axis=-1) / np.linalg.norm(ref_w, axis=-1)).max() / EPS
        angle_err = attitude.relative_angle(exact.q, ref_q).max() / EPS
        long = torque_free(body, omega, Q0, t=t_long)
        energy, momentum = long.energy, long.momentum_inertial
        size = np.linalg.norm(momentum, axis=-1)
        direction = momentum / size[:, None]
        k = len(t_long) // 3
        rest = torque_free(body, long.omega[k], long.q[k], t=t_long[k:])
        nudged = torque_free(body, long.omega[k] * (1 + np.array([1, -1, 1]) * EPS), long.q[k], t=t_long[k:])
        print(f"{case:30s} {rate_err:6.1f} {angle_err:7.1f} {np.abs(energy / energy[0] - 1).max() / EPS:5.1f} "
              f"{np.abs(size / size[0] - 1).max() / EPS:5.1f} {np.abs(direction - direction[0]).max() / EPS:8.1f} "
              f"{np.abs(rest.omega - long.omega[k:]).max() / EPS:8.0f} "
              f"{np.abs(nudged.omega - rest.omega).max() / EPS:8.0f}")
    print("rate: max |Δω|/|ω| and angle: max attitude error (rad), against the 80-bit Taylor reference over 20 s\n"
          "(about 20 rad turned); T, |L|, L_N dir: largest relative drift over 1e4 s; restart: max |Δω| (rad/s)\n"
          "over the 6667 s after restarting from the state at t = 3333 s; 1-ulp: the same for the restart state\n"
          "nudged by 1 ulp: the motion's own sensitivity, which bounds what a restart can reach.")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes")
    args = parser.parse_args()
    threads = numba.config.NUMBA_NUM_THREADS
    print(f"tumble exact torque-free benchmark: numba {numba.__version__}, scipy {scipy.__version__}, "
          f"{threads} threads\n{machine()}")
    single_body(100_000 if args.quick else 1_000_000, 1000.0, threads)
    batch(20_000 if args.quick else 200_000, threads)
    accuracy()


if __name__ == "__main__":
    main()
