"""Work–precision study: error at t = 100 s against cost, for every tumble method, scipy and MuJoCo.

One torque-free asymmetric body, I = diag(1, 2, 3) kg m². The reference is
tumble's closed form (``method="exact"``, Jacobi elliptic functions, exact to
a few ulps). The error of a run is

    max(|ω(100 s) − ω_exact| (rad/s), θ(q, q_exact) (rad)),

θ the angle of the rotation between the two attitudes
(:func:`tumble.attitude.relative_angle`). Fixed-step methods sweep the step
``dt``, adaptive ones ``rtol`` (``atol = rtol / 100``). The cost is the wall
time of one run (best of a few, after a warm-up call that compiles), and the
number of steps.

Compared: every method in ``tumble.integrate.METHODS``; scipy's
``solve_ivp`` (RK45, DOP853) on Euler's equations + quaternion kinematics
written in NumPy; and, if installed, MuJoCo (``pip install mujoco``): one
free-joint body with the same inertia, no gravity, integrators RK4, Euler
(its default) and implicit. MuJoCo's conventions are checked at start-up
(:func:`check_mujoco_conventions`).

Then a table of the drift of energy and |L| over 10⁶ steps of dt = 0.01 s
(10⁴ s) for the fixed-step methods.

Run by hand (not a test; timings vary with the machine)::

    python benchmarks/work_precision.py            # full run, about 2 min on 2 cores
    python benchmarks/work_precision.py --quick    # fewer and cheaper points, shorter drift run
    python benchmarks/work_precision.py --case separatrix   # ω0 near the separatrix

The figure ``work_precision.png`` goes to the directory given by ``--out``: by default ``out/`` at the
repository root, which git ignores, so a run never overwrites the tracked ``docs/img/work_precision.png``;
``--out docs/img`` regenerates the figure of the docs on purpose.
"""

from __future__ import annotations

import argparse
import os
import platform
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import tumble
from _timing import best_of
from tumble import attitude, dynamics
from tumble.integrate import METHODS

try:
    import mujoco
except ImportError:
    mujoco = None

MOMENTS = np.array([1.0, 2.0, 3.0])                       # kg m², principal axes = body axes
CASES = {
    # far from the separatrix (T/|L|² away from 1/(2 I₂)): errors grow linearly in t
    "regular": np.array([1.0, 0.2, 0.5]),
    # close to the separatrix (tumbling about the intermediate axis): errors are amplified
    "separatrix": np.array([0.05, 1.0, 0.05]),
}
T_END = 100.0                                             # s
ERROR_FLOOR = 1e-16                                       # plotted in place of a zero error
MUJOCO_INTEGRATORS = ("RK4", "Euler", "implicit")         # Euler is MuJoCo's default
ROOT = Path(__file__).resolve().parents[1]


def cpu_name():
    """The processor's model name (from /proc/cpuinfo where there is one)."""
    try:
        with open("/proc/cpuinfo") as f:
            return next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def error(omega, q, reference):
    """max(|Δω| (rad/s), attitude angle (rad)) of the end state against the exact trajectory."""
    d_omega = np.linalg.norm(omega - reference.omega[-1])
    d_angle = attitude.relative_angle(reference.q[-1], attitude.normalize(q))
    return max(float(d_omega), float(d_angle), ERROR_FLOOR)


def timed(fn):
    """Best wall time (s) of a few calls of ``fn`` after a warm-up call, and its result."""
    first, result = best_of(1, fn)                       # warm-up: compiles or loads the cache
    repeats = 5 if first < 0.2 else 2 if first < 2.0 else 0
    if repeats:
        seconds, result = best_of(repeats, fn)
        first = min(first, seconds)
    return first, result


# --------------------------------------------------------------------------
# tumble and scipy
# --------------------------------------------------------------------------


