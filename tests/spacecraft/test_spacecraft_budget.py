"""The momentum budget of tumble.spacecraft.budget (``tumble demo budget``): the gravity gradient's secular
build-up against its exact closed form, every source against SMAD's estimates within a factor 2, the eclipse
seasons' closed form against the sampled shadow, and the demo through the CLI."""

import math
import re
from datetime import timedelta

import numpy as np
import pytest
from typer.testing import CliRunner

from tumble.cli import app
from tumble.spacecraft.budget import (DEMO_EPOCH, SOURCES, SmallSat, demo_orbit, eclipse_fraction, momentum_budget,
                                      smad_estimates)
from tumble.viz.budget import demo_budget
from tumble.spacecraft.environment_table import Environment
from tumble.spacecraft.orbit import Orbit

# SMAD's estimates are worst cases of one number each (the largest face square to the flow or the Sun, the whole
# offset as lever arm, the mean density, the polar field): the demo's day measures the ratios simulated/SMAD
# 1.00 (gravity gradient, exact), 1.7 (solar pressure), 1.07 (drag), 1.5 (magnetic) for the momentum and
# 1.00, 0.99, 1.9, 0.66 for the peak torques.
SMAD_FACTOR = 2.0


@pytest.fixture(scope="module")
def three_hours():
    orbit = demo_orbit()
    env = Environment.sample(orbit, DEMO_EPOCH, duration=3 * 3600.0, step=10.0, j2=True)
    return orbit, env, momentum_budget(SmallSat(), env)


@pytest.mark.slow  # simulates a spacecraft: compiles it (~40 CPU s on a cold cache)
def test_gravity_gradient_builds_pitch_momentum_at_exactly_3_n2_jxz(three_hours):
    # Earth pointing, body z nadir: τ = 3 μ/|r|³ ẑ × (J ẑ) = 3 n² (−J_yz, J_xz, 0), n² = μ/|r|³, constant in the
    # body, and ω × J ω = ω² (J_yz, 0, −J_xy) = 0: h_y = 3 n² J_xz t exactly (RK4 on a constant rate)
    orbit, env, budget = three_hours
    h = budget.momentum[:, SOURCES.index("gravity_gradient")]
    n2 = orbit.mu / np.linalg.norm(env.position, axis=1) ** 3
    expected = 3.0 * SmallSat().product_xz * np.concatenate([[0.0], np.cumsum(
        0.5 * (n2[1:] + n2[:-1]) * np.diff(env.t))])
    assert np.abs(h[:, 1] - expected).max() < 1e-9 * expected[-1]
    assert np.abs(h[:, [0, 2]]).max() < 1e-12 * expected[-1]


@pytest.mark.slow  # simulates a spacecraft: compiles it (~37 CPU s on a cold cache)
def test_every_source_is_within_a_factor_2_of_smads_estimate(three_hours):
    orbit, env, budget = three_hours
    estimates = smad_estimates(SmallSat(), orbit, float(np.mean(env.density)))
    duration = env.t[-1]
    for i, source in enumerate(SOURCES):
        e = estimates[source]
        torque = np.linalg.norm(budget.torques[:, i], axis=1).max()
        momentum = np.linalg.norm(budget.momentum[:, i], axis=1).max()
        expected = e.get("momentum_per_orbit", e.get("momentum_per_s", 0.0) * duration)
        assert 1.0 / SMAD_FACTOR < torque / e["torque"] < SMAD_FACTOR, source
        assert 1.0 / SMAD_FACTOR < momentum / expected < SMAD_FACTOR, source


@pytest.mark.slow  # simulates a spacecraft: compiles it (~37 CPU s on a cold cache)
def test_the_wheels_share_the_momentum_exactly(three_hours):
    from tumble.spacecraft import pyramid_wheels

    _, _, budget = three_hours
    axes = np.array([w.axis for w in pyramid_wheels(1.0)])
    assert np.abs(budget.wheels @ axes - budget.total).max() < 1e-15 * np.abs(budget.total).max() * 10


def test_eclipse_fraction_matches_the_sampled_cylindrical_shadow():
    orbit = demo_orbit()
    _, fraction = eclipse_fraction(orbit, DEMO_EPOCH, np.arange(0.0, 366.0))
    day = int(np.argmax(fraction))
    assert fraction[day] > 0.2 and (fraction == 0.0).sum() > 200      # a season of eclipses, then none
    seconds = day * 86400.0
    drifted = Orbit.circular(500e3, orbit.inclination, raan=orbit.raan + orbit.j2_rates()[0] * seconds)
    env = Environment.sample(drifted, DEMO_EPOCH + timedelta(seconds=seconds), duration=drifted.period, step=2.0,
                             shadow="cylindrical")
    sampled = np.mean(env.shadow[:-1] == 0.0)
    # the closed form holds the Sun still over the orbit; the samples resolve 2 s of 5677 s
    assert sampled == pytest.approx(fraction[day], abs=2e-3)


@pytest.mark.slow  # simulates a spacecraft: compiles it (~38 CPU s on a cold cache)
def test_demo_budget_runs_from_the_command_line_with_its_gravity_gradient_momentum_at_smads(tmp_path):
    # an hour and two Monte-Carlo orbits (the default day and 32 orbits take about a minute)
    result = CliRunner().invoke(app, ["demo", "budget", "-o", str(tmp_path), "--hours", "1", "--samples", "2"])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "budget.png").stat().st_size > 10_000
    row = next(line for line in result.stdout.splitlines() if line.startswith("gravity gradient"))
    momentum, smad = map(float, re.search(r"momentum (\S+) N m s \(SMAD (\S+)\)", row).groups())
    assert momentum == pytest.approx(smad, rel=2e-3)  # within 1e-3 (test_demo_budget_reduced), printed to 3 digits
    assert "over 1 h" in result.stdout and "(2 draws)" in result.stdout


@pytest.mark.parametrize("args, message", [(["--samples", "0"], "--samples: must be an integer >= 1, got 0"),
                                           (["--hours", "-1"], "--hours: must be a finite number > 0, got -1.0")])
def test_demo_budget_refuses_a_bad_option_naming_it(tmp_path, args, message):
    result = CliRunner().invoke(app, ["demo", "budget", "-o", str(tmp_path), *args])
    assert result.exit_code == 2 and result.stderr.strip() == f"error: {message}"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow  # simulates a spacecraft: compiles it (~38 CPU s on a cold cache)
def test_demo_budget_reduced(tmp_path):
    summary = demo_budget(tmp_path, hours=1.0, samples=2)
    assert summary["hours"] == pytest.approx(1.0, abs=10 / 3600)
    assert summary["peak_momentum"]["gravity_gradient"] == pytest.approx(
        summary["estimate_momentum"]["gravity_gradient"], rel=1e-3)
    assert summary["monte_carlo_samples"] == 2 and math.isfinite(summary["monte_carlo_p95"])
    assert (tmp_path / "budget.png").is_file()
