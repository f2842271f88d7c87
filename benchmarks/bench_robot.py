"""Speed of tumble.robot's RNEA, CRBA and forward dynamics beside Pinocchio, in one run, from the same URDFs.

    PYTHONPATH=src python benchmarks/bench_robot.py [--batch 20000] [--calls 2000] [--repeats 7]
    PYTHONPATH=src python benchmarks/bench_robot.py --centroidal     # only the centroidal momentum row

Robots: tumble's 6-axis industrial6.urdf and 7-DOF panda.urdf (``tumble.examples``), UR5 and Panda with its
two fingers (9 DOF; fixed base) and the Talos humanoid and Solo12 quadruped (floating base) from
example-robot-data. Pinocchio builds its model from the same file with its own URDF parser
(``buildModelFromUrdf``: axis-aligned RX/RY/RZ joints where the URDF has them), and the torques are compared
first. Per row: µs per call of ``tumble.robot.rnea`` / ``mass_matrix`` / ``forward_dynamics`` on one state
from Python and of Pinocchio's ``rnea`` / ``crba`` / ``aba`` from Python, in CPU time of the calling thread
(single calls run on one thread; other work on a shared machine does not count), the six timed in turn
within each repeat; per sample of a batched
call (parallel over the Numba threads) and of Pinocchio's ``rneaInParallel`` on as many threads N: the CPU
time of the call on one thread / N (what the N cores would give if they were this run's alone, with perfect
scaling; on N threads of a loaded machine the CPU time also counts OpenMP threads spinning at the barrier for
a descheduled one) and the wall time on N threads. Each figure: min and median over ``--repeats`` repeats
(≥ 5). Prints the CPU, the cores and the load average first, then the ratios the issue's goals name, and
last where one ``rnea`` call's time goes (the Python layer, the compiled entry, the sweep inside Numba).
``--centroidal``: the centroidal momentum that a floating-base ``tumble.simulate`` outputs at every sample,
Talos, µs per sample (thread CPU, min/median): compiled over a batch of samples, the same as ``A_G(q) q̇`` in
NumPy (what the output cost before it was compiled), and Pinocchio's ``computeCentroidalMomentum`` and ``aba``
per call.
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
from tumble.kernels import featherstone
from tumble.robot import dynamics

from _timing import machine


try:
    import pinocchio as pin
except ImportError:  # the comparison is optional
    pin = None


def robots() -> dict[str, tuple[Path, bool]]:
    cases = {"industrial6": (tumble.examples.path("industrial6.urdf"), False),
             "panda7": (tumble.examples.path("panda.urdf"), False)}
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


def singles(fns: dict, calls: int, repeats: int) -> dict[str, tuple[float, float]]:
    """(min, median) over ``repeats`` of the mean CPU time of this thread over ``calls`` calls of each of ``fns``
    (name: function), µs. Each repeat times every function in turn, so that a change of the machine's load
    falls on all of them alike."""
    times = {name: [] for name in fns}
    for _ in range(max(repeats, 5)):
        for name, fn in fns.items():
            start = time.thread_time()
            for _ in range(calls):
                fn()
            times[name].append((time.thread_time() - start) / calls * 1e6)
    return {name: (float(np.min(t)), float(np.median(t))) for name, t in times.items()}


def single(fn, calls: int, repeats: int) -> tuple[float, float]:
    """:func:`singles` of one function."""
    return singles({"": fn}, calls, repeats)[""]


def batched(fn, samples: int, threads: int, repeats: int) -> tuple[tuple[float, float], tuple[float, float]]:
    """Per sample, µs, (min, median) over ``repeats`` calls: ``fn(1)`` (one thread): process CPU time /
    (samples × threads); ``fn(threads)``: wall time / samples."""
    cpu, wall = [], []
    fn(1)
    for _ in range(max(repeats, 5)):
        c = time.process_time()
        fn(1)
        cpu.append((time.process_time() - c) / (samples * threads) * 1e6)
    fn(threads)
    for _ in range(max(repeats, 5)):
        w = time.perf_counter()
        fn(threads)
        wall.append((time.perf_counter() - w) / samples * 1e6)
    return (float(np.min(cpu)), float(np.median(cpu))), (float(np.min(wall)), float(np.median(wall)))


def on_threads(fn):
    """``fn`` as a function of the number of Numba threads it runs on (left set after the call)."""
    def run(n: int):
        numba.set_num_threads(n)
        return fn()
    return run


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


@numba.njit
def sweeps(P, q, qd, qdd, g, f, W, tau, n):
    """``n`` RNEA sweeps of one state inside Numba (no call from Python)."""
    for _ in range(n):
        featherstone.rnea_one(P, q, qd, qdd, g, f, W, tau)


def anatomy(tree, calls: int, repeats: int) -> str:
    """Thread CPU µs (min) of one ``rnea`` call from Python, of its compiled entry called directly, of the
    sweep inside Numba, of the type checks and of the result's allocation."""
    q, qd, qdd = np.random.default_rng(0).uniform(-1.0, 1.0, (3, tree.nv))
    P, g, f, S, tau = tree._params, tree._gravity, tree._no_wrench, tree._workspace, np.empty(tree.nv)
    entry = dynamics._one.rnea
    W = featherstone.scratch(P.shape[0])
    sweeps(P, q, qd, qdd, g, f, W, tau, 1)
    nothing = single(lambda: None, calls, repeats)[0]
    public = single(lambda: robot.rnea(tree, q, qd, qdd), calls, repeats)[0] - nothing
    direct = single(lambda: entry(P, q, qd, qdd, g, f, S, tau), calls, repeats)[0] - nothing
    sweep = single(lambda: sweeps(P, q, qd, qdd, g, f, W, tau, calls), 1, repeats)[0] / calls
    checks = single(lambda: dynamics._vectors(q, qd, qdd), calls, repeats)[0] - nothing
    result = single(lambda: np.empty(tree.nv), calls, repeats)[0] - nothing
    return (f"rnea {public:.2f} µs = Python layer {public - direct:.2f} (type checks {checks:.2f}, result "
            f"{result:.2f}) + compiled entry {direct:.2f} (sweep {sweep:.2f}, {sweep / tree.nv * 1e3:.0f} ns "
            "per joint)")


