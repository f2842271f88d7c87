"""GPU benchmark: RK4 on an NVIDIA GPU beside tumble's CPU batch RK4, in one run.

Prints, with the machine line and min / median wall time over at least 5 repeats (``_timing``),
body-steps per second of the CUDA kernel (``tumble.integrate._cuda``) for batches of N bodies:

1. the kernel alone (data already on the GPU, synchronised before the clock is read) and
   ``solve_cuda`` end to end (copies to and from the GPU included), for torque-free bodies with one
   shared body, torque-free bodies with one inertia each, and one shared body under a compiled torque
   program (a constant body torque plus gravity on a top);
2. ``tumble.simulate(..., device="cuda")`` end to end (body axes in and out) for one inertia per body,
   diagonal tensors and the same in rotated body axes, beside ``tumble.simulate`` on the CPU (all cores)
   for the first of the same bodies, and the largest difference between the two;
3. the same with ``output="device"`` and 11 output times (set-up, conversions and results left on the
   GPU, synchronised before the clock is read): the target of docs/gpu.md, ≥ 10¹⁰ body-steps/s at
   N = 1e6 and 1000 steps;
4. a Monte-Carlo sweep of spacecraft with four wheels and MRP feedback over 600 s (``tumble.sweeps.sweep``,
   dispersed rates and wheel speeds, the final pointing error and the peak yaw rate with their percentiles),
   ``device="cuda"`` end to end beside ``device="cpu"`` on every core for the first ``--sweep-cpu`` samples,
   and the largest difference of their outcomes and percentiles on those samples: the target of docs/gpu.md,
   10⁶ spacecraft in ≤ 30 s.

Without a GPU it says so and exits 0. Run by hand (not a test)::

    python benchmarks/bench_gpu.py            # N = 1e6, 1e7; 1000 steps
    python benchmarks/bench_gpu.py --quick    # N = 1e6; 100 steps
    python benchmarks/bench_gpu.py --sweep-only --sweep-samples 1000000   # section 4 alone
"""

from __future__ import annotations

import argparse
import math
import os

import numpy as np
from numba import cuda, types
from numba.core import config

import tumble
from _timing import fmt, machine, measure
from tumble import attitude, integrate, torques
from tumble.integrate import _cuda, _fixed
from tumble.kernels import rigid as _rigid

DT = 1e-3                                   # s
OMEGA0 = np.array([1e-3, 1.0, 1e-3])        # rad/s, near the intermediate axis, dispersed per body
TORQUE = torques.ConstantBody([0.0, 0.0, 0.01]) + torques.Gravity(1.0, [0.0, 0.0, 0.1])  # N·m; kg, m
CPU_BODIES = 100_000
TARGET = (np.cos(0.15), 0.0, np.sin(0.15), 0.0)  # the spacecraft's commanded attitude (body -> inertial)
SWEEP_DT = 0.1                              # s, the spacecraft sweep's RK4 step
CORES = len(os.sched_getaffinity(0))


def moments(n, seed=1):
    """n principal moments (n, 3) uniform in [1.5, 2.5] kg m² (physical: each at most the sum of the others)."""
    return np.random.default_rng(seed).uniform(1.5, 2.5, (n, 3))


def states(n, seed=2):
    """n initial states [q_NP, ω_P] (n, 7): random attitudes, rates dispersed about OMEGA0."""
    rng = np.random.default_rng(seed)
    y0 = np.empty((n, 7))
    y0[:, :4] = attitude.normalize(rng.standard_normal((n, 4)))
    y0[:, 4:] = OMEGA0 + 1e-2 * rng.standard_normal((n, 3))
    return y0


def models(n):
    """name -> the RigidModel of n bodies (principal axes = body axes) that the GPU and CPU integrate."""
    eye = np.eye(3)[None]
    return {
        "free, one shared body": _rigid.from_principal(moments(1), eye, None),
        "free, one inertia each": _rigid.from_principal(moments(n), eye, None),
        "torque program, shared body": _rigid.from_principal(moments(1), eye, TORQUE),
    }


def kernel_timing(model, y0, t, kernel=_cuda._rk4_kernel):
    """Timing of ``kernel`` (by default tumble's) alone, on data already on the GPU."""
    codes = () if model.codes is None else cuda.to_device(model.codes)
    args = [cuda.to_device(model.coefficients), cuda.to_device(model.params), codes, cuda.to_device(y0),
            cuda.to_device(t), *map(cuda.to_device, _fixed.landing_steps(t, DT, integrate.MAX_STEPS)),
            cuda.device_array((t.size, *y0.shape))]
    blocks = math.ceil(y0.shape[0] / _cuda.THREADS_PER_BLOCK)

    def launch():
        kernel[blocks, _cuda.THREADS_PER_BLOCK](*args)
        cuda.synchronize()

    launch()                                            # compile / load from the cache
    return measure(launch)


