"""Flexible appendages as a part of the spacecraft hub (``FlexibleModes``): the same motion as the independent
``FlexibleBody`` kernel, conservation and the energy balance with wheels and an MRP law, the free-hub modal
frequency, and the refusals."""

import numpy as np
import pytest
from scipy.integrate import cumulative_simpson

import tumble
from tumble import flexible
from tumble._validate import ValidationError
from tumble.scenario import ScenarioError, parse
from tumble.spacecraft import FlexibleModes, MRPFeedback, Spacecraft, pyramid_wheels

from helpers import assert_same_run

# A simulation compiles the spacecraft's rk4 path on a cold Numba cache (~100 CPU s on the development
# machine); warm, each test runs in well under a second.
SLOW = pytest.mark.slow

INERTIA = np.array([[2000.0, 30.0, -20.0], [30.0, 1500.0, 10.0], [-20.0, 10.0, 3000.0]])  # kg m², undeformed
PARTICIPATION = np.array([[0.0, 4.0, 25.0], [6.0, 0.0, 8.0]])  # δ_k, kg^½ m, body axes
FREQUENCY = 2.0 * np.pi * np.array([0.2, 1.1])  # Ω_k, rad/s
DAMPING = np.array([0.003, 0.005])  # ζ_k
MODES = FlexibleModes(PARTICIPATION, FREQUENCY, DAMPING)
TARGET = [np.cos(0.1), 0.0, 0.0, np.sin(0.1)]  # 0.2 rad about z

# The same rk4 steps in two kernels whose arithmetic differs in order (the spacecraft sums H as J_ω ω +
# Σ δ_k (δ_k·ω + η̇_k), FlexibleBody as I ω + Σ δ_k η̇_k; J_ω⁻¹ from I − Σ δ_kδ_kᵀ built mode by mode): over
# 20 s (2000 steps) the largest differences measured are 2.2e-16 in q, 6.9e-18 rad/s in ω (of 0.03),
# 5.6e-17 in η (of 0.10) and 9.7e-17 in η̇ (of 0.35): round-off. Allowed: 1e-14 relative to each's size.
ORACLE_RTOL = 1e-14

# RK4 at dt = 0.01 s over 60 s of an MRP-controlled turn with four wheels and two damped modes: the drift of
# the inertial momentum H_I measured 4.6e-15 relative. Allowed 1e-12, as for the wheels alone.
MOMENTUM_RTOL = 1e-12
# E − E₀ − W + ∫ Σ 2ζ_kΩ_k η̇_k² dt, the dissipation integrated by Simpson's rule over the 0.01 s samples:
# measured 1.2e-9 J, 3e-7 of the 4.2e-3 J dissipated (Simpson's error (Ω h)⁴/180 ≈ 1e-7 at Ω = 6.9 rad/s).
# Allowed: 1e-5 of the dissipation.
BALANCE_RTOL = 1e-5
# Frequency of η from the 9 upward zero crossings over 40 s (linear interpolation between the 0.01 s samples)
# against the closed form: measured 2.5e-10 relative, RK4's phase error (σh)⁴/120 ≈ 1e-10. Allowed 1e-8.
FREQUENCY_RTOL = 1e-8


@SLOW
def test_a_spacecraft_of_modes_moves_as_the_flexible_body():
    body = flexible.FlexibleBody(INERTIA, tuple(flexible.Mode(w, z, d)
                                                for w, z, d in zip(FREQUENCY, DAMPING, PARTICIPATION)))
    craft = Spacecraft(inertia=INERTIA, flexible_modes=MODES)
    run = dict(omega0=[0.01, -0.02, 0.03], eta0=[0.1, -0.05], eta_rate0=[0.02, 0.01],
               t=np.linspace(0.0, 20.0, 201), method="rk4", dt=0.01)
    oracle, traj = tumble.simulate(body, **run), tumble.simulate(craft, **run)
    for name in ("q", "omega", "modal_coordinate", "modal_rate", "energy", "momentum_body"):
        expected, got = getattr(oracle, name), getattr(traj, name)
        np.testing.assert_allclose(got, expected, rtol=0.0, atol=ORACLE_RTOL * np.abs(expected).max(),
                                   err_msg=name)
    np.testing.assert_allclose(craft.rate_inertia, body.hub_inertia, rtol=1e-15, atol=0.0)


