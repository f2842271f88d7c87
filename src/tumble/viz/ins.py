"""The figures and demos of :mod:`tumble.ins`: the Allan-deviation figure, and demos that each write their figures
atomically and return their numbers.

``allan_figure(curves)``          Allan deviations on log-log axes with the N and B model lines

================================  ==================================================================
``demo_gyroscope(out_dir)``       a gyro rotor released on its pivot (precession, nutation) and its
                                  drift from imbalance, spin-bearing and pivot friction:
                                  ``ins_gyro_precession.png``, ``ins_gyro_drift.png``
``demo_coning(out_dir)``          coning drift of the four strapdown algorithms against their laws
                                  over a range of update rates: ``ins_coning.png``
``demo_ins(out_dir)``             a tumbling body → gyro with errors → strapdown → attitude error
                                  growth (``ins_error.png``), and the Allan deviation of the gyro at
                                  rest with the N and B it recovers (``ins_allan.png``)
================================  ==================================================================
"""

from __future__ import annotations

import math
import os
from dataclasses import replace
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from tumble import attitude
from tumble._validate import require_positive
from tumble.analytic import measure_nutation
from tumble.ins.allan import FLICKER_FACTOR, allan_deviation
from tumble.ins.coning import CONING_RANGES, Coning, drift_law, measure_drift
from tumble.ins.gyroscope import Gyroscope
from tumble.ins.increments import from_trajectory
from tumble.ins.sensors import Imu, SensorErrors
from tumble.ins.strapdown import ALGORITHMS, strapdown
from tumble.simulate import simulate
from tumble.viz._output import out_directory, save_png

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from tumble.ins.allan import AllanDeviation

__all__ = ["DEMO_GYRO", "DEMO_GYRO_ERRORS", "allan_figure", "demo_coning", "demo_gyroscope", "demo_ins"]

_DEG_PER_HOUR = math.radians(1.0) / 3600.0          # rad/s
_DEG_PER_ROOT_HOUR = math.radians(1.0) / 60.0       # rad/√s

#: The demonstration gyro rotor: I_s = 2e-3, I_t = 1.5e-3 kg·m² about the pivot, 100 rad/s,
#: 0.1 kg with its centre of mass 2 cm off the pivot (ε = τ I_t / (I_s ω_s)² = 7.4e-4).
DEMO_GYRO = Gyroscope(spin_inertia=2e-3, transverse_inertia=1.5e-3, spin=100.0, mass=0.1, offset=0.02)

#: A tactical-grade gyro triad (IEEE 952 terms): bias 1 °/h, ARW 0.05 °/√h, bias
#: instability 0.5 °/h (flicker over 1 s … 10⁴ s), RRW 0.01 °/h/√s, scale factor 100 ppm,
#: misalignment 50 µrad, quantization 0.1 µrad.
DEMO_GYRO_ERRORS = SensorErrors(
    bias=np.array([1.0, -0.7, 0.5]) * _DEG_PER_HOUR,
    white_noise=0.05 * _DEG_PER_ROOT_HOUR,
    bias_instability=0.5 * _DEG_PER_HOUR,
    flicker_band=(1.0, 1e4),
    random_walk=0.01 * _DEG_PER_HOUR,
    scale_factor=np.array([100e-6, -80e-6, 60e-6]),
    misalignment=50e-6 * np.array([[0.0, 1.0, -1.0], [0.5, 0.0, 1.0], [-1.0, 0.5, 0.0]]),
    quantization=1e-7,
)


_GYRO_TOLERANCE = 1e-12            # rtol = atol of the gyroscope runs (dop853)
_CONING_HALF_ANGLE = 0.01           # rad
_CONING_FREQUENCY = 2.0 * math.pi   # rad/s
_CONING_PERIODS_SHOWN = 2           # cone periods of the coning motion in ins_coning.html
_CONING_FRAMES = 201                # its samples


def _steady(gyro: Gyroscope, t):
    """``gyro`` started in steady precession, simulated through ``t`` (s)."""
    return simulate(gyro, t=t, precession_rate0=gyro.steady_precession_rate, rtol=_GYRO_TOLERANCE,
                    atol=_GYRO_TOLERANCE)


