"""Where the non-spinning frame pays: work–precision of AxisymmetricBody against the body-frame model.

Two axisymmetric heavy tops (``tumble.torques.Gravity`` on a pivot, inertia about the pivot), each run by
``tumble.axisymmetric.AxisymmetricBody`` (non-spinning frame, κ = 0) and by the rigid body itself (body frame):

* ``gyroscope``: a disk rotor (I_s = 2e-3, I_t = 1.2e-3 kg m² about the pivot, m g l = 0.098 N m) spun at
  1e4 rad/s and released at 60° from the vertical: it precesses at m g l/(I_s ω₃) = 4.9e-3 rad/s and nutates
  by 4e-7 in cos θ at the nutation rate I_s ω₃/I_t = 1.7e4 rad/s; 0.2 s, 318 spin periods.
* ``top``: a spin-stabilised prolate top (I_s/I_t = 0.1, the heavy top of tests/test_frames.py) at 250
  rad/s, 1.8 times its critical spin, released at 40°: it nutates by 7° at 25 rad/s; 2 s, 80 spin periods.

The error of a run is the largest, over 21 output times, of the attitude angle between the run and the
reference (:func:`tumble.attitude.relative_angle`, rad) plus |Δω|/|ω|. The reference is the frame model at
dop853 rtol = atol = 1e-14 (the body-frame model at the same tolerance agrees with it to the figure
printed). ``rk4`` sweeps dt (equal steps: the same dt for both models), ``dop853`` sweeps rtol
(atol = rtol × |ω₀|·1e-3). Cost: right-hand-side evaluations and wall time (best of 3, after a warm-up
call that compiles).

Run by hand (not a test)::

    python benchmarks/bench_frames.py           # writes docs/img/frames_work_precision.png
"""

from __future__ import annotations

import argparse
import platform
from pathlib import Path

import numpy as np

import tumble
from _timing import best_of
from tumble import attitude
from tumble.analytic import HeavyTop
from tumble.axisymmetric import AxisymmetricBody
from tumble.trajectory import write_atomic

CASES = {
    "gyroscope": (HeavyTop.from_state(I1=1.2e-3, I3=2e-3, mass=0.5, length=0.02, g=9.81, theta0=np.pi / 3,
                                      theta_dot0=0.0, phi_dot0=0.0, spin=1e4), 0.2,
                  [2e-5, 1e-5, 5e-6, 2.5e-6, 1.25e-6]),
    "top": (HeavyTop.from_state(I1=0.02, I3=0.002, mass=1.0, length=0.1, g=9.81, theta0=0.7, theta_dot0=0.0,
                                phi_dot0=0.0, spin=250.0), 2.0, [2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4]),
}
RTOLS = [1e-5, 1e-7, 1e-9, 1e-11, 1e-13]


def _error(traj, ref):
    angle = attitude.relative_angle(traj.q, ref.q).max()
    rate = (np.linalg.norm(traj.omega - ref.omega, axis=-1) / np.linalg.norm(ref.omega, axis=-1)).max()
    return float(angle + rate)


def run_case(name):
    top, duration, dts = CASES[name]
    inputs = top.simulation_inputs(phi0=0.3, psi0=1.1)
    body = tumble.RigidBody(inputs.pop("model"))
    models = {"frame": AxisymmetricBody(body), "body": body}
    t = np.linspace(0.0, duration, 21)
    ref = tumble.simulate(models["frame"], **inputs, t=t, rtol=1e-14, atol=1e-14)
    check = tumble.simulate(models["body"], **inputs, t=t, rtol=1e-14, atol=1e-14)
    print(f"\n== {name}: spin {top.spin:g} rad/s, {duration * top.spin / (2 * np.pi):.0f} spin periods; "
          f"references frame vs body differ by {_error(check, ref):.1e}")
    rows = []
    scale = np.linalg.norm(inputs["omega0"]) * 1e-3
    for label, model in models.items():
        for dt in dts:
            seconds, traj = best_of(3, lambda: tumble.simulate(model, **inputs, t=t, method="rk4", dt=dt))
            rows.append((label, "rk4", dt, traj.info["n_rhs"], seconds, _error(traj, ref)))
        for rtol in RTOLS:
            seconds, traj = best_of(3, lambda: tumble.simulate(model, **inputs, t=t, rtol=rtol, atol=rtol * scale))
            rows.append((label, "dop853", rtol, traj.info["n_rhs"], seconds, _error(traj, ref)))
    print(f"{'model':6} {'method':7} {'dt | rtol':>10} {'n_rhs':>9} {'wall s':>9} {'error':>9}")
    for r in rows:
        print(f"{r[0]:6} {r[1]:7} {r[2]:10.3g} {r[3]:9d} {r[4]:9.4f} {r[5]:9.2e}")
    return rows


def figure(results):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.5), layout="constrained")
    for ax, (name, rows) in zip(fig.subplots(1, len(results)), results.items()):
        for label, style, legend in (("frame", "-", "non-spinning frame"), ("body", "--", "body axes")):
            for method, marker in (("rk4", "o"), ("dop853", "s")):
                pts = [(r[3], r[5]) for r in rows if r[0] == label and r[1] == method]
                ax.loglog([p[0] for p in pts], [max(p[1], 1e-16) for p in pts], style, marker=marker,
                          label=f"{legend}, {method}")
        ax.set_title(name)
        ax.set_xlabel("right-hand-side evaluations")
        ax.set_ylabel("error (rad + relative rate)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    return fig


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "docs/img/frames_work_precision.png"))
    args = parser.parse_args()
    print(f"{platform.processor() or platform.machine()}, numpy {np.__version__}, tumble {tumble.__version__}")
    results = {name: run_case(name) for name in CASES}
    fig = figure(results)
    write_atomic(args.out, lambda tmp: fig.savefig(tmp, format="png", dpi=110))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
