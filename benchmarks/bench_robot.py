"""Speed of tumble.robot's RNEA and forward dynamics (ABA) beside Pinocchio, in one run.

    PYTHONPATH=src python benchmarks/bench_robot.py [--batch 20000]

For the planar 2-link arm, the PUMA 560, the Franka Panda (examples/robots/)
and a random 30-joint chain: microseconds per call of ``tumble.robot.rnea``
and ``tumble.robot.forward_dynamics`` on one state from Python, per sample on
a batch (parallel over the cores), and ``pinocchio.rnea`` / ``pinocchio.aba``
called from Python on the same model (built here joint by joint from the
chain; the torques are compared first). Best of several repeats. Takes about
half a minute with a warm Numba cache. Pinocchio is optional: without it,
its columns are empty.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import tumble
from tumble import robot

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _timing import best_of  # noqa: E402

try:
    import pinocchio as pin
except ImportError:  # the comparison is optional
    pin = None


def random_chain(n: int, seed: int = 0) -> robot.SerialChain:
    """n revolute joints with random DH parameters and random, physically consistent links."""
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(n):
        r, _ = np.linalg.qr(rng.standard_normal((3, 3)))
        rows.append(dict(a=rng.uniform(0.0, 0.3), d=rng.uniform(0.0, 0.3), alpha=rng.uniform(-np.pi, np.pi),
                         mass=rng.uniform(0.5, 3.0), com=rng.uniform(-0.1, 0.1, 3),
                         inertia=r @ np.diag(rng.uniform(0.01, 0.02, 3)) @ r.T))
    return robot.SerialChain.from_dh(rows, name=f"random {n}-DOF")


def pinocchio_model(chain: robot.SerialChain):
    """The same chain as a pinocchio.Model, from its canonical frames (tumble.kernels.featherstone layout)."""
    P = chain.params
    model = pin.Model()
    parent = 0
    for i in range(chain.dof):
        placement = pin.SE3(P[i, 0:9].reshape(3, 3), P[i, 9:12].copy())
        joint = pin.JointModelRevoluteUnaligned(P[i, 12:15].copy())
        parent = model.addJoint(parent, joint, placement, f"j{i}")
        m, h, inertia_o = P[i, 17], P[i, 18:21], P[i, 21:30].reshape(3, 3)
        com = h / m if m > 0 else np.zeros(3)
        inertia_c = inertia_o - m * (com @ com * np.eye(3) - np.outer(com, com))
        model.appendBodyToJoint(parent, pin.Inertia(m, com, inertia_c), pin.SE3.Identity())
    model.gravity.linear[:] = chain.gravity
    return model


def per_call(fn, calls: int, repeats: int = 5) -> float:
    """Best over ``repeats`` of the mean time of ``calls`` calls of ``fn`` (µs)."""
    def loop():
        for _ in range(calls):
            fn()
    return best_of(repeats, loop)[0] / calls * 1e6


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batch", type=int, default=20000, help="samples per batched call")
    parser.add_argument("--calls", type=int, default=2000, help="single calls per timing")
    args = parser.parse_args()
    chains = [robot.load(tumble.examples.path(name))
              for name in ("planar_2link.toml", "puma560.toml", "panda.urdf")] + [random_chain(30)]
    import numba

    print(f"tumble.robot vs {'Pinocchio ' + pin.__version__ if pin else 'no Pinocchio'}; "
          f"{numba.get_num_threads()} threads; batch of {args.batch}; µs per call or per sample")
    header = (f"{'chain':<22} {'n':>3} | {'RNEA 1':>8} {'RNEA B':>8} {'pin.rnea':>8} | "
              f"{'FD 1':>8} {'FD B':>8} {'pin.aba':>8} | {'max |Δτ|':>8}")
    print(header)
    print("-" * len(header))
    rng = np.random.default_rng(1)
    for chain in chains:
        n = chain.dof
        q, qd, qdd = rng.uniform(-1.0, 1.0, (3, n))
        Q, QD, QDD = rng.uniform(-1.0, 1.0, (3, args.batch, n))
        tau = robot.rnea(chain, q, qd, qdd)
        TAU = robot.rnea(chain, Q, QD, QDD)
        robot.forward_dynamics(chain, Q, QD, TAU)
        row = [per_call(lambda: robot.rnea(chain, q, qd, qdd), args.calls),
               best_of(5, lambda: robot.rnea(chain, Q, QD, QDD))[0] / args.batch * 1e6]
        fd = [per_call(lambda: robot.forward_dynamics(chain, q, qd, tau), args.calls),
              best_of(5, lambda: robot.forward_dynamics(chain, Q, QD, TAU))[0] / args.batch * 1e6]
        peer_rnea = peer_aba = delta = float("nan")
        if pin is not None:
            model = pinocchio_model(chain)
            data = model.createData()
            delta = np.abs(pin.rnea(model, data, q, qd, qdd) - tau).max()
            peer_rnea = per_call(lambda: pin.rnea(model, data, q, qd, qdd), args.calls)
            peer_aba = per_call(lambda: pin.aba(model, data, q, qd, tau), args.calls)
        print(f"{chain.name:<22} {n:>3} | {row[0]:8.2f} {row[1]:8.3f} {peer_rnea:8.2f} | "
              f"{fd[0]:8.2f} {fd[1]:8.3f} {peer_aba:8.2f} | {delta:8.1e}")
    print("RNEA 1 / FD 1: one state from Python; RNEA B / FD B: per sample of a batched call.")


if __name__ == "__main__":
    start = time.perf_counter()
    main()
    print(f"({time.perf_counter() - start:.0f} s)")
