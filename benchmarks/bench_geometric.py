"""Geometric integrators beside RK4, in one run: speed, long-run invariants, and the design choices.

Prints, side by side for rk4, splitting2, splitting4 and cf4:

1. speed: body-steps per second for one body (compiled loop) and for a batch
   of N = 100 000 bodies on all cores;
2. invariants after 1e6 steps of dt = 0.05 s (about 8000 turns): the
   relative energy error in the first and last tenth of the run, |L|, L_N and
   |q| − 1;
3. the splitting's axes: energy error of the six ways to assign the Casimir
   axis and the two split flows to the principal axes (Strang and
   Blanes–Moan S6), over random bodies;
4. the order-4 composition: Blanes–Moan S6 beside the Yoshida triple jump and
   Suzuki's fivefold composition of Strang steps, at equal work.

Run by hand (not a test; timings vary with the machine)::

    python benchmarks/bench_geometric.py            # full run
    python benchmarks/bench_geometric.py --quick    # smaller sizes
"""

from __future__ import annotations

import argparse
import itertools
import os

import numpy as np

import tumble
from _timing import best_of
from tumble import dynamics
from tumble.kernels import rigid as _rigid
from tumble.integrate import _fixed, _splitting

MOMENTS = np.array([1.0, 2.0, 3.0])           # kg m², principal axes = body axes
OMEGA0 = np.array([0.3, 1.0, -0.2])            # rad/s
METHODS = ("rk4", "splitting2", "splitting4", "cf4")


def speed(method, n_bodies, steps_single, steps_batch):
    body = tumble.RigidBody(np.diag(MOMENTS))
    dt = 1e-3
    t_single = np.array([0.0, steps_single * dt])
    tumble.simulate(body, OMEGA0, t=np.array([0.0, dt]), method=method, dt=dt)  # compile / load from cache
    single, _ = best_of(5, lambda: tumble.simulate(body, OMEGA0, t=t_single, method=method, dt=dt))
    rng = np.random.default_rng(1)
    omega0 = OMEGA0 + 1e-2 * rng.standard_normal((n_bodies, 3))
    t_batch = np.array([0.0, steps_batch * dt])
    tumble.simulate(body, omega0[:2], t=t_batch, method=method, dt=dt)  # compile / load from cache
    batch, _ = best_of(3, lambda: tumble.simulate(body, omega0, t=t_batch, method=method, dt=dt))
    return steps_single / single, n_bodies * steps_batch / batch


def invariants(method, steps, dt=0.05):
    inertia = np.diag(MOMENTS)
    t = np.linspace(0.0, steps * dt, 1001)
    seconds, traj = best_of(1, lambda: tumble.simulate(tumble.RigidBody(inertia), OMEGA0, t=t, method=method, dt=dt))
    energy = dynamics.kinetic_energy(inertia, traj.omega)
    d_energy = np.abs(energy / energy[0] - 1.0)
    norm = np.linalg.norm(dynamics.angular_momentum(inertia, traj.omega), axis=-1)
    momentum = dynamics.angular_momentum_inertial(inertia, traj.omega, traj.q)
    return {
        "s": seconds,
        "dE first": d_energy[1:101].max(), "dE last": d_energy[-100:].max(),
        "|L|": np.abs(norm / norm[0] - 1.0).max(),
        "L_N": np.linalg.norm(momentum - momentum[0], axis=-1).max() / norm[0],
        "|q|-1": np.abs(np.linalg.norm(traj.q, axis=-1) - 1.0).max(),
    }


def random_bodies(n, seed=1):
    """n (moments ascending, triangle inequality, spread up to 4x; unit ω0)."""
    rng = np.random.default_rng(seed)
    bodies = []
    while len(bodies) < n:
        moments = np.sort(np.exp(rng.uniform(0.0, np.log(4.0), 3)))
        if moments[0] + moments[1] >= moments[2]:
            omega = rng.standard_normal(3)
            bodies.append((moments, omega / np.linalg.norm(omega)))
    return bodies


def splitting_energy_error(scheme, moments, omega0, dt, steps):
    """max relative energy error of ``steps`` steps of the splitting ``scheme`` (every step sampled)."""
    model = _rigid.build([tumble.RigidBody(np.diag(moments))], None)
    y = np.concatenate([[1.0, 0.0, 0.0, 0.0], omega0])[None, :]
    t = np.arange(steps + 1) * dt
    out, stats = np.empty((steps + 1, 1, 7)), np.zeros((1, 5))
    m, h = _fixed.landing_steps(t, dt, 10**9)
    _fixed.run_block(scheme, model, 0, y, t, m, h, out, stats)
    omega = out[:, 0, 4:]
    energy = 0.5 * (omega**2 * moments).sum(axis=-1)
    return np.abs(energy / energy[0] - 1.0).max()


