"""Fuel slosh as a part of the spacecraft hub (``SloshPendulum``): the same motion as the independent
``SloshBody`` kernel, conservation and a monotone energy with wheels, two tanks' energy balance, the scenario
tables, the viewer's rods, and the refusals."""

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson

import tumble
from tumble import slosh
from tumble._validate import ValidationError
from tumble.scenario import ScenarioError, parse
from tumble.spacecraft import MRPFeedback, SloshPendulum, Spacecraft, pyramid_wheels

from helpers import assert_same_run

# A simulation compiles the spacecraft's rk4 path on a cold Numba cache (~100 CPU s); warm, each test runs in
# well under a second.
SLOW = pytest.mark.slow

HUB = tumble.RigidBody(np.array([[600.0, 5.0, -3.0], [5.0, 640.0, 2.0], [-3.0, 2.0, 300.0]]), mass=900.0)
PENDULUM = slosh.Pendulum(mass=60.0, length=0.6, hinge=np.array([0.2, 0.1, -0.3]), damping=0.5)
SLOSH_BODY = slosh.SloshBody(HUB, PENDULUM)
TANK = SloshPendulum(SLOSH_BODY.reduced_mass, PENDULUM.length, PENDULUM.hinge, PENDULUM.damping)
TARGET = [np.cos(0.1), 0.0, 0.0, np.sin(0.1)]  # 0.2 rad about z

# The same rk4 steps in two kernels whose arithmetic differs in order (the spacecraft solves
# (I_B + μ g gᵀ) ω̇ = rhs by Cramer's rule and forms H as I_B ω + μ r × ṙ, with ω × H on the right and
# ω × h in the tank's torque; SloshBody by Sherman–Morrison from I_B⁻¹ with ω × I_B ω): over 20 s (2000 steps)
# the largest differences measured are 5.6e-17 in q, 4.2e-17 rad/s in ω (of 0.3), 2.2e-16 in s, 4.2e-17 rad/s
# in ν (of 0.097), 3.6e-15 J in T (of 15.8) and 2.8e-14 N m s in H (of 100): at most 4.3e-16 of each's size.
# Allowed: 1e-14 of each's size.
ORACLE_RTOL = 1e-14
# The change of the inertial momentum, relative: RK4's truncation over the first 2.5 s of the controlled turn
# (wheel torques up to 0.48 N m, the rod swinging at 0.2 rad/s), measured 1.6e-11, 2.1e-12 and 1.3e-13 at
# dt = 0.02, 0.01 and 0.005 s (fourth order); run at 0.005 s. Two free tanks over 40 s: 7.6e-13 at 0.01 s,
# 5.5e-14 at 0.005 s (run). Allowed 1e-12, as for the wheels alone.
MOMENTUM_RTOL = 1e-12
# The energy of a free craft with a damped tank falls at −μ l² d |ν|² ≤ 0: from sample to sample (0.05 s)
# it may rise by no more than round-off of its size (measured: it falls at every sample, by 1.8e-7 J at least,
# 6.9 % in all over 60 s).
MONOTONE_RTOL = 1e-13
# E − E₀ + ∫ Σ μ l² d |ν|² dt, the dissipation integrated by Simpson's rule over the 0.01 s samples: measured
# 5.9e-10 J, 2.5e-10 of the 2.35 J dissipated (of 17.3 J). Allowed 1e-8 of the dissipation.
BALANCE_RTOL = 1e-8


@SLOW
def test_a_spacecraft_of_one_tank_moves_as_the_slosh_body():
    craft = Spacecraft(inertia=HUB.inertia, slosh=[TANK])
    run = dict(omega0=[0.05, -0.02, 0.3], direction0=[1.0, 0.2, 0.1], rate0=[0.0, 0.1, -0.05],
               t=np.linspace(0.0, 20.0, 201), method="rk4", dt=0.01)
    oracle, traj = tumble.simulate(SLOSH_BODY, **run), tumble.simulate(craft, **run)
    for name in ("q", "omega", "pendulum_direction", "pendulum_rate", "energy", "momentum_body"):
        expected, got = getattr(oracle, name), getattr(traj, name)
        if name.startswith("pendulum"):
            got = got[:, 0]  # the first (only) tank
        np.testing.assert_allclose(got, expected, rtol=0.0, atol=ORACLE_RTOL * np.abs(expected).max(),
                                   err_msg=name)
    assert np.abs(oracle.pendulum_rate).max() > 0.05  # the pendulum swung