def centroidal(calls: int, repeats: int) -> str:
    """The ``--centroidal`` row (Talos, floating base, 20 random states)."""
    from tumble.robot import kinematics

    path = robots()["talos"][0]
    tree = robot.RobotTree.from_urdf(path, floating_base=True, mimic=False, check_triangle=False)
    rng = np.random.default_rng(2)
    Q = np.tile(tree.neutral(), (calls, 1))
    Q[:, 7:] = rng.uniform(-1.0, 1.0, (calls, tree.dof))
    QD = rng.uniform(-1.0, 1.0, (calls, tree.nv))
    compiled = single(lambda: kinematics.centroidal_momentum(tree, Q, QD), 1, repeats)
    numpy = single(lambda: kinematics.centroidal_momentum_matrix(tree, Q[0]) @ QD[0], max(calls // 100, 1),
                   repeats)
    row = (f"talos centroidal momentum, µs per sample: compiled {fmt(tuple(t / calls for t in compiled))}, "
           f"A_G q̇ in NumPy {fmt(numpy)}")
    if pin is not None:
        model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
        data = model.createData()
        pq, pv, _ = pin_state(model, tree, Q[0], QD[0])
        hg = pin.computeCentroidalMomentum(model, data, pq, pv)
        delta = np.abs(np.concatenate([hg.angular, hg.linear]) - kinematics.centroidal_momentum(tree, Q[0], QD[0]))
        timed = singles({"h": lambda: pin.computeCentroidalMomentum(model, data, pq, pv),
                         "aba": lambda: pin.aba(model, data, pq, pv, pv)}, calls, repeats)
        row += (f", pin.computeCentroidalMomentum {fmt(timed['h'])}, pin.aba {fmt(timed['aba'])}; "
                f"max|Δh| = {delta.max():.1e}")
    return row


def fmt(pair) -> str:
    return f"{pair[0]:5.2f}/{pair[1]:<5.2f}"


NAN = (float("nan"),) * 2


def ratio(a, b) -> tuple[float, float]:
    """(min / min, median / median) of two (min, median) timings."""
    return a[0] / b[0], a[1] / b[1]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batch", type=int, default=20000, help="samples per batched call")
    parser.add_argument("--calls", type=int, default=2000, help="single calls per repeat")
    parser.add_argument("--repeats", type=int, default=7, help="repeats (min and median are printed), >= 5")
    parser.add_argument("--centroidal", action="store_true", help="only the centroidal momentum row (Talos)")
    args = parser.parse_args()
    r, B = args.repeats, args.batch
    if args.centroidal:
        print(f"{machine()}\n{centroidal(args.calls, r)}")
        return
    threads = numba.get_num_threads()
    print(f"{machine()}; {threads} Numba threads")
    print(f"tumble.robot vs {'Pinocchio ' + pin.__version__ if pin else 'no Pinocchio'}; µs per call of one state "
          f"(CPU time of the thread) or per sample of a batch of {B} (cpu: CPU time on one thread / {threads}; wall: "
          f"on {threads} threads); each cell min/median")
    cols = ["RNEA 1", "pin.rnea", "CRBA 1", "pin.crba", "FD 1", "pin.aba", "RNEA B cpu", "RNEA B wall",
            "rneaPar cpu", "rneaPar wall", "FD B cpu"]
    print(f"{'robot':<12} {'nv':>3} | " + " ".join(f"{c:>11}" for c in cols) + " | max|Δτ|")
    rng = np.random.default_rng(1)
    rows = {}
    for name, (path, floating) in robots().items():
        tree = robot.RobotTree.from_urdf(path, floating_base=floating, mimic=False, check_triangle=False)
        q = tree.neutral()
        q[tree.nq - tree.dof:] = rng.uniform(-1.0, 1.0, tree.dof)
        qd, qdd = rng.uniform(-1.0, 1.0, (2, tree.nv))
        Q, QD, QDD = np.tile(q, (B, 1)), *rng.uniform(-1.0, 1.0, (2, B, tree.nv))
        tau = robot.rnea(tree, q, qd, qdd)
        TAU = robot.rnea(tree, Q, QD, QDD)
        robot.mass_matrix(tree, q), robot.forward_dynamics(tree, q, qd, tau), robot.forward_dynamics(tree, Q, QD, TAU)
        one_state = {"RNEA 1": lambda: robot.rnea(tree, q, qd, qdd), "CRBA 1": lambda: robot.mass_matrix(tree, q),
                     "FD 1": lambda: robot.forward_dynamics(tree, q, qd, tau)}
        row = {}
        row["RNEA B cpu"], row["RNEA B wall"] = batched(on_threads(lambda: robot.rnea(tree, Q, QD, QDD)), B,
                                                        threads, r)
        row["FD B cpu"] = batched(on_threads(lambda: robot.forward_dynamics(tree, Q, QD, TAU)), B, threads, r)[0]
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
            one_state.update({"pin.rnea": lambda: pin.rnea(model, data, pq, pv, pa),
                              "pin.crba": lambda: pin.crba(model, data, pq),
                              "pin.aba": lambda: pin.aba(model, data, pq, pv, ptau)})
            if hasattr(pin, "rneaInParallel"):
                PQ, PV, PA = (np.asfortranarray(np.tile(x, (B, 1)).T) for x in (pq, pv, pa))
                out = np.zeros((model.nv, B), order="F")
                pool = pin.ModelPool(model, threads)
                row["rneaPar cpu"], row["rneaPar wall"] = batched(
                    lambda n: pin.rneaInParallel(n, pool, PQ, PV, PA, out), B, threads, r)
        row.update(singles(one_state, args.calls, r))
        rows[name] = row
        print(f"{name:<12} {tree.nv:>3} | " + " ".join(f"{fmt(row.get(c, NAN)):>11}" for c in cols)
              + f" | {delta:.1e}", flush=True)
    print(f"Numba threading layer: {numba.threading_layer()}")
    if pin is not None:
        print("goals (min/median ratios or µs):")
        for name in ("industrial6", "ur5", "panda7", "panda"):
            if name in rows:
                x = rows[name]
                print(f"  {name:<12} RNEA 1 / pin.rnea {fmt(ratio(x['RNEA 1'], x['pin.rnea']))} (goal <= 1.0);"
                      f"  CRBA 1 / pin.crba {fmt(ratio(x['CRBA 1'], x['pin.crba']))} (goal <= 1.2)")
        x = rows["panda7"]
        print(f"  panda7       RNEA B per sample: {fmt(x['RNEA B cpu'])} µs CPU-based, {fmt(x['RNEA B wall'])} µs "
              "wall (goal <= 0.2)")
        if "talos" in rows and "rneaPar cpu" in rows["talos"]:
            x = rows["talos"]
            print(f"  talos        RNEA B / rneaInParallel per sample: "
                  f"{fmt(ratio(x['RNEA B cpu'], x['rneaPar cpu']))} CPU-based, "
                  f"{fmt(ratio(x['RNEA B wall'], x['rneaPar wall']))} wall (goal < 1)")
    arm = robot.RobotTree.from_urdf(robots()["panda7"][0])
    print(f"panda7, where one call's time goes (thread CPU, min): {anatomy(arm, 10 * args.calls, r)}")


if __name__ == "__main__":
    start = time.perf_counter()
    main()
    print(f"({time.perf_counter() - start:.0f} s)", file=sys.stderr)
