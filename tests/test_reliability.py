"""Reliability (issue 18): no silent wrong answer, no unbounded run, one-line errors naming the field.

Every run here is a RigidBody with rk4 or dop853 and no torque, single body, a few steps: the compiled
specializations the rest of the suite already builds.
"""

import math
import re

import numpy as np
import pytest

import tumble
from tumble import integrate
from tumble import _validate
from tumble._validate import ValidationError, require_memory
from tumble.integrate import SolverError, _fixed

BODY = tumble.RigidBody(np.diag([1.0, 2.0, 3.0]))
OMEGA0 = [1e-3, 1.0, 1e-3]


# -- step counts: exact, bounded, checked before the run --------------------------------------------


@pytest.mark.parametrize("t, dt, needed", [
    ([0.0, 1e20], 1.0, "1e+20"),                  # the reproducer: wrapped past 2**63 to one step
    ([0.0, 1.0], 1e-300, "1e+300"),               # the scenario of the issue: "2 steps", exit 0
    ([0.0, 1.0], 1e-18, "1e+18"),                 # ran for ever
    ([0.0, 1e308, 1.7e308], 1e-300, "more than 1.8e308"),  # the quotient itself overflows to inf
])
def test_a_run_past_max_steps_is_refused_before_it_starts_saying_how_many_steps_it_needs(t, dt, needed):
    with pytest.raises(ValidationError, match=rf"^max_steps: the run needs {re.escape(needed)} steps of dt = "):
        tumble.simulate(BODY, OMEGA0, t=t, method="rk4", dt=dt)


def test_the_refusal_says_which_max_steps_allows_the_run_and_that_value_runs_it():
    with pytest.raises(ValidationError, match=r"more than max_steps = 10; give a larger dt, or max_steps=20 to allow"):
        tumble.simulate(BODY, OMEGA0, t=[0.0, 1.0, 2.0], method="rk4", dt=0.1, max_steps=10)
    traj = tumble.simulate(BODY, OMEGA0, t=[0.0, 1.0, 2.0], method="rk4", dt=0.1, max_steps=20)
    assert traj.info["n_steps"] == 20  # 10 steps of 0.1 s per unit interval, exactly


def test_landing_steps_are_exact_integers_near_the_float64_limit():
    # 2**53 steps of 1 s are exact in float64 and in int64; one more second needs one more step
    m, h = _fixed.landing_steps(np.array([0.0, 2.0**53]), 1.0, 2**53)
    assert m.dtype == np.int64 and int(m[0]) == 2**53 and h[0] == 1.0
    with pytest.raises(ValidationError, match=r"^max_steps: the run needs 9\.01e\+15 steps"):
        _fixed.landing_steps(np.array([0.0, 2.0**53, 2.0**53 + 2.0]), 1.0, 2**53)


@pytest.mark.parametrize("max_steps, rule", [
    (0, r"must be >= 1"), (2**53 + 1, r"must be a whole number from 1 to 2\*\*53"),
    (1.5, r"must be a whole number"), (math.inf, r"must be a whole number"), ("many", r"must be a whole number"),
])
def test_max_steps_must_be_a_whole_number_within_the_exact_range(max_steps, rule):
    for method, option in (("rk4", {"dt": 0.1}), ("dop853", {})):
        with pytest.raises(ValidationError, match=rf"^max_steps: {rule}"):
            tumble.simulate(BODY, OMEGA0, t=[0.0, 1.0], method=method, max_steps=max_steps, **option)


def test_every_stepping_method_reads_max_steps_and_the_default_is_bounded():
    for name, m in integrate.METHODS.items():
        assert ("max_steps" in m.options) == m.stepper, name
    assert integrate.MAX_STEPS == 10**8
    assert {m.options["max_steps"].default for m in integrate.METHODS.values() if m.stepper} == {10**8}


@pytest.mark.parametrize("t", [[0.0, 1e300], [0.0, 5e299, 1e300]], ids=["one interval", "two"])
def test_an_adaptive_run_that_could_only_end_at_max_steps_stops_after_its_first_thousand_steps(t):
    # DOP853's step count is not known beforehand: after PROJECT_AFTER = 1000 steps the rest of the span at
    # their mean step is projected, and a run projected past 100 x max_steps stops there, not 1e8 steps later
    # (and the output rows it never reached are not mistaken for a divergence)
    with pytest.raises(SolverError, match=r"^max_steps: the run would need \S+ steps or more to t=1e\+300") as caught:
        tumble.simulate(BODY, OMEGA0, t=t, method="dop853")
    assert "more than max_steps = 1e+08" in str(caught.value)
    # rates of 1e19 rad/s: steps of ~1e-20 s, which float64 resolves near t = 0, projected to 2.4e20 steps
    with pytest.raises(SolverError, match=r"^max_steps: the run would need 2.4e\+20 steps or more to t=10 "):
        tumble.simulate(BODY, 1e19 * np.asarray(OMEGA0), t=[0.0, 10.0], method="dop853")
    # a run within the bound is untouched: 1000 steps in, this one projects about 2e4 (max_steps 1e3 allows
    # the projection check to fire from 1e5), and it reaches its end
    traj = tumble.simulate(BODY, OMEGA0, t=[0.0, 2000.0], method="dop853", rtol=1e-12, atol=1e-12)
    assert 1e3 < traj.info["n_steps"] < 1e5 and np.isfinite(traj.omega).all()


