"""Speed of tumble.robot's RNEA, CRBA and forward dynamics beside Pinocchio, in one run, from the same URDFs.

    PYTHONPATH=src python benchmarks/bench_robot.py [--batch 20000] [--repeats 7]

Robots: the 6-axis tumble.examples.path("industrial6.urdf"), UR5 and Panda (fixed base) and the Talos humanoid and
Solo12 quadruped (floating base) from example-robot-data. Pinocchio builds its model from the same file with
its own URDF parser (``buildModelFromUrdf``: axis-aligned RX/RY/RZ joints where the URDF has them), and the
torques are compared first. Per row: µs per call of ``tumble.robot.rnea`` / ``mass_matrix`` /
``forward_dynamics`` on one state from Python, per sample of a batched call (parallel over the cores),
and Pinocchio's ``rnea`` / ``crba`` / ``aba`` called from Python, and its ``rneaInParallel`` per sample
where this build has it. Each figure: min and median over ``--repeats`` repeats (≥ 5). Prints the CPU,
the cores and the load average first: on a shared machine the medians move with the load.
"""

from __future__ import annotations

import argparse
import sys
import time
from importlib import metadata
from pathlib import Path

import numba
import numpy as np

import tumble
from tumble import robot

from _timing import machine


try:
    import pinocchio as pin
except ImportError:  # the comparison is optional
    pin = None


def robots() -> dict[str, tuple[Path, bool]]:
    cases = {"industrial6": (tumble.examples.path("industrial6.urdf"), False)}
    try:
        erd = Path(metadata.distribution("example-robot-data").locate_file(
            "cmeel.prefix/share/example-robot-data/robots"))
    except metadata.PackageNotFoundError:
        return cases
    cases.update({"ur5": (erd / "ur_description/urdf/ur5_robot.urdf", False),
                  "panda": (erd / "panda_description/urdf/panda.urdf", False),
                  "talos": (erd / "talos_data/robots/talos_full_v2.urdf", True),
                  "solo12": (erd / "solo_description/robots/solo12.urdf", True)})
    return cases


def timed(fn, calls: int, repeats: int) -> tuple[float, float]:
    """(min, median) over ``repeats`` of the mean time of ``calls`` calls of ``fn``, µs."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        times.append((time.perf_counter() - start) / calls * 1e6)
    return float(np.min(times)), float(np.median(times))


def pin_state(model, tree, q, v):
    """Tumble's (q, v) in Pinocchio's coordinates (quaternion xyzw; base (v, ω)); joints matched by name."""
    index = {model.names[j]: model.joints[j].idx_v for j in range(1, model.njoints) if model.joints[j].nv == 1}
    of = np.array([index[n] for n in tree.joint_names])
    fl = int(tree.floating_base)
    pq, pv = np.zeros(model.nq), np.zeros(model.nv)
    if fl:
        pq[0:3], pq[3:6], pq[6] = q[0:3], q[4:7], q[3]
        pv[0:3], pv[3:6] = v[3:6], v[0:3]
    pq[of + fl] = q[7 * fl:]
    pv[of] = v[6 * fl:]
    return pq, pv, of


def fmt(pair) -> str:
    return f"{pair[0]:7.2f}/{pair[1]:<7.2f}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batch", type=int, default=20000, help="samples per batched call")
    parser.add_argument("--calls", type=int, default=2000, help="single calls per repeat")
    parser.add_argument("--repeats", type=int, default=7, help="repeats (min and median are printed), >= 5")
    args = parser.parse_args()
    print(f"{machine()}; {numba.get_num_threads()} Numba threads")
    print(f"tumble.robot vs {'Pinocchio ' + pin.__version__ if pin else 'no Pinocchio'}; batch of {args.batch}; "
          "µs per call (one state) or per sample (batch B); each cell min/median")
    cols = ["RNEA 1", "RNEA B", "pin.rnea", "pin.rneaPar", "CRBA 1", "pin.crba", "FD 1", "FD B", "pin.aba"]
    print(f"{'robot':<12} {'nv':>3} | " + " ".join(f"{c:>15}" for c in cols) + " | max|Δτ|")
    rng = np.random.default_rng(1)
    r = args.repeats
    for name, (path, floating) in robots().items():
        tree = robot.RobotTree.from_urdf(path, floating_base=floating, mimic=False, check_triangle=False)
        q = tree.neutral()
        q[tree.nq - tree.dof:] = rng.uniform(-1.0, 1.0, tree.dof)
        qd, qdd = rng.uniform(-1.0, 1.0, (2, tree.nv))
        Q, QD, QDD = np.tile(q, (args.batch, 1)), *rng.uniform(-1.0, 1.0, (2, args.batch, tree.nv))
        tau = robot.rnea(tree, q, qd, qdd)
        TAU = robot.rnea(tree, Q, QD, QDD)
        robot.mass_matrix(tree, q), robot.forward_dynamics(tree, Q, QD, TAU)
        row = [timed(lambda: robot.rnea(tree, q, qd, qdd), args.calls, r),
               tuple(x / args.batch for x in timed(lambda: robot.rnea(tree, Q, QD, QDD), 1, r))]
        peer = [(float("nan"),) * 2] * 2
        crba = [timed(lambda: robot.mass_matrix(tree, q), args.calls, r)]
        fd = [timed(lambda: robot.forward_dynamics(tree, q, qd, tau), args.calls, r),
              tuple(x / args.batch for x in timed(lambda: robot.forward_dynamics(tree, Q, QD, TAU), 1, r))]
        peer_crba = peer_aba = (float("nan"),) * 2
        delta = float("nan")
        if pin is not None:
            root = (pin.JointModelFreeFlyer(),) if floating else ()
            model = pin.buildModelFromUrdf(str(path), *root)
            data = model.createData()
            pq, pv, of = pin_state(model, tree, q, qd)
            pa = pin_state(model, tree, q, qdd)[1]
            ptau = pin_state(model, tree, q, tau)[1]
            expected = pin.rnea(model, data, pq, pv, pa)
            delta = float(np.abs(expected[of] - tau[tree.nv - tree.dof:]).max())
            peer[0] = timed(lambda: pin.rnea(model, data, pq, pv, pa), args.calls, r)
            if hasattr(pin, "rneaInParallel"):
                PQ, PV, PA = (np.asfortranarray(np.tile(x, (args.batch, 1)).T) for x in (pq, pv, pa))
                out = np.zeros((model.nv, args.batch), order="F")
                threads = numba.get_num_threads()
                pool = pin.ModelPool(model, threads)
                peer[1] = tuple(x / args.batch for x in timed(
                    lambda: pin.rneaInParallel(threads, pool, PQ, PV, PA, out), 1, r))
            peer_crba = timed(lambda: pin.crba(model, data, pq), args.calls, r)
            peer_aba = timed(lambda: pin.aba(model, data, pq, pv, ptau), args.calls, r)
        cells = [row[0], row[1], peer[0], peer[1], crba[0], peer_crba, fd[0], fd[1], peer_aba]
        print(f"{name:<12} {tree.nv:>3} | " + " ".join(fmt(c) for c in cells) + f" | {delta:.1e}")


if __name__ == "__main__":
    start = time.perf_counter()
    main()
    print(f"({time.perf_counter() - start:.0f} s)", file=sys.stderr)