@pytest.fixture(scope="module")
def controlled():
    """A turn of 0.2 rad about z by four wheels under MRP feedback, with two damped modes excited."""
    damping = np.array([0.05, 0.02])
    craft = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.5), controller=MRPFeedback(K=40.0, P=400.0,
                                                                                            target=TARGET),
                       flexible_modes=FlexibleModes(PARTICIPATION, FREQUENCY, damping))
    traj = tumble.simulate(craft, omega0=[0.002, -0.001, 0.003], wheel_speeds0=[5.0, -2.0, 1.0, 0.0],
                           eta0=[0.05, 0.01], t=np.linspace(0.0, 60.0, 6001), method="rk4", dt=0.01)
    return craft, traj


@SLOW
def test_wheels_law_and_modes_conserve_the_inertial_momentum(controlled):
    craft, traj = controlled
    assert set(craft.invariants(traj)) == {"momentum_inertial"}  # damped modes: no energy invariant
    h = traj.momentum_inertial
    assert np.linalg.norm(h - h[0], axis=-1).max() < MOMENTUM_RTOL * np.linalg.norm(h[0])
    assert np.abs(traj.wheel_torque).max() > 0.1  # the wheels turned the hub


@SLOW
def test_the_energy_changes_by_the_motor_work_less_the_modal_dissipation(controlled):
    """``Ė = Ẇ − Σ 2ζ_kΩ_k η̇_k²``: the motors' work ``W`` (a state of the wheels) less what the modes'
    damping dissipates (the Rayleigh function's rate, hybrid-coordinate equations)."""
    craft, traj = controlled
    modes = craft.flexible_modes
    rate = traj.modal_rate
    dissipated = cumulative_simpson(np.sum(2.0 * modes.damping * modes.frequency * rate**2, axis=-1), x=traj.t,
                                    initial=0.0)
    assert dissipated[-1] > 1e-3  # the damping matters: 4.2e-3 J
    balance = traj.energy - traj.energy[0] - traj.wheel_work + dissipated
    assert np.abs(balance).max() < BALANCE_RTOL * dissipated[-1]


@SLOW
def test_the_free_hub_raises_the_mode_to_its_unconstrained_frequency():
    """One undamped mode about the principal axis z of a hub at rest: with ``ω = ω_z e_z`` and ``δ = δ e_z``,
    ``ω × h`` vanishes and the equations are the linear pair ``I_z ω̇_z + δ η̈ = 0``, ``η̈ + Ω² η + δ ω̇_z = 0``.
    Eliminating ``ω̇_z = −δ η̈ / I_z``: ``(1 − δ²/I_z) η̈ + Ω² η = 0``, so η oscillates at the unconstrained
    (free-free) frequency ``σ = Ω / √(1 − δ²/I_z)`` (Likins 1974; Wie 2008, §7), above the cantilever
    ``Ω`` of a hub held still. Here δ² / I_z = 625 / 3000, σ = 1.1239 Ω."""
    inertia, delta, omega = np.diag([2000.0, 1500.0, 3000.0]), 25.0, 2.0 * np.pi * 0.2
    craft = Spacecraft(inertia=inertia, flexible_modes=FlexibleModes([[0.0, 0.0, delta]], [omega]))
    t = np.linspace(0.0, 40.0, 4001)
    eta = tumble.simulate(craft, omega0=[0.0, 0.0, 0.0], eta0=[0.1], t=t, method="rk4", dt=0.01).modal_coordinate[:, 0]
    up = np.nonzero((eta[:-1] < 0.0) & (eta[1:] >= 0.0))[0]
    crossings = t[up] - eta[up] * (t[up + 1] - t[up]) / (eta[up + 1] - eta[up])
    assert len(crossings) >= 8
    period = (crossings[-1] - crossings[0]) / (len(crossings) - 1)
    sigma = omega / np.sqrt(1.0 - delta**2 / inertia[2, 2])
    assert abs(2.0 * np.pi / period / sigma - 1.0) < FREQUENCY_RTOL


