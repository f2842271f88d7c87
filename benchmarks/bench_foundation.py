"""Foundation benchmark: tumble's RK4 and DOP853 beside their peers, in one run (issue 17, goals 1-3).

Prints, side by side, with the machine (CPU model, cores, load average), min / median over at least
5 repeats, wall and CPU-time-based rates (``_timing``):

1. single-body RK4, cost per step: tumble's compiled loop, the same step on two independent bodies in one
   loop (what the step costs when its chain of dependent operations is not the bound), a naive Numba loop
   and a NumPy loop;
2. batch RK4, body-steps per second on all cores, one shared inertia and one inertia per body:
   ``simulate`` end to end and its compiled kernel alone, beside a hand-written C kernel
   (``rk4_reference.c``, all four stages fused in registers) built here with
   ``gcc -O3 -march=native -fopenmp -fno-math-errno`` when gcc is present, with and without
   ``-ffp-contract=off`` (no fused multiply-adds, as tumble);
   and the same batch and one body under compiled torque programs (a constant torque, gravity on a top);
3. the cost per body of set-up and output at N = 1e6 (a run of one step, less the kernel's share);
4. the adaptive method against scipy's ``solve_ivp(DOP853)`` at equal error, end to end, with scipy
   given a fair right-hand side (one preallocated-free expression returning one array), the cost of one
   DOP853 step over a long run beside one right-hand side and one projection measured alone, and the
   fixed cost of one ``simulate`` call.

Run by hand (not a test; timings vary with the machine)::

    python benchmarks/bench_foundation.py            # full run
    python benchmarks/bench_foundation.py --quick    # smaller sizes
"""

from __future__ import annotations

import argparse
import ctypes
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from numba import njit
from scipy.integrate import solve_ivp

import tumble
from _timing import fmt, machine, measure
from tumble import attitude
from tumble._protocol import project, rhs
from tumble._validate import readonly
from tumble.integrate import _fixed, _rk4
from tumble.kernels import rigid as _rigid
from tumble.rigid_model import RigidBodies

MOMENTS = np.array([1.0, 2.0, 3.0])          # kg m², principal axes = body axes
C1, C2, C3 = (MOMENTS[1] - MOMENTS[2]) / MOMENTS[0], (MOMENTS[2] - MOMENTS[0]) / MOMENTS[1], \
    (MOMENTS[0] - MOMENTS[1]) / MOMENTS[2]
OMEGA0 = np.array([1e-3, 1.0, 1e-3])          # rad/s: near the intermediate axis (flips)
# For the accuracy comparison, a motion far from the separatrix: near it, rounding
# differences of 1e-16 grow to 1e-9 in 100 s, and no reference can tell methods apart.
OMEGA0_ACCURACY = np.array([1.0, 0.2, 0.5])
Q0 = np.array([1.0, 0.0, 0.0, 0.0])
CORES = len(os.sched_getaffinity(0))


def euler_rhs(t, y):
    """Euler's equations + quaternion kinematics for solve_ivp: one array built from scalars (fair to scipy)."""
    qw, qx, qy, qz, w1, w2, w3 = y
    return np.array([0.5 * (-qx * w1 - qy * w2 - qz * w3), 0.5 * (qw * w1 + qy * w3 - qz * w2),
                     0.5 * (qw * w2 - qx * w3 + qz * w1), 0.5 * (qw * w3 + qx * w2 - qy * w1),
                     C1 * w2 * w3, C2 * w3 * w1, C3 * w1 * w2])


def rk4_loop(rhs, y, dt, steps):
    """A hand-written RK4 loop on ``rhs(t, y)``, normalising q each step: in NumPy with :func:`euler_rhs`
    (the peer for the per-step cost), and the same loop under ``@njit`` with the right-hand side under
    ``@njit``, as a user would write it (the issue's 'naive Numba loop')."""
    for k in range(steps):
        t = k * dt
        k1 = rhs(t, y)
        k2 = rhs(t + dt / 2, y + dt / 2 * k1)
        k3 = rhs(t + dt / 2, y + dt / 2 * k2)
        k4 = rhs(t + dt, y + dt * k3)
        y = y + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        y[:4] /= np.sqrt(y[0] ** 2 + y[1] ** 2 + y[2] ** 2 + y[3] ** 2)
    return y


