"""Scenario files: the examples build and run with the right physics; every rule refuses bad input
with a message naming the file, the key and the rule."""

from pathlib import Path

import numpy as np
import pytest

import tumble
from tumble import attitude
from tumble.scenario import Scenario, ScenarioError, Time, load_scenario, parse_scenario, run_scenario
from tumble.scenario.kinds import KINDS

EXAMPLES = tumble.examples.directory()

# dop853 at rtol = atol = 1e-12 over a few seconds conserves T and |L| to a
# few 1e-14; 1e-11 leaves room for the accumulation of rounding.
CONSERVED_RTOL = 1e-11
# dop853 at its default rtol = 1e-10: the error of a quantity of size x is a
# few 1e-10 |x| over these short runs.
DEFAULT_SOLVER_RTOL = 1e-8
# RK4 with dt = 0.01 s on a body turning at ~0.01 rad/s: local error ~ (ω dt)^5,
# far below this.
RK4_ATOL = 1e-12  # N m s

BASE = """\
[body]
moments = [1.0, 2.0, 3.0]

[initial]
omega = [0.001, 1.0, 0.001]

[time]
stop = 1.0
samples = 11
"""


def shortened(scenario: Scenario, stop: float, samples: int) -> Scenario:
    """The same scenario over [start, stop] with ``samples`` output times."""
    time = Time(start=scenario.time.start, stop=stop, samples=samples)
    return scenario.model_copy(update={"time": time})


def write(tmp_path: Path, text: str, name: str = "case.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# --------------------------------------------------------------------------
# The examples
# --------------------------------------------------------------------------


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")), ids=lambda p: p.stem)
def test_every_example_builds_and_runs(path):
    scenario = load_scenario(path)
    assert scenario.source == str(path)
    problem = scenario.build()
    assert problem.t[0] == scenario.time.start
    assert problem.t[-1] == scenario.time.stop  # every example's time grid ends on stop exactly
    traj = run_scenario(shortened(scenario, stop=scenario.time.start + 0.5, samples=6))
    assert traj.t.tolist() == pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4, 0.5], abs=1e-15)
    assert traj.method == scenario.solver.method


@pytest.mark.parametrize("path", sorted(EXAMPLES.glob("*.toml")) + sorted(EXAMPLES.glob("spacecraft/*.toml")),
                         ids=lambda p: p.stem)
def test_every_example_of_every_kind_loads_and_builds(path):
    # `tumble run` runs these (it reads a file with load and checks it with build before running it);
    # the spacecraft runs themselves are in tests/spacecraft/test_spacecraft_*.py and tests/cli/test_cli.py.
    scenario = load_scenario(path)
    assert scenario.kind == ("spacecraft" if "[spacecraft" in path.read_text(encoding="utf-8") else "rigid")
    problem = scenario.build()
    assert problem.model is not None and problem.t[-1] == scenario.time.stop


def test_at_least_three_examples():
    names = {p.stem for p in EXAMPLES.glob("*.toml")}
    assert {"intermediate_axis", "box_inertial_torque", "symmetric_top"} <= names


def test_intermediate_axis_example_conserves_energy_and_momentum():
    scenario = load_scenario(EXAMPLES / "intermediate_axis.toml")
    problem = scenario.build()
    np.testing.assert_array_equal(problem.body.inertia, np.diag([1.0, 2.0, 3.0]))
    assert problem.options == {"rtol": 1e-12, "atol": 1e-12}
    traj = run_scenario(shortened(scenario, stop=5.0, samples=251))
    assert np.abs(traj.energy_drift).max() < CONSERVED_RTOL
    assert np.abs(traj.momentum_inertial_drift).max() < CONSERVED_RTOL


