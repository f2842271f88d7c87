"""The one front door: what tumble.simulate checks once for every model, and the declared method/model match."""

import numpy as np
import pytest

import tumble
from tumble import integrate
from tumble._protocol import CAPABILITIES
from tumble._validate import ValidationError
from tumble.rigid_model import RigidBodies
from tumble.simulate import Model

DIAG = np.diag([1.0, 2.0, 3.0])
OMEGA0 = np.array([0.3, 1.0, -0.2])
T = [0.0, 1.0]


# -- options a method does not read ---------------------------------------------------------


@pytest.mark.parametrize("method, option", [("dop853", "dt"), ("rk4", "rtol"), ("rk4", "atol"),
                                            ("cf4", "rtol"), ("exact", "dt"), ("exact", "max_steps")])
def test_an_option_the_method_does_not_read_is_refused(method, option):
    with pytest.raises(ValidationError, match=rf"^{option}: method '{method}' does not use {option}"):
        tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=T, method=method, **{option: 0.1})


def test_every_method_names_the_options_it_reads():
    for name, m in integrate.METHODS.items():
        expected = ("rtol", "atol", "max_steps") if m.adaptive else (("dt", "max_steps") if m.stepper else ())
        assert tuple(m.options) == expected, name


def test_defaults_of_the_adaptive_method_are_recorded():
    traj = tumble.simulate(tumble.RigidBody(DIAG), OMEGA0, t=T)
    assert (traj.info["rtol"], traj.info["atol"]) == (1e-10, 1e-12)
    assert "max_steps" not in traj.info and "dt" not in traj.info


# -- the initial state by name ------------------------------------------------------------------


def test_an_unknown_initial_state_is_refused_with_a_hint_and_the_names_the_model_takes():
    with pytest.raises(ValidationError, match=r"^omega: a RigidBody has no initial state 'omega' "
                                              r"\(did you mean 'omega0'\?\); it takes omega0 \(.*rad/s.*\), q0"):
        tumble.simulate(tumble.RigidBody(DIAG), t=T, omega=OMEGA0)


def test_a_required_initial_state_is_named_with_its_meaning():
    with pytest.raises(ValidationError, match=r"^omega0: a RigidBody needs it: initial body rate, rad/s, body axes"):
        tumble.simulate(tumble.RigidBody(DIAG), t=T)


def test_omega0_by_position_or_by_name_is_the_same_run():
    body = tumble.RigidBody(DIAG)
    a = tumble.simulate(body, OMEGA0, t=T)
    b = tumble.simulate(body, t=T, omega0=OMEGA0)
    np.testing.assert_array_equal(a.q, b.q)
    np.testing.assert_array_equal(a.omega, b.omega)


# -- declared compatibility ---------------------------------------------------------------------


def test_every_capability_a_method_needs_is_described():
    for m in integrate.METHODS.values():
        assert m.needs <= set(CAPABILITIES), m.name


@pytest.mark.parametrize("method", sorted(integrate.METHODS))
def test_a_method_is_refused_exactly_when_the_kernel_misses_what_it_needs(method):
    # a rigid body under a torque provides everything but "torque_free" (and "cuda" with a Python torque)
    body = tumble.RigidBody(DIAG)
    torque = tumble.torques.ConstantBody([0.0, 0.0, 0.1])
    provides = tumble.as_model(body).compile(torque, 0.0).provides
    options = {"dt": 0.1} if "dt" in integrate.METHODS[method].options else {}
    if integrate.METHODS[method].needs <= provides:
        traj = tumble.simulate(body, OMEGA0, t=T, method=method, torque=torque, **options)
        assert traj.method == method
    else:
        working = ", ".join(repr(n) for n, m in integrate.METHODS.items() if m.needs <= provides)
        with pytest.raises(ValidationError) as info:
            tumble.simulate(body, OMEGA0, t=T, method=method, torque=torque, **options)
        assert str(info.value) == (f"method: {method!r} needs {CAPABILITIES['torque_free']}, which a RigidBody "
                                   f"under torque={torque!r} is not; methods for it: {working}")