naive_rhs = njit(euler_rhs)
naive_numba_rk4 = njit(rk4_loop)


@njit(error_model="numpy")
def two_chains(model, y, z, t0, h, m):
    """``m`` RK4 steps of two independent bodies ``y`` and ``z`` (updated in place) in one loop, by tumble's
    one-body step: the second body's step fills the gaps of the first's chain of dependent operations."""
    a = (y[0], y[1], y[2], y[3], y[4], y[5], y[6])
    b = (z[0], z[1], z[2], z[3], z[4], z[5], z[6])
    for s in range(m):
        a = _rk4.point_step(model, 0, t0 + s * h, h, a)
        b = _rk4.point_step(model, 0, t0 + s * h, h, b)
    y[0], y[1], y[2], y[3], y[4], y[5], y[6] = a
    z[0], z[1], z[2], z[3], z[4], z[5], z[6] = b


@njit(error_model="numpy")
def rhs_chain(model, y, out, m):
    """``m`` right-hand sides of the one-body state ``y``, each fed by the last (a dependent chain)."""
    for _ in range(m):
        rhs(model, 0, 0.0, y, out)
        y[4] = y[4] + 1e-12 * out[5]


@njit(error_model="numpy")
def project_chain(model, y, m):
    """``m`` projections of the quaternion of ``y`` onto the unit sphere, each of a perturbed quaternion."""
    for _ in range(m):
        project(model, 0, 0.0, y)
        y[0] += 1e-12


def dop853_step(t_end=20_000.0):
    """CPU ns (min / median) of one DOP853 step over a long run (the fixed cost spread over ≈ 5e4 steps), and,
    measured alone, of one right-hand side and one projection of the quaternion."""
    body = tumble.RigidBody(np.diag(MOMENTS))
    t = np.array([0.0, t_end / 2, t_end])
    steps = tumble.simulate(body, OMEGA0_ACCURACY, t=t, rtol=1e-10, atol=1e-10).info["n_steps"]
    run = measure(lambda: tumble.simulate(body, OMEGA0_ACCURACY, t=t, rtol=1e-10, atol=1e-10))
    model = _rigid.build([body], None)
    y, out, m = np.concatenate([Q0, OMEGA0_ACCURACY]), np.empty(7), 10**6
    rhs_chain(model, y, out, 10)
    project_chain(model, y.copy(), 10)
    ns = lambda timing, n: tuple(1e9 / r for r in timing.rates(n)["cpu"])  # noqa: E731
    return steps, {"step": ns(run, steps), "rhs": ns(measure(lambda: rhs_chain(model, y, out, m)), m),
                   "projection": ns(measure(lambda: project_chain(model, y.copy(), m)), m)}


