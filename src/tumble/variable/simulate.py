"""``simulate_variable``: the rotation of a body whose inertia changes, by the integrators of ``tumble.integrate``.

Solves the equations of a deformable body in a body frame B::

    L_B = I(t) ω + A(t),        dL_B/dt + ω × L_B = τ_B,        q̇ = ½ q ⊗ [0, ω]

(Euler's law ``dL/dt = τ`` for the angular momentum about the centre of mass,
written in the rotating axes of B), as the model of
:mod:`tumble.kernels.variable`: the state holds ``L`` in inertial axes, which no
integrator changes when there is no torque, so ``|L|`` is conserved to
rounding. The rotational energy ``T = ½ ω·Iω`` is *not* conserved: the
muscles (or actuators) that change the shape work on the body at the rate

    dT/dt = −ω·Ȧ − ½ ω·İ ω + ω·τ                (see :func:`shape_power`)

which is why a skater who pulls in the arms (İ < 0, A = 0) spins faster and
has more energy.
"""

from __future__ import annotations

import numpy as np

from tumble import attitude, integrate, torques
from tumble._validate import ValidationError, as_array
from tumble.trajectory import Extra, Trajectory
from tumble.kernels import variable as _model
from tumble.variable.body import VariableBody

__all__ = ["METHODS", "angular_velocity", "shape_power", "simulate_variable"]

#: The integrators that apply to a deformable body (those that take any right-hand side).
METHODS = ("dop853", "rk4", "cf4")


def simulate_variable(
    body: VariableBody,
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
) -> Trajectory:
    """Integrate the rotation of the deformable ``body`` through the output times ``t`` (s).

    Parameters
    ----------
    body : VariableBody
        ``I(t)`` and ``A(t)`` in body axes; every output time must lie in ``body.t_span``.
    omega0 : (3,) or (N, 3) array_like
        Initial angular velocity of B relative to inertial, rad/s, body axes
        (then ``L_B(t₀) = I(t₀) ω₀ + A(t₀)``). N rows run N motions of the same body.
    q0 : (4,) or (N, 4) array_like, optional
        Initial attitude of B, unit quaternion ``[w, x, y, z]``, body → inertial (default identity).
    method, rtol, atol, dt, max_steps
        As in :func:`tumble.simulate`: ``"dop853"`` (adaptive), ``"rk4"`` or
        ``"cf4"`` (fixed step ``dt``, s). The free-rigid-body methods
        (splitting, exact) do not apply.
    torque : TorqueModel, callable ``f(t, q, omega) -> (3,)``, or None
        External torque about the centre of mass, body axes (N·m).

    Returns
    -------
    Trajectory
        ``q``, ``omega`` at ``t``; ``inertia`` is ``I(t₀)``, and the extras hold
        the time-varying quantities (body axes): ``inertia_t`` (n, [N,] 3, 3)
        ``I(t)``; ``shape_momentum`` ``A(t)``; ``angular_momentum`` ``L_B``; and
        ``energy_rotational`` ``½ ω·I(t)ω`` (J). Use these, not
        ``Trajectory.energy``/``momentum_*`` (those of the constant ``inertia``).
    """
    if not isinstance(body, VariableBody):
        raise ValidationError(f"body: must be a tumble.variable.VariableBody, got {type(body).__name__}")
    method = str(method)
    if method not in METHODS:
        raise ValidationError(f"method: a body whose inertia changes is integrated by one of {list(METHODS)}, "
                              f"got {method!r} (the splitting and exact methods are built on the rigid body)")
    integrate.check_options(method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps)
    times = as_array(t, "t")
    if times.ndim != 1 or times.size < 1 or np.any(np.diff(times) <= 0.0):
        raise ValidationError(f"t: must be a 1-D array of strictly increasing output times, got shape {times.shape}")
    body.check_times(times)
    omega0 = as_array(omega0, "omega0", tail=(3,))
    q0 = attitude.identity() if q0 is None else as_array(q0, "q0", tail=(4,))
    if omega0.ndim > 2 or q0.ndim > 2:
        raise ValidationError("omega0, q0: a batch has one leading axis")
    batch = {a.shape[0] for a in (omega0, q0) if a.ndim == 2}
    if len(batch) > 1:
        raise ValidationError(f"omega0, q0: batch sizes disagree ({omega0.shape[0]} and {q0.shape[0]})")
    n = batch.pop() if batch else None
    if np.any(np.linalg.norm(q0, axis=-1) == 0.0):
        raise ValidationError("q0: must be a non-zero quaternion [w, x, y, z] (it is normalised here)")
    q0 = attitude.normalize(np.broadcast_to(q0, (n or 1, 4)))
    omega0 = np.broadcast_to(omega0, (n or 1, 3))

    inertia0 = body.inertia(times[0])
    momentum0 = omega0 @ inertia0 + body.shape_momentum(times[0])   # I symmetric: (I ω)ᵀ = ωᵀ I
    y0 = np.empty((n or 1, _model.STATE_SIZE))
    y0[:, :4] = q0
    y0[:, 4:7] = attitude.rotate(q0, momentum0)
    y0[:, 7] = times[0]
    model = torques.as_torque_model(torque)
    compiled = _model.build(body, model)
    solution = integrate.solve(compiled, y0, times, method=method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps)
    states, stats = solution.states, solution.statistics()

    q = states[..., :4]
    momentum_body = attitude.rotate_inverse(q, states[..., 4:7])              # (n, B, 3)
    inertia_t = body.inertia(times)                                          # (n, 3, 3)
    shape_momentum = body.shape_momentum(times)
    omega = angular_velocity(inertia_t[:, None], shape_momentum[:, None], momentum_body)
    energy = 0.5 * np.einsum("tbi,tij,tbj->tb", omega, inertia_t, omega)
    inertia_b = np.broadcast_to(inertia_t[:, None], omega.shape + (3,))
    shape_b = np.broadcast_to(shape_momentum[:, None], omega.shape)
    if n is None:
        q, omega, momentum_body, energy = q[:, 0], omega[:, 0], momentum_body[:, 0], energy[:, 0]
        inertia_b, shape_b = inertia_b[:, 0], shape_b[:, 0]
    extras = {
        "inertia_t": Extra(inertia_b, ("row", "col"), "kg m2", "inertia tensor I(t) about the centre of mass, "
                           "body axes"),
        "shape_momentum": Extra(shape_b, ("vec",), "kg m2 s-1", "angular momentum A(t) of the shape change "
                                "relative to the body frame, body axes"),
        "angular_momentum": Extra(momentum_body, ("vec",), "kg m2 s-1", "angular momentum L = I(t) omega + A(t) "
                               "about the centre of mass, body axes"),
        "energy_rotational": Extra(energy, (), "J", "rotational energy 0.5 omega.I(t) omega of the body frozen "
                                   "in its current shape"),
    }
    info = {"torque": repr(model) if model is not None else "none", "model": "variable inertia", **stats}
    if integrate.METHODS[method].adaptive:
        info.update(rtol=float(rtol), atol=float(atol))
    else:
        info.update(dt=float(dt))
    return Trajectory(t=times, q=q, omega=omega, inertia=inertia0, method=method, info=info, extras=extras)