def run_tumble(method, omega0, reference, setting):
    """(wall time, steps, error) of tumble's ``method`` at step count or rtol ``setting``."""
    body = tumble.RigidBody(np.diag(MOMENTS))
    t = np.array([0.0, T_END])
    if METHODS[method].adaptive:
        options = {"rtol": setting, "atol": setting / 100}
    elif METHODS[method].stepper:
        options = {"dt": T_END / setting}
    else:
        options = {}
    seconds, traj = timed(lambda: tumble.simulate(body, omega0, t=t, method=method, **options))
    steps = traj.info["n_steps"] + traj.info["n_rejected"] if METHODS[method].stepper else 1
    return seconds, steps, error(traj.omega[-1], traj.q[-1], reference)


def euler_rhs(t, y):
    """Euler's equations + q̇ = ½ q ⊗ [0, ω] in NumPy, as a solve_ivp user would write them."""
    q, w = y[:4], y[4:]
    i1, i2, i3 = MOMENTS
    wdot = [(i2 - i3) * w[1] * w[2] / i1, (i3 - i1) * w[2] * w[0] / i2, (i1 - i2) * w[0] * w[1] / i3]
    qdot = [
        0.5 * (-q[1] * w[0] - q[2] * w[1] - q[3] * w[2]),
        0.5 * (q[0] * w[0] + q[2] * w[2] - q[3] * w[1]),
        0.5 * (q[0] * w[1] - q[1] * w[2] + q[3] * w[0]),
        0.5 * (q[0] * w[2] + q[1] * w[1] - q[2] * w[0]),
    ]
    return np.array(qdot + wdot)


SCIPY_STAGES = {"RK45": 6, "DOP853": 12}               # RHS evaluations per step (FSAL)


def run_scipy(method, omega0, reference, rtol):
    """(wall time, steps, error) of scipy's ``solve_ivp(method)`` at ``rtol`` (``atol = rtol / 100``)."""
    y0 = np.concatenate([attitude.identity(), omega0])
    seconds, sol = timed(lambda: solve_ivp(euler_rhs, (0.0, T_END), y0, method=method, rtol=rtol, atol=rtol / 100))
    steps = (sol.nfev - 2) // SCIPY_STAGES[method]      # accepted + rejected (2 evaluations start the run)
    return seconds, steps, error(sol.y[4:, -1], sol.y[:4, -1], reference)


# --------------------------------------------------------------------------
# MuJoCo
# --------------------------------------------------------------------------


def mujoco_model(integrator, dt):
    """A MuJoCo model of one free body with principal moments MOMENTS about its centre of mass, no gravity."""
    i1, i2, i3 = MOMENTS
    xml = f"""<mujoco>
      <option gravity="0 0 0" timestep="{float(dt)!r}" integrator="{integrator}"/>
      <worldbody><body><freejoint/><inertial pos="0 0 0" mass="1" diaginertia="{i1} {i2} {i3}"/></body></worldbody>
    </mujoco>"""
    return mujoco.MjModel.from_xml_string(xml)


def mujoco_state(integrator, dt, omega0, q0, steps):
    """(model, data) after ``steps`` steps from attitude q0 and body rate omega0.

    MuJoCo's free joint: ``qpos[3:7]`` is the unit quaternion [w, x, y, z]
    mapping body → world axes (tumble's convention); ``qvel[3:6]`` is the
    angular velocity in body (local) axes (checked by
    :func:`check_mujoco_conventions`).
    """
    model = mujoco_model(integrator, dt)
    data = mujoco.MjData(model)
    mujoco_run(model, data, omega0, q0, steps)
    return model, data


def mujoco_run(model, data, omega0, q0, steps):
    """Reset ``data`` to attitude q0 and body rate omega0, then take ``steps`` steps (one C loop)."""
    mujoco.mj_resetData(model, data)
    data.qpos[3:7] = q0
    data.qvel[3:6] = omega0
    mujoco.mj_step(model, data, nstep=steps)
    return data


