"""A million bodies with dispersed inertia, 101 output times: streamed statistics and their peak memory.

    python benchmarks/bench_ensemble.py [n_bodies]

Prints the wall time, the peak resident memory of the process and, for
comparison, the memory that ``q`` and ``omega`` of the whole batch would take
at every output time.
"""

from __future__ import annotations

import resource
import sys
import time

import numpy as np

from tumble.ensemble import ensemble_statistics


def main(n_bodies: int = 10**6) -> None:
    rng = np.random.default_rng(0)
    inertia = np.diag([1.0, 2.0, 3.0]) * rng.uniform(0.9, 1.1, (n_bodies, 1, 1))  # ±10 % dispersion
    omega0 = rng.normal([0.0, 1.0, 0.0], 0.05, (n_bodies, 3))
    t = np.linspace(0.0, 10.0, 101)
    # compile on a small batch first
    ensemble_statistics(inertia[:100], omega0[:100], t=t, method="rk4", dt=0.01, chunk=64)
    start = time.perf_counter()
    ds = ensemble_statistics(inertia, omega0, t=t, method="rk4", dt=0.01)
    wall = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20  # kB -> GB (Linux)
    whole = t.size * n_bodies * 7 * 8 / 2**30
    steps = n_bodies * 1000
    print(f"{n_bodies:.0e} bodies, 1000 RK4 steps each, 101 outputs: {wall:.2f} s "
          f"({steps / wall:.3g} body-steps/s incl. statistics)")
    print(f"peak resident memory {peak:.2f} GB (whole batch at every output would be {whole:.2f} GB for q and omega)")
    print("max |energy drift| over the batch at t = 10 s:", float(np.abs(ds['energy_drift'].sel(statistic=['min', 'max'])[-1]).max()))


if __name__ == "__main__":
    main(int(float(sys.argv[1])) if len(sys.argv) > 1 else 10**6)