def single_body(steps):
    """ns per step (CPU, min / median): tumble's one-body path, the same step on two independent bodies in
    one loop (per step of one body), the naive Numba loop, NumPy."""
    model = _rigid.build([tumble.RigidBody(np.diag(MOMENTS))], None)
    y = np.concatenate([Q0, OMEGA0])[None, :]
    t = np.array([0.0, steps * 1e-3])
    m, h = _fixed.landing_steps(t, 1e-3, 10**9)
    out, stats = np.empty((2, 1, 7)), np.zeros((1, 5))
    t = readonly(t)  # the arguments' types those of simulate's call: the same compiled function runs
    run = lambda: _fixed.run_one(_rk4.SCHEME, model, y.copy(), t, m, h, out, stats)  # noqa: E731
    run()  # compile / load from cache
    naive_numba_rk4(naive_rhs, y[0].copy(), 1e-3, 10)
    z = np.concatenate([Q0, OMEGA0 + np.array([0.01, 0.0, -0.01])])  # another body, its own path
    pair = lambda: two_chains(model, y[0].copy(), z.copy(), 0.0, 1e-3, steps)  # noqa: E731
    pair()
    ns = lambda timing, n: tuple(1e9 / r for r in timing.rates(n)["cpu"])  # noqa: E731
    return {"tumble": ns(measure(run), steps), "2 bodies/loop": ns(measure(pair), 2 * steps),
            "naive Numba": ns(measure(lambda: naive_numba_rk4(naive_rhs, y[0].copy(), 1e-3, steps)), steps),
            "NumPy": ns(measure(lambda: rk4_loop(euler_rhs, y[0].copy(), 1e-3, 2000)), 2000)}


def numba_target():
    """The CPU name Numba compiles for, and whether its features include AVX-512 (``NUMBA_CPU_NAME``,
    ``NUMBA_CPU_FEATURES`` set them; else the host's)."""
    from numba.core import config
    from llvmlite import binding

    name = config.CPU_NAME or binding.get_host_cpu_name()
    features = config.CPU_FEATURES if config.CPU_FEATURES is not None else binding.get_host_cpu_features().flatten()
    return f"{name}, {'AVX-512' if '+avx512f' in features else 'no AVX-512'}"


def c_reference(march="native"):
    """The C kernel's ``rk4_batch`` (ctypes) for ``gcc -march=MARCH``, built twice, ``{"C reference": …, "C, no FMA": …}``: as gcc
    contracts ``a·b + c`` into fused multiply-adds by default, and with ``-ffp-contract=off``, rounding every
    operation as tumble does (which must not contract: its CPU and CUDA-simulator states agree bit for bit).
    Empty without gcc."""
    gcc = shutil.which("gcc")
    if gcc is None:
        return {}
    kernels = {}
    for name, flags in (("C reference", []), ("C, no FMA", ["-ffp-contract=off"])):
        lib = Path(tempfile.mkdtemp()) / "rk4_reference.so"
        subprocess.run([gcc, "-O3", f"-march={march}", "-fopenmp", "-fno-math-errno", *flags, "-shared", "-fPIC",
                        "-o", str(lib), str(Path(__file__).with_name("rk4_reference.c"))], check=True)
        f = ctypes.CDLL(str(lib)).rk4_batch
        f.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_ssize_t, ctypes.c_double,
                      ctypes.c_long]
        kernels[name] = f
    return kernels


def batch(n_bodies, steps, per_body, c_kernels):
    """Body-steps per second (wall and CPU × cores, min / median): tumble.simulate, its compiled kernel alone
    (``_fixed.run_batch``: no set-up or output conversion) and the C kernels."""
    rng = np.random.default_rng(1)
    omega0 = OMEGA0 + 1e-2 * rng.standard_normal((n_bodies, 3))
    t = np.array([0.0, steps * 1e-3])
    scale = 1.0 + 0.1 * rng.random(n_bodies) if per_body else np.ones(1)
    model = RigidBodies.of(np.diag(MOMENTS) * scale[:, None, None]) if per_body else tumble.RigidBody(np.diag(MOMENTS))
    tumble.simulate(model, omega0, t=t[:1].tolist() + [1e-3], method="rk4", dt=1e-3)  # compile / load from cache
    work = n_bodies * steps
    rows = {"tumble": measure(lambda: tumble.simulate(model, omega0, t=t, method="rk4", dt=1e-3)).rates(work, CORES)}
    kernel = _rigid.from_principal(MOMENTS[None] * scale[:, None], np.broadcast_to(np.eye(3), (scale.size, 3, 3)),
                                   None)
    m, h = _fixed.landing_steps(t, 1e-3, 10**9)
    y = np.zeros((n_bodies, 7))
    y[:, 0], y[:, 4:] = 1.0, omega0
    # the arguments' types those of simulate's call (read-only times, float statistics): the same compiled
    # function runs, not a copy compiled here against a cached rest (docs/architecture.md)
    out, stats, t = np.empty((2, n_bodies, 7)), np.zeros((n_bodies, 5)), readonly(t)
    rows["kernel alone"] = measure(lambda: _fixed.run_batch(_rk4.SCHEME, kernel, y, t, m, h, out, stats)).rates(
        work, CORES)
    for name, c_kernel in c_kernels.items():
        y = np.zeros((7, n_bodies))
        y[0], y[4:] = 1.0, omega0.T
        # (3, N) one column per body (a scaled inertia has the same c₁, c₂, c₃: the memory traffic is the point)
        c = np.ascontiguousarray(np.repeat([[C1], [C2], [C3]], n_bodies if per_body else 1, axis=1))
        rows[name] = measure(lambda c_kernel=c_kernel, y=y, c=c: c_kernel(
            y.ctypes.data, c.ctypes.data, int(per_body), n_bodies, 1e-3, steps)).rates(work, CORES)
    return rows