@pytest.fixture(scope="module")
def controlled():
    """A turn of 0.2 rad about z by four wheels under MRP feedback, with a damped tank sloshing."""
    craft = Spacecraft(inertia=HUB.inertia, wheels=pyramid_wheels(0.5),
                       controller=MRPFeedback(K=20.0, P=200.0, target=TARGET), slosh=[TANK])
    traj = tumble.simulate(craft, omega0=[0.002, -0.001, 0.003], wheel_speeds0=[5.0, -2.0, 1.0, 0.0],
                           direction0=[1.0, 0.0, 0.5], rate0=[0.0, 0.2, 0.0],
                           t=np.linspace(0.0, 60.0, 1201), method="rk4", dt=0.005)
    return craft, traj


@SLOW
def test_wheels_law_and_tank_conserve_the_inertial_momentum(controlled):
    craft, traj = controlled
    assert set(craft.invariants(traj)) == {"momentum_inertial"}  # damped slosh: no energy invariant
    h = traj.momentum_inertial
    assert np.linalg.norm(h - h[0], axis=-1).max() < MOMENTUM_RTOL * np.linalg.norm(h[0])
    assert np.abs(traj.wheel_torque).max() > 0.1  # the wheels turned the hub
    np.testing.assert_allclose(np.linalg.norm(traj.pendulum_direction, axis=-1), 1.0, rtol=0.0, atol=1e-15)
    assert np.abs(np.sum(traj.pendulum_direction * traj.pendulum_rate, axis=-1)).max() < 1e-16


@SLOW
def test_free_wheels_and_a_damped_tank_lose_energy_monotonically():
    """No controller and frictionless wheels: no motor work, so ``Ė = −μ l² d |ν|² ≤ 0`` at every sample."""
    craft = Spacecraft(inertia=HUB.inertia, wheels=pyramid_wheels(0.5), slosh=[TANK])
    traj = tumble.simulate(craft, omega0=[0.05, -0.02, 0.3], wheel_speeds0=[5.0, -2.0, 1.0, 0.0],
                           direction0=[1.0, 0.2, 0.1], rate0=[0.0, 0.3, 0.0], t=np.linspace(0.0, 60.0, 1201),
                           method="rk4", dt=0.01)
    energy = traj.energy
    assert np.diff(energy).max() < MONOTONE_RTOL * energy[0]
    assert energy[0] - energy[-1] > 1e-3 * energy[0]  # it did fall
    np.testing.assert_array_equal(traj.wheel_work, 0.0)


@SLOW
def test_two_tanks_conserve_momentum_and_dissipate_by_their_hinge_damping():
    """``R(q) H`` constant and ``E(t) = E₀ − ∫ Σ μ l² d |ν|² dt`` for two tanks (the dissipation of each
    tank's hinge friction torque ``−μ l² d ν`` on its relative rate ``ν``)."""
    tanks = [TANK, SloshPendulum(25.0, 0.4, [-0.3, 0.2, 0.5], damping=0.8)]
    craft = Spacecraft(inertia=HUB.inertia, slosh=tanks)
    traj = tumble.simulate(craft, omega0=[0.05, -0.02, 0.3], direction0=[1.0, 0.2, 0.1, 0.0, -0.3, 1.0],
                           rate0=[0.0, 0.3, 0.0, 0.2, 0.0, 0.0], t=np.linspace(0.0, 40.0, 4001), method="rk4",
                           dt=0.005)
    h = traj.momentum_inertial
    assert np.linalg.norm(h - h[0], axis=-1).max() < MOMENTUM_RTOL * np.linalg.norm(h[0])
    weight = np.array([t.reduced_mass * t.length**2 * t.damping for t in tanks])
    rate = np.sum(weight * np.sum(traj.pendulum_rate**2, axis=-1), axis=-1)
    dissipated = cumulative_simpson(rate, x=traj.t, initial=0.0)
    assert dissipated[-1] > 1e-2 * traj.energy[0]
    assert np.abs(traj.energy - traj.energy[0] + dissipated).max() < BALANCE_RTOL * dissipated[-1]
    assert traj.pendulum_direction.shape == (4001, 2, 3)


