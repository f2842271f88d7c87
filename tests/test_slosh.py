"""The slosh pendulum in a free-floating hub (tumble.slosh): invariants, rigid limit, linear frequency, demo."""

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import simpson

import tumble
from tumble import attitude, slosh, torques
from tumble._validate import ValidationError
from tumble.slosh import Pendulum, SloshBody
from tumble.viz.slosh import demo_slosh

from helpers import read_by

# Every test here compiles this model kind's integrators on a cold Numba cache (several CPU s each).
pytestmark = pytest.mark.slow

HUB = tumble.RigidBody(np.array([[3.0, 0.1, 0.0], [0.1, 4.0, -0.2], [0.0, -0.2, 5.0]]), mass=10.0)
OMEGA0 = np.array([0.3, 1.0, -0.4])  # rad/s: a generic tumble
TIGHT = dict(method="dop853", rtol=1e-12, atol=1e-12)

# dop853 at rtol = atol = 1e-12 keeps momentum and energy to ~6e-13 relative over these
# runs (measured); 1e-11 leaves a factor 15.
INVARIANT_TOL = 1e-11
# Two integrations of the same motion with different step sequences, each to 1e-12.
AGREEMENT_TOL = 1e-10


def sloshing(damping=0.0, mass=2.0):
    return SloshBody(HUB, Pendulum(mass=mass, length=0.5, hinge=[0.3, -0.2, 0.4], damping=damping))


def run(sbody, t, *, torque=None, **options):
    return tumble.simulate(sbody, OMEGA0, t=t, direction0=[1.0, 1.0, 0.0], rate0=[0.0, 0.3, 1.0], torque=torque,
                           **read_by(**{**TIGHT, **options}))


def test_undamped_slosh_conserves_momentum_and_energy():
    sbody = sloshing()
    traj = run(sbody, np.linspace(0.0, 20.0, 201))
    h_inertial = attitude.rotate(traj.q, slosh.momentum_body(sbody, traj))
    assert np.abs(h_inertial - h_inertial[0]).max() / np.linalg.norm(h_inertial[0]) < INVARIANT_TOL
    e = slosh.energy(sbody, traj)
    assert np.abs(e / e[0] - 1.0).max() < INVARIANT_TOL
    hub = tumble.dynamics.kinetic_energy(traj.inertia, traj.omega)
    assert np.ptp(hub) / hub[0] > 1e-2  # the pendulum does exchange energy with the hub
    s = traj.extras["pendulum_direction"].data
    nu = traj.extras["pendulum_rate"].data
    assert np.abs(np.linalg.norm(s, axis=-1) - 1.0).max() < 1e-15
    assert np.abs(np.sum(s * nu, axis=-1)).max() < 1e-15


def test_damped_slosh_loses_energy_monotonically_at_the_hinge_rate():
    sbody = sloshing(damping=0.5)
    t = np.linspace(0.0, 20.0, 2001)
    traj = run(sbody, t)
    e = slosh.energy(sbody, traj)
    assert np.all(np.diff(e) < 0.0)
    h_inertial = attitude.rotate(traj.q, slosh.momentum_body(sbody, traj))
    assert np.abs(h_inertial - h_inertial[0]).max() / np.linalg.norm(h_inertial[0]) < INVARIANT_TOL
    # Ṫ = −μ l² d |ν|²: Simpson's rule on the 0.01 s samples (error ~ h⁴ |P''''|/180; measured 4e-11)
    nu = traj.extras["pendulum_rate"].data
    lost = simpson(sbody.reduced_mass * 0.5**2 * 0.5 * np.sum(nu * nu, axis=-1), x=t)
    assert abs((e[0] - e[-1]) / lost - 1.0) < 1e-9


def test_without_slosh_mass_the_hub_is_the_rigid_body():
    t = np.linspace(0.0, 10.0, 51)
    torque = torques.ConstantBody([0.05, -0.02, 0.1])
    traj = run(sloshing(damping=0.3, mass=0.0), t, torque=torque)
    rigid = tumble.simulate(HUB, OMEGA0, t=t, torque=torque, **TIGHT)
    assert np.abs(traj.omega - rigid.omega).max() < AGREEMENT_TOL
    assert attitude.relative_angle(traj.q, rigid.q).max() < AGREEMENT_TOL