def test_box_example_inertial_momentum_grows_linearly():
    scenario = load_scenario(EXAMPLES / "box_inertial_torque.toml")
    problem = scenario.build()
    m, (a, b, c) = 2.0, (0.3, 0.2, 0.1)
    expected = np.diag([m * (b * b + c * c), m * (a * a + c * c), m * (a * a + b * b)]) / 12.0
    np.testing.assert_allclose(problem.body.inertia, expected, rtol=1e-15)
    # 10° of intrinsic pitch (Y): q = [cos 5°, 0, sin 5°, 0].
    np.testing.assert_allclose(problem.q0, [np.cos(np.radians(5)), 0, np.sin(np.radians(5)), 0], atol=1e-15)
    traj = run_scenario(shortened(scenario, stop=5.0, samples=51))
    tau = np.array([0.0, 0.002, 0.0])  # N m, inertial axes (the file's value)
    exact = traj.momentum_inertial[0] + traj.t[:, None] * tau  # L_I(t) = L_I(0) + τ t
    scale = np.linalg.norm(exact, axis=-1).max()
    assert np.abs(traj.momentum_inertial - exact).max() < DEFAULT_SOLVER_RTOL * scale


def test_symmetric_top_example_matches_the_closed_form():
    scenario = load_scenario(EXAMPLES / "symmetric_top.toml")
    traj = run_scenario(shortened(scenario, stop=2.0, samples=201))
    m, r, length = 1.5, 0.1, 0.02
    i1, i3 = m * (3 * r * r + length * length) / 12.0, m * r * r / 2.0
    rate = (i3 - i1) / i1 * 5.0  # rad/s: the body-frame precession of (ω_x, ω_y)
    exact = np.stack([0.3 * np.cos(rate * traj.t), 0.3 * np.sin(rate * traj.t), np.full_like(traj.t, 5.0)], -1)
    assert np.abs(traj.omega - exact).max() < DEFAULT_SOLVER_RTOL * 5.0


def test_thruster_pulse_example_adds_the_pulse_impulse():
    scenario = load_scenario(EXAMPLES / "thruster_pulse.toml")
    problem = scenario.build()
    assert problem.method == "rk4" and problem.options == {"dt": 0.01}
    traj = run_scenario(shortened(scenario, stop=3.0, samples=31))
    impulse = np.array([0.0, 0.0, 0.05])  # 0.05 N m for 1 s, inertial z
    before, after = traj.t < 1.0, traj.t >= 2.0
    change = traj.momentum_inertial - traj.momentum_inertial[0]
    np.testing.assert_allclose(change[before], np.zeros((before.sum(), 3)), rtol=0, atol=RK4_ATOL)
    np.testing.assert_allclose(change[after], np.tile(impulse, (after.sum(), 1)), rtol=0, atol=RK4_ATOL)


# --------------------------------------------------------------------------
# What a valid file means
# --------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("time", "expected"),
    [
        ("stop = 1.0\nsamples = 5", [0.0, 0.25, 0.5, 0.75, 1.0]),
        ("start = 2.0\nstop = 3.0\nstep = 0.25", [2.0, 2.25, 2.5, 2.75, 3.0]),
        ("stop = 1.0\nstep = 0.3", [0.0, 0.3, 0.6, 0.9]),  # the last time stays within stop
    ],
)
def test_output_times(time, expected):
    problem = parse_scenario(BASE.replace("stop = 1.0\nsamples = 11", time)).build()
    np.testing.assert_allclose(problem.t, expected, rtol=0, atol=1e-15)


def test_step_that_divides_the_span_ends_exactly_on_stop():
    problem = parse_scenario(BASE.replace("samples = 11", "step = 0.1")).build()
    assert problem.t.size == 11 and problem.t[-1] == 1.0


def test_defaults_identity_attitude_default_solver_no_torque():
    problem = parse_scenario(BASE).build()
    assert problem.q0.tolist() == [1.0, 0.0, 0.0, 0.0]
    assert problem.method == "dop853" and problem.options == {} and problem.torque is None


def test_quaternion_is_normalised():
    problem = parse_scenario(BASE.replace("[initial]", "[initial]\nq = [1.0, 1.0, 0.0, 0.0]")).build()
    rounding = np.finfo(float).eps  # one rounding of a number of size ~1
    np.testing.assert_allclose(problem.q0, [2**-0.5, 2**-0.5, 0.0, 0.0], rtol=0, atol=rounding)


def test_torques_add():
    text = BASE + """
[[torque]]
kind = "constant_body"
value = [1.0, 0.0, 0.0]

[[torque]]
kind = "constant_body"
value = [0.0, 2.0, 0.0]
"""
    torque = parse_scenario(text).build().torque
    np.testing.assert_array_equal(torque(0.0, [1, 0, 0, 0], [0, 0, 0]), [1.0, 2.0, 0.0])


