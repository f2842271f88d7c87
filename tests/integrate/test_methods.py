"""Every method of the registry (tumble.integrate.METHODS): its declared order measured on an exact motion.

One row per method (``ROWS``): the exact motion it is measured on and its steps. Adding a method is its file
(its ``METHODS`` declaration, tumble/integrate/) and its row here; a method without a row fails
``test_every_method_has_a_row``. The order is read from the registry, never typed in.

The exact motions (tumble.analytic):

* ``"heavy top"``: a heavy symmetric (Lagrange) top, :class:`tumble.analytic.HeavyTop`; the error is that
  of the symmetry axis in inertial axes at t = 4 s, ``(sin θ sin φ, −sin θ cos φ, cos θ)`` from the closed
  forms θ(t) and φ(t) (elliptic functions and Legendre's integral of the third kind). The methods that take a
  torque run here: with no torque the exact-flow splittings are the exact motion, and show no order.
* ``"free body"``: the torque-free asymmetric body, :func:`tumble.analytic.torque_free` (Jacobi elliptic
  functions); the error is the largest of ``|ΔR(q)|`` and ``|Δω|`` at t = 4 s. The methods that need a
  torque-free body run here, and dop853.

A method's steps ``dt`` halve from run to run; the measured order is the slope of the log-log fit of the
error against the step. An adaptive method runs with tolerances so loose (``rtol = atol = 1e3``) that every
step it proposes reaches the next output time, where it lands (:mod:`tumble.integrate._dop853`): with output
times every ``dt`` its steps are ``dt`` (after a few starting steps, shorter), so it too is measured on equal
steps. (On its error control, error against tolerance, it is checked in tests/test_simulate.py.)
"""

import re
from pathlib import Path

import numpy as np
import pytest
from numba import typeof

import tumble
from tumble import analytic, attitude, integrate
from tumble._validate import ValidationError
from tumble.measure import lyapunov_exponents

DOCS = Path(__file__).resolve().parents[2] / "docs"

# The measured order is within ± 0.2 of the declared one (diffrax's test allows ± 0.9). Measured (this file's
# rows): rk4 4.13, dop853 8.03, cf4 4.06, splitting2 2.000, splitting4 4.003, exact_split2 1.989, exact_split4 3.992
# (the heavy top's axis error at 4 s converges to the asymptotic ratio from above: rk4 log2 ratios 4.52, 4.35,
# 4.22 from dt = 0.05 s; and dop853's there stays near 8.5 up to the rounding floor, so it runs on the free body).
ORDER_TOL = 0.2
# The closed form (method="exact") against analytic.torque_free, which evaluate the same elliptic functions:
# rounding (measured 2e-16).
TOL_EXACT = 1e-13

T_END = 4.0  # s
TOP = analytic.HeavyTop.from_state(I1=1.0, I3=0.6, mass=1.0, length=0.3, g=9.80665, theta0=0.7, theta_dot0=0.4,
                                   phi_dot0=1.0, spin=4.0)  # kg·m², m, m/s², rad, rad/s: nutation period ≈ 2 s
FREE_INERTIA = np.array([[2.0, -0.5, 0.3], [-0.5, 3.0, 0.25], [0.3, 0.25, 4.0]])  # kg·m², moments ≈ 1.6, 2.9, 4.5
FREE_OMEGA0 = np.array([0.3, 1.0, -0.2])  # rad/s
FREE_Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])

HALVING = [0.2, 0.1, 0.05, 0.025]  # dt, s
LOOSE = 1e3  # rtol = atol of an adaptive method: each step lands on the next output time
ROWS = {  # method: (exact motion, steps dt, s)
    "rk4": ("heavy top", [0.0125, 0.00625, 0.003125, 0.0015625]),
    "dop853": ("free body", [0.8, 0.4, 0.2]),  # at 0.1 s its error is rounding
    "cf4": ("heavy top", [0.0125, 0.00625, 0.003125, 0.0015625]),
    "splitting2": ("free body", HALVING),
    "splitting4": ("free body", [0.4, 0.2, 0.1, 0.05]),
    "exact_split2": ("heavy top", HALVING),
    "exact_split4": ("heavy top", [0.4, 0.2, 0.1, 0.05]),
    "exact": ("free body", []),  # a closed form: no steps
}