def test_in_plane_swing_frequency_under_spin_matches_the_linear_theory():
    # Hub spinning at Ω about z, hinge at ρ on x, rod radially out; a small in-plane swing φ₀
    # oscillates at σ² = Ω² (ρ/l)(C + μ(ρ + l)²)/C (Routh reduction; module docstring).
    # Amplitude 1e-4 rad: the nonlinear shift of σ is O(φ₀²) ~ 1e-8.
    hub = tumble.RigidBody(np.diag([6.0, 7.0, 8.0]), mass=10.0)
    rho, length, spin = 0.4, 0.5, 2.0
    sbody = SloshBody(hub, Pendulum(mass=5.0, length=length, hinge=[rho, 0.0, 0.0]))
    sigma = slosh.in_plane_frequency(spin, rho, length, 8.0, sbody.reduced_mass)
    assert sigma / (spin * math.sqrt(rho / length)) > 1.1  # the finite hub shifts the frequency noticeably
    phi0 = 1e-4
    t = np.linspace(0.0, 12 * 2 * math.pi / sigma, 2401)
    traj = tumble.simulate(sbody, [0.0, 0.0, spin], t=t, direction0=[math.cos(phi0), math.sin(phi0), 0.0], **TIGHT)
    s = traj.extras["pendulum_direction"].data
    phi = np.arctan2(s[:, 1], s[:, 0])
    k = np.flatnonzero(np.sign(phi[1:]) != np.sign(phi[:-1]))
    crossings = t[k] - phi[k] * (t[k + 1] - t[k]) / (phi[k + 1] - phi[k])
    period = (crossings[-1] - crossings[0]) / ((crossings.size - 1) / 2)
    assert 2 * math.pi / period == pytest.approx(sigma, rel=1e-7)  # measured 1.1e-9
    np.testing.assert_allclose(np.abs(traj.omega[:, :2]), 0.0, atol=1e-15)  # the swing stays in the spin plane


def test_linearised_steady_spin_has_the_known_frequencies():
    # m = 0: the hub's nutation frequency λ = Ω √((C − A)(C − B)/(AB)) (major-axis spin, Landau–Lifshitz §37)
    hub = tumble.RigidBody(np.diag([6.0, 7.0, 8.0]), mass=10.0)
    empty = SloshBody(hub, Pendulum(mass=0.0, length=0.5, hinge=[0.4, 0.0, 0.0], damping=0.3))
    nutation = 2.0 * math.sqrt((8.0 - 6.0) * (8.0 - 7.0) / (6.0 * 7.0))
    eigenvalues = slosh.steady_spin_eigenvalues(empty, [0.0, 0.0, 2.0], [1.0, 0.0, 0.0])
    assert np.abs(eigenvalues - 1j * nutation).min() < 1e-8  # central differences: measured 4e-16
    # with a slosh mass: the in-plane swing at σ of the spin test above (undamped)
    sbody = SloshBody(hub, Pendulum(mass=5.0, length=0.5, hinge=[0.4, 0.0, 0.0]))
    sigma = slosh.in_plane_frequency(2.0, 0.4, 0.5, 8.0, sbody.reduced_mass)
    eigenvalues = slosh.steady_spin_eigenvalues(sbody, [0.0, 0.0, 2.0], [1.0, 0.0, 0.0])
    assert np.abs(eigenvalues - 1j * sigma).min() < 1e-8  # measured 1e-12
    with pytest.raises(ValidationError, match="not a steady spin"):
        slosh.steady_spin_eigenvalues(sbody, [0.0, 0.0, 2.0], [1.0, 1.0, 0.0])


@pytest.mark.slow  # compiles the rk4 integrator for this model (~20 s cold)
def test_rk4_converges_to_the_adaptive_solution():
    sbody = sloshing(damping=0.2)
    t = np.linspace(0.0, 5.0, 11)
    reference = run(sbody, t)
    traj = run(sbody, t, method="rk4", dt=1e-3)
    # fourth order at h = 1e-3 with rates of a few rad/s: error ~ (3h)⁴ ~ 1e-10 (measured 3e-13)
    assert np.abs(traj.omega - reference.omega).max() < 1e-9


@pytest.mark.parametrize(
    "make, message",
    [
        (lambda: SloshBody(tumble.RigidBody(np.eye(3)), Pendulum(1.0, 1.0, [0, 0, 0])), "body: must be a tumble.Rigid"),
        (lambda: Pendulum(-1.0, 1.0, [0, 0, 0]), "mass: must be a finite number >= 0"),
        (lambda: Pendulum(1.0, 0.0, [0, 0, 0]), "length: must be a finite number > 0"),
        (lambda: Pendulum(1.0, 1.0, [0, 0]), "hinge: must have shape"),
        (lambda: Pendulum(1.0, 1.0, [0, 0, 0], damping=math.nan), "damping: must be a finite number >= 0"),
        (lambda: tumble.simulate(sloshing(), OMEGA0, t=[0, 1], direction0=[0, 0, 0]),
         "direction0: must be a non-zero"),
        (lambda: tumble.simulate(sloshing(), OMEGA0, t=[0, 1], direction0=[1, 0, 0], method="exact"),
         "method: 'exact' needs .* which a SloshBody is not; methods for it: 'rk4', 'dop853', 'cf4'"),
        (lambda: tumble.simulate(sloshing(), OMEGA0, t=[0, 1]), "direction0: a SloshBody needs it"),
    ],
)
def test_bad_input_is_refused_naming_the_field(make, message):
    with pytest.raises(ValidationError, match=message):
        make()