@pytest.mark.parametrize(
    ("shape", "constructor"),
    [
        ('shape = "sphere"\nmass = 2.0\nradius = 0.5', lambda: tumble.RigidBody.sphere(mass=2.0, radius=0.5)),
        ('shape = "hollow_cylinder"\nmass = 1.0\ninner_radius = 0.1\nouter_radius = 0.2\nlength = 1.0\naxis = "x"',
         lambda: tumble.RigidBody.hollow_cylinder(mass=1.0, inner_radius=0.1, outer_radius=0.2, length=1.0, axis="x")),
        ('shape = "ellipsoid"\nmass = 3.0\nsemi_axes = [1.0, 2.0, 3.0]',
         lambda: tumble.RigidBody.ellipsoid(mass=3.0, semi_axes=[1.0, 2.0, 3.0])),
        ('shape = "point_masses"\nmasses = [1.0, 2.0, 3.0]\npositions = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]',
         lambda: tumble.RigidBody.point_masses([1.0, 2.0, 3.0], np.eye(3))),
        ('shape = "t_handle"', tumble.RigidBody.t_handle),
    ],
)
def test_shapes_are_the_library_constructors(shape, constructor):
    body = parse_scenario(BASE.replace("moments = [1.0, 2.0, 3.0]", shape)).build().body
    np.testing.assert_array_equal(body.inertia, constructor().inertia)


def test_run_scenario_reports_progress_up_to_the_last_sample(tmp_path):
    calls = []
    traj = run_scenario(write(tmp_path, BASE), progress=lambda done, total: calls.append((done, total)))
    assert calls[-1] == (11, 11) and len(traj) == 11


# --------------------------------------------------------------------------
# Bad input: file, key, rule
# --------------------------------------------------------------------------

