"""The environment parts of the spacecraft (solar radiation pressure and drag on facets, the IGRF field) and the
compiled table reader they share, against closed forms: a flat plate and a cube, in the sunlight and the air
of an Environment; bad facets and bad compositions refused."""

import math
from datetime import datetime, timezone

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.kernels import spacecraft as _kernel
from tumble.spacecraft import Environment, Orbit, ResidualDipole, Spacecraft
from tumble.spacecraft.surfaces import SOLAR_IRRADIANCE, Drag, Facet, SolarPressure, box_facets

# Every test here compiles the spacecraft's kernels on a cold Numba cache (its assembled right-hand side alone
# ~35 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.
pytestmark = pytest.mark.slow

AU, LIGHT_SPEED = 149597870700.0, 299792458.0
EPOCH = datetime(2026, 3, 20, 12, 0, tzinfo=timezone.utc)
ORBIT = Orbit.circular(400e3, np.radians(51.6), raan=1.0)
INERTIA = np.diag([10.0, 12.0, 8.0])
# The facet sums and the quaternion rotations round at a few 1e-16 of the torque.
TORQUE_RTOL = 1e-12


@pytest.fixture(scope="module")
def env():
    return Environment.sample(ORBIT, EPOCH, duration=600.0, step=10.0)


def _diagnostics(craft, t, q):
    """The compiled diagnostics (``outputs``' aux rows) of the craft at rest at the attitude ``q``, time ``t``."""
    model = craft.compile(None, 0.0)
    y = np.zeros((1, model.size))
    y[0, :4] = q
    aux = np.empty((1, model.aux_size))
    _kernel.evaluate(model, np.array([t]), y, aux)
    return model, aux[0]


def _part_torque(craft, kind, t, q):
    model, aux = _diagnostics(craft, t, q)
    a = _kernel.slices(model, kind).a
    return aux[a:a + 3]


def _q(seed):
    q = np.random.default_rng(seed).standard_normal(4)
    return q / np.linalg.norm(q)


def _body(q, v):
    return attitude.rotate(attitude.conjugate(q), v)


# -- the compiled reader -----------------------------------------------------------------------------------


def test_reader_returns_the_samples_at_the_sample_times(env):
    assert np.abs(env.at(env.t) - env.data).max() <= 1e-15 * np.abs(env.data).max(axis=0).clip(1.0).max()
    assert np.array_equal(env.at(env.t)[:, :6], env.data[:, :6])


def test_reader_interpolates_within_the_stated_errors(env):
    mid = env.t[:-1] + 0.5 * env.step
    rows = env.at(mid)
    r, v = ORBIT.state(mid)
    assert np.linalg.norm(rows[:, 0:3] - r, axis=1).max() < 1e-3          # m: h⁴ n⁴ |r| / 384 = 3e-4 (measured 2.9e-4)
    assert np.linalg.norm(rows[:, 3:6] - v, axis=1).max() < 1e-6          # m/s: O(h³) (measured 6.6e-8)
    fine = Environment.sample(ORBIT, EPOCH, duration=600.0, step=5.0)
    field = np.linalg.norm(rows[:, 11:14] - fine.magnetic_field[1::2], axis=1)
    assert (field / np.linalg.norm(fine.magnetic_field[1::2], axis=1)).max() < 2e-4    # measured 1.2e-4
    assert np.abs(np.linalg.norm(rows[:, 6:9], axis=1) - 1.0).max() < 1e-15


def test_a_run_outside_the_table_is_refused(env):
    craft = Spacecraft(inertia=INERTIA, environment=env)
    with pytest.raises(tumble.ValidationError, match=r"^t: must lie within the environment table, \[0, 600.0\] s"):
        tumble.simulate(craft, omega0=[0.0, 0.0, 0.0], t=[0.0, 700.0], method="rk4", dt=1.0)


# -- solar radiation pressure ---------------------------------------------------------------------------------


def _pressure(env, k):
    return env.shadow[k] * SOLAR_IRRADIANCE / LIGHT_SPEED * (AU / env.sun_distance[k]) ** 2