def test_totals_are_the_energy_and_momentum_of_hub_and_slosh_mass():
    # traj.energy and traj.momentum_body are T and H about the system centre of mass, computed by
    # slosh.energy and slosh.momentum_body (the same code: bitwise), for a single run and a batch
    sbody = sloshing(damping=0.5)
    t = np.linspace(0.0, 2.0, 21)
    traj = run(sbody, t)
    np.testing.assert_array_equal(traj.energy, slosh.energy(sbody, traj))
    np.testing.assert_array_equal(traj.momentum_body, slosh.momentum_body(sbody, traj))
    # and by hand at the start: s = (1, 1, 0)/√2, ν = (0, 0.3, 1) less its part along s,
    # ṙ = ω × r + l ν × s, T = ½ ω·I_B ω + ½ μ |ṙ|², H = I_B ω + μ r × ṙ
    s0 = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    nu0 = np.array([0.0, 0.3, 1.0]) - 0.3 / np.sqrt(2.0) * s0
    r = np.array([0.3, -0.2, 0.4]) + 0.5 * s0
    v = np.cross(OMEGA0, r) + 0.5 * np.cross(nu0, s0)
    mu = 2.0 * 10.0 / 12.0
    # the same sums in another order: rounding
    assert traj.energy[0] == pytest.approx(0.5 * OMEGA0 @ HUB.inertia @ OMEGA0 + 0.5 * mu * v @ v, rel=1e-14)
    np.testing.assert_allclose(traj.momentum_body[0], HUB.inertia @ OMEGA0 + mu * np.cross(r, v), rtol=1e-14)
    assert sbody.invariants(traj).keys() == {"momentum_inertial"}   # damped: the energy is not kept
    batch = tumble.simulate(sbody, [OMEGA0, -OMEGA0], t=t, direction0=[1.0, 0.0, 0.0], method="rk4", dt=1e-2)
    np.testing.assert_array_equal(batch.energy, slosh.energy(sbody, batch))
    assert batch.energy.shape == (t.size, 2) and batch.momentum_body.shape == (t.size, 2, 3)


def test_documented_example_runs():
    # docs/slosh.md: its Python block runs as a script (a short run of the demo spinner)
    text = (Path(__file__).resolve().parents[1] / "docs" / "slosh.md").read_text(encoding="utf-8")
    start = text.index("```python") + len("```python")
    namespace: dict = {}
    exec(compile(text[start:text.index("```", start)], "slosh.md", "exec"), namespace)  # the project's own text
    traj = namespace["traj"]
    assert traj.pendulum_direction.shape == (traj.t.size, 3)
    assert np.all(np.diff(traj.energy) <= 0.0)   # the damped slosh only loses energy


def test_demo_nutation_grows_while_momentum_stays_and_energy_falls(tmp_path):
    summary = demo_slosh(tmp_path)
    traj = tumble.load(summary["nc"])
    assert traj.extras["pendulum_direction"].data.shape == (traj.t.size, 3)
    assert (tmp_path / "slosh.png").stat().st_size > 0
    assert summary["nutation_initial_deg"] < 2.0 and summary["nutation_final_deg"] > 85.0
    assert summary["energy_monotonic"]
    assert summary["momentum_norm_drift"] < 1e-10  # dop853 at 1e-11 over 600 s: measured 3e-12
    # the spinner ends in a flat spin, energy |H|²/(2 I_max): measured 2.6e-6 above it after 600 s
    # (the last of the nutation still decaying)
    assert summary["energy_final"] == pytest.approx(summary["energy_flat_spin"], rel=1e-4)
    # the exponential growth is that of the unstable eigenvalue of the linearised steady spin:
    # measured 78.16 s from the fit over 2°–20° against 78.01 s predicted (0.2 %)
    assert summary["growth_time_constant_s"] == pytest.approx(summary["growth_time_constant_linear_s"], rel=0.01)