@pytest.mark.parametrize(("arguments", "message"), [
    (dict(participation=[0.0, 0.0, 1.0], frequency=[1.0]), r"^participation: must have shape \(m, 3\)"),
    (dict(participation=[[0.0, 0.0]], frequency=[1.0]), r"^participation: must have shape \(…, 3\)"),
    (dict(participation=[[0.0, 0.0, 1.0]], frequency=[1.0, 2.0]), r"^frequency: must have shape \(1,\)"),
    (dict(participation=[[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]], frequency=[1.0, 0.0]),
     r"^frequency\[1\]: must be > 0 \(rad/s\), got 0.0"),
    (dict(participation=[[0.0, 0.0, 1.0]], frequency=[np.inf]), r"^frequency: must be finite"),
    (dict(participation=[[0.0, 0.0, 1.0]], frequency=[1.0], damping=[-0.1]),
     r"^damping\[0\]: must be a damping ratio >= 0, got -0.1"),
    (dict(participation=[[0.0, 0.0, 1.0]], frequency=[1.0], damping=0.1), r"^damping: must have shape \(1,\)"),
])
def test_bad_modes_are_refused_naming_the_field(arguments, message):
    with pytest.raises(ValidationError, match=message):
        FlexibleModes(**arguments)


def test_modes_that_carry_more_inertia_than_the_body_are_refused():
    with pytest.raises(ValidationError, match=r"^flexible_modes: J_ω = .* must be positive definite .* smallest "
                                              r"eigenvalue is -25 kg m\^2"):
        Spacecraft(inertia=np.diag([2000.0, 1500.0, 3000.0]), flexible_modes=FlexibleModes([[0.0, 0.0, 55.0]], [1.0]))
    with pytest.raises(ValidationError, match=r"^flexible_modes: must be a FlexibleModes or None, got list"):
        Spacecraft(inertia=INERTIA, flexible_modes=[MODES])


def test_the_modes_leave_the_rate_inertia_and_keep_the_laws_rigid_design():
    """``J_ω = J − Σ I_s a aᵀ − Σ δ_kδ_kᵀ``; the laws' gains read ``J_ω + Σ δ_kδ_kᵀ`` (the appendages rigid)."""
    wheels = pyramid_wheels(0.5)
    craft = Spacecraft(inertia=INERTIA, wheels=wheels, flexible_modes=MODES)
    spin = sum(w.inertia * np.outer(w.axis, w.axis) for w in wheels)
    np.testing.assert_allclose(craft.rate_inertia, INERTIA - spin - PARTICIPATION.T @ PARTICIPATION, rtol=1e-15)
    rigid = Spacecraft(inertia=INERTIA, wheels=wheels)
    np.testing.assert_allclose(craft._law_inertia, rigid.rate_inertia, rtol=1e-15)


SCENARIO = """
[spacecraft]
moments = [2000.0, 1500.0, 3000.0]

[spacecraft.wheel_pyramid]
inertia = 0.5

[spacecraft.flexible_modes]
participation = [[0.0, 0.0, 25.0], [0.0, 0.0, 8.0]]
frequency = [1.25, 6.9]
damping = [0.003, 0.005]

[[spacecraft.controller]]
kind = "mrp_feedback"
K = 40.0
P = 400.0
target = [0.9961946980917455, 0.0, 0.0, 0.08715574274765817]

[initial]
omega = [0.0, 0.0, 0.001]
eta = [0.01, 0.0]
eta_rate = [0.0, 0.002]

[time]
stop = 2.0
step = 0.5

[solver]
dt = 0.01
"""