def test_radiation_torque_on_a_flat_plate_matches_the_normal_and_tangential_closed_forms(env):
    q = _q(1)
    s = _body(q, env.sun_direction[3])
    assert env.shadow[3] == 1.0
    axis = np.cross(s, [0.0, 0.0, 1.0])
    axis /= np.linalg.norm(axis)
    theta = 0.6                                         # the Sun 0.6 rad off the normal
    normal = math.cos(theta) * s + math.sin(theta) * np.cross(axis, s)
    tangent = (s - math.cos(theta) * normal) / math.sin(theta)
    centre = np.array([0.3, -0.2, 0.5])
    rho_s, rho_d, area = 0.3, 0.25, 2.0
    plate = Facet(area=area, normal=normal, centre=centre, absorbed=1.0 - rho_s - rho_d, specular=rho_s,
                  diffuse=rho_d)
    craft = Spacecraft(inertia=INERTIA, environment=env, solar_pressure=SolarPressure([plate]))
    p = _pressure(env, 3)
    # an opaque plate (Wertz §17.2): F_n = −P A [(1 + ρs) cos²θ + (2/3) ρd cos θ], F_t = −P A (1 − ρs) cos θ sin θ
    c = math.cos(theta)
    force = (-p * area * ((1 + rho_s) * c * c + 2.0 / 3.0 * rho_d * c) * normal
             - p * area * (1 - rho_s) * c * math.sin(theta) * tangent)
    torque = _part_torque(craft, "solar_pressure", env.t[3], q)
    assert np.linalg.norm(torque - np.cross(centre, force)) < TORQUE_RTOL * np.linalg.norm(torque)


def test_radiation_torque_on_a_black_cube_is_the_offset_times_the_projected_area(env):
    # Σ over the lit faces of (c_i − c_m) × (−P A cos θ_i ŝ) = P L² (|ŝx| + |ŝy| + |ŝz|) c_m × ŝ for a cube
    # centred at the origin (Σ cos θ_i c_i = (L/2) ŝ is parallel to ŝ)
    side, com = 1.3, np.array([0.04, -0.07, 0.02])
    craft = Spacecraft(inertia=INERTIA, environment=env,
                       solar_pressure=SolarPressure(box_facets([side] * 3, centre_of_mass=com)))
    for k, seed in ((0, 2), (30, 3), (60, 4)):
        q = _q(seed)
        s = _body(q, env.sun_direction[k])
        expected = _pressure(env, k) * side**2 * np.abs(s).sum() * np.cross(com, s)
        torque = _part_torque(craft, "solar_pressure", env.t[k], q)
        assert np.linalg.norm(torque - expected) < TORQUE_RTOL * np.linalg.norm(expected)


def test_no_radiation_torque_in_the_umbra():
    orbit = Orbit.circular(500e3, 0.0)
    dark = Environment.sample(orbit, EPOCH, duration=orbit.period, step=30.0, shadow="cylindrical")
    k = int(np.argmin(dark.shadow))
    craft = Spacecraft(inertia=INERTIA, environment=dark,
                       solar_pressure=SolarPressure(box_facets([1.0] * 3, centre_of_mass=[0.1, 0.0, 0.0])))
    assert dark.shadow[k] == 0.0
    assert np.array_equal(_part_torque(craft, "solar_pressure", dark.t[k], _q(5)), np.zeros(3))


# -- drag ----------------------------------------------------------------------------------------------------


def test_drag_and_lift_torque_on_a_flat_plate_match_the_closed_form(env):
    q = _q(6)
    v = _body(q, env.velocity_air[2])
    speed, u = np.linalg.norm(v), v / np.linalg.norm(v)
    axis = np.cross(u, [1.0, 0.0, 0.0])
    axis /= np.linalg.norm(axis)
    alpha = 0.4                                          # the flow 0.4 rad off the normal
    normal = math.cos(alpha) * u + math.sin(alpha) * np.cross(axis, u)
    centre, area, cd, cl = np.array([-0.5, 0.1, 0.2]), 1.5, 2.2, 0.4
    plate = Facet(area=area, normal=normal, centre=centre, drag_coefficient=cd, lift_coefficient=cl)
    craft = Spacecraft(inertia=INERTIA, environment=env, drag=Drag([plate]))
    dynamic = 0.5 * env.density[2] * speed**2 * area * math.cos(alpha)
    across = (normal - math.cos(alpha) * u) / math.sin(alpha)       # the normal's part across the flow
    force = -dynamic * (cd * u + cl * across)
    torque = _part_torque(craft, "drag", env.t[2], q)
    assert np.linalg.norm(torque - np.cross(centre, force)) < TORQUE_RTOL * np.linalg.norm(torque)


def test_drag_torque_on_a_cube_is_the_offset_times_the_projected_area(env):
    side, com = 0.8, np.array([-0.03, 0.05, 0.06])
    craft = Spacecraft(inertia=INERTIA, environment=env,
                       drag=Drag(box_facets([side] * 3, centre_of_mass=com, drag_coefficient=2.2)))
    for k, seed in ((1, 7), (40, 8)):
        q = _q(seed)
        v = _body(q, env.velocity_air[k])
        speed, u = np.linalg.norm(v), v / np.linalg.norm(v)
        expected = 0.5 * env.density[k] * 2.2 * side**2 * speed**2 * np.abs(u).sum() * np.cross(com, u)
        torque = _part_torque(craft, "drag", env.t[k], q)
        assert np.linalg.norm(torque - expected) < TORQUE_RTOL * np.linalg.norm(expected)


