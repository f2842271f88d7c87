"""GPU benchmark: torque-free RK4 on an NVIDIA GPU beside tumble's CPU batch RK4, in one run.

Prints body-steps per second of the CUDA kernel (``tumble.integrate._cuda``)
for N = 10⁶ … 10⁷ torque-free bodies, each with its own moments of inertia,
timed two ways: the kernel alone (data already on the GPU), and
``solve_cuda`` end to end (copies to and from the GPU included). Beside them:
tumble's CPU batch RK4 (``tumble.integrate.solve``, all cores) on the first
bodies of the same batch, and the largest difference between the two results.

Without a GPU it says so and exits 0. Run by hand (not a test)::

    python benchmarks/bench_gpu.py            # N = 1e6, 3e6, 1e7; 1000 steps
    python benchmarks/bench_gpu.py --quick    # N = 1e6; 100 steps
"""

from __future__ import annotations

import argparse
import math
import os

import numpy as np
from numba import cuda
from numba.core import config

import tumble
from _timing import best_of
from tumble import attitude, integrate
from tumble.kernels import rigid as _rigid
from tumble.dynamics import euler_coefficients
from tumble.integrate import _cuda, _fixed

DT = 1e-3                                   # s
OMEGA0 = np.array([1e-3, 1.0, 1e-3])        # rad/s, near the intermediate axis, dispersed per body
CPU_BODIES = 100_000


def batch(n, seed=1):
    """n torque-free bodies: Euler coefficients (n, 6), principal moments (n, 3) in [1, 3] kg m², states (n, 7)."""
    rng = np.random.default_rng(seed)
    moments = rng.uniform(1.0, 3.0, (n, 3))
    coefficients = np.ascontiguousarray(np.stack(euler_coefficients(*moments.T), axis=1))
    y0 = np.empty((n, 7))
    y0[:, :4] = attitude.normalize(rng.standard_normal((n, 4)))
    y0[:, 4:] = OMEGA0 + 1e-2 * rng.standard_normal((n, 3))
    return coefficients, moments, y0


def cpu_model(coefficients, moments):
    """The CPU integrators' RigidModel of the same bodies (one row each), torque-free."""
    one = _rigid.build([tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))], None)
    return one._replace(coefficients=coefficients, moments=moments, params=np.zeros((coefficients.shape[0], 0)))


def kernel_seconds(coefficients, y0, t):
    """Best time (s) of the kernel alone, on data already on the GPU (synchronised before the clock is read)."""
    args = [cuda.to_device(coefficients), cuda.to_device(np.zeros((y0.shape[0], 0))), (), cuda.to_device(y0),
            cuda.to_device(t), *map(cuda.to_device, _fixed.landing_steps(t, DT, integrate.MAX_STEPS)),
            cuda.device_array((t.size, *y0.shape))]
    blocks = math.ceil(y0.shape[0] / _cuda.THREADS_PER_BLOCK)

    def launch():
        _cuda._rk4_kernel[blocks, _cuda.THREADS_PER_BLOCK](*args)
        cuda.synchronize()

    return wall_seconds(launch)[0]


def wall_seconds(fn, repeats=3):
    """Best wall time (s) of ``fn()`` and its last result."""
    return best_of(repeats, fn)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="N = 1e6 and 100 steps")
    parser.add_argument("--sizes", type=int, nargs="+", help="batch sizes N (default 1e6, 3e6, 1e7)")
    parser.add_argument("--steps", type=int, help="RK4 steps of 1 ms per body (default 1000)")
    args = parser.parse_args()
    if not _cuda.cuda_available():
        print("No CUDA GPU present (numba.cuda.is_available() is False): nothing measured.")
        return
    sizes = args.sizes or ([1_000_000] if args.quick else [1_000_000, 3_000_000, 10_000_000])
    steps = args.steps or (100 if args.quick else 1000)
    t = np.array([0.0, steps * DT])
    cores = len(os.sched_getaffinity(0))
    if config.ENABLE_CUDASIM:
        print("NUMBA_ENABLE_CUDASIM=1: Numba's CUDA simulator, not a GPU; the figures are not GPU measurements.")
        device = "simulator"
    else:
        dev = cuda.get_current_device()
        name = dev.name.decode() if isinstance(dev.name, bytes) else dev.name
        device = f"{name} (compute capability {'.'.join(map(str, dev.compute_capability))})"
    print(f"tumble {tumble.__version__}; GPU: {device}; CPU: {cores} cores")
    print(f"torque-free RK4, float64, one Euler-coefficient row per body, {steps} steps of {DT * 1e3:g} ms, "
          f"{_cuda.THREADS_PER_BLOCK} threads per block\n")

    def gpu_run(coefficients, y0):
        return _cuda.solve_cuda(cpu_model(coefficients, np.ones((y0.shape[0], 3))), y0, t, DT)[0]

    small, _, small_y0 = batch(2 * _cuda.THREADS_PER_BLOCK)
    gpu_run(small, small_y0)                              # compile the kernel / load it from the cache
    print(f"   {'N bodies':>12} {'kernel body-steps/s':>22} {'solve_cuda body-steps/s':>25}")
    for n in sizes:
        coefficients, moments, y0 = batch(n)
        kernel = kernel_seconds(coefficients, y0, t)
        end_to_end, gpu = wall_seconds(lambda: gpu_run(coefficients, y0))
        print(f"   {n:12,d} {n * steps / kernel:22.3g} {n * steps / end_to_end:25.3g}")

    n_cpu = min(CPU_BODIES, sizes[-1])
    model = cpu_model(coefficients[:n_cpu], moments[:n_cpu])
    integrate.solve(model, y0[:2], t, method="rk4", dt=DT)    # compile / load from cache
    seconds, cpu = wall_seconds(lambda: integrate.solve(model, y0[:n_cpu], t, method="rk4", dt=DT).states)
    print(f"\n   CPU, tumble rk4 on all {cores} cores, N = {n_cpu:,d}: {n_cpu * steps / seconds:.3g} body-steps/s")
    print(f"   max |GPU - CPU| over those bodies at t = {t[-1]:g} s: {np.abs(gpu[:, :n_cpu] - cpu).max():.2e}")


if __name__ == "__main__":
    main()
