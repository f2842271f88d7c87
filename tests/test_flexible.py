"""The hub with flexible appendages (tumble.flexible): rigid limit, invariants, free frequencies, slews."""

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import simpson
from scipy.integrate import quad

import tumble
from tumble import attitude, flexible, torques
from tumble._validate import ValidationError
from tumble.flexible import FlexibleBody, Mode
from tumble.viz.flexible import demo_flexible

# Every test here compiles this model kind's integrators on a cold Numba cache (several CPU s each).
pytestmark = pytest.mark.slow

INERTIA = np.array([[2.0, 0.1, -0.05], [0.1, 3.0, 0.2], [-0.05, 0.2, 4.0]])  # kg m², body axes
OMEGA0 = np.array([0.3, 1.0, -0.4])  # rad/s: a generic tumble
TIGHT = dict(method="dop853", rtol=1e-12, atol=1e-12)

# With rtol = atol = 1e-12, dop853 keeps the invariants to a few 1e-13 over these runs
# (measured 4e-15 momentum, 3e-13 energy, relative); 1e-11 leaves a factor 30.
INVARIANT_TOL = 1e-11
# Two integrations of the same motion with different step sequences, each to 1e-12:
# measured differences ~1e-12 rad/s.
AGREEMENT_TOL = 1e-10


def coupled(damping=0.0):
    """A two-mode body with participation about all three axes (the ω × h terms all work)."""
    return FlexibleBody(INERTIA, [Mode(3.0, damping, [0.3, 0.5, 0.2]), Mode(7.0, damping, [0.1, -0.4, 0.6])])


def test_zero_coupling_equals_rigid_body_and_free_oscillators():
    fbody = FlexibleBody(INERTIA, [Mode(3.0, 0.02, [0.0, 0.0, 0.0])])
    t = np.linspace(0.0, 10.0, 51)
    torque = torques.ConstantBody([0.05, -0.02, 0.1])
    flex = tumble.simulate(fbody, OMEGA0, t=t, eta0=[0.1], torque=torque, **TIGHT)
    rigid = tumble.simulate(tumble.RigidBody(INERTIA), OMEGA0, t=t, torque=torque, **TIGHT)
    assert np.abs(flex.omega - rigid.omega).max() < AGREEMENT_TOL
    assert attitude.relative_angle(flex.q, rigid.q).max() < AGREEMENT_TOL
    # the uncoupled mode is a free damped oscillator: η = η₀ e^{−ζΩt} (cos Ω_d t + ζΩ/Ω_d sin Ω_d t)
    zeta, w = 0.02, 3.0
    wd = w * math.sqrt(1.0 - zeta**2)
    eta = 0.1 * np.exp(-zeta * w * t) * (np.cos(wd * t) + zeta * w / wd * np.sin(wd * t))
    assert np.abs(flex.extras["modal_coordinate"].data[:, 0] - eta).max() < AGREEMENT_TOL


def test_undamped_coupled_motion_conserves_momentum_and_energy():
    fbody = coupled()
    t = np.linspace(0.0, 20.0, 201)
    traj = tumble.simulate(fbody, OMEGA0, t=t, eta0=[0.05, 0.0], eta_rate0=[0.0, 0.1], **TIGHT)
    h_inertial = attitude.rotate(traj.q, flexible.momentum_body(fbody, traj))
    assert np.abs(h_inertial - h_inertial[0]).max() / np.linalg.norm(h_inertial[0]) < INVARIANT_TOL
    e = flexible.energy(fbody, traj)
    assert np.abs(e / e[0] - 1.0).max() < INVARIANT_TOL
    # the modes do move the hub: its rigid-body energy alone is not conserved
    rigid_part = tumble.dynamics.kinetic_energy(traj.inertia, traj.omega)
    assert np.ptp(rigid_part) / rigid_part[0] > 1e-3