def run(m, dt, **model):
    """``simulate`` to T_END with steps ``dt`` (s; None for a closed form), as the module docstring says."""
    if m.adaptive:
        t = np.linspace(0.0, T_END, round(T_END / dt) + 1)
        traj = tumble.simulate(t=t, method=m.name, rtol=LOOSE, atol=LOOSE, **model)
        assert traj.info["n_steps"] <= t.size + 10 and traj.info["n_rejected"] == 0  # the steps are dt
        return traj
    return tumble.simulate(t=[0.0, T_END], method=m.name, **({} if dt is None else {"dt": dt}), **model)


def heavy_top_error(m, dt):
    """The error of the symmetry axis (body z) in inertial axes at T_END."""
    traj = run(m, dt, **TOP.simulation_inputs())
    theta, phi = TOP.theta(np.array([T_END]))[0], TOP.precession_angle(np.array([T_END]))[0]
    exact = np.array([np.sin(theta) * np.sin(phi), -np.sin(theta) * np.cos(phi), np.cos(theta)])
    return np.abs(attitude.to_matrix(traj.q[-1])[:, 2] - exact).max()


def free_body_error(m, dt):
    """The largest error of R(q) and ω at T_END against the closed form."""
    exact = analytic.torque_free(tumble.RigidBody(FREE_INERTIA), FREE_OMEGA0, FREE_Q0, t=np.array([0.0, T_END]))
    traj = run(m, dt, model=FREE_INERTIA, omega0=FREE_OMEGA0, q0=FREE_Q0)
    return max(np.abs(attitude.to_matrix(traj.q[-1]) - attitude.to_matrix(exact.q[-1])).max(),
               np.abs(traj.omega[-1] - exact.omega[-1]).max())


ERROR = {"heavy top": heavy_top_error, "free body": free_body_error}


def test_every_method_has_a_row():
    assert set(ROWS) == set(integrate.METHODS)


@pytest.mark.parametrize("name", list(integrate.METHODS))
def test_measured_order_is_the_declared_order(name):
    m = integrate.METHODS[name]
    motion, steps = ROWS[name]
    error = ERROR[motion]
    if m.order is None:  # a closed form: exact to rounding, whatever the span
        assert error(m, None) <= TOL_EXACT
        return
    errors = np.array([error(m, dt) for dt in steps])
    assert (errors > 1e-13).all()  # above rounding: the fit measures truncation
    measured = np.polyfit(np.log(steps), np.log(errors), 1)[0]
    assert abs(measured - m.order) <= ORDER_TOL, measured


# -- the registry -------------------------------------------------------------------------------


def test_an_unknown_name_is_refused_in_one_place_listing_the_names():
    names = sorted(integrate.METHODS)
    for call in (lambda: integrate.method("euler"),
                 lambda: tumble.simulate(np.eye(3), [0.0, 0.0, 1.0], t=[0.0, 1.0], method="euler"),
                 lambda: lyapunov_exponents(np.eye(3), omega0=[0.0, 0.0, 1.0], t=[0.0, 1.0], method="euler")):
        with pytest.raises(ValidationError) as info:
            call()
        assert str(info.value) == f"method: must be one of {names}, got 'euler'"


def test_options_come_with_their_declared_defaults_and_rules():
    dop853, rk4 = integrate.METHODS["dop853"], integrate.METHODS["rk4"]
    assert dop853.resolve({}) == {"rtol": 1e-10, "atol": 1e-12, "max_steps": 10**8}
    assert rk4.resolve({"dt": 1, "max_steps": 5.0}) == {"dt": 1.0, "max_steps": 5}
    assert integrate.METHODS["exact"].resolve({"dt": None}) == {}
    for method, given, message in [
        (rk4, {}, "dt: method 'rk4' has a fixed step: give dt > 0 (s)"),
        (rk4, {"dt": 0.1, "rtol": 1e-6}, "rtol: method 'rk4' does not use rtol (it reads dt, max_steps)"),
        (dop853, {"rtol": 1e-16}, "rtol: must be >= 1e-15 (float64 cannot do better), got 1e-16"),
        (dop853, {"max_steps": 2.5}, "max_steps: must be a whole number from 1 to 2**53 = 9007199254740992, "
                                     "got 2.5"),
    ]:
        with pytest.raises(ValidationError) as info:
            method.resolve(given)
        assert str(info.value) == message


