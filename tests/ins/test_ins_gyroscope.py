"""Mechanical gyroscopes simulated with Euler's equations (tumble.ins.gyroscope)."""

import math
from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble.analytic import measure_nutation
from tumble.ins import Gyroscope
from tumble._validate import ValidationError

# Every test here compiles this model kind's integrators on a cold Numba cache (several CPU s each).
pytestmark = pytest.mark.slow

# Released at rest with its axis horizontal, the rotor precesses on average at
# τ/(I_s ω_s) (1 − 2ε² + O(ε⁴)), ε = τ I_t/(I_s ω_s)² (from the exact heavy top,
# tumble.analytic.HeavyTop: −1.08e-6 at ε = 7.4e-4, −1.73e-9 at ε = 2.9e-5). At
# ω_s = 500 rad/s, ε = 2.9e-5, so the law holds to 2e-9 and the 1e-6 is
# limited by the integrator (dop853, rtol 1e-12): measured −4.3e-9.
PRECESSION_RTOL = 1e-6
# Nutation period 2π I_t/(I_s ω_s) (1 − 3ε² + …): at ε = 7.4e-4 the law is off by
# 1.6e-6; the period measured from the simulation agrees with the exact heavy top to 1.6e-14.
NUTATION_LAW_RTOL = 5 * (7.4e-4) ** 2
NUTATION_EXACT_RTOL = 1e-9

ROTOR = dict(spin_inertia=2e-3, transverse_inertia=1.5e-3, mass=0.1, offset=0.02)
TIGHT = dict(rtol=1e-12, atol=1e-12)


def released(gyro, t):
    """The gyro released at rest (``precession_rate0`` 0, the default), dop853 at rtol = atol = 1e-12."""
    return tumble.simulate(gyro, t=t, **TIGHT)


def steady(gyro, t):
    """The gyro started in steady precession."""
    return tumble.simulate(gyro, t=t, precession_rate0=gyro.steady_precession_rate, **TIGHT)


@pytest.mark.slow  # the first dop853 run with a torque program compiles it (~10 s of CPU cold)
def test_precession_rate_is_torque_over_spin_momentum():
    gyro = Gyroscope(spin=500.0, **ROTOR)
    period = 2.0 * math.pi / gyro.nutation_frequency
    cycles = 200
    t = np.linspace(0.0, cycles * period, cycles * 40 + 1)
    axis = gyro.axis(released(gyro, t))
    # over whole nutation periods the nutation averages out of the azimuth
    rate = (axis.phi[-1] - axis.phi[0]) / t[-1]
    law = gyro.imbalance_torque / (gyro.spin_inertia * gyro.spin)
    assert rate == pytest.approx(law, rel=PRECESSION_RTOL)
    assert rate == pytest.approx(gyro.heavy_top().mean_precession_rate, rel=PRECESSION_RTOL)


def test_steady_precession_has_no_nutation():
    gyro = Gyroscope(spin=500.0, **ROTOR)
    t = np.linspace(0.0, 10.0, 501)
    axis = gyro.axis(steady(gyro, t))
    # exact for a horizontal axis; measured: rate to 3.7e-13, tilt constant to 2.7e-14 rad
    assert np.polyfit(t, axis.phi, 1)[0] == pytest.approx(gyro.precession_rate, rel=1e-10)
    assert np.ptp(axis.theta) < 1e-11


def test_nutation_frequency():
    gyro = Gyroscope(spin=100.0, **ROTOR)
    top = gyro.heavy_top()
    t = np.linspace(0.0, 50 * top.nutation_period, 50 * 200 + 1)
    measured = measure_nutation(released(gyro, t), com=[0.0, 0.0, gyro.offset], g=[0.0, 0.0, -gyro.g])
    assert measured.period == pytest.approx(top.nutation_period, rel=NUTATION_EXACT_RTOL)
    assert 2 * math.pi / measured.period == pytest.approx(gyro.nutation_frequency, rel=NUTATION_LAW_RTOL)


def test_spin_bearing_friction_speeds_up_the_imbalance_drift():
    drag = 2e-3
    gyro = Gyroscope(spin=500.0, spin_friction=drag, **ROTOR)
    t = np.linspace(0.0, 100.0, 2001)
    axis = gyro.axis(steady(gyro, t))
    spin = gyro.spin - drag * t / gyro.spin_inertia          # 500 → 400 rad/s
    np.testing.assert_allclose(axis.spin, spin, rtol=1e-12)
    phi = gyro.imbalance_torque / drag * np.log(gyro.spin / spin)
    # adiabatic law: measured 3.0e-10 of the final azimuth (2.2 rad)
    np.testing.assert_allclose(axis.phi, phi, rtol=0, atol=1e-8 * phi[-1])