def test_damping_dissipates_energy_monotonically_at_the_modal_rate():
    fbody = coupled(damping=0.05)
    t = np.linspace(0.0, 20.0, 2001)
    traj = tumble.simulate(fbody, OMEGA0, t=t, eta0=[0.05, 0.0], eta_rate0=[0.0, 0.1], **TIGHT)
    e = flexible.energy(fbody, traj)
    assert np.all(np.diff(e) < 0.0)
    h_inertial = attitude.rotate(traj.q, flexible.momentum_body(fbody, traj))
    assert np.abs(h_inertial - h_inertial[0]).max() / np.linalg.norm(h_inertial[0]) < INVARIANT_TOL
    # Ė = −Σ 2ζΩ η̇²: Simpson's rule on the 0.01 s samples (error ~ h⁴ |P''''|/180; measured 1e-8)
    rate = traj.extras["modal_rate"].data
    lost = simpson(np.sum(2.0 * 0.05 * fbody.frequencies * rate**2, axis=-1), x=t)
    assert abs((e[0] - e[-1]) / lost - 1.0) < 1e-7


def test_free_hub_oscillates_at_the_unconstrained_frequency():
    # With h = 0 the term ω × h vanishes and the motion is exactly linear:
    # η = η₀ cos σt with σ = Ω / √(1 − δᵀ I⁻¹ δ), and the hub counter-rotates, I ω = −δ η̇.
    delta = np.array([0.4, -0.3, 0.9])
    fbody = FlexibleBody(INERTIA, [Mode(2.0, 0.0, delta)])
    sigma = 2.0 / math.sqrt(1.0 - delta @ np.linalg.solve(INERTIA, delta))
    assert fbody.free_frequencies()[0] == pytest.approx(sigma, rel=1e-14)
    t = np.linspace(0.0, 10.0, 101)
    traj = tumble.simulate(fbody, np.zeros(3), t=t, eta0=[0.2], **TIGHT)
    eta = traj.extras["modal_coordinate"].data[:, 0]
    assert np.abs(eta - 0.2 * np.cos(sigma * t)).max() < 0.2 * AGREEMENT_TOL
    omega = -np.outer(traj.extras["modal_rate"].data[:, 0], np.linalg.solve(INERTIA, delta))
    assert np.abs(traj.omega - omega).max() < AGREEMENT_TOL


def test_free_frequencies_of_two_modes_solve_the_characteristic_equation():
    # det(diag(Ω²) − σ² M) = 0 with M = 1 − Dᵀ I⁻¹ D is a quadratic in x = σ²:
    # det(M) x² − (Ω₁² M₂₂ + Ω₂² M₁₁) x + Ω₁² Ω₂² = 0
    fbody = coupled()
    D = fbody.participation
    M = np.eye(2) - D.T @ np.linalg.solve(INERTIA, D)
    w2 = fbody.frequencies**2
    x = np.roots([np.linalg.det(M), -(w2[0] * M[1, 1] + w2[1] * M[0, 0]), w2[0] * w2[1]])
    np.testing.assert_allclose(fbody.free_frequencies(), np.sqrt(np.sort(x)), rtol=1e-12)


def test_residual_vibration_after_a_slew_matches_the_linear_response():
    # A slew about z with δ ∥ z keeps ω, h ∥ z: the motion is exactly linear, and the mode obeys
    # η̈ + σ² η = −g τ(t), g = (δ/I_z) / (1 − δ²/I_z), whose response is Duhamel's integral
    # η(t) = −(g/σ) ∫₀ᵗ sin σ(t − s) τ(s) ds, evaluated here with scipy's adaptive quadrature.
    delta, w = 25.0, 2 * math.pi * 0.2
    inertia = np.diag([2000.0, 1500.0, 3000.0])
    fbody = FlexibleBody(inertia, [Mode(w, 0.0, [0.0, 0.0, delta])])
    angle, T = math.radians(30.0), 40.0
    torque = flexible.slew_torque([0.0, 0.0, 1.0], angle, duration=T, inertia=3000.0, ramp=0.4)
    t = np.array([0.0, 10.0, 20.0, T, 45.0, 50.0, 60.0])
    traj = tumble.simulate(fbody, np.zeros(3), t=t, torque=torque, **TIGHT)
    ratio = delta**2 / 3000.0
    g, sigma = delta / 3000.0 / (1.0 - ratio), w / math.sqrt(1.0 - ratio)
    knots = torque.t

    def tau(s):
        return np.interp(s, knots, torque.torque[:, 2])

    def duhamel(time):
        pieces = [quad(lambda s: math.sin(sigma * (time - s)) * tau(s), a, min(b, time), epsabs=1e-12,
                       epsrel=1e-12)[0] for a, b in zip(knots[:-1], knots[1:]) if a < time]
        return -g / sigma * sum(pieces)

    expected = np.array([duhamel(x) for x in t])
    eta = traj.extras["modal_coordinate"].data[:, 0]
    assert np.abs(eta - expected).max() < 1e-9 * np.abs(expected).max()
    # after the slew the total momentum is zero, so the hub angle is θ = angle − (δ/I_z) η
    theta = 2.0 * np.arctan2(traj.q[:, 3], traj.q[:, 0])
    after = t >= T
    assert np.abs(theta[after] - (angle - delta / 3000.0 * eta[after])).max() < AGREEMENT_TOL