def compositions():
    """Order-4 compositions of Strang steps (as tables A(a₀h) B(b₁h) …) to compare with S6."""
    def of_strang(fractions):
        a = [fractions[0] / 2] + [(x + y) / 2 for x, y in zip(fractions[:-1], fractions[1:])] + [fractions[-1] / 2]
        return np.array(a), np.array(fractions)

    g = 1.0 / (2.0 - 2.0 ** (1.0 / 3.0))                     # Yoshida, Phys. Lett. A 150 (1990) 262
    p = 1.0 / (4.0 - 4.0 ** (1.0 / 3.0))                     # Suzuki, Phys. Lett. A 146 (1990) 319
    return {
        "Strang (order 2)": (_splitting.STRANG.a, _splitting.STRANG.b),
        "Yoshida triple jump": of_strang([g, 1.0 - 2.0 * g, g]),
        "Suzuki fivefold": of_strang([p, p, 1.0 - 4.0 * p, p, p]),
        "Blanes-Moan S6": (_splitting.BLANES_MOAN.a, _splitting.BLANES_MOAN.b),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes")
    args = parser.parse_args()
    cores = len(os.sched_getaffinity(0))
    n_bodies = 100_000
    print(f"tumble {tumble.__version__}, {cores} cores; body I = diag{MOMENTS.tolist()} kg m², "
          f"omega0 = {OMEGA0.tolist()} rad/s\n")

    print(f"1. speed, body-steps/s: one body, and N = {n_bodies} bodies on all {cores} cores")
    print(f"   {'method':>11} {'one body':>10} {'ns/step':>8} {'batch':>10} {'per core':>9}")
    for method in METHODS:
        single, batch = speed(method, n_bodies, 100_000 if args.quick else 500_000, 50 if args.quick else 200)
        print(f"   {method:>11} {single:10.3g} {1e9 / single:8.1f} {batch:10.3g} {batch / cores:9.3g}")

    steps = 10**6
    print(f"\n2. invariants after {steps:.0e} steps of dt = 0.05 s (relative; energy error max over the "
          "first and last tenth)")
    print(f"   {'method':>11} {'dE first':>9} {'dE last':>9} {'|L|':>9} {'L_N':>9} {'|q|-1':>9} {'s':>6}")
    for method in METHODS:
        r = invariants(method, steps)
        print(f"   {method:>11} {r['dE first']:9.2e} {r['dE last']:9.2e} {r['|L|']:9.2e} {r['L_N']:9.2e} "
              f"{r['|q|-1']:9.2e} {r['s']:6.2f}")

    bodies = random_bodies(20 if args.quick else 60)
    run = 2000
    print(f"\n3. splitting axes (Casimir c, flow A, flow B; 1 = smallest moment): max |dE|/E over {run} steps, "
          f"{len(bodies)} random bodies (moments within 4x, |omega0| = 1 rad/s), median / worst")
    print(f"   {'c a b':>7} {'Strang dt=0.05':>21} {'S6 dt=0.3':>21}")
    rows = []
    for axes in itertools.permutations(range(3)):
        axes = np.array(axes, dtype=np.int64)
        errors = [[splitting_energy_error(_splitting.Splitting(s.a, s.b, axes), m, w, dt, run) for m, w in bodies]
                  for s, dt in ((_splitting.STRANG, 0.05), (_splitting.BLANES_MOAN, 0.3))]
        rows.append((np.median(errors[1]), axes, errors))
    for _, axes, (strang, s6) in sorted(rows, key=lambda row: row[0]):
        chosen = "  <- used" if np.array_equal(axes, _splitting.AXES) else ""
        print(f"   {' '.join(str(a + 1) for a in axes):>7} {np.median(strang):10.2e} {max(strang):10.2e} "
              f"{np.median(s6):10.2e} {max(s6):10.2e}{chosen}")

    print(f"\n4. compositions at equal work (dt = 0.05 s per 2 turns): max |dE|/E over 100 s, {len(bodies)} random "
          "bodies, median / worst")
    for name, (a, b) in compositions().items():
        dt = 0.05 * len(b)
        scheme = _splitting.Splitting(a, b, _splitting.AXES)
        errors = [splitting_energy_error(scheme, m, w, dt, int(round(100.0 / dt))) for m, w in bodies]
        print(f"   {name:>20} dt = {dt:4.2f} s: {np.median(errors):9.2e} {max(errors):9.2e}")


if __name__ == "__main__":
    main()