@pytest.mark.parametrize(("arguments", "message"), [
    (dict(reduced_mass=0.0, length=0.5, hinge=[0.0, 0.0, 1.0]), r"^reduced_mass: must be a finite number > 0, got 0.0"),
    (dict(reduced_mass=1.0, length=-0.5, hinge=[0.0, 0.0, 1.0]), r"^length: must be a finite number > 0, got -0.5"),
    (dict(reduced_mass=1.0, length=0.5, hinge=[0.0, 1.0]), r"^hinge: must have shape \(…, 3\)"),
    (dict(reduced_mass=1.0, length=0.5, hinge=[[0.0, 0.0, 1.0]]),
     r"^hinge: must have shape \(3,\), got \(1, 3\)"),
    (dict(reduced_mass=1.0, length=0.5, hinge=[0.0, np.nan, 1.0]), r"^hinge: must be finite"),
    (dict(reduced_mass=1.0, length=0.5, hinge=[0.0, 0.0, 1.0], damping=-1.0),
     r"^damping: must be a finite number >= 0, got -1.0"),
])
def test_bad_tanks_are_refused_naming_the_field(arguments, message):
    with pytest.raises(ValidationError, match=message):
        SloshPendulum(**arguments)


def test_bad_slosh_and_initial_rods_are_refused_naming_the_field():
    with pytest.raises(ValidationError, match=r"^slosh\[1\]: must be a SloshPendulum, got Pendulum"):
        Spacecraft(inertia=HUB.inertia, slosh=[TANK, PENDULUM])
    craft = Spacecraft(inertia=HUB.inertia, slosh=[TANK, TANK])
    with pytest.raises(ValidationError, match=r"^direction0: the direction of tank 1 must be a non-zero vector"):
        tumble.simulate(craft, omega0=[0.0, 0.0, 0.1], direction0=[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], t=[0.0, 1.0],
                        method="rk4", dt=0.1)
    with pytest.raises(ValidationError, match=r"^direction0: "):
        tumble.simulate(craft, omega0=[0.0, 0.0, 0.1], t=[0.0, 1.0], method="rk4", dt=0.1)


SCENARIO = """
[spacecraft]
inertia = [[600.0, 5.0, -3.0], [5.0, 640.0, 2.0], [-3.0, 2.0, 300.0]]

[spacecraft.wheel_pyramid]
inertia = 0.5

[[spacecraft.slosh]]
reduced_mass = 25.0
length = 0.4
hinge = [-0.3, 0.2, 0.5]
damping = 0.8

[[spacecraft.slosh]]
reduced_mass = 10.0
length = 0.3
hinge = [0.4, 0.0, 0.0]

[[spacecraft.controller]]
kind = "mrp_feedback"
K = 20.0
P = 200.0
target = [0.9950041652780258, 0.0, 0.0, 0.09983341664682815]

[initial]
omega = [0.0, 0.0, 0.01]
direction = [0.0, -0.3, 1.0, 1.0, 0.0, 0.0]
rate = [0.2, 0.0, 0.0, 0.0, 0.1, 0.0]

[time]
stop = 2.0
step = 0.5

[solver]
dt = 0.01
"""