def test_slew_torque_turns_the_rigid_body_rest_to_rest():
    body = tumble.RigidBody(np.diag([2000.0, 1500.0, 3000.0]))
    # output times on the knots of the profile, so that no step straddles a kink of τ(t)
    # (measured: 3e-13 rad; steps across the kinks leave 5e-10)
    for ramp in (0.4, 2.0):
        torque = flexible.slew_torque([0.0, 0.0, 2.0], 0.5, duration=40.0, inertia=3000.0, ramp=ramp)
        traj = tumble.simulate(body, np.zeros(3), t=torque.t, torque=torque, **TIGHT)
        assert 2.0 * math.atan2(traj.q[-1, 3], traj.q[-1, 0]) == pytest.approx(0.5, abs=1e-11)
        assert np.abs(traj.omega[-1]).max() < 1e-14
    assert flexible.slew_torque([0, 0, 1], 0.5, duration=40.0, inertia=3000.0).torque[1, 2] == pytest.approx(
        4 * 3000.0 * 0.5 / 40.0**2, rel=1e-8)  # u = 4 I θ / T² without ramps (to the 1e-9 T jump)


def test_python_torque_equals_the_compiled_one():
    fbody = coupled(damping=0.01)
    t = np.linspace(0.0, 2.0, 5)
    compiled = tumble.simulate(fbody, OMEGA0, t=t, torque=torques.ConstantBody([0.05, -0.02, 0.1]), **TIGHT)
    python = tumble.simulate(fbody, OMEGA0, t=t, torque=lambda t, q, omega: [0.05, -0.02, 0.1], **TIGHT)
    np.testing.assert_array_equal(python.omega, compiled.omega)  # the same numbers reach the same kernel


@pytest.mark.slow  # compiles the rk4 and cf4 integrators for this model (~40 s cold)
def test_fixed_step_methods_converge_to_the_adaptive_solution():
    fbody = coupled(damping=0.01)
    t = np.linspace(0.0, 5.0, 11)
    torque = torques.ConstantBody([0.05, -0.02, 0.1])
    reference = tumble.simulate(fbody, OMEGA0, t=t, eta0=[0.05, 0.0], torque=torque, **TIGHT)
    for method in ("rk4", "cf4"):
        traj = tumble.simulate(fbody, OMEGA0, t=t, eta0=[0.05, 0.0], torque=torque, method=method, dt=1e-3)
        # fourth order, h = 1e-3 with the fastest free frequency ~ 8 rad/s: error ~ (8h)⁴ ~ 4e-9 at most
        # (measured 3e-12, the reference's own error)
        assert np.abs(traj.omega - reference.omega).max() < 1e-9


@pytest.mark.slow  # compiles the parallel batch driver for this model (~10 s cold)
def test_batch_of_initial_states_equals_one_by_one():
    fbody = coupled()
    t = np.linspace(0.0, 2.0, 5)
    eta0 = np.array([[0.05, 0.0], [0.0, -0.02]])
    batch = tumble.simulate(fbody, OMEGA0, t=t, eta0=eta0, method="rk4", dt=1e-2)
    assert batch.extras["modal_coordinate"].data.shape == (5, 2, 2)
    for i in range(2):
        one = tumble.simulate(fbody, OMEGA0, t=t, eta0=eta0[i], method="rk4", dt=1e-2)
        np.testing.assert_array_equal(batch.omega[:, i], one.omega)


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: Mode(-1.0, 0.0, [0, 0, 1]), "frequency: must be a finite number > 0"),
        (lambda: Mode(1.0, -0.1, [0, 0, 1]), "damping: must be a finite damping ratio >= 0"),
        (lambda: Mode(1.0, 0.0, [0, 1]), "participation: must have shape"),
        (lambda: FlexibleBody(INERTIA, []), "modes: must be a non-empty sequence"),
        (lambda: FlexibleBody(INERTIA, [Mode(1.0, 0.0, [0, 0, 2.1])]), "must be positive definite"),
        (lambda: tumble.simulate(coupled(), OMEGA0, t=[0, 1], method="splitting2", dt=0.1),
         "method: 'splitting2' needs a rigid body without torque, which a FlexibleBody is not"),
        (lambda: tumble.simulate(coupled(), OMEGA0, t=[0, 1], eta0=[1.0]), "eta0: must have shape"),
        (lambda: tumble.simulate(coupled(), OMEGA0, t=[0, 1], q0=[0, 0, 0, 0]), "q0: must be a non-zero"),
        (lambda: flexible.slew_torque([0, 0, 0], 1.0, duration=1.0, inertia=1.0), "axis: must be a non-zero"),
    ],
)
def test_bad_input_is_refused_naming_the_field(make, message):
    with pytest.raises(ValidationError, match=message):
        make()


