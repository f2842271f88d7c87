"""A spacecraft in orbit: gravity gradient and geomagnetic field from the orbit, momentum dumping."""

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.spacecraft import (DipoleField, Magnetorquers, MomentumDumping, Orbit, QuaternionPD, Spacecraft,
                               pyramid_wheels)
from tumble.scenario import load

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

INERTIA = np.array([[30.0, 0.5, 0.0], [0.5, 25.0, -0.3], [0.0, -0.3, 15.0]])
ORBIT = Orbit.circular(600e3, inclination=np.radians(97.8))
FIELD = DipoleField()
WHEEL_INERTIA = 0.05


EXAMPLE = tumble.examples.directory() / "spacecraft" / "momentum_dumping.toml"


@pytest.fixture(scope="module")
def dumping():
    """examples/spacecraft/momentum_dumping.toml, run as ``tumble run`` runs it."""
    scenario = load(EXAMPLE)
    return scenario.model, scenario.run()


def test_dumping_example_is_the_spacecraft_described_here(dumping):
    craft, traj = dumping
    direct = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(WHEEL_INERTIA), magnetorquers=Magnetorquers(20.0),
                        orbit=ORBIT, magnetic_field=FIELD, gravity_gradient=True,
                        controller=[QuaternionPD(0.1, 0.9), MomentumDumping(2e-3)])
    a, b = craft.compile(None, 0.0), direct.compile(None, 0.0)   # the compiled parameters: every number and flag
    for name in a._fields:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    np.testing.assert_array_equal(traj.t, np.linspace(0.0, ORBIT.period, 1201))
    np.testing.assert_allclose(traj.extras["wheel_speed"].data[0], [60.0, -20.0, 30.0, 10.0], rtol=0, atol=1e-12)


def test_environment_torques_are_those_of_the_orbit(dumping):
    craft, traj = dumping
    r, _ = ORBIT.state(traj.t)
    r_b = attitude.rotate_inverse(traj.q, r)
    n = np.linalg.norm(r_b, axis=-1)[:, None]
    expected = 3.0 * ORBIT.mu / n**5 * np.cross(r_b, r_b @ INERTIA.T)   # τ = 3μ/|r|⁵ r × (J r)
    np.testing.assert_allclose(traj.extras["gravity_gradient_torque"].data, expected, rtol=1e-12,
                               atol=1e-12 * np.abs(expected).max())
    b_b = attitude.rotate_inverse(traj.q, FIELD.field(traj.t, r))
    np.testing.assert_allclose(traj.extras["magnetic_field"].data, b_b, rtol=0, atol=1e-12 * np.abs(b_b).max())


def test_momentum_changes_by_the_external_torque_impulse(dumping):
    # dH_I/dt = R (τ_gg + m × B): the trapezoidal integral over the 1200 output intervals
    # (4.8 s) has error ~ Δt²/12 |τ̈| T, measured 1.4e-5 of the largest change of H_I
    _, traj = dumping
    tau = traj.extras["gravity_gradient_torque"].data + np.cross(traj.extras["dipole"].data,
                                                                 traj.extras["magnetic_field"].data)
    tau_i = attitude.rotate(traj.q, tau)
    impulse = np.concatenate([np.zeros((1, 3)), np.cumsum(0.5 * (tau_i[1:] + tau_i[:-1]) * np.diff(traj.t)[:, None],
                                                        axis=0)])
    h = traj.extras["total_momentum_inertial"].data
    change = np.abs(h - h[0]).max()
    np.testing.assert_allclose(h - h[0], impulse, rtol=0, atol=1e-4 * change)


def test_dumping_unloads_the_wheels(dumping):
    craft, traj = dumping
    axes = np.array([w.axis for w in craft.wheels])
    h = traj.extras["wheel_momentum"].data @ axes          # wheel momentum, body axes
    start, end = np.linalg.norm(h[0]), np.linalg.norm(h[-1])
    # measured: one orbit with k = 2e-3 1/s takes |h_w| from 3.49 to 0.89 N·m·s
    assert end < 0.3 * start
    # while the PD law holds the attitude against the dumping torque (measured 0.31 deg at most
    # after the first 8 minutes)
    assert np.degrees(attitude.angle(traj.q[100:])).max() < 0.5