# -- finite state -------------------------------------------------------------------------------------


def test_a_diverged_run_names_the_time_and_the_rate_not_an_internal_parameter():
    # rk4 with dt = 1 s on |ω| = 1e5 rad/s: h|ω| = 1e5 ≫ 2.8 (the stability limit), so |ω| grows by
    # ~(h|ω|)^4 per step and overflows within a few output times
    with pytest.raises(SolverError, match=r"^simulation diverged at t = \d+ s \(\|ω\| = \S+ rad/s at t = \d+ s, "
                                          r"the last finite state\): reduce dt or check the torque$"):
        tumble.simulate(BODY, [1e3, 1e5, 1e3], t=np.linspace(0.0, 10.0, 11), method="rk4", dt=1.0)


# -- sizes checked before allocation -------------------------------------------------------------------


def test_outputs_too_large_are_refused_with_the_bytes_needed():
    # 10**6 bodies × 10**6 output times × (7 state + 11 output) values × 8 bytes = 1.44e14 bytes: refused before
    # anything is allocated (the inputs themselves are views of 24 MB)
    omega0 = np.broadcast_to(OMEGA0, (10**6, 3))
    with pytest.raises(ValidationError, match=r"^store: 1000000 members x 1000000 output times need at least "
                                              r"144,000,000,000,000 bytes"):
        tumble.simulate(BODY, omega0, t=np.linspace(0.0, 1.0, 10**6), method="rk4", dt=1.0)


def test_every_allocation_sized_from_input_is_checked_against_half_the_memory():
    # the check of integrate.solve (for its direct callers), of tumble.load and of the demos
    with pytest.raises(ValidationError, match=r"^t: the states need 50\.9 TiB \(5\.6e\+13 bytes\), more than half "
                                              r"this machine's memory"):
        require_memory(7 * 8 * 10**12, "t", "the states")
    require_memory(_validate.memory_bytes() // 2, "t", "the states")  # exactly half: allowed


# -- the small reproducers of the issue -------------------------------------------------------------


@pytest.mark.parametrize("make, message", [
    (lambda: tumble.RigidBody.sphere(mass=1.0, radius=[1, 2]), r"^radius: must be a finite number > 0, got \[1, 2\]"),
    (lambda: tumble.RigidBody.box(mass="heavy", size=[1.0, 2.0, 3.0]),
     r"^mass: must be a finite number > 0, got 'heavy'"),
])
def test_shape_constructors_name_the_field_of_a_value_that_is_not_a_number(make, message):
    with pytest.raises(ValidationError, match=message):
        make()


def test_to_rotvec_of_a_tiny_quaternion_is_its_rotation():
    # [1e-200, 1e-200, 0, 0] is [1, 1, 0, 0]/|.|: a quarter turn about x (the squares underflowed to 0/0)
    np.testing.assert_allclose(tumble.attitude.to_rotvec([1e-200, 1e-200, 0.0, 0.0]), [math.pi / 2, 0.0, 0.0],
                               rtol=4 * np.finfo(float).eps)  # atan2 and one division: a few ulps


def test_from_rotvec_of_a_huge_angle_is_refused_naming_r_not_nan():
    # float64 numbers near 1e300 are ~1e284 apart: the angle defines no rotation (it gave NaN)
    with pytest.raises(ValidationError, match=r"^r: rotation angle \|r\| = 1e\+300 rad is past 1e\+16 rad"):
        tumble.attitude.from_rotvec([1e300, 0.0, 0.0])
    q = tumble.attitude.from_rotvec([1e16, 0.0, 0.0])  # the largest accepted: still a unit quaternion
    assert abs(np.linalg.norm(q) - 1.0) < 4 * np.finfo(float).eps


def test_a_torque_function_returning_none_is_named_with_what_it_returned():
    with pytest.raises(ValidationError, match=r"^torque: the function no_torque\(t, q, omega\) must return 3 finite "
                                              r"numbers .*; at t=0\.0 it returned None$"):
        tumble.simulate(BODY, OMEGA0, t=[0.0, 1.0], method="rk4", dt=0.5, torque=no_torque)


def no_torque(t, q, omega):
    return None


def _urdf(last_link: str) -> str:
    return ('<robot name="r"><link name="base"/>' + last_link
            + '<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>'
              '<limit lower="-1" upper="1"/></joint></robot>')


@pytest.mark.parametrize("link, message", [
    ('<link name="a"><inertial><mass value="inf"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'
     '</inertial></link>', r"^link 'a' <inertial> <mass>: value must be a finite number >= 0 kg, got inf"),
])
def test_urdf_links_with_infinite_mass_are_refused_naming_the_element(link, message):
    with pytest.raises(ValidationError, match=message):
        tumble.robot.SerialChain.from_urdf(_urdf(link))


@pytest.mark.parametrize("method", ["dop853", "rk4"])
def test_rates_whose_square_overflows_are_refused_naming_omega0(method):
    # 1e200 rad/s: ω·Iω overflows; dop853 and the exact flow raised ZeroDivisionError from compiled code
    with pytest.raises(ValidationError, match=r"^omega0: must be at most 1e\+150 in magnitude .* got 1e\+200"):
        tumble.simulate(BODY, [0.0, 1e200, 1.0], t=[0.0, 1.0], method=method,
                        **({"dt": 0.1} if method == "rk4" else {}))