@SLOW
def test_the_scenario_table_builds_the_spacecraft_of_the_python_api():
    craft = Spacecraft(inertia=np.diag([2000.0, 1500.0, 3000.0]), wheels=pyramid_wheels(0.5),
                       flexible_modes=FlexibleModes([[0.0, 0.0, 25.0], [0.0, 0.0, 8.0]], [1.25, 6.9], [0.003, 0.005]),
                       controller=MRPFeedback(K=40.0, P=400.0, target=[0.9961946980917455, 0.0, 0.0,
                                                                       0.08715574274765817]))
    expected = tumble.simulate(craft, omega0=[0.0, 0.0, 0.001], eta0=[0.01, 0.0], eta_rate0=[0.0, 0.002],
                               t=np.linspace(0.0, 2.0, 5), method="rk4", dt=0.01)
    assert_same_run(parse(SCENARIO).run(), expected)


@pytest.mark.parametrize(("old", "new", "where", "rule"), [
    ("frequency = [1.25, 6.9]", "frequency = [1.25]", "spacecraft.flexible_modes.frequency",
     "must have shape (2,), one per mode of participation, got (1,)"),
    ("frequency = [1.25, 6.9]", "frequency = [1.25, 0.0]", "spacecraft.flexible_modes.frequency[1]",
     "must be > 0 (rad/s), got 0.0"),
    ("damping = [0.003, 0.005]", "damping = [0.003, -0.005]", "spacecraft.flexible_modes.damping[1]",
     "must be a damping ratio >= 0, got -0.005"),
    ("[0.0, 0.0, 25.0], [0.0, 0.0, 8.0]", "[0.0, 0.0, 25.0], [0.0, 8.0]", "spacecraft.flexible_modes.participation[1]",
     "must have at least 3 entries, got 2"),
    ("[0.0, 0.0, 25.0], [0.0, 0.0, 8.0]", "[0.0, 0.0, 55.0], [0.0, 0.0, 8.0]", "spacecraft.flexible_modes",
     "must be positive definite"),
    ("frequency = [1.25, 6.9]", "frequency = [1.25, 6.9]\nstiffness = 1.0", "spacecraft.flexible_modes.stiffness",
     "unknown key"),
    ("eta = [0.01, 0.0]", "eta = [0.01]", "initial.eta", "must have shape (…, 2), got (1,)"),
])
def test_bad_tables_name_the_key(old, new, where, rule):
    assert SCENARIO.count(old) == 1, old
    with pytest.raises(ScenarioError) as info:
        parse(SCENARIO.replace(old, new), source="craft.toml").run()
    assert any(w == where and rule in r for w, r in info.value.problems), info.value.problems


@SLOW
def test_the_viewer_draws_each_mode_swinging_along_its_participation_axis(controlled):
    from tumble.viz import viewer

    craft, traj = controlled
    scene = viewer.scene(traj, model=craft, frames=50)
    hub = scene.solids[0].rotation                                    # R(q) of the frames
    frames = np.searchsorted(traj.t, scene.t)
    for k, delta in enumerate(PARTICIPATION):
        line = {line.name: line.points for line in scene.lines}[f"flexible mode {k + 1}"]
        np.testing.assert_array_equal(line[:, 0], 0.0)
        length = np.linalg.norm(line[:, 1], axis=-1)
        np.testing.assert_allclose(line[:, 1] / length[:, None], hub @ (delta / np.linalg.norm(delta)), atol=1e-15)
        eta = traj.modal_coordinate[frames, k]
        np.testing.assert_array_equal(traj.t[frames], scene.t)
        base = length / (1.0 + 0.5 * eta / np.abs(eta).max())         # the same at every frame
        np.testing.assert_allclose(base, base[0], rtol=1e-14)
        assert np.ptp(length) > 0.1 * base[0]                          # it swings