def test_totals_are_the_energy_and_momentum_of_hub_and_modes():
    # traj.energy and traj.momentum_body are E and h of the module docstring, computed by the functions
    # flexible.energy and flexible.momentum_body (the same code: bitwise), for a single run and a batch
    fbody = coupled(damping=0.05)
    t = np.linspace(0.0, 2.0, 21)
    traj = tumble.simulate(fbody, OMEGA0, t=t, eta0=[0.05, 0.0], eta_rate0=[0.0, 0.1], **TIGHT)
    np.testing.assert_array_equal(traj.energy, flexible.energy(fbody, traj))
    np.testing.assert_array_equal(traj.momentum_body, flexible.momentum_body(fbody, traj))
    # and E by hand at the start: ½ ω·Iω + (δ₂·ω) η̇₂ + ½ (η̇₂² + Ω₁² η₁²)
    by_hand = (0.5 * OMEGA0 @ INERTIA @ OMEGA0 + (np.array([0.1, -0.4, 0.6]) @ OMEGA0) * 0.1
               + 0.5 * (0.1**2 + 3.0**2 * 0.05**2))
    assert traj.energy[0] == pytest.approx(by_hand, rel=1e-14)  # the same sum in another order: rounding
    assert fbody.invariants(traj).keys() == {"momentum_inertial"}   # damped: the energy is not kept
    batch = tumble.simulate(fbody, OMEGA0, t=t, eta0=[[0.05, 0.0], [0.0, 0.02]], method="rk4", dt=1e-2)
    np.testing.assert_array_equal(batch.energy, flexible.energy(fbody, batch))
    assert batch.energy.shape == (t.size, 2) and batch.momentum_body.shape == (t.size, 2, 3)


def test_documented_example_runs():
    # docs/flexible.md: every Python block runs as a script and prints what it claims
    text = (Path(__file__).resolve().parents[1] / "docs" / "flexible.md").read_text(encoding="utf-8")
    start = text.index("```python") + len("```python")
    namespace: dict = {}
    exec(compile(text[start:text.index("```", start)], "flexible.md", "exec"), namespace)  # the project's own text
    traj = namespace["traj"]
    assert traj.modal_coordinate.shape == (traj.t.size, 2)
    np.testing.assert_allclose(namespace["sc"].free_frequencies(), [1.4121, 7.0074], atol=1e-4)


def test_demo_writes_its_files_and_reports_the_jitter(tmp_path):
    summary = demo_flexible(tmp_path)
    traj = tumble.load(summary["nc"])
    assert traj.extras["modal_coordinate"].data.shape == (traj.t.size, 2)
    assert (tmp_path / "flexible.png").stat().st_size > 0
    # the jitter is the hub's counter-rotation: peak |θ − target| = max |Σ δ_k η_k| / I_z (δ ∥ z)
    delta = flexible.DEMO_BODY.participation[2]
    after = traj.t >= 40.0
    expected = np.abs(traj.extras["modal_coordinate"].data[after] @ delta).max() / 3000.0
    assert summary["jitter_peak_arcsec"] == pytest.approx(math.degrees(expected) * 3600.0, rel=1e-6)
    assert summary["rigid_pointing_error_arcsec"] < 1e-3
    assert summary["residual_momentum"] < 1e-9