def check_mujoco_conventions(omega0):
    """Check MuJoCo's free-joint conventions against tumble; returns a line of text for the report.

    1. Frames: attitude q0 = 90° about world z, qvel[3:6] = (1, 0, 0). If
       qvel[3:6] is in body axes the world-frame rate (``cvel[0:3]``) is
       R(q0) (1, 0, 0) = (0, 1, 0); if it were in world axes it would be (1, 0, 0).
    2. Dynamics: 1 s of RK4 at dt = 1e-4 s from a generic attitude against
       tumble's closed form: ω and q must agree to the RK4 error (< 1e-9).
    """
    q0 = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])
    model, data = mujoco_state("RK4", 1e-3, [1.0, 0.0, 0.0], q0, 0)
    mujoco.mj_forward(model, data)
    rate_world = data.cvel[1, :3]
    expected = attitude.rotate(q0, np.array([1.0, 0.0, 0.0]))
    if not np.allclose(rate_world, expected, atol=1e-12):
        raise RuntimeError(f"MuJoCo: qvel[3:6] is not the body-axes rate (world rate {rate_world}, "
                           f"expected {expected})")
    q0 = attitude.normalize(np.array([0.9, 0.1, -0.3, 0.2]))
    _, data = mujoco_state("RK4", 1e-4, omega0, q0, 10_000)
    exact = tumble.simulate(tumble.RigidBody(np.diag(MOMENTS)), omega0, q0=q0, t=[0.0, 1.0], method="exact")
    d_omega = np.linalg.norm(data.qvel[3:6] - exact.omega[-1])
    d_angle = attitude.relative_angle(exact.q[-1], data.qpos[3:7])
    if max(d_omega, d_angle) > 1e-9:   # RK4 at dt = 1e-4 s over 1 s: error ~1e-14; a convention slip: ~1
        raise RuntimeError(f"MuJoCo disagrees with tumble after 1 s: |dω| = {d_omega:.1e}, angle {d_angle:.1e}")
    return (f"MuJoCo {mujoco.__version__}: qvel[3:6] is the body-axes rate (world rate of (1,0,0) at 90° about z "
            f"= {np.round(rate_world, 12).tolist()}); qpos[3:7] = [w,x,y,z] body->world; vs tumble exact after 1 s "
            f"of RK4 dt=1e-4: |dω| = {d_omega:.1e} rad/s, angle {d_angle:.1e} rad")


def mujoco_unstable(data):
    """True once MuJoCo has met a NaN or huge value (it then resets the state and goes on, with a warning)."""
    return any(data.warning[w].number > 0 for w in (mujoco.mjtWarning.mjWARN_BADQACC,
                                                    mujoco.mjtWarning.mjWARN_BADQVEL,
                                                    mujoco.mjtWarning.mjWARN_BADQPOS))


def run_mujoco(integrator, omega0, reference, steps):
    """(wall time, steps, error) of MuJoCo's ``integrator`` with ``steps`` steps over T_END (model built untimed).

    An unstable run (see :func:`mujoco_unstable`) gives NaN time and error: no point on the figure.
    """
    model = mujoco_model(integrator, T_END / steps)
    data = mujoco.MjData(model)
    if mujoco_unstable(mujoco_run(model, data, omega0, attitude.identity(), steps)):
        return np.nan, steps, np.nan
    seconds, data = timed(lambda: mujoco_run(model, data, omega0, attitude.identity(), steps))
    return seconds, steps, error(data.qvel[3:6], data.qpos[3:7], reference)


# --------------------------------------------------------------------------
# the sweep, the figure and the drift table
# --------------------------------------------------------------------------


def step_counts(lo, hi, quick):
    """Step counts over T_END from 10**lo to 10**hi, log-spaced (``quick``: 6 points, to a 5x smaller count)."""
    return np.unique(np.round(np.logspace(lo, hi - 0.7 if quick else hi, 6 if quick else 11))).astype(int)