def test_the_engine_imports_no_model():
    import ast
    from pathlib import Path

    package = Path(integrate.__file__).parent
    for path in package.glob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        imported = [getattr(node, "module", None) or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)]
        imported += [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names]
        models = [name for name in imported if name.startswith("tumble.kernels") or name in (
            "tumble.rigid_body", "tumble.rigid_model", "tumble._free_flow")]
        assert not models, (path.name, models)


# -- the model interface --------------------------------------------------------------------------


def test_a_rigid_body_is_a_value_that_simulate_turns_into_its_model_as_it_does_arrays():
    body = tumble.RigidBody(DIAG, mass=2.0)
    assert not isinstance(body, Model)
    model = tumble.as_model(body)
    assert isinstance(model, RigidBodies) and model.kind == "RigidBody" and model.batch_size is None
    assert model.masses.tolist() == [2.0] and model.inertia is body.inertia
    np.testing.assert_array_equal(model.q_bp[0], tumble.attitude.from_matrix(body.axes))
    assert tumble.simulate(body, OMEGA0, t=T).model == "RigidBody"
    traj = tumble.simulate(np.stack([DIAG, 2.0 * DIAG]), np.tile(OMEGA0, (2, 1)), t=T)
    assert traj.model == "RigidBodies" and traj.batch_size == 2


def test_the_model_interface_of_a_rigid_body_answers_for_one_release_with_a_deprecation_naming_as_model():
    body = tumble.RigidBody(DIAG)
    traj = tumble.simulate(body, OMEGA0, t=T)
    message = r"^RigidBody\.invariants is deprecated: .* use tumble\.as_model\(body\)\.invariants$"
    with pytest.warns(DeprecationWarning, match=message):
        kept = body.invariants(traj)
    assert kept.keys() == {"energy", "momentum_inertial"}
    for name, values in tumble.as_model(body).invariants(traj).items():
        np.testing.assert_array_equal(kept[name], values)
    with pytest.warns(DeprecationWarning, match=r"^RigidBody\.state_fields is deprecated"):
        assert [f.name for f in body.state_fields()] == ["omega0", "q0"]
    with pytest.warns(DeprecationWarning, match=r"^tumble\.rigid\.RigidMotion is deprecated: .*RigidBodies"), \
            pytest.warns(DeprecationWarning, match=r"^tumble\.rigid is deprecated .*: use tumble\.rigid_model$"):
        assert tumble.rigid.RigidMotion is RigidBodies  # the old spelling: tumble.rigid is tumble.rigid_model
    with pytest.raises(AttributeError, match="'RigidBody' object has no attribute 'spin'"):
        body.spin  # noqa: B018 (the attribute access is the test)


def test_torque_free_invariants_of_a_rigid_body_hold_under_dop853():
    # T and L_N of the free body, dop853 at rtol = atol = 1e-12 over 20 s: the local errors add up
    # to ~1e-12 (test_simulate measures 3e-11 over 1000 s); bound 1e-11 relative.
    body = tumble.RigidBody(DIAG)
    traj = tumble.simulate(body, OMEGA0, t=np.linspace(0.0, 20.0, 21), rtol=1e-12, atol=1e-12)
    invariants = tumble.as_model(body).invariants(traj)
    assert set(invariants) == {"energy", "momentum_inertial"}
    for values in invariants.values():
        assert np.abs(values - values[0]).max() <= 1e-11 * np.abs(values[0]).max()


def test_a_torque_has_no_invariant_to_promise():
    body = tumble.RigidBody(DIAG)
    traj = tumble.simulate(body, OMEGA0, t=T, torque=tumble.torques.ConstantBody([0.0, 0.0, 0.1]))
    assert tumble.as_model(body).invariants(traj) == {}