def test_pivot_friction_tilts_the_axis():
    drag = 1e-4
    gyro = Gyroscope(spin=500.0, pivot_friction=drag, **ROTOR)
    t = np.linspace(0.0, 10.0, 2001)
    axis = gyro.axis(steady(gyro, t))
    tilt_rate = np.polyfit(t, axis.theta, 1)[0]
    # θ̇ = τ_p/(I_s ω_s) at θ = π/2; the axis tilts by 1 mrad, which changes the gravity torque
    # by (1 − cos) ~ 5e-7: measured −4.3e-7 relative
    assert tilt_rate == pytest.approx(drag / gyro.momentum, rel=1e-5)


def test_gyroscope_validation():
    with pytest.raises(ValidationError, match="spin"):
        Gyroscope(spin=0.0, **ROTOR)
    with pytest.raises(ValidationError, match="offset"):
        Gyroscope(spin=10.0, **{**ROTOR, "offset": -1.0})
    with pytest.raises(ValidationError, match="tilt"):
        Gyroscope(spin=10.0, tilt=0.0, **ROTOR)
    with pytest.raises(ValidationError, match="offset"):
        Gyroscope(spin=10.0, **{**ROTOR, "offset": 0.0}).heavy_top()
    with pytest.raises(ValidationError,
                       match="released: a Gyroscope has no initial state 'released'; it takes precession_rate0"):
        tumble.simulate(Gyroscope(spin=10.0, **ROTOR), t=[0.0, 1.0], released=False)


# The total energy E = ½ ω·Iω + m g l cos θ of the free heavy top, its vertical momentum L_N·ẑ and its axial
# momentum I_s ω₃ (module docstring), conserved without friction. dop853 at rtol = atol = 1e-12 over 40
# nutation periods: measured 1.8e-16 (E, of its start), 1.4e-14 (L_z) and 0 (I_s ω₃) of |L| = I_s ω_s.
# Energy by hand at the start: ½ I_s ω_s² + ½ I_t φ̇² sin²θ (at θ = π/2, cos θ = 0): measured equal.
GYRO_INVARIANT_TOL = 1e-12


def test_energy_and_momenta_of_the_frictionless_gyro_are_conserved():
    gyro = Gyroscope(spin=100.0, **ROTOR)
    t = np.linspace(0.0, 40 * 2.0 * math.pi / gyro.nutation_frequency, 801)
    traj = tumble.simulate(gyro, t=t, precession_rate0=0.5, **TIGHT)
    e0 = 0.5 * gyro.spin_inertia * gyro.spin**2 + 0.5 * gyro.transverse_inertia * 0.5**2
    assert traj.energy[0] == pytest.approx(e0, rel=1e-15)   # the same few terms: rounding
    momentum = abs(gyro.momentum)
    for name, value in gyro.invariants(traj).items():
        scale = e0 if name == "energy" else momentum
        assert np.abs(value - value[0]).max() < GYRO_INVARIANT_TOL * scale, name
    assert gyro.invariants(traj).keys() == {"energy", "momentum_vertical", "momentum_axial"}
    # with friction nothing is kept, and the energy does fall
    dragged = Gyroscope(spin=100.0, spin_friction=2e-3, **ROTOR)
    traj = tumble.simulate(dragged, t=t, **TIGHT)
    assert dragged.invariants(traj) == {} and traj.energy[-1] < traj.energy[0]


def test_a_batch_of_initial_precession_rates_equals_one_by_one():
    gyro = Gyroscope(spin=100.0, **ROTOR)
    t = np.linspace(0.0, 0.1, 11)
    rates = np.array([[0.0], [gyro.steady_precession_rate]])
    batch = tumble.simulate(gyro, t=t, precession_rate0=rates, **TIGHT)
    for i, rate in enumerate(rates[:, 0]):
        one = tumble.simulate(gyro, t=t, precession_rate0=rate, **TIGHT)   # a plain number
        np.testing.assert_array_equal(batch.q[:, i], one.q)


def test_documented_example_runs(capsys):
    # the gyroscope block of docs/ins.md runs as a script and prints what it claims
    text = (Path(__file__).resolve().parents[2] / "docs" / "ins.md").read_text(encoding="utf-8")
    start = text.index("```python", text.index("### A rotor in gimbals")) + len("```python")
    exec(compile(text[start:text.index("```", start)], "docs/ins.md", "exec"), {})  # the project's own text
    printed = {line.split()[0]: float(line.split()[1]) for line in capsys.readouterr().out.splitlines()}
    gyro = Gyroscope(spin=100.0, **ROTOR)
    assert printed["precession"] == pytest.approx(gyro.precession_rate, rel=1e-5)   # printed to 6 digits
    assert printed["energy"] < GYRO_INVARIANT_TOL
    assert printed["gimbal"] == pytest.approx(0.0196 / (2e-3 * 100.0), rel=1e-5)
