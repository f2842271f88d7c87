"""``tumble demo estimation``: a slew and fine pointing with a star tracker and a gyro through the MEKF in the
loop, and a Monte-Carlo over sensor noise seeds and gyro biases (``docs/estimation.md``, "The flight-software
loop").

The spacecraft (:func:`spacecraft`): inertia diag(10, 12, 8) kg·m², four
pyramid wheels, a quaternion-feedback PD law (ω_n = 0.2 rad/s, ζ = 0.707,
slew rate ≤ 1°/s) to a target 30° about (1, 2, 2)/3, sampled at 2 Hz with a
one-period computation delay; a star tracker of 10″ (1σ per axis) and a gyro of
σ_v = 1e-5 rad/√s, σ_u = 1e-8 rad/s^1.5 (:data:`FSW`). Each run of the
Monte-Carlo has its own noise seed, its own gyro bias (1σ = 1e-5 rad/s per axis)
and its own initial estimate error (1σ = 1e-3 rad per axis): the spread the
filter starts from (``attitude_sigma0``, ``bias_sigma0``).
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from tumble import attitude
from tumble.simulate import simulate
from tumble.spacecraft.actuators import pyramid_wheels
from tumble.spacecraft.control import QuaternionPD
from tumble.spacecraft.flight_software import FlightSoftware
from tumble.spacecraft.model import Spacecraft
from tumble.trajectory import Trajectory

__all__ = ["FSW", "TARGET", "demo_estimation", "dispersions", "loop_response", "monte_carlo", "spacecraft"]

#: The slew's target: 30° about (1, 2, 2)/3.
TARGET = attitude.from_rotvec(np.radians(30.0) * np.array([1.0, 2.0, 2.0]) / 3.0)
#: Control (and filter) period, s; the integration step, s.
PERIOD, DT = 0.5, 0.1
#: A 10″ star tracker, a gyro of σ_v = 1e-5 rad/√s and σ_u = 1e-8 rad/s^1.5, a one-period delay.
FSW = FlightSoftware(gyro_arw=1e-5, gyro_rrw=1e-8, star_tracker_sigma=np.radians(10.0 / 3600.0),
                     attitude_sigma0=1e-3, bias_sigma0=1e-5, delay=1)


def spacecraft(fsw: FlightSoftware | None = FSW, natural_frequency: float = 0.2) -> Spacecraft:
    """The demo's spacecraft with the flight software ``fsw`` (None: the law reads the truth)."""
    law = QuaternionPD(natural_frequency=natural_frequency, target=TARGET, max_rate=np.radians(1.0))
    return Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]), wheels=pyramid_wheels(0.02, max_torque=0.2),
                      controller=law, control_period=PERIOD, flight_software=fsw)


def monte_carlo(runs: int, *, duration: float, seed: int = 0, craft: Spacecraft | None = None) -> Trajectory:
    """``runs`` runs of ``craft`` (default :func:`spacecraft`) from rest at the identity, outputs at every
    sample: run ``i`` has the noise seed ``seed + i`` and draws its gyro bias and initial estimate error
    (with ``numpy.random.default_rng(seed)``) from the filter's initial spread."""
    craft = spacecraft() if craft is None else craft
    assert craft.flight_software is not None
    t = np.arange(0.0, duration + 0.5 * PERIOD, PERIOD)
    initial = dispersions(craft.flight_software, runs, seed)
    return simulate(craft, np.zeros((runs, 3)), t=t, method="rk4", dt=DT, q_estimate0=initial["q_estimate0"],
                    gyro_bias0=initial["gyro_bias0"], sensor_seed0=initial["sensor_seed0"])


def dispersions(fsw: FlightSoftware, runs: int, seed: int) -> dict[str, np.ndarray]:
    """The initial states of the Monte-Carlo's runs: ``q_estimate0`` (the identity turned by N(0, σ_θ0²) per
    axis), ``gyro_bias0`` (N(0, σ_β0²) per axis), drawn with ``numpy.random.default_rng(seed)``, and
    ``sensor_seed0`` = seed + run."""
    rng = np.random.default_rng(seed)
    bias = rng.normal(0.0, fsw.bias_sigma0, (runs, 3))
    q_estimate0 = attitude.from_rotvec(rng.normal(0.0, fsw.attitude_sigma0, (runs, 3)))
    return {"q_estimate0": q_estimate0, "gyro_bias0": bias,
            "sensor_seed0": seed + np.arange(runs, dtype=float)[:, None]}


def loop_response(traj: Trajectory, start: int, knowledge_error: np.ndarray, rate_error: np.ndarray, *,
                  initial: bool = True) -> np.ndarray:
    """The control error (K − start, …, 3) from sample ``start`` on as the linear response of the demo's sampled
    loop to the estimator's errors ``knowledge_error`` and ``rate_error`` (ω̂ − ω) at the samples (K, …, 3),
    from the state of ``traj`` at ``start`` (``initial``) or from rest at the target.

    In fine pointing the loop is linear and decoupled per axis (PD gains ∝ J; the gyroscopic term is second
    order): with θ = −control error, the law commands ``a_k = −ω_n² (θ_k + e_k) − 2ζω_n (θ̇_k + n_k)``
    from the estimate, and it acts one period later (:data:`FSW`'s delay) on the double integrator
    ``θ̈ = a``, exact under a zero-order hold: ``θ ← θ + T θ̇ + ½ T² a``, ``θ̇ ← θ̇ + T a``."""
    craft = spacecraft()
    law = craft.controller[0]
    wn, zeta = law.natural_frequency, law.damping_ratio
    assert traj.omega is not None  # a spacecraft's hub rate
    theta, rate = -traj.control_error[start], traj.omega[start]
    acting = traj.torque_command[start] / np.diag(craft.rate_inertia)
    if not initial:
        theta, rate, acting = np.zeros_like(theta), np.zeros_like(rate), np.zeros_like(acting)
    response = [theta]
    for k in range(start, traj.t.size - 1):
        command = -wn**2 * (theta + knowledge_error[k]) - 2.0 * zeta * wn * (rate + rate_error[k])
        theta, rate = theta + PERIOD * rate + 0.5 * PERIOD**2 * acting, rate + PERIOD * acting
        acting = command
        response.append(theta)
    return -np.array(response)