@SLOW
def test_the_scenario_tables_build_the_spacecraft_of_the_python_api():
    craft = Spacecraft(inertia=HUB.inertia, wheels=pyramid_wheels(0.5),
                       slosh=[SloshPendulum(25.0, 0.4, [-0.3, 0.2, 0.5], 0.8),
                              SloshPendulum(10.0, 0.3, [0.4, 0.0, 0.0])],
                       controller=MRPFeedback(K=20.0, P=200.0, target=[0.9950041652780258, 0.0, 0.0,
                                                                       0.09983341664682815]))
    expected = tumble.simulate(craft, omega0=[0.0, 0.0, 0.01], direction0=[0.0, -0.3, 1.0, 1.0, 0.0, 0.0],
                               rate0=[0.2, 0.0, 0.0, 0.0, 0.1, 0.0], t=np.linspace(0.0, 2.0, 5), method="rk4",
                               dt=0.01)
    assert_same_run(parse(SCENARIO).run(), expected)


@pytest.mark.parametrize(("old", "new", "where", "rule"), [
    ("length = 0.4", "length = 0.0", "spacecraft.slosh[0].length", "must be > 0.0, got 0.0"),
    ("damping = 0.8", "damping = -0.8", "spacecraft.slosh[0].damping",
     "must be a finite number >= 0, got -0.8"),
    ("hinge = [0.4, 0.0, 0.0]", "hinge = [0.4, 0.0]", "spacecraft.slosh[1].hinge", "must have at least 3 entries"),
    ("length = 0.3", "length = 0.3\nmass = 1.0", "spacecraft.slosh[1].mass", "unknown key"),
    ("direction = [0.0, -0.3, 1.0, 1.0, 0.0, 0.0]", "direction = [0.0, -0.3, 1.0]", "initial.direction",
     "must have shape (…, 6), got (3,)"),
])
def test_bad_tables_name_the_key(old, new, where, rule):
    assert SCENARIO.count(old) == 1, old
    with pytest.raises(ScenarioError) as info:
        parse(SCENARIO.replace(old, new), source="craft.toml").run()
    assert any(w == where and rule in r for w, r in info.value.problems), info.value.problems


@SLOW
def test_the_viewer_draws_each_rod_from_its_hinge_to_the_slosh_mass(controlled):
    from tumble.viz import viewer

    craft, traj = controlled
    scene = viewer.scene(traj, model=craft, frames=50)
    hub = scene.solids[0].rotation                                    # R(q) of the frames
    frames = np.searchsorted(traj.t, scene.t)
    np.testing.assert_array_equal(traj.t[frames], scene.t)
    rod = {line.name: line.points for line in scene.lines}["slosh pendulum 1"]
    np.testing.assert_allclose(rod[:, 0], hub @ TANK.hinge, rtol=0.0, atol=1e-15)
    mass = TANK.hinge + TANK.length * traj.pendulum_direction[frames, 0]
    np.testing.assert_allclose(rod[:, 1], np.einsum("fij,fj->fi", hub, mass), rtol=0.0, atol=1e-15)


@SLOW
def test_a_batch_of_two_equals_each_run_alone():
    """The block path (lanes of 64: the tanks' state access, hub matrix and projection per lane) gives each
    member's single run bit for bit."""
    craft = Spacecraft(inertia=HUB.inertia, wheels=pyramid_wheels(0.5), slosh=[TANK, TANK],
                       controller=MRPFeedback(K=20.0, P=200.0, target=TARGET))
    members = dict(omega0=[[0.05, -0.02, 0.3], [0.0, 0.01, -0.1]],
                   direction0=[[1.0, 0.2, 0.1, 0.0, -0.3, 1.0], [0.0, 1.0, 0.0, 1.0, 0.0, 0.0]],
                   rate0=[[0.0, 0.3, 0.0, 0.2, 0.0, 0.0], [0.1, 0.0, 0.0, 0.0, 0.0, 0.2]])
    run = dict(t=np.linspace(0.0, 5.0, 11), method="rk4", dt=0.01)
    batch = tumble.simulate(craft, **members, **run)
    for b in range(2):
        alone = tumble.simulate(craft, **{name: value[b] for name, value in members.items()}, **run)
        for name in ("q", "omega", "pendulum_direction", "pendulum_rate", "energy"):
            np.testing.assert_array_equal(getattr(batch, name)[:, b], getattr(alone, name), err_msg=name)