def sweeps(quick):
    """{label: (runner, settings)}: every curve of the figure."""
    def rtols(lo, hi):
        return np.logspace(-lo, -hi, 5 if quick else (hi - lo) + 1)

    curves = {}
    for name, m in METHODS.items():
        if not m.stepper:
            curves[f"tumble {name}"] = (lambda w, ref, s, n=name: run_tumble(n, w, ref, s), [None])
        elif m.adaptive:
            curves[f"tumble {name}"] = (lambda w, ref, s, n=name: run_tumble(n, w, ref, s), rtols(3, 14))
        else:
            hi = {"splitting2": 6.3, "splitting4": 5.3}.get(name, 5.7)   # log10 steps: down to ~rounding
            curves[f"tumble {name}"] = (lambda w, ref, s, n=name: run_tumble(n, w, ref, s), step_counts(2.0, hi, quick))
    curves["scipy RK45"] = (lambda w, ref, s: run_scipy("RK45", w, ref, s), rtols(3, 10))
    curves["scipy DOP853"] = (lambda w, ref, s: run_scipy("DOP853", w, ref, s), rtols(3, 13))
    if mujoco is not None:
        for integrator in MUJOCO_INTEGRATORS:
            hi = 5.3 if integrator == "RK4" else 6.0
            curves[f"MuJoCo {integrator}"] = (lambda w, ref, s, i=integrator: run_mujoco(i, w, ref, s),
                                              step_counts(2.0, hi, quick))
    return curves


def measure(omega0, quick):
    """{label: (seconds, steps, errors)} arrays, printed as they come."""
    reference = tumble.simulate(tumble.RigidBody(np.diag(MOMENTS)), omega0, t=[0.0, T_END], method="exact")
    results = {}
    for label, (runner, settings) in sweeps(quick).items():
        rows = [runner(omega0, reference, s) for s in settings]
        results[label] = tuple(np.array(column) for column in zip(*rows))
        print(f"  {label:>16}: " + "  ".join(f"{e:.0e}@{t * 1e3:.2g}ms" for t, _, e in rows))
    return results


STYLE = {  # label -> (colour, marker, line style); same colour = same scheme
    "tumble rk4": ("C0", "o", "-"), "tumble dop853": ("C1", "s", "-"), "tumble cf4": ("C2", "^", "-"),
    "tumble splitting2": ("C3", "v", "-"), "tumble splitting4": ("C4", "D", "-"),
    "tumble exact": ("k", "*", ""), "scipy RK45": ("C5", "o", "--"), "scipy DOP853": ("C1", "s", "--"),
    "MuJoCo RK4": ("C0", "o", ":"), "MuJoCo Euler": ("C7", "x", ":"), "MuJoCo implicit": ("C8", "+", ":"),
}
SPARE_STYLES = [("C6", "<", "-."), ("C9", ">", "-."), ("olive", "h", "-."), ("navy", "p", "-.")]  # other methods