def torque_programs(n_bodies, steps):
    """``simulate`` rk4 under compiled torque programs (a constant body torque, uniform gravity on a top):
    body-steps per second of the batch (wall and CPU × cores, min / median) and CPU ns per step of one body."""
    from tumble.torques import ConstantBody, Gravity

    rng = np.random.default_rng(1)
    omega0 = OMEGA0 + 1e-2 * rng.standard_normal((n_bodies, 3))
    t, t_one = np.array([0.0, steps * 1e-3]), np.array([0.0, 100 * steps * 1e-3])
    body = tumble.RigidBody(np.diag(MOMENTS))
    rows = {}
    for name, torque in (("none", None), ("constant", ConstantBody([0.0, 0.0, 0.01])),
                         ("gravity", Gravity(1.0, [0.0, 0.0, 0.1]))):
        run = lambda omega, t, torque=torque: tumble.simulate(body, omega, t=t, method="rk4", dt=1e-3,  # noqa: E731
                                                              torque=torque)
        run(omega0[:100], t[:1].tolist() + [1e-3])  # compile / load from cache
        run(omega0[0], t[:1].tolist() + [1e-3])
        one = measure(lambda run=run: run(omega0[0], t_one)).rates(100 * steps)["cpu"]
        rows[name] = {**measure(lambda run=run: run(omega0, t)).rates(n_bodies * steps, CORES),
                      "one": tuple(1e9 / r for r in one)}
    return rows


def big_batch_overhead(n_bodies, per_body=False):
    """CPU ns per body of set-up and output at N = n_bodies: a one-step run less one step's kernel cost.

    With ``per_body``, the model is an inertia array (N, 3, 3) of rotated tensors, so the set-up includes
    validating each tensor and finding its principal axes."""
    rng = np.random.default_rng(2)
    body = tumble.RigidBody(np.diag(MOMENTS))
    if per_body:
        r = attitude.to_matrix(rng.standard_normal((n_bodies, 4)))
        body = r @ ((MOMENTS * rng.uniform(1.0, 1.1, (n_bodies, 1)))[..., None] * np.swapaxes(r, -1, -2))
    omega0 = OMEGA0 + 1e-2 * rng.standard_normal((n_bodies, 3))
    one = measure(lambda: tumble.simulate(body, omega0, t=[0.0, 1e-3], method="rk4", dt=1e-3), 3)
    ten = measure(lambda: tumble.simulate(body, omega0, t=[0.0, 1e-2], method="rk4", dt=1e-3), 3)
    per_step = (ten.cpu.min() - one.cpu.min()) / 9
    setup = (np.array([one.cpu.min(), np.median(one.cpu)]) - per_step) / n_bodies * 1e9
    return setup, per_step / n_bodies * 1e9