BAD = [
    # (id, replace this, by this, key, rule fragment)
    ("unknown key", "samples = 11", "samples = 11\nsampels = 3", "time.sampels",
     "unknown key (did you mean 'samples'?)"),
    ("unknown table", "[time]", "[timing]\nx = 1\n[time]", "timing", "unknown key"),
    ("unknown key of a shape", "moments = [1.0, 2.0, 3.0]",
     'shape = "box"\nmass = 1.0\nsize = [1, 2, 3]\nradius = 1.0', "body.radius",
     "unknown key (this table takes: shape, mass, size)"),
    ("missing key", "stop = 1.0\n", "", "time.stop", "missing required key"),
    ("missing table", "[initial]\nomega = [0.001, 1.0, 0.001]\n", "", "initial", "missing required key"),
    ("missing shape parameter", "moments = [1.0, 2.0, 3.0]", 'shape = "box"\nmass = 1.0', "body.size",
     "missing required key"),
    ("wrong type", "stop = 1.0", 'stop = "1.0"', "time.stop", "must be a number, got '1.0'"),
    ("boolean as a number", "samples = 11", "samples = true", "time.samples", "must be an integer, got True"),
    ("short vector", "omega = [0.001, 1.0, 0.001]", "omega = [0.001, 1.0]", "initial.omega",
     "must have at least 3 entries, got 2"),
    ("nan", "omega = [0.001, 1.0, 0.001]", "omega = [nan, 1.0, 0.001]", "initial.omega[0]", "must be finite"),
    ("two body descriptions", "[body]", "[body]\ninertia = [[1, 0, 0], [0, 2, 0], [0, 0, 3]]", "body",
     "give exactly one of inertia, moments or shape"),
    ("no body description", "moments = [1.0, 2.0, 3.0]", "mass = 1.0", "body",
     "give exactly one of inertia, moments or shape"),
    ("unknown shape", "moments = [1.0, 2.0, 3.0]", 'shape = "blob"', "body.shape", "got 'blob'"),
    ("rk4 without dt", "[time]", "[solver]\nmethod = 'rk4'\n[time]", "solver.dt", "required by method 'rk4'"),
    ("dop853 with dt", "[time]", "[solver]\ndt = 0.1\n[time]", "solver.dt", "not used by method 'dop853'"),
    ("rk4 with rtol", "[time]", "[solver]\nmethod = 'rk4'\ndt = 0.1\nrtol = 1e-6\n[time]", "solver.rtol",
     "not used by method 'rk4'"),
    ("unknown method", "[time]", "[solver]\nmethod = 'euler'\n[time]", "solver.method", "got 'euler'"),
    ("non-positive tolerance", "[time]", "[solver]\nrtol = 0.0\n[time]", "solver.rtol", "must be > 0.0"),
    ("non-positive-definite inertia", "moments = [1.0, 2.0, 3.0]",
     "inertia = [[1, 0, 0], [0, 2, 0], [0, 0, -3]]", "body.inertia", "must be positive definite"),
    ("non-symmetric inertia", "moments = [1.0, 2.0, 3.0]",
     "inertia = [[1, 0.5, 0], [0, 2, 0], [0, 0, 3]]", "body.inertia", "must be symmetric"),
    ("triangle inequality", "moments = [1.0, 2.0, 3.0]", "moments = [1.0, 1.0, 3.0]", "body.moments",
     "triangle inequality"),
    ("negative mass", "moments = [1.0, 2.0, 3.0]", 'shape = "sphere"\nmass = -1.0\nradius = 1.0', "body.mass", "> 0"),
    ("negative stop", "stop = 1.0", "stop = -1.0", "time.stop", "must be greater than start = 0.0 s, got -1.0"),
    ("stop equal to start", "stop = 1.0", "start = 1.0\nstop = 1.0", "time.stop", "must be greater than start"),
    ("samples and step", "samples = 11", "samples = 11\nstep = 0.1", "time.step", "exactly one of samples"),
    ("neither samples nor step", "samples = 11", "", "time.step", "exactly one of samples"),
    ("one sample", "samples = 11", "samples = 1", "time.samples", "must be >= 2"),
    ("too many samples", "samples = 11", "step = 1e-12", "time.step", "more than the limit"),
    ("q and euler", "[initial]", "[initial]\nq = [1, 0, 0, 0]\neuler = { seq = 'ZYX', angles = [0, 0, 0] }",
     "initial.euler", "not both"),
    ("zero quaternion", "[initial]", "[initial]\nq = [0, 0, 0, 0]", "initial.q", "must be non-zero"),
    ("bad Euler sequence", "[initial]", "[initial]\neuler = { seq = 'ZZY', angles = [0, 0, 0] }",
     "initial.euler.seq", "consecutive axes must differ"),
    ("unknown torque kind", "", "[[torque]]\nkind = 'magnetic'\n", "torque[0].kind", "got 'magnetic'"),
    ("torque without kind", "", "[[torque]]\nvalue = [1, 2, 3]\n", "torque[0].kind", "missing required key"),
    ("torque times not increasing", "",
     "[[torque]]\nkind = 'tabulated'\ntimes = [0, 1, 1]\nvalues = [[0, 0, 0], [0, 0, 1], [0, 0, 0]]\n",
     "torque[0].times", "strictly increasing"),
    ("torque values not matching times", "",
     "[[torque]]\nkind = 'tabulated'\ntimes = [0, 1]\nvalues = [[0, 0, 0]]\n", "torque[0].values", "shape"),
]


