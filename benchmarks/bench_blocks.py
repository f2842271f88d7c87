"""Blocks behind function pointers (``tumble._block``) against the kind's kernel inlined into the block driver.

Both paths are in the code: ``integrate._fixed.run_block`` given the kind's own kernel (its overloads inlined:
one driver compiled per kind and method, the path every batch took before ``tumble._block``) or given its
:class:`tumble._block.BlockModel` (one driver per method for every kind, the kind's functions called through
pointers: the path a batch takes now)::

    python benchmarks/bench_blocks.py steps     # CPU ns per step of a block of 64 lanes, best of 7, interleaved
    python benchmarks/bench_blocks.py compile   # CPU s of each first call, each path in a new process, empty cache
    ... --spacecraft                            # the spacecraft too (several minutes of compile on 2 cores)

The kinds run in the order below, so in ``compile`` the first kind's row also holds what the kinds share (the
driver of the pointers' path, the torque program's evaluator, the quaternion helpers).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

LANES = 64
DT = 0.01


def models(spacecraft: bool) -> dict:
    """name -> (model, torque): the kinds moved to blocks, each with a torque program where it takes one (the
    deformable bodies' splines span the 10 s of :func:`steps`' runs)."""
    import tumble
    from tumble import torques
    from tumble.flexible import FlexibleBody, Mode
    from tumble.fluid import KirchhoffBody
    from tumble.slosh import Pendulum, SloshBody

    inertia = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
    torque = torques.ConstantBody([0.05, -0.02, 0.1])
    fluid = np.diag([5.0, 8.0, 9.0, 1.0, 2.0, 2.5])
    fluid[0, 4] = fluid[4, 0] = 0.3
    found = {
        "FlexibleBody (2 modes)": (FlexibleBody(inertia, [Mode(3.0, 0.02, [0.3, 0.5, 0.2]),
                                                          Mode(7.0, 0.01, [0.1, -0.4, 0.6])]), torque),
        "SloshBody": (SloshBody(tumble.RigidBody(inertia, mass=10.0),
                                Pendulum(mass=2.0, length=0.5, hinge=[0.3, -0.2, 0.4], damping=0.1)), torque),
        "KirchhoffBody": (KirchhoffBody(tumble.RigidBody(inertia, mass=20.0), fluid), None),
    }
    from tumble.variable import Human, Motion, VariableBody

    def growing(t):  # an inertia growing by 1 % a second, splined over the 10 s a block runs
        return inertia * (1.0 + 0.01 * np.asarray(t))[:, None, None]

    found["VariableBody"] = (VariableBody.from_functions(growing, t_span=(0.0, 10.0), dt=0.01), torque)
    found["MovingHuman"] = (Human.de_leva().moving({"left_shoulder_abduction": Motion(np.pi, [(0.0, 10.0, 0.0)])},
                                                   t_span=(0.0, 10.0)), None)
    from tumble.ins import GimbaledGyro

    found["GimbaledGyro"] = (GimbaledGyro(spin_inertia=2e-3, transverse_inertia=1.5e-3,
                                          inner_gimbal=(4e-4, 5e-4, 3e-4), outer_gimbal=1e-3, imbalance=0.01), None)
    if spacecraft:
        from tumble.spacecraft import MRPFeedback, Spacecraft, pyramid_wheels

        target = [np.cos(0.2), 0.0, np.sin(0.2), 0.0]
        found["Spacecraft (4 wheels, MRP)"] = (Spacecraft(inertia=inertia, wheels=pyramid_wheels(0.02),
                                                          controller=MRPFeedback(K=1.0, P=5.0, target=target)), None)
    return found


def block(model, torque, lanes: int = LANES):
    """``(kernel, y0)``: the model's kernel and ``lanes`` initial states (spread body rates), as simulate makes
    them."""
    from tumble.simulate import _initial_values

    kernel = model.compile(torque, 0.0)
    spread = 1.0 + 0.01 * np.arange(lanes)
    fields = [f.name for f in model.state_fields()]
    state = {"omega0": np.array([0.3, 1.0, -0.4]) * spread[:, None]} if "omega0" in fields else {
        "spin": 100.0 * spread[:, None], "theta0": np.ones((lanes, 1))}  # a gimbaled gyro
    if "direction0" in fields:
        state["direction0"] = np.tile([0.0, 0.0, -1.0], (lanes, 1))
    values, _ = _initial_values(model, state)
    return kernel, model.initial_states(kernel, values, 0.0)


def methods(kernel) -> tuple[str, ...]:
    """The block methods of a kernel: rk4, and cf4 where it gives its body rate."""
    return ("rk4", "cf4") if "body_rate" in kernel.provides else ("rk4",)


def run(kernel, y0, method: str, steps: int) -> np.ndarray:
    """``steps`` steps of ``DT`` of the block ``y0`` through ``run_block`` of ``method`` with ``kernel`` (the
    kind's own or its BlockModel); the path."""
    from tumble.integrate import METHODS, _fixed

    driver = METHODS[method].driver
    t = np.array([0.0, steps * DT])
    m, h = driver.plan(t, {"dt": DT, "max_steps": 10**9})
    y = np.array(y0)
    out = np.empty((2, *y.shape))
    _fixed.run_block(driver.scheme, kernel, 0, y, t, m, h, out, np.zeros((y.shape[0], 5)))
    return out


def steps(spacecraft: bool, count: int = 1000, repeats: int = 7) -> dict:
    """CPU ns per block step, best of ``repeats`` (the two paths interleaved), and whether they agree bit for
    bit, per kind and method."""
    from tumble import _block

    rows = {}
    for name, (model, torque) in models(spacecraft).items():
        kernel, y0 = block(model, torque)
        pointers = _block.block_model(kernel)
        for method in methods(kernel):
            calls = {"inlined": lambda: run(kernel, y0, method, count), "pointers": lambda: run(pointers, y0, method,
                                                                                                 count)}
            paths = {path: call() for path, call in calls.items()}  # compiled here, outside the timing
            best = dict.fromkeys(calls, np.inf)
            for _ in range(repeats):
                for path, call in calls.items():
                    start = time.process_time()
                    call()
                    best[path] = min(best[path], time.process_time() - start)
            rows[f"{name}, {method}"] = {
                **{f"{path} ns/block step": round(seconds / count * 1e9) for path, seconds in best.items()},
                "change %": round(100.0 * (best["pointers"] / best["inlined"] - 1.0), 1),
                "bits equal": bool(np.array_equal(paths["inlined"].view(np.int64),
                                                  paths["pointers"].view(np.int64)))}
    return rows


def first_calls(path: str, spacecraft: bool) -> dict:
    """CPU s of the first call (compile included) of a block of each kind, rk4 then cf4, in this process (run
    with an empty ``NUMBA_CACHE_DIR``), through ``path``: "inlined" or "pointers"."""
    from tumble import _block

    rows = {}
    for method in ("rk4", "cf4"):
        for name, (model, torque) in models(spacecraft).items():
            kernel, y0 = block(model, torque, lanes=2)
            if method not in methods(kernel):
                continue
            start = time.process_time()
            run(_block.block_model(kernel) if path == "pointers" else kernel, y0, method, 2)
            rows[f"{name}, {method}"] = round(time.process_time() - start, 2)
    return rows


def compile_times(spacecraft: bool) -> dict:
    """:func:`first_calls` of each path, each in a new process with its own empty ``NUMBA_CACHE_DIR``."""
    rows: dict = {}
    for path in ("inlined", "pointers"):
        with tempfile.TemporaryDirectory(prefix="bench-blocks-") as cache:
            done = subprocess.run([sys.executable, __file__, "--child", path] + ["--spacecraft"] * spacecraft,
                                  env={**os.environ, "NUMBA_CACHE_DIR": cache}, check=True, capture_output=True,
                                  text=True)
        for row, seconds in json.loads(done.stdout.strip().splitlines()[-1]).items():
            rows.setdefault(row, {})[f"{path}, first call CPU s"] = seconds
    return rows


def main(argv: list[str]) -> None:
    spacecraft = "--spacecraft" in argv
    if argv[:1] == ["--child"]:
        print(json.dumps(first_calls(argv[1], spacecraft)))
        return
    sys.path.insert(0, os.path.dirname(__file__))
    from _timing import machine

    print(machine())
    rows = compile_times(spacecraft) if argv[:1] == ["compile"] else steps(spacecraft)
    for row, values in rows.items():
        print(f"| {row} | " + " | ".join(f"{key}: {value}" for key, value in values.items()) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