def adaptive_vs_scipy(t_end, rtol, atol, reference):
    t = np.linspace(0.0, t_end, 101)
    y0 = np.concatenate([Q0, OMEGA0_ACCURACY])
    body = tumble.RigidBody(np.diag(MOMENTS))
    tumble.simulate(body, OMEGA0_ACCURACY, t=t[:3], rtol=rtol, atol=atol)  # compile / load from cache
    ours = measure(lambda: tumble.simulate(body, OMEGA0_ACCURACY, t=t, rtol=rtol, atol=atol))
    theirs = measure(lambda: solve_ivp(euler_rhs, (0.0, t_end), y0, method="DOP853", t_eval=t, rtol=rtol, atol=atol))
    return {"tumble": ours.seconds(), "scipy": theirs.seconds(),
            "tumble_err": np.abs(ours.result.omega - reference).max(),
            "scipy_err": np.abs(theirs.result.y[4:].T - reference).max()}


_COMPILING = """
import os, sys, time
import numpy as np
import tumble
body = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
n, steps = int(sys.argv[1]), int(sys.argv[2])
omega0 = np.array([1e-3, 1.0, 1e-3]) + 1e-2 * np.random.default_rng(1).standard_normal((n, 3))
tumble.simulate(body, omega0, t=[0.0, 1e-3], method="rk4", dt=1e-3)  # compiles the batch path here
best = float("inf")
for _ in range(5):
    start = time.process_time()
    tumble.simulate(body, omega0, t=[0.0, steps * 1e-3], method="rk4", dt=1e-3)
    best = min(best, time.process_time() - start)
print(n * steps / best * len(os.sched_getaffinity(0)))
"""