def plot(by_case, path):
    """One row per case: error against wall time (left) and against steps (right), log-log."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = list(next(iter(by_case.values())))
    spare = iter(SPARE_STYLES * len(labels))
    styles = {label: STYLE[label] if label in STYLE else next(spare) for label in labels}
    fig, axes = plt.subplots(len(by_case), 2, figsize=(13, 4.9 * len(by_case) + 1.0), sharey=True, squeeze=False)
    for row, (case, results) in zip(axes, by_case.items()):
        for label, (seconds, steps, errors) in results.items():
            colour, marker, line = styles[label]
            name = label.replace("Euler", "Euler (its default)")
            size = 14 if marker == "*" else 5
            row[0].loglog(seconds, errors, marker=marker, ls=line, color=colour, ms=size, label=name)
            row[1].loglog(steps, errors, marker=marker, ls=line, color=colour, ms=size, label=name)
        row[0].set_xlabel("wall time of one run, s (best of up to 5)")
        row[1].set_xlabel("steps over 100 s (adaptive: accepted + rejected)")
        row[0].set_ylabel("error at t = 100 s:\nmax(|Δω| rad/s, attitude angle rad)")
        for ax in row:
            ax.set_title(f"{case}: ω0 = {CASES[case].tolist()} rad/s", fontsize=10)
            ax.grid(True, which="major", alpha=0.4)
            ax.grid(True, which="minor", alpha=0.1)
            ax.set_ylim(3e-17, 30.0)
    handles, names = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower center", ncol=6, fontsize=9, frameon=False)
    cpu = cpu_name()
    fig.suptitle(f"Work–precision of the free rigid body, I = diag(1, 2, 3) kg m², error at t = 100 s against "
                 f"tumble's closed form\n{cpu}, {len(os.sched_getaffinity(0))} cores, one body per run; points below "
                 f"1e-16 are drawn at 1e-16; MuJoCo points missing where its run went unstable", fontsize=10)
    fig.tight_layout(rect=(0.0, 0.9 / (4.9 * len(by_case) + 1.0), 1.0, 1.0))
    fig.savefig(path, dpi=100)
    print(f"\nfigure: {path}")


def drift(omega0, steps, dt):
    """{label: (seconds, max |ΔE|/E, max |Δ|L||/|L|, time of failure or None)} over ``steps`` steps of ``dt``.

    The drifts are the largest over 1001 samples (up to the failure, if a MuJoCo run goes unstable).
    """
    inertia = np.diag(MOMENTS)
    t = np.linspace(0.0, steps * dt, 1001)

    def relative(omega):
        energy = dynamics.kinetic_energy(inertia, omega)
        norm = np.linalg.norm(dynamics.angular_momentum(inertia, omega), axis=-1)
        return np.abs(energy / energy[0] - 1.0).max(), np.abs(norm / norm[0] - 1.0).max()

    rows = {}
    for name, m in METHODS.items():
        if m.stepper and not m.adaptive:
            body = tumble.RigidBody(inertia)
            tumble.simulate(body, omega0, t=[0.0, dt], method=name, dt=dt)          # compile / load the cache
            seconds, traj = best_of(1, lambda: tumble.simulate(body, omega0, t=t, method=name, dt=dt))
            rows[f"tumble {name}"] = (seconds, *relative(traj.omega), None)
    if mujoco is not None:
        for integrator in MUJOCO_INTEGRATORS:
            def run():
                model, data = mujoco_state(integrator, dt, omega0, attitude.identity(), 0)
                omega = [data.qvel[3:6].copy()]
                for k in range(1, t.size):
                    mujoco.mj_step(model, data, nstep=steps // (t.size - 1))
                    if mujoco_unstable(data):
                        return np.array(omega), t[k]
                    omega.append(data.qvel[3:6].copy())
                return np.array(omega), None

            seconds, (omega, failed_at) = best_of(1, run)
            rows[f"MuJoCo {integrator}"] = (seconds, *relative(omega), failed_at)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer points, smaller step counts, 1e5 drift steps")
    parser.add_argument("--case", choices=sorted(CASES), default=None, help="one initial rate (default: both)")
    parser.add_argument("--out", type=Path, default=ROOT / "out",
                        help="directory of the figure work_precision.png (default: out/, ignored by git)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    cases = [args.case] if args.case else list(CASES)
    print(f"tumble {tumble.__version__}, {cpu_name()}, "
          f"{len(os.sched_getaffinity(0))} cores; I = diag{MOMENTS.tolist()} kg m², t = {T_END} s")
    if mujoco is None:
        print("MuJoCo not installed: its curves and rows are left out (pip install mujoco)")
    else:
        mujoco.set_mju_user_warning(lambda message: None)   # instability is detected and reported here instead
        print(check_mujoco_conventions(CASES[cases[0]]))

    by_case = {}
    for case in cases:
        print(f"\n{case}: omega0 = {CASES[case].tolist()} rad/s; error@wall time of one run:")
        by_case[case] = measure(CASES[case], args.quick)
    plot(by_case, args.out / "work_precision.png")

    omega0, steps, dt = CASES[cases[0]], (10**5 if args.quick else 10**6), 0.01
    print(f"\ndrift over {steps:.0e} steps of dt = {dt} s ({steps * dt:.0f} s), {cases[0]} case, relative, "
          "max over 1001 samples:")
    print(f"  {'method':>20} {'|dE|/E':>9} {'|d|L||/|L|':>11} {'wall s':>7}")
    for label, (seconds, d_energy, d_norm, failed_at) in drift(omega0, steps, dt).items():
        note = f"  unstable at t = {failed_at:.0f} s (drifts up to then)" if failed_at is not None else ""
        print(f"  {label:>20} {d_energy:9.1e} {d_norm:11.1e} {seconds:7.2f}{note}")


if __name__ == "__main__":
    main()