def angular_velocity(inertia, shape_momentum, momentum_body) -> np.ndarray:
    """``ω = I⁻¹ (L_B − A)`` (rad/s, body axes) from ``I`` (…, 3, 3), ``A`` and ``L_B`` (…, 3), broadcast."""
    rhs = np.asarray(momentum_body) - np.asarray(shape_momentum)
    inertia = np.broadcast_to(inertia, rhs.shape + (3,))
    return np.linalg.solve(inertia, rhs[..., None])[..., 0]


def shape_power(body: VariableBody, t, omega) -> np.ndarray:
    """Power of the shape change on the rotation, W: ``dT/dt = −ω·Ȧ − ½ ω·İ ω`` (torque-free).

    ``T = ½ ω·Iω`` is the rotational energy of the body frozen in its current
    shape. Derivation: with ``u = L_B − A = I ω`` and ``dL_B/dt = −ω × L_B``
    (no torque), ``T = ½ u·I⁻¹u`` gives
    ``dT/dt = ω·(−ω × L_B − Ȧ) − ½ ω·İ ω = −ω·Ȧ − ½ ω·İ ω``.
    ``t`` (n,) s and ``omega`` (n, [N,] 3) rad/s (body axes) as in a Trajectory.
    """
    t = body.check_times(t)
    omega = np.asarray(omega, dtype=np.float64)
    inertia_rate = body.inertia(t, 1)
    shape_rate = body.shape_momentum(t, 1)
    if omega.ndim == 3:
        inertia_rate, shape_rate = inertia_rate[:, None], shape_rate[:, None]
    return -np.einsum("...i,...i->...", omega, shape_rate) - 0.5 * np.einsum("...i,...ij,...j->...", omega,
                                                                              inertia_rate, omega)