# -- the field ----------------------------------------------------------------------------------------------


def test_residual_dipole_and_magnetorquers_read_the_igrf_field_of_the_table(env):
    dipole = np.array([0.2, -0.1, 0.3])
    craft = Spacecraft(inertia=INERTIA, environment=env, residual_dipole=ResidualDipole(dipole))
    q = _q(9)
    model, aux = _diagnostics(craft, env.t[5], q)
    field = _body(q, env.magnetic_field[5])
    assert np.linalg.norm(aux[_kernel.AUX_FIELD:_kernel.AUX_FIELD + 3] - field) < 1e-15 * np.linalg.norm(field)
    a = _kernel.slices(model, "residual_dipole").a
    torque = np.cross(dipole, field)
    assert np.linalg.norm(aux[a:a + 3] - torque) < 1e-15 * np.linalg.norm(dipole) * np.linalg.norm(field)


def test_gravity_gradient_reads_the_tables_position(env):
    craft = Spacecraft(inertia=INERTIA + 0.5, environment=env, gravity_gradient=True)
    q = _q(10)
    _, aux = _diagnostics(craft, env.t[7], q)
    r = _body(q, env.position[7])
    expected = 3.0 * ORBIT.mu / np.linalg.norm(r) ** 5 * np.cross(r, (INERTIA + 0.5) @ r)
    got = aux[_kernel.AUX_GRAVITY:_kernel.AUX_GRAVITY + 3]
    assert np.linalg.norm(got - expected) < 1e-12 * np.linalg.norm(expected)


# -- bad input -----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"normal": [0.0, 0.0, 0.0]}, r"^normal: must be a unit vector \(\|n\| = 1 to 1e-09\), got \|n\| = 0"),
    ({"normal": [1.0, 1.0, 0.0]}, r"^normal: must be a unit vector .* got \|n\| = 1.414"),
    ({"specular": 1.2, "absorbed": 0.0}, r"^specular: must be in \[0, 1\] \(a fraction of the sunlight\), got 1.2"),
    ({"diffuse": -0.1}, r"^diffuse: must be a finite number >= 0"),
    ({"absorbed": 0.6, "specular": 0.3, "diffuse": 0.2},
     r"^absorbed \+ specular \+ diffuse: must be at most 1 \(fractions of the same light\), got 1.1"),
    ({"area": 0.0}, r"^area: must be a finite number > 0"),
    ({"drag_coefficient": -2.0}, r"^drag_coefficient: must be a finite number >= 0"),
])
def test_a_bad_facet_is_refused_naming_the_field_and_the_rule(kwargs, message):
    with pytest.raises(tumble.ValidationError, match=message):
        Facet(**{"area": 1.0, "normal": [0.0, 0.0, 1.0], **kwargs})


def test_bad_compositions_are_refused(env):
    faces = box_facets([1.0, 1.0, 1.0])
    with pytest.raises(tumble.ValidationError, match=r"^solar_pressure: needs an environment"):
        Spacecraft(inertia=INERTIA, solar_pressure=SolarPressure(faces))
    with pytest.raises(tumble.ValidationError, match=r"^drag: needs an environment"):
        Spacecraft(inertia=INERTIA, drag=Drag(faces))
    with pytest.raises(tumble.ValidationError, match=r"^orbit: the environment gives the orbit and the field"):
        Spacecraft(inertia=INERTIA, environment=env, orbit=ORBIT)
    with pytest.raises(tumble.ValidationError, match=r"^magnetic_field: the environment gives"):
        Spacecraft(inertia=INERTIA, environment=env, magnetic_field=[0.0, 0.0, 1e-5])
    with pytest.raises(tumble.ValidationError, match=r"^drag\.facets: must be a non-empty sequence of Facet"):
        Drag([])


# -- integrated -------------------------------------------------------------------------------------------------