def _psd(x: np.ndarray, period: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided periodogram (rad²/Hz) of the rows of ``x`` (runs, K), averaged over the runs, mean removed."""
    x = x - x.mean(axis=-1, keepdims=True)
    spectrum = np.abs(np.fft.rfft(x, axis=-1)) ** 2 * (2.0 * period / x.shape[-1])
    return np.fft.rfftfreq(x.shape[-1], period), spectrum.mean(axis=0)


def demo_estimation(out_dir: str | os.PathLike[str], *, runs: int = 40, duration: float = 600.0,
                    seed: int = 2026) -> dict:
    """Run the Monte-Carlo (module docstring) and write ``estimation_loop.png`` (one run: the knowledge error
    with the filter's 3σ, the control error; the runs' fraction inside 3σ) and ``estimation_spectra.png``
    (the spectra of the knowledge and control errors in fine pointing, after ``duration / 3``). Returns the
    fraction of knowledge errors inside 3σ, the fine-pointing RMS of both errors, their correlation and the
    paths written."""
    from matplotlib.figure import Figure

    from tumble.viz._output import out_directory as _check_dir
    from tumble.viz._output import save_png as _save

    out_dir = _check_dir(out_dir)
    traj = monte_carlo(runs, duration=duration, seed=seed)
    t = traj.t
    knowledge, bound, control = traj.knowledge_error, traj.knowledge_error_3sigma, traj.control_error
    inside = float(np.mean(np.abs(knowledge) <= bound))
    fine = t >= duration / 3.0
    k_fine, c_fine = knowledge[fine], control[fine]
    summary: dict[str, Any] = {
        "runs": runs, "duration_s": float(t[-1]), "inside_3sigma": inside,
        "knowledge_rms_rad": float(np.sqrt(np.mean(k_fine**2))), "control_rms_rad": float(np.sqrt(np.mean(c_fine**2))),
        "correlation": float(np.corrcoef(k_fine.ravel(), c_fine.ravel())[0, 1]),
        "slew_angle_deg": float(np.degrees(np.linalg.norm(control[0, 0]))),
    }
    arcsec = np.degrees(1.0) * 3600.0
    figure = Figure(figsize=(7.0, 7.0), layout="constrained")
    axes = figure.subplots(3, 1, sharex=True)
    for i, ax in enumerate(axes):
        ax.fill_between(t, -bound[:, 0, i] * arcsec, bound[:, 0, i] * arcsec, color="0.85", label="filter 3σ")
        ax.plot(t, knowledge[:, 0, i] * arcsec, lw=0.6, label="knowledge error (estimate − truth)")
        ax.plot(t, control[:, 0, i] * arcsec, lw=0.6, label="control error (target − truth)")
        ax.set_ylim(-60.0, 60.0)
        ax.set_ylabel(f"{'xyz'[i]}, arcsec")
    axes[0].set_title(f"Slew then fine pointing, MEKF in the loop (run 1 of {runs}; {inside:.2%} of "
                      "all knowledge errors inside 3σ)", fontsize=9)
    axes[0].legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("t, s")
    summary["loop_figure"] = _save(figure, os.path.join(out_dir, "estimation_loop.png"))

    figure = Figure(figsize=(6.4, 4.6), layout="constrained")
    ax = figure.add_subplot()
    start = int(np.argmax(fine)) - int(round(50.0 / PERIOD))  # 50 s for the responses' transients to decay
    rate_error = traj.omega_estimate - traj.omega
    zero = np.zeros_like(knowledge)
    curves = (("knowledge error", k_fine, "C0", "-"), ("control error", c_fine, "C1", "-"),
              ("loop response to the knowledge error", loop_response(traj, start, knowledge, zero, initial=False),
               "C0", ":"),
              ("loop response to the rate error", loop_response(traj, start, zero, rate_error, initial=False),
               "C2", ":"),
              ("loop response to both", loop_response(traj, start, knowledge, rate_error), "C1", "--"))
    for name, x, color, style in curves:
        x = x[-k_fine.shape[0]:]
        f, p = _psd(np.moveaxis(x, 0, -1).reshape(-1, x.shape[0]), PERIOD)
        ax.loglog(f[1:], p[1:], color=color, ls=style, lw=1, label=name)
    ax.axvline(spacecraft().controller[0].natural_frequency / (2.0 * np.pi), color="k", lw=0.6, ls=":",
               label="loop natural frequency ω_n / 2π")
    ax.set_xlabel("frequency, Hz")
    ax.set_ylabel("PSD, rad²/Hz (per axis, mean of runs)")
    ax.set_title("Fine pointing: the control error is the estimator's errors through the loop", fontsize=9)
    ax.legend(fontsize=7)
    summary["spectra_figure"] = _save(figure, os.path.join(out_dir, "estimation_spectra.png"))
    return summary