def spacecraft_sweep(samples, seconds, device):
    """The sweep of section 4: ``samples`` spacecraft (four wheels in a pyramid, MRP feedback to ``TARGET``)
    with dispersed body rates and wheel speeds, ``seconds`` of RK4 at ``SWEEP_DT``, 61 output times; the final
    pointing error (rad) and the peak yaw rate (rad/s) of each, and their 5th, 50th and 95th percentiles."""
    from tumble.spacecraft import MRPFeedback, Spacecraft, pyramid_wheels
    from tumble.sweeps import Component, Final, Max, Normal, PointingError, sweep

    craft = Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02),
                       controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))
    return sweep(craft, {"omega0": Normal([0.05, -0.02, 0.03], 0.02),
                         "wheel_speeds0": Normal([10.0, -5.0, 3.0, 0.0], 5.0)},
                 samples=samples, seed=3, t=np.linspace(0.0, seconds, 61), method="rk4", dt=SWEEP_DT,
                 outcomes={"pointing": Final(PointingError(TARGET)), "peak_yaw_rate": Max(Component("omega", 2))},
                 percentiles=(5.0, 50.0, 95.0), workers=0, device=device)


def sweep_section(samples, seconds, cpu_samples):
    """Section 4: the spacecraft sweep on the GPU (end to end), on the CPU's cores for the first samples, and
    the largest difference of their outcomes and percentiles over the samples both ran."""
    steps = samples * round(seconds / SWEEP_DT)
    k = min(cpu_samples, samples)
    print(f"\n   Monte-Carlo sweep of spacecraft (4 wheels, MRP feedback), {seconds:g} s of RK4 at {SWEEP_DT:g} s, "
          "end to end (min / median):")
    spacecraft_sweep(4, 2 * SWEEP_DT, "cuda"), spacecraft_sweep(4, 2 * SWEEP_DT, "cpu")  # compile / load
    gpu = measure(lambda: spacecraft_sweep(samples, seconds, "cuda"))
    cpu = measure(lambda: spacecraft_sweep(k, seconds, "cpu"))
    same = spacecraft_sweep(k, seconds, "cuda")
    rates = cpu.rates(k * round(seconds / SWEEP_DT), CORES)
    wall = gpu.seconds()
    print(f"   device='cuda', {samples:,d} samples: {wall[0]:.2f} / {wall[1]:.2f} s "
          f"({fmt(gpu.rates(steps)['wall'])} spacecraft-steps/s); device='cpu' on {CORES} cores, {k:,d} samples: "
          f"{fmt(rates['wall'])} wall, {fmt(rates['cpu'])} CPU-time based spacecraft-steps/s")
    for name in ("pointing", "peak_yaw_rate"):
        a, b = same[name].values, cpu.result[name].values
        pa, pb = same[f"{name}_percentiles"].values, cpu.result[f"{name}_percentiles"].values
        print(f"   {name}: max |GPU - CPU| over the {k:,d} samples {np.abs(a - b).max():.2e}, of their percentiles "
              f"{np.abs(pa - pb).max():.2e}; percentiles of all {samples:,d} on the GPU: "
              f"{np.array2string(gpu.result[f'{name}_percentiles'].values, precision=6)}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 1e6 and 100 steps")
    parser.add_argument("--sizes", type=int, nargs="+", help="batch sizes N (default 1e6, 1e7)")
    parser.add_argument("--steps", type=int, help="RK4 steps of 1 ms per body (default 1000)")
    parser.add_argument("--registers", type=int, nargs="+", default=[],
                        help="also time the torque-program kernel compiled with each of these caps on its registers "
                             "per thread (numba.cuda's max_registers), at the first N")
    parser.add_argument("--sweep-samples", type=int, default=1_000_000, help="spacecraft in the sweep (section 4)")
    parser.add_argument("--sweep-seconds", type=float, default=600.0, help="simulated time of the sweep, s")
    parser.add_argument("--sweep-cpu", type=int, default=10_000, help="of them, the samples the CPU also runs")
    parser.add_argument("--sweep-only", action="store_true", help="section 4 alone")
    args = parser.parse_args()
    if not _cuda.cuda_available():
        print("No CUDA GPU present (numba.cuda.is_available() is False): nothing measured.")
        return
    sizes = args.sizes or ([1_000_000] if args.quick else [1_000_000, 10_000_000])
    steps = args.steps or (100 if args.quick else 1000)
    t = np.array([0.0, steps * DT])
    if config.ENABLE_CUDASIM:
        print("NUMBA_ENABLE_CUDASIM=1: Numba's CUDA simulator, not a GPU; the figures are not GPU measurements.")
        device = "simulator"
    else:
        dev = cuda.get_current_device()
        name = dev.name.decode() if isinstance(dev.name, bytes) else dev.name
        device = f"{name} (compute capability {'.'.join(map(str, dev.compute_capability))})"
    print(machine())
    print(f"tumble {tumble.__version__}; GPU: {device}")
    if args.sweep_only:
        sweep_section(args.sweep_samples, args.sweep_seconds, args.sweep_cpu)
        return
    print(f"RK4, float64, {steps} steps of {DT * 1e3:g} ms, {_cuda.THREADS_PER_BLOCK} threads per block; "
          "body-steps/s from wall time, min / median\n")

    print(f"   {'bodies':<30} {'N':>12} {'kernel alone':>24} {'solve_cuda end to end':>24}")
    for n in sizes:
        y0 = states(n)
        for name, model in models(n).items():
            kernel = kernel_timing(model, y0, t)
            _cuda.solve_cuda(model, y0[:256], t, DT)
            whole = measure(lambda: _cuda.solve_cuda(model, y0, t, DT)[0])
            print(f"   {name:<30} {n:12,d} {fmt(kernel.rates(n * steps)['wall']):>24} "
                  f"{fmt(whole.rates(n * steps)['wall']):>24}")

    if not config.ENABLE_CUDASIM:  # registers per thread of each compiled kernel (torque-free, torque program)
        for signature, regs in getattr(_cuda._rk4_kernel, "get_regs_per_thread", dict)().items():
            kind = "torque-free" if isinstance(signature[2], types.BaseTuple) else "torque program"  # codes = ()
            print(f"   registers per thread, {kind} kernel: {regs}")

    if args.registers and not config.ENABLE_CUDASIM:
        n, model = sizes[0], models(1)["torque program, shared body"]
        y0 = states(n)
        print(f"\n   torque program, shared body, N = {n:,d}, kernel alone, by cap on registers per thread:")
        for cap in args.registers:
            capped = cuda.jit(max_registers=cap)(_cuda._rk4_kernel.py_func)
            timing = kernel_timing(model, y0, t, capped)
            regs = list(capped.get_regs_per_thread().values())
            print(f"   at most {cap:4d}: {fmt(timing.rates(n * steps)['wall'])} body-steps/s, {regs} registers, "
                  f"local memory {list(getattr(capped, 'get_local_mem_per_thread', dict)().values())} bytes per thread")

    # The public front door, body axes in and out, one inertia per body (diagonal tensors, then the same
    # tensors in rotated body axes: their set-up finds each one's principal axes); the CPU on the first bodies.
    n, k = sizes[0], min(CPU_BODIES, sizes[0])
    diagonal = np.einsum("bi,ij->bij", moments(n), np.eye(3))        # (n, 3, 3) kg m², principal = body axes
    turn = attitude.to_matrix(states(n, seed=3)[:, :4])
    y0 = states(n)
    q0, omega0 = y0[:, :4], y0[:, 4:]
    print("\n   tumble.simulate, one inertia per body, end to end, body-steps/s (min / median):")
    for name, inertia in (("diagonal", diagonal), ("rotated", turn @ diagonal @ np.swapaxes(turn, -1, -2))):

        def run(device, k, inertia=inertia):
            return tumble.simulate(inertia[:k], omega0[:k], q0=q0[:k], t=t, method="rk4", dt=DT, device=device)

        run("cuda", 256), run("cpu", 256)
        gpu, cpu = measure(lambda: run("cuda", n)), measure(lambda: run("cpu", k))
        rates = cpu.rates(k * steps, CORES)
        a, b = gpu.result, cpu.result
        print(f"   {name} tensors: device='cuda', N = {n:,d}: {fmt(gpu.rates(n * steps)['wall'])}; device='cpu' on "
              f"{CORES} cores, N = {k:,d}: {fmt(rates['wall'])} wall, {fmt(rates['cpu'])} CPU-time based; "
              f"max |GPU - CPU| at t = {t[-1]:g} s: q {np.abs(a.q[:, :k] - b.q).max():.2e}, "
              f"omega {np.abs(a.omega[:, :k] - b.omega).max():.2e} rad/s")

    times = np.linspace(0.0, steps * DT, 11)
    print(f"\n   tumble.simulate(..., output='device'), {times.size} output times, N = {n:,d}, body-steps/s "
          "(min / median):")
    for name, inertia in (("diagonal", diagonal), ("rotated", turn @ diagonal @ np.swapaxes(turn, -1, -2))):

        def kept(m, inertia=inertia):
            traj = tumble.simulate(inertia[:m], omega0[:m], q0=q0[:m], t=times, method="rk4", dt=DT, device="cuda",
                                   output="device")
            cuda.synchronize()
            return traj

        kept(256)
        on_gpu = measure(lambda: kept(n))
        print(f"   {name} tensors: {fmt(on_gpu.rates(n * steps)['wall'])}")

    sweep_section(args.sweep_samples, args.sweep_seconds, args.sweep_cpu)

if __name__ == "__main__":
    main()
