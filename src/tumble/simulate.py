"""``simulate``: integrate Euler's equations and the attitude of one body or a batch.

The integrators work in each body's principal axes, where Euler's equations
are cheapest (``I₁ω̇₁ = τ₁ + (I₂ − I₃)ω₂ω₃`` and cyclic). ``simulate`` moves
the initial state into those axes and the results back::

    q_NP = q_NB ⊗ q_BP,   ω_P = R_BPᵀ ω_B        (in)
    q_NB = q_NP ⊗ q_BP*,  ω_B = R_BP ω_P         (out)

with ``R_BP = body.axes`` (columns: the principal axes in body axes). The
change of axes is exact for a diagonal inertia and costs a few rounding errors
otherwise; the motion does not depend on the body axes chosen (tested).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from tumble import _rigid, attitude, integrate, limits, torques
from tumble._validate import ValidationError, as_array
from tumble.body import RigidBody, principal_axes
from tumble.trajectory import Trajectory

__all__ = ["simulate"]


def simulate(
    body,
    omega0,
    *,
    t,
    q0=None,
    method: str = "dop853",
    rtol: float = 1e-10,
    atol: float = 1e-12,
    dt: float | None = None,
    torque=None,
    max_steps: int = 10**9,
    progress: Callable[[int, int], None] | None = None,
    device: str = "cpu",
) -> Trajectory:
    """Integrate the rotation of a rigid body (or a batch of bodies) through the times ``t``.

    Solves Euler's equations ``I ω̇ + ω × (I ω) = τ`` (body axes) together with
    the attitude kinematics ``q̇ = ½ q ⊗ [0, ω]``.

    Parameters
    ----------
    body : RigidBody, (3, 3) or (N, 3, 3) inertia array (kg·m², body axes), or a sequence of RigidBody
        The body, or one body per batch member.
    omega0 : (3,) or (N, 3) array_like
        Initial body rate, rad/s, in body axes. A leading axis of length N
        integrates N bodies at once, in parallel over the cores.
    t : (n,) array_like
        Output times, s, strictly increasing; ``t[0]`` is the start.
    q0 : (4,) or (N, 4) array_like, optional
        Initial attitude, unit quaternion ``[w, x, y, z]`` mapping body →
        inertial axes (normalised here; default: identity).
    method : str, one of ``tumble.integrate.METHODS``
        ``"dop853"``: adaptive 8th-order Dormand–Prince (``rtol``, ``atol``);
        ``"rk4"``, ``"cf4"`` (Lie group), ``"splitting2"``/``"splitting4"``
        (Lie–Poisson, torque-free), ``"exact_split2"``/``"exact_split4"``
        (exact free flow + torque kicks): fixed step ``dt`` (s); ``"exact"``:
        the closed-form torque-free motion (no step). See
        :mod:`tumble.integrate` and ``docs/integrators.md``.
    torque : TorqueModel, callable ``f(t, q, omega) -> (3,)``, or None
        External torque in body axes (N·m); see :mod:`tumble.torques`. Python
        callables run at Python speed and on one core.
    max_steps : int
        Adaptive steps allowed per body before :class:`~tumble.integrate.SolverError`.
    progress : callable ``progress(done, total)``, optional
        Called as output samples are completed (the CLI draws a progress bar).
        Not available with ``device="cuda"``.
    device : {"cpu", "cuda"}
        ``"cuda"`` runs ``method="rk4"`` batches on an NVIDIA GPU, one thread
        per body (compiled torque models only; see ``docs/gpu.md``).

    Returns
    -------
    Trajectory
        ``t`` (n,), ``q`` (n, [N,] 4), ``omega`` (n, [N,] 3) and the inertia, with
        energy, angular momentum and their drifts.
    """
    method = str(method)
    if device not in ("cpu", "cuda"):
        raise ValidationError(f"device: must be 'cpu' or 'cuda', got {device!r}")
    if device == "cuda" and (method != "rk4" or progress is not None):
        raise ValidationError(f"device: 'cuda' runs method='rk4' without progress reporting, got method={method!r}"
                              + (" and a progress callback" if progress is not None else ""))
    m = integrate.check_options(method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps, torque=torque)
    times = _output_times(t)
    moments, axes, batch_inertia, mass = _bodies(body)
    omega0 = as_array(omega0, "omega0", tail=(3,))
    q0 = attitude.identity() if q0 is None else as_array(q0, "q0", tail=(4,))
    n = _batch_size(batch_inertia, omega0, q0)
    if np.any(np.linalg.norm(q0, axis=-1) == 0.0):
        raise ValidationError("q0: must be a non-zero quaternion [w, x, y, z] (it is normalised here)")
    q0 = attitude.normalize(np.broadcast_to(q0, (n or 1, 4)))
    omega0 = np.broadcast_to(omega0, (n or 1, 3))
    model = torques.as_torque_model(torque)

    # Into principal axes, one set of axes per distinct body: R_BP (B, 3, 3), B = 1 or N.
    q_bp = attitude.from_matrix(axes)                              # (B, 4)
    y0 = np.empty((n or 1, _rigid.STATE_SIZE))
    y0[:, :4] = attitude.multiply(q0, q_bp)
    y0[:, 4:] = np.einsum("bji,bj->bi", axes, omega0)
    rigid = _rigid.from_principal(moments, axes, model)
    limits.check_rigid_motion(moments, y0[:, 4:], mass, stacklevel=3)

    if device == "cuda":
        from tumble.integrate import _cuda  # imports numba.cuda: only when asked for

        states, stats = _cuda.solve_cuda(rigid.coefficients, rigid.params, rigid.codes, y0, times, dt)
    else:
        with torques.registered(model):
            states, stats = integrate.solve(
                rigid, y0, times, method=method, dt=dt, rtol=rtol, atol=atol,
                max_steps=max_steps, serial=model is not None and model.needs_python, progress=progress,
            )

    if model is not None:  # a torque may have spun the body up: check where it ended
        limits.check_rigid_motion(moments, states[-1, :, 4:], mass, stacklevel=3)
    q = attitude.multiply(states[..., :4], attitude.conjugate(q_bp))
    omega = np.einsum("bij,tbj->tbi", axes, states[..., 4:])
    if n is None:
        q, omega = q[:, 0], omega[:, 0]
    info = {"torque": repr(model) if model is not None else "none", **stats}
    if m.adaptive:
        info.update(rtol=float(rtol), atol=float(atol))
    elif m.stepper:
        info.update(dt=float(dt))
    return Trajectory(t=times, q=q, omega=omega, inertia=batch_inertia, method=method, info=info)


def _output_times(t) -> np.ndarray:
    times = as_array(t, "t")
    if times.ndim != 1 or times.size < 1:
        raise ValidationError(f"t: must be a 1-D array of output times, got shape {times.shape}")
    steps = np.diff(times)
    if np.any(steps <= 0.0):
        k = int(np.flatnonzero(steps <= 0.0)[0])
        raise ValidationError(
            f"t: output times must be strictly increasing (t[{k + 1}] = {times[k + 1]} <= t[{k}] = {times[k]})"
        )
    return times


# Models of the extension packages that have their own entry point (named here, not
# imported: those packages are built on this module).
_OWN_SIMULATE = {
    "tumble.variable.body.VariableBody": "integrate it with tumble.variable.simulate_variable",
    "tumble.variable.human.Human": ("make its VariableBody with Human.variable_body(...) and integrate that with "
                                    "tumble.variable.simulate_variable"),
    "tumble.flexible.FlexibleBody": "integrate it with tumble.flexible.simulate",
    "tumble.slosh.SloshBody": "integrate it with tumble.slosh.simulate",
    "tumble.spacecraft.model.Spacecraft": "integrate it with tumble.spacecraft.simulate",
    "tumble.robot.chain.SerialChain": "integrate it with tumble.robot.simulate",
}


def _bodies(body) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | float | None]:
    """Principal moments (B, 3), axes R_BP (B, 3, 3), the inertia to report and the mass (kg, or None
    when unknown), B = 1 or one per member.

    An (N, 3, 3) inertia array is validated in one vectorised call
    (:func:`tumble.body.principal_axes`), with the rules of :class:`RigidBody`.
    """
    if isinstance(body, RigidBody):
        return body.moments[None], body.axes[None], np.array(body.inertia), body.mass
    if isinstance(body, Sequence) and body and all(isinstance(b, RigidBody) for b in body):
        masses = [b.mass for b in body]
        return (np.stack([b.moments for b in body]), np.stack([b.axes for b in body]),
                np.stack([b.inertia for b in body]), None if None in masses else np.array(masses))
    own = _OWN_SIMULATE.get(f"{type(body).__module__}.{type(body).__qualname__}")
    if own is not None:
        raise ValidationError(f"body: a {type(body).__name__} is not a rigid body; {own}")
    inertia = as_array(body, "inertia", tail=(3, 3))
    if inertia.ndim not in (2, 3):
        raise ValidationError(f"inertia: must have shape (3, 3) or (N, 3, 3), got {inertia.shape}")
    inertia, moments, axes = principal_axes(inertia, "inertia")
    if inertia.ndim == 2:
        return moments[None], axes[None], inertia, None
    return moments, axes, inertia, None


def _batch_size(inertia, omega0, q0) -> int | None:
    """N for a batch, None for a single body; refuses inconsistent batch sizes."""
    sizes = {}
    for name, arr, single_ndim in (("omega0", omega0, 1), ("q0", q0, 1), ("body", inertia, 2)):
        if arr.ndim > single_ndim + 1:
            raise ValidationError(f"{name}: a batch has one leading axis, got shape {arr.shape}")
        if arr.ndim == single_ndim + 1:
            sizes[name] = arr.shape[0]
    if len(set(sizes.values())) > 1:
        raise ValidationError(f"batch sizes disagree: {sizes}")
    return next(iter(sizes.values()), None)