@pytest.mark.slow  # compiles the spacecraft's dop853 driver on a cold cache (minutes on 2 shared cores)
def test_disturbances_change_momentum_and_energy_by_exactly_their_impulse_and_work(env):
    """dop853: the inertial momentum of hub and spinning wheels changes by ∫ R(q) τ dt of the facet torques, its
    energy (less the wheels' motor work, none here) by ∫ ω·τ dt; nothing else changes them."""
    faces = box_facets([1.0, 2.0, 1.5], centre_of_mass=[0.05, -0.03, 0.08], specular=0.2, diffuse=0.3,
                       absorbed=0.5, lift_coefficient=0.3)
    craft = Spacecraft(inertia=INERTIA, wheels=tumble.spacecraft.pyramid_wheels(0.02), environment=env,
                       solar_pressure=SolarPressure(faces), drag=Drag(faces))
    t = np.linspace(0.0, 600.0, 6001)
    run = tumble.simulate(craft, omega0=[0.01, -0.02, 0.015], wheel_speeds0=[50.0, -30.0, 20.0, 10.0], t=t,
                          method="dop853", rtol=1e-12, atol=1e-14)
    torque = run.solar_pressure_torque + run.drag_torque
    impulse = _simpson(attitude.rotate(run.q, torque), t)
    work = _simpson(np.einsum("ki,ki->k", run.omega, torque)[:, None], t)[0]
    change = run.total_momentum_inertial[-1] - run.total_momentum_inertial[0]
    assert np.linalg.norm(impulse) > 1e-3 * np.linalg.norm(run.total_momentum_inertial[0])   # a real push
    # the quadrature's limit: Simpson's rule on the 0.1 s grid across the kinks where a facet turns into or out
    # of the flow or the light (its force ∝ (n̂·v̂)₊ has a kink there), O(h² Δτ'); at 0.5 s it measured 6.5e-6
    assert np.linalg.norm(change - impulse) < 1e-6 * np.linalg.norm(impulse)
    # the work (2e-5 J) is a small change of the energy (39 J): measured 4.3e-11 J off, 1e-12 of the energy,
    # the integration's tolerance
    assert abs(run.total_energy[-1] - run.total_energy[0] - work) < 1e-10 * run.total_energy[0]
    assert abs(work) > 1e-7 * run.total_energy[0]
    assert np.abs(run.wheel_work).max() == 0.0


def _simpson(f, t):
    """∫ f dt over the uniform grid ``t`` (odd length), Simpson's rule: (n, k) → (k,)."""
    h = t[1] - t[0]
    return h / 3.0 * (f[0] + f[-1] + 4.0 * f[1:-1:2].sum(axis=0) + 2.0 * f[2:-1:2].sum(axis=0))


# -- scenario files and the viewer --------------------------------------------------------------------------


def test_the_example_scenario_builds_the_environment_parts():
    from tumble.scenario import load_scenario

    scenario = load_scenario(tumble.examples.path("spacecraft/leo_disturbances.toml"))
    craft = scenario.model
    assert craft.environment.epoch == datetime(2026, 3, 20, 12, 0, tzinfo=timezone.utc)
    assert craft.environment.t[-1] >= scenario.time.stop and craft.gravity_gradient
    assert len(craft.solar_pressure.facets) == len(craft.drag.facets) == 6
    top = craft.solar_pressure.facets[4]                       # the +z face: 0.2 m × 0.1 m at z = 0.17 − 0.02
    assert (top.area, top.specular, top.diffuse) == (pytest.approx(0.02), 0.3, 0.1)
    np.testing.assert_allclose(top.centre, [0.0, 0.0, 0.15], atol=1e-15)


@pytest.mark.parametrize(("old", "new", "message"), [
    ("specular = 0.3", "specular = 1.3", r"spacecraft\.solar_pressure\.specular: must be <= 1"),
    ("absorbed = 0.6", "absorbed = 0.8",
     r"spacecraft\.solar_pressure: absorbed \+ specular \+ diffuse: must be at most 1"),
    ("orbit = {", 'tle = ["a", "b"]\norbit = {', r"spacecraft\.environment: give exactly one of orbit .* or tle"),
    ("epoch = 2026-03-20T12:00:00Z", "epoch = 2063-03-20T12:00:00Z", r"spacecraft\.environment\.epoch: the run must"),
])
def test_bad_environment_tables_are_refused_naming_the_key(old, new, message):
    from tumble.scenario import ScenarioError, parse_scenario

    text = tumble.examples.path("spacecraft/leo_disturbances.toml").read_text(encoding="utf-8")
    assert old in text
    with pytest.raises(ScenarioError, match=message):
        parse_scenario(text.replace(old, new, 1)).build()


def test_viewer_draws_the_sun_hidden_in_the_umbra_and_the_facet_normals():
    from tumble.viz import viewer

    orbit = Orbit.circular(500e3, 0.0)
    dark = Environment.sample(orbit, EPOCH, duration=orbit.period, step=10.0, shadow="cylindrical")
    craft = Spacecraft(inertia=INERTIA, environment=dark, solar_pressure=SolarPressure(box_facets([1.0] * 3)))
    run = tumble.simulate(craft, omega0=[0.0, 0.0, 0.0], t=dark.t, method="rk4", dt=10.0)
    scene = viewer.scene(run, model=craft, frames=len(dark.t))
    lines = {line.name: line.points for line in scene.lines}
    sun = lines["Sun"][:, 1]
    lit = dark.shadow == 1.0
    assert np.isnan(sun[~lit]).all() and (~lit).sum() > 100
    np.testing.assert_allclose(sun[lit] / np.linalg.norm(sun[lit], axis=1)[:, None], dark.sun_direction[lit],
                               atol=1e-15)
    assert sum(line.name == "facet normals" for line in scene.lines) == 6