@pytest.mark.parametrize(("old", "new", "key", "rule"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input_names_file_key_and_rule(tmp_path, old, new, key, rule):
    text = BASE.replace(old, new, 1) if old else BASE + "\n" + new  # old = "": append [[torque]] tables
    assert text != BASE
    path = write(tmp_path, text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path).build()
    message = str(info.value)
    assert message.startswith(f"{path}: {key}: "), message
    assert rule in message, message
    assert len(message.splitlines()) == 1, message


def test_bad_toml_syntax_gives_the_line(tmp_path):
    path = write(tmp_path, BASE.replace("stop = 1.0", "stop = = 1.0"))  # line 8 of BASE
    with pytest.raises(ScenarioError, match=rf"^{path}: line 8, column 8: invalid TOML: "):
        load_scenario(path)


def test_every_problem_of_a_file_is_reported(tmp_path):
    path = write(tmp_path, BASE.replace("stop = 1.0", 'stop = "x"').replace("[body]", "[body]\ncolour = 1"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert [where for where, _ in info.value.problems] == ["body.colour", "time.stop"]
    assert len(str(info.value).splitlines()) == 2


def test_unreadable_files(tmp_path):
    with pytest.raises(ScenarioError, match="missing.toml: cannot read the file"):
        load_scenario(tmp_path / "missing.toml")
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes(BASE.replace("[body]", "# caf\xe9\n[body]").encode("latin-1"))
    with pytest.raises(ScenarioError, match="latin1.toml: not UTF-8 text"):
        load_scenario(latin1)


def test_error_raised_at_simulation_is_reported_against_its_key(tmp_path):
    # rtol = 1e-16 passes the schema (> 0) but the integrator refuses it (< 1e-15).
    path = write(tmp_path, BASE + "\n[solver]\nrtol = 1e-16\n")
    with pytest.raises(ScenarioError, match=rf"^{path}: solver.rtol: must be >= 1e-15"):
        run_scenario(path)


def test_scenario_error_is_a_validation_error():
    assert issubclass(ScenarioError, tumble.ValidationError) and issubclass(ScenarioError, ValueError)


def test_strings_are_data_not_code(tmp_path):
    # A scenario is never evaluated: an expression in a number's place is refused as a string.
    path = write(tmp_path, BASE.replace("stop = 1.0", 'stop = "__import__(\'os\').getcwd()"'))
    with pytest.raises(ScenarioError, match="time.stop: must be a number"):
        load_scenario(path)


def test_heavy_top_example_conserves_total_energy_and_vertical_momentum():
    # Gravity torque from the file: E = T + m g·(R r) and L_z (inertial, along g) are
    # conserved by the exact motion; DOP853 at 1e-12 keeps them to about 1e-11 over 1 s.
    scenario = load_scenario(EXAMPLES / "heavy_top.toml")
    problem = scenario.build()
    traj = run_scenario(shortened(scenario, stop=1.0, samples=101))
    mass, com, g = 1.0, np.array([0.0, 0.0, 0.1]), 9.81
    energy = traj.energy + mass * g * attitude.rotate(traj.q, com)[:, 2]
    lz = traj.momentum_inertial[:, 2]
    assert repr(problem.torque).startswith("Gravity(")
    assert np.abs(energy - energy[0]).max() <= 1e-10 * abs(energy[0])
    assert np.abs(lz - lz[0]).max() <= 1e-10 * abs(lz[0])


def test_exact_method_takes_no_solver_options(tmp_path):
    # method = "exact" is the closed form: a file without options runs and equals
    # tumble.analytic.torque_free bitwise; a dt (or rtol) is refused, naming the key.
    traj = run_scenario(load_scenario(write(tmp_path, BASE + '\n[solver]\nmethod = "exact"\n')))
    exact = tumble.analytic.torque_free(tumble.RigidBody(np.diag([1.0, 2.0, 3.0])), [0.001, 1.0, 0.001],
                                        t=traj.t)
    assert traj.method == "exact" and np.array_equal(traj.omega, exact.omega)
    for option in ("dt = 0.01", "rtol = 1e-9"):
        with pytest.raises(ScenarioError, match=r"solver\.(dt|rtol): not used by method 'exact'"):
            load_scenario(write(tmp_path, BASE + f'\n[solver]\nmethod = "exact"\n{option}\n'))


# --------------------------------------------------------------------------
# One dialect: the kind table, the one orbit table, library errors by .field
# --------------------------------------------------------------------------

SPACECRAFT = """
[spacecraft]
moments = [1.0, 2.0, 2.5]
[initial]
omega = [0.1, 0.0, 0.0]
[time]
stop = 1.0
samples = 3
"""


def test_kind_is_given_or_inferred_from_the_tables():
    from tumble.scenario.rigid import RigidScenario
    from tumble.scenario.spacecraft import SpacecraftScenario

    assert type(parse_scenario(BASE)) is RigidScenario and parse_scenario(BASE).kind == "rigid"
    assert type(parse_scenario('kind = "rigid"\n' + BASE)) is RigidScenario
    assert type(parse_scenario(SPACECRAFT)) is SpacecraftScenario  # a [spacecraft] table: no kind needed
    assert parse_scenario('kind = "spacecraft"\n' + SPACECRAFT).kind == "spacecraft"


def test_every_kind_of_the_table_is_a_scenario():
    from tumble.scenario.kinds import scenario_class

    assert {"rigid", "spacecraft"} <= set(KINDS)  # and every kind of the registry (tests/test_kinds.py)
    for kind in KINDS:
        assert issubclass(scenario_class(kind), Scenario)


@pytest.mark.parametrize(("kind", "got"), [('"submarine"', "'submarine'"), ("3", "3")])
def test_unknown_kind_is_refused_naming_the_kinds(tmp_path, kind, got):
    path = write(tmp_path, f"kind = {kind}\n" + BASE)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    kinds = ", ".join(map(repr, KINDS))  # the registry's, in its order: 'rigid', 'spacecraft', ...
    assert kinds.startswith("'rigid', 'spacecraft', ")
    assert str(info.value) == f"{path}: kind: must be one of {kinds}, got {got}"
    assert info.value.field == "kind"


def test_a_kind_refuses_the_tables_of_another():
    with pytest.raises(ScenarioError) as info:
        parse_scenario('kind = "spacecraft"\n' + BASE, source="case.toml")
    assert {where for where, _ in info.value.problems} == {"body", "spacecraft"}


# An orbit with every element away from its default, once by altitude (degrees) and once by
# semi-major axis (rad): the Orbit each kind builds, and the one built here by hand.
ORBITS = [
    ("altitude = 600e3\ninclination = 97.8\nraan = 20.0\narg_periapsis = 10.0\nmean_anomaly = 5.0",
     tumble.spacecraft.Orbit(6378137.0 + 600e3, 0.0, np.radians(97.8), np.radians(20.0), np.radians(10.0),
                             np.radians(5.0))),
    ("semi_major_axis = 7.2e6\neccentricity = 0.1\ninclination = 0.5\narg_periapsis = 1.0\ndegrees = false\n"
     "mu = 4.9e12",
     tumble.spacecraft.Orbit(7.2e6, 0.1, 0.5, 0.0, 1.0, 0.0, mu=4.9e12)),
]


@pytest.mark.parametrize(("orbit", "expected"), ORBITS, ids=["altitude", "semi_major_axis"])
def test_the_one_orbit_table_gives_the_same_orbit_in_every_kind(orbit, expected):
    rigid = parse_scenario(BASE + f"\n[[torque]]\nkind = 'gravity_gradient'\n[torque.orbit]\n{orbit}\n")
    craft = parse_scenario(SPACECRAFT + f"\n[spacecraft.orbit]\n{orbit}\n")
    # Orbit is a frozen dataclass: == compares every element exactly
    assert rigid.build().torque.orbit == expected
    assert craft.model.orbit == expected


@pytest.mark.parametrize(("text", "key", "argument"), [
    (BASE.replace("moments = [1.0, 2.0, 3.0]", "inertia = [[1, 0, 0], [0, 2, 0], [0, 0, -3]]"),
     "body.inertia", "inertia"),
    (BASE.replace("moments = [1.0, 2.0, 3.0]", "moments = [1.0, 1.0, 3.0]"), "body.moments", "inertia"),
    (BASE + "[[torque]]\nkind = 'tabulated'\ntimes = [0, 1, 1]\nvalues = [[0, 0, 0], [0, 0, 1], [0, 0, 0]]\n",
     "torque[0].times", "t"),
    (SPACECRAFT.replace("moments = [1.0, 2.0, 2.5]", "moments = [1.0, 2.0, 5.0]"), "spacecraft.moments", "inertia"),
])
def test_a_library_error_reaches_the_user_with_its_key(text, key, argument):
    # The library names the argument it refuses (ValidationError.field); the table's argument -> key
    # table turns it into the key of the file, without reading the message.
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, source="case.toml").model
    assert info.value.field == key
    assert str(info.value).startswith(f"case.toml: {key}: ")
    cause = info.value.__cause__
    assert isinstance(cause, tumble.ValidationError) and cause.field == argument
    assert info.value.rule == cause.rule


def test_scenario_error_field_is_the_first_problem():
    with pytest.raises(ScenarioError) as info:
        parse_scenario(BASE.replace("stop = 1.0", 'stop = "x"').replace("[body]", "[body]\ncolour = 1"))
    assert info.value.field == "body.colour" and info.value.rule.startswith("unknown key")