def test_a_fixed_step_run_counts_its_declared_evaluations_per_step():
    for name in ("rk4", "exact_split4"):
        traj = tumble.simulate(np.diag([1.0, 2.0, 3.0]), [0.1, 1.0, 0.1], t=[0.0, 1.0], method=name, dt=0.1,
                               torque=tumble.torques.ConstantBody([0.0, 0.0, 0.1]))
        assert traj.info["n_steps"] == 10
        assert traj.info["n_rhs"] == 10 * integrate.METHODS[name].evaluations


# dop853 carries its step size and count from chunk to chunk, so a run advanced one output interval at a time
# takes the same steps; each chunk evaluates its first stage again, at the projected state (one run reuses the
# last stage, at the state before projection): the states agree to rounding (measured 1.2e-15).
TOL_CHUNKS = 1e-14


def test_a_run_advanced_in_chunks_is_the_run_made_at_once():
    kernel = tumble.RigidBody(np.diag([1.0, 2.0, 3.0])).compile(None, 0.0)
    y0 = np.array([[1.0, 0.0, 0.0, 0.0, 0.1, 1.0, 0.1]])
    t = np.linspace(0.0, 5.0, 6)
    whole = integrate.solve(kernel, y0, t, method="dop853")
    run = integrate.Run(kernel, y0, t, method="dop853")
    chunks = np.empty_like(whole.states)
    for k in range(1, t.size):
        run.advance(k, chunks[k - 1:k + 1])
    np.testing.assert_allclose(chunks, whole.states, rtol=0, atol=TOL_CHUNKS)
    chunked = run.solution(chunks)
    assert (chunked.n_steps, chunked.n_rejected) == (whole.n_steps, whole.n_rejected)
    assert chunked.n_rhs == whole.n_rhs + t.size - 2  # a first stage per chunk after the first


# -- documentation tables read against the registry --------------------------------------------------


def table_rows(page, header):
    """The rows (lists of cells) of the Markdown table of ``page`` whose header row starts with ``header``."""
    lines = (DOCS / page).read_text(encoding="utf-8").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith(header))
    rows = []
    for line in lines[start + 2:]:
        if not line.startswith("|"):
            break
        rows.append([cell.strip() for cell in re.split(r"(?<!\\)\|", line)[1:-1]])
    return rows


def test_the_methods_table_gives_every_declared_order():
    orders = {row[0].strip('`"'): row[1] for row in table_rows("integrators.md", "| method | order |")}
    assert orders == {name: "—" if m.order is None else str(m.order) for name, m in integrate.METHODS.items()}


def test_the_compatibility_table_names_the_methods_that_need_each_capability():
    def expand(cell):  # `exact_split2/4` names exact_split2 and exact_split4
        names = []
        for name in re.findall(r"`([a-z0-9_/]+)`", cell):
            stem, *orders = name.split("/")
            names += [stem] + [stem[:-1] + order for order in orders]
        return set(names)

    for capability, _, methods in table_rows("architecture.md", "| capability |"):
        capability = capability.strip("`")
        if capability not in ("cuda", "rigid_fields"):  # a device's, not a method's needs
            assert expand(methods) == {n for n, m in integrate.METHODS.items() if capability in m.needs}, capability


# -- reference counting of the fused lane passes, from the kernel kind's declaration ----------------


def test_reference_counting_is_read_from_the_kind_not_from_a_field():
    from typing import NamedTuple

    from tumble.integrate import _fused

    class Declared(NamedTuple):  # a field called codes, None, and a declaration that says otherwise
        codes: None

        @staticmethod
        def may_call_python(numba_type):
            return True

    assert _fused.counts_references(typeof(Declared(None)))