def compiling_process_rate(n_bodies, steps):
    """Body-steps/s (CPU × cores, best of 5) of the shared-inertia batch in a new process that compiles the
    batch path itself (an empty ``NUMBA_CACHE_DIR``): it runs the copy of the lane passes compiled on its
    own, which ran scalar, 5x slower, until they were compiled without reference counting
    (``_fused.advance`'s lane passes`, docs/architecture.md)."""
    with tempfile.TemporaryDirectory() as cache:
        done = subprocess.run([sys.executable, "-c", _COMPILING, str(n_bodies), str(steps)], check=True,
                              capture_output=True, text=True, env=dict(os.environ, NUMBA_CACHE_DIR=cache))
    return float(done.stdout.split()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="smaller sizes")
    parser.add_argument("--march", default="native",
                        help="gcc's -march for the C kernel; give Numba the same target through NUMBA_CPU_NAME and "
                             "NUMBA_CPU_FEATURES (e.g. haswell and '+avx,+avx2,+fma') to compare on another ISA")
    args = parser.parse_args()
    print(machine())
    print(f"Numba target: {numba_target()}; C kernel: gcc -march={args.march}")
    # the rows measure compiled code loaded from the cache, as every process after the first runs it (row 2c:
    # the process that compiles)
    subprocess.run([sys.executable, "-m", "tumble", "warmup"], check=True, capture_output=True)
    print(f"tumble {tumble.__version__}; body I = diag{MOMENTS.tolist()} kg m²; min / median of >= 5 repeats; "
          f"'cpu' rates = work / CPU s × {CORES} cores\n")

    r = single_body(20_000 if args.quick else 200_000)
    print("1. single-body RK4, CPU ns per step (min / median)")
    for name, v in r.items():
        print(f"   {name:<14} {fmt(v, ' ns')}")

    c_kernels = c_reference(args.march)
    n_bodies, steps = (20_000, 200) if args.quick else (100_000, 500)
    for per_body in (False, True):
        print(f"\n2{'b' if per_body else 'a'}. batch RK4, N = {n_bodies}, {steps} steps, "
              f"{'one inertia per body' if per_body else 'one shared inertia'}: body-steps/s (min-time / median)")
        rows = batch(n_bodies, steps, per_body, c_kernels)
        for name, v in rows.items():
            print(f"   {name:<13} wall {fmt(v['wall'])}   cpu {fmt(v['cpu'])}")
        for c_name in ("C reference", "C, no FMA"):
            if c_name in rows:
                print(f"   tumble / {c_name} (cpu, best): {rows['tumble']['cpu'][0] / rows[c_name]['cpu'][0]:.0%}; "
                      f"kernel alone: {rows['kernel alone']['cpu'][0] / rows[c_name]['cpu'][0]:.0%}")

    print(f"\n2c. batch RK4 as 2a, in a new process that compiles it (empty NUMBA_CACHE_DIR): "
          f"{compiling_process_rate(n_bodies, steps):.3g} body-steps/s (cpu, best of 5)")

    print(f"\n2d. rk4 under a compiled torque program: the batch as 2a (body-steps/s, min-time / median), one body "
          f"(CPU ns per step, min / median)")
    for name, v in torque_programs(n_bodies, steps).items():
        print(f"   {name:<9} batch wall {fmt(v['wall'])}   cpu {fmt(v['cpu'])}   one body {fmt(v['one'], ' ns')}")

    n_big = 200_000 if args.quick else 1_000_000
    setup, step = big_batch_overhead(n_big)
    print(f"\n3. N = {n_big}: set-up and output {setup[0]:.0f} / {setup[1]:.0f} CPU ns per body per call (min / "
          f"median); one step {step:.1f} ns per body")
    setup, step = big_batch_overhead(n_big, per_body=True)
    print(f"   one inertia per body, (N, 3, 3) rotated tensors: set-up and output {setup[0]:.0f} / {setup[1]:.0f} "
          f"CPU ns per body per call; one step {step:.1f} ns per body")

    t = np.linspace(0.0, 100.0, 101)
    y0 = np.concatenate([Q0, OMEGA0_ACCURACY])
    reference = solve_ivp(euler_rhs, (0.0, 100.0), y0, method="DOP853", t_eval=t, rtol=2.3e-14, atol=1e-16).y[4:].T
    print("\n4. adaptive DOP853 at the same tolerance, t = 0..100 s, 101 outputs; error = max |Δω| (rad/s) against "
          "scipy DOP853 at rtol = 2.3e-14, atol = 1e-16; wall s (min / median)")
    print(f"   {'rtol=atol':>10} {'tumble s':>20} {'scipy s':>20} {'speed-up':>9} {'tumble err':>11} {'scipy err':>11}")
    for tol in (1e-8, 1e-10, 1e-12):
        r = adaptive_vs_scipy(100.0, tol, tol, reference)
        print(f"   {tol:10.0e} {fmt(r['tumble']):>20} {fmt(r['scipy']):>20} {r['scipy'][0] / r['tumble'][0]:8.0f}x "
              f"{r['tumble_err']:11.2e} {r['scipy_err']:11.2e}")
    steps, cost = dop853_step()
    print(f"   one DOP853 step ({steps} steps over 0..20 000 s, rtol = atol = 1e-10): {fmt(cost['step'], ' ns')} CPU; "
          f"measured alone, one right-hand side {fmt(cost['rhs'], ' ns')} (a step makes 12), the projection "
          f"{fmt(cost['projection'], ' ns')}")
    body = tumble.RigidBody(np.diag(MOMENTS))
    for method, options in (("dop853", {}), ("rk4", {"dt": 1e-3})):
        tumble.simulate(body, OMEGA0_ACCURACY, t=[0.0, 1e-3], method=method, **options)
        c = measure(lambda: tumble.simulate(body, OMEGA0_ACCURACY, t=[0.0, 1e-3], method=method, **options), 200)
        print(f"   fixed cost of one simulate call ({method}, one step): {c.cpu.min() * 1e6:.0f} / "
              f"{np.median(c.cpu) * 1e6:.0f} µs CPU (min / median)")


if __name__ == "__main__":
    main()