def demo_gyroscope(out_dir: str | os.PathLike[str]) -> dict:
    """Simulate :data:`DEMO_GYRO` released with its axis horizontal, and its drift mechanisms.

    Writes ``ins_gyro_precession.png`` (azimuth and tilt of the axis over
    0.4 s: cycloidal nutation about the mean precession) with ``ins_gyro_precession.html`` (that
    run in the offline viewer, :mod:`tumble.viz.viewer`) and
    ``ins_gyro_drift.png`` (azimuth drift from imbalance with and without a
    spin-bearing drag of 2e-3 N·m, which slows the spin from 100 to 80 rad/s,
    and the tilt from a pivot friction of 1e-5 N·m, over 20 s, each against
    its law). Returns the predicted and
    measured precession rate (rad/s, over whole nutation periods), the
    nutation period (s) measured, of the fast-top law ``2π/ω_n``
    (``nutation_period_s``) and of the exact heavy top
    (``nutation_period_s_exact``), and the largest deviations of the drifts
    from their laws (rad).
    """
    from matplotlib.figure import Figure

    out_dir = out_directory(out_dir)
    gyro = DEMO_GYRO
    period = 2.0 * math.pi / gyro.nutation_frequency
    cycles = 8
    t = np.linspace(0.0, cycles * period, cycles * 100 + 1)
    released = simulate(gyro, t=t, rtol=_GYRO_TOLERANCE, atol=_GYRO_TOLERANCE)   # released at rest
    axis = gyro.axis(released)
    rate = (axis.phi[-1] - axis.phi[0]) / t[-1]
    nutation = measure_nutation(released, com=[0.0, 0.0, gyro.offset], g=[0.0, 0.0, -gyro.g])

    figure = Figure(figsize=(6.4, 5.0), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(t, 1e3 * axis.phi, label="simulated φ")
    top.plot(t, 1e3 * gyro.precession_rate * t, "k--", lw=0.8, label="τ / (I_s ω_s) · t")
    top.set_ylabel("azimuth φ (mrad)")
    top.legend(fontsize=8)
    bottom.plot(t, 1e3 * (axis.theta - math.pi / 2), label="simulated")
    bottom.set_ylabel("tilt θ − 90° (mrad)")
    bottom.set_xlabel("t (s)")
    top.set_title(f"gyro released at rest: I_s ω_s = {gyro.momentum:g} N·m·s, τ = {gyro.imbalance_torque:.3g} N·m, "
                  f"ω_n = {gyro.nutation_frequency:.4g} rad/s", fontsize=9)
    precession_png = save_png(figure, os.path.join(out_dir, "ins_gyro_precession.png"))
    precession_html = os.path.join(out_dir, "ins_gyro_precession.html")
    released.to_html(precession_html, model=gyro)

    spin_drag, pivot_drag = 2e-3, 1e-5
    t = np.linspace(0.0, 20.0, 401)
    steady = gyro.axis(_steady(gyro, t))
    dragged_gyro = replace(gyro, spin_friction=spin_drag)
    dragged = dragged_gyro.axis(_steady(dragged_gyro, t))
    spin_t = gyro.spin - spin_drag * t / gyro.spin_inertia
    dragged_law = gyro.imbalance_torque / spin_drag * np.log(gyro.spin / spin_t)
    pivot_gyro = replace(gyro, pivot_friction=pivot_drag)
    tilted = pivot_gyro.axis(_steady(pivot_gyro, t))
    tilt_law = pivot_drag / gyro.momentum * t

    figure = Figure(figsize=(6.4, 5.0), layout="constrained")
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(t, steady.phi, label="imbalance")
    top.plot(t, gyro.precession_rate * t, "k--", lw=0.8, label="m g l t / (I_s ω_s)")
    top.plot(t, dragged.phi, label=f"imbalance + spin drag {spin_drag:g} N·m")
    top.plot(t, dragged_law, "k:", lw=0.8, label="(m g l / τ_f) ln(ω_s0 / ω_s(t))")
    top.set_ylabel("azimuth drift φ (rad)")
    top.legend(fontsize=8)
    bottom.plot(t, 1e3 * (tilted.theta - math.pi / 2), label=f"pivot friction {pivot_drag:g} N·m")
    bottom.plot(t, 1e3 * tilt_law, "k--", lw=0.8, label="τ_p t / (I_s ω_s)")
    bottom.set_ylabel("tilt θ − 90° (mrad)")
    bottom.set_xlabel("t (s)")
    bottom.legend(fontsize=8)
    drift_png = save_png(figure, os.path.join(out_dir, "ins_gyro_drift.png"))
    return {
        "precession_rate": gyro.precession_rate,
        "precession_rate_measured": float(rate),
        "nutation_period_s": period,
        "nutation_period_s_measured": nutation.period,
        "nutation_period_s_exact": gyro.heavy_top().nutation_period,
        "imbalance_drift_error_rad": float(np.abs(steady.phi - gyro.precession_rate * t).max()),
        "spin_drag_drift_error_rad": float(np.abs(dragged.phi - dragged_law).max()),
        "pivot_tilt_error_rad": float(np.abs(tilted.theta - math.pi / 2 - tilt_law).max()),
        "precession_png": precession_png,
        "precession_html": precession_html,
        "drift_png": drift_png,
    }


def demo_coning(out_dir: str | os.PathLike[str], *, points: int = 12) -> dict:
    """Coning drift (α = 0.01 rad, Ω = 2π rad/s) of every algorithm over Ω T from 0.05 to 1.

    Writes ``ins_coning.png`` (measured |drift| and the laws of
    :func:`~tumble.ins.coning.drift_law` against the update rate 1/T) and
    ``ins_coning.html`` (two periods of the coning motion in the offline viewer), and
    returns, per algorithm, the update rates (Hz), measured and predicted
    drifts (rad/s, magnitudes) and the largest relative deviation from the
    law inside :data:`CONING_RANGES`.
    """
    from matplotlib.figure import Figure

    out_dir = out_directory(out_dir)
    coning = Coning(_CONING_HALF_ANGLE, _CONING_FREQUENCY)
    x = np.geomspace(0.05, 1.0, int(points))
    figure = Figure(figsize=(6.4, 4.6), layout="constrained")
    ax = figure.add_subplot()
    summary: dict[str, Any] = {"half_angle": coning.half_angle, "frequency": coning.frequency}
    for algorithm in ALGORITHMS:
        T = x / coning.frequency
        measured = np.abs([measure_drift(coning, algorithm, float(step), 400) for step in T])
        predicted = drift_law(algorithm, coning.half_angle, coning.frequency, T)
        lo, hi = CONING_RANGES[algorithm]
        inside = (x >= lo * (1 - 1e-12)) & (x <= hi * (1 + 1e-12))
        (line,) = ax.loglog(1.0 / T, predicted, lw=1, label=f"{algorithm}: law")
        ax.loglog(1.0 / T, measured, "o", color=line.get_color(), ms=4, label=f"{algorithm}: measured")
        summary[algorithm] = {
            "update_rate_hz": (1.0 / T).tolist(),
            "measured": measured.tolist(),
            "predicted": predicted.tolist(),
            "max_relative_deviation": float(np.max(np.abs(measured[inside] / predicted[inside] - 1.0))),
        }
    ax.set_xlabel("update rate 1/T (Hz)")
    ax.set_ylabel("drift about the cone axis (rad/s)")
    ax.set_title(f"coning α = {coning.half_angle} rad, Ω = 2π rad/s", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    summary["png"] = save_png(figure, os.path.join(out_dir, "ins_coning.png"))
    summary["html"] = os.path.join(out_dir, "ins_coning.html")
    coning.trajectory(np.linspace(0.0, _CONING_PERIODS_SHOWN * 2.0 * math.pi / coning.frequency,
                                  _CONING_FRAMES)).to_html(summary["html"])
    return summary


def demo_ins(out_dir: str | os.PathLike[str], *, duration: float = 60.0, seed: int = 2026) -> dict:
    """Tumbling body → gyro with :data:`DEMO_GYRO_ERRORS` → three-sample strapdown → attitude error.

    The body (inertia diag(0.05, 0.1, 0.12) kg·m², ω₀ = (0.5, 2, 0.3) rad/s)
    is simulated with ``tumble.simulate`` (``method="exact"``: the closed-form
    torque-free motion, so the truth has no integration error) on a 400 Hz
    grid; the gyro samples it at 200 Hz (:func:`from_trajectory`, Simpson's
    rule). Three runs of the strapdown algorithm: error-free increments, angle
    random walk alone, and every error term. Writes ``ins_error.png`` (error
    angle against time, with ``N √(3t)``, the RMS angle random walk of three
    axes), ``ins_truth.html`` (the tumbling body in the offline viewer) and ``ins_allan.png`` (Allan deviation of the same gyro at rest for
    4 h at 10 Hz, with the N and B it recovers). Returns the final and
    largest errors (rad) of each run, the ARW prediction and the recovered N,
    B against the true ones.
    """
    from matplotlib.figure import Figure

    out_dir = out_directory(out_dir)
    duration = require_positive(duration, "duration")
    dt = 1.0 / 200.0
    steps = 6 * max(1, round(duration / (3 * dt)))  # whole three-sample updates, grid at dt / 2
    t = 0.5 * dt * np.arange(steps + 1)
    truth = simulate(np.diag([0.05, 0.1, 0.12]), [0.5, 2.0, 0.3], t=t, method="exact")
    assert truth.q is not None  # a rigid body's attitude
    exact = from_trajectory(truth, oversample=2)
    errors = DEMO_GYRO_ERRORS
    cases = {
        "error-free": exact,
        "angle random walk": Imu(gyro=SensorErrors(white_noise=errors.white_noise)).measure(exact, seed=seed),
        "all error terms": Imu(gyro=errors).measure(exact, seed=seed),
    }
    figure = Figure(figsize=(6.4, 4.6), layout="constrained")
    ax = figure.add_subplot()
    summary: dict[str, Any] = {"duration_s": float(t[-1]), "sample_rate_hz": 1.0 / dt}
    for name, increments in cases.items():
        nav = strapdown(increments, q0=truth.q[0], algorithm="three-sample")
        error = attitude.relative_angle(cast(np.ndarray, nav.attitude.q), truth.q[::6])
        ax.loglog(nav.attitude.t[1:], error[1:], lw=1, label=name)
        summary[name] = {"final_rad": float(error[-1]), "max_rad": float(error.max())}
    span = np.geomspace(3 * dt, t[-1], 50)
    ax.loglog(span, errors.white_noise * np.sqrt(3 * span), "k--", lw=0.8, label="N √(3t)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("attitude error (rad)")
    ax.set_title("strapdown (three-sample, 200 Hz) of a tumbling body", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    summary["arw_prediction_rad"] = float(errors.white_noise * math.sqrt(3 * t[-1]))
    summary["error_png"] = save_png(figure, os.path.join(out_dir, "ins_error.png"))
    summary["truth_html"] = os.path.join(out_dir, "ins_truth.html")
    truth.to_html(summary["truth_html"])

    rest_dt = 0.1
    rest = errors.apply(np.zeros((round(4 * 3600.0 / rest_dt), 3)), rest_dt, np.random.default_rng(seed))
    adev = allan_deviation(rest, rest_dt, kind="increment")
    n_fit, b_fit = adev.white_noise(tau_max=0.3), adev.bias_instability()
    figure = allan_figure({"gyro at rest": adev}, white_noise=errors.white_noise,
                          bias_instability=errors.bias_instability,
                          title="demo gyro at rest: 4 h at 10 Hz (black: the model's N and B)")
    summary.update(white_noise=errors.white_noise, white_noise_recovered=n_fit.tolist(),
                   bias_instability=errors.bias_instability, bias_instability_recovered=b_fit.tolist(),
                   allan_png=save_png(figure, os.path.join(out_dir, "ins_allan.png")))
    return summary


def allan_figure(curves: dict[str, AllanDeviation], *, white_noise: float | None = None, bias_instability: float | None = None,
                 units: str = "rad/s", title: str | None = None) -> Figure:
    """Log-log figure of Allan deviations: ``curves`` maps a label to an :class:`AllanDeviation`.

    With ``white_noise`` (N) and ``bias_instability`` (B) the model lines
    ``N/√τ`` and ``0.664 B`` are drawn dashed. Returns a matplotlib Figure
    (object-oriented API; nothing shown).
    """
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.4, 4.4), layout="constrained")
    ax = figure.add_subplot()
    tau_all = np.concatenate([c.tau for c in curves.values()])
    for label, curve in curves.items():
        lines = ax.loglog(curve.tau, curve.sigma, marker=".", lw=1)
        lines[0].set_label(label if len(lines) == 1 else f"{label} (x, y, z)")
    span = np.geomspace(tau_all.min(), tau_all.max(), 50)
    if white_noise is not None:
        ax.loglog(span, white_noise / np.sqrt(span), "k--", lw=0.8, label=f"N/√τ, N = {white_noise:.3g}")
    if bias_instability is not None:
        ax.axhline(FLICKER_FACTOR * bias_instability, color="k", ls=":", lw=0.8,
                   label=f"0.664 B, B = {bias_instability:.3g}")
    ax.set_xlabel("cluster time τ (s)")
    ax.set_ylabel(f"Allan deviation σ(τ) ({units})")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return figure

