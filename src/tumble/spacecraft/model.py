"""``Spacecraft``: a rigid hub with actuators, environment and controller; ``simulate`` integrates it.

Conventions (``docs/spacecraft.md``): SI units; body axes B are the hub's
reference axes; ``q`` maps body → inertial (scalar first); ``omega`` is the
hub's rate relative to inertial, in body axes. The spacecraft's mass
properties are described in one of two ways:

* ``Spacecraft(inertia=J, ...)``: ``J`` is the **total** inertia about the
  centre of mass, wheels included (each wheel counted as a rigid part of the
  spacecraft, its spin inertia included);
* ``Spacecraft(hub=RigidBody(...), ...)``: the hub **without** the wheels,
  and each wheel with ``mass``, ``position`` and ``transverse_inertia``; the
  total ``J`` is then the composite of hub and rotors
  (:meth:`tumble.body.RigidBody.composite`).

Both give the same motion for the same total (tested). The body rate answers
to ``J_ω = J − Σ I_s a aᵀ`` (the wheels' spin inertias are carried by the
wheel momenta), see :mod:`tumble.spacecraft._kernel`.
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from tumble import attitude, integrate
from tumble._validate import ValidationError, as_array
from tumble.body import RigidBody
from tumble.spacecraft import _kernel, _params
from tumble.spacecraft.actuators import PWPF, CMGCluster, Magnetorquers, ReactionWheel, Thruster
from tumble.spacecraft.control import BDot, ConstantTorque, MomentumDumping, QuaternionPD, RateDamping
from tumble.spacecraft.environment import DipoleField
from tumble.spacecraft.orbit import Orbit
from tumble.trajectory import Extra, Trajectory

__all__ = ["Spacecraft", "SaturationWarning", "simulate", "METHODS"]

#: Methods that call the model's projection after every step, as the sampled controller needs.
METHODS = ("rk4", "dop853")
_ATTITUDE_LAWS = (QuaternionPD, RateDamping, ConstantTorque)
_ROUTES = {"wheels": _params.ROUTE_WHEELS, "cmgs": _params.ROUTE_CMGS, "thrusters": _params.ROUTE_THRUSTERS,
           "magnetorquers": _params.ROUTE_MAGNETORQUERS}
# A whole number of steps per control period or output interval to this relative tolerance.
_WHOLE = 1e-9


class SaturationWarning(UserWarning):
    """A reaction wheel reached its speed limit during a simulation (see ``extras['wheel_saturated']``)."""


@dataclass(frozen=True)
class Spacecraft:
    """A spacecraft: rigid hub, actuators, environment and controller (all optional but the mass properties).

    inertia : RigidBody or (3, 3) array, kg·m², body axes: the total inertia, wheels included
    hub : RigidBody with a mass: the hub without its wheels (give ``inertia`` or ``hub``)
    wheels : sequence of :class:`ReactionWheel`
    cmgs : :class:`CMGCluster` or None
    thrusters : sequence of :class:`Thruster`, with ``pwpf`` the modulator of the three axes
    magnetorquers : :class:`Magnetorquers` or None
    orbit : :class:`tumble.spacecraft.orbit.Orbit` or None (needed by the gravity gradient and the dipole field)
    magnetic_field : :class:`~tumble.spacecraft.environment.DipoleField`, a (3,) uniform field in
        inertial axes (T), or None
    gravity_gradient : bool, the gravity-gradient torque of the orbit on the total inertia
    controller : an attitude law (:class:`QuaternionPD`, :class:`RateDamping`), :class:`BDot`,
        :class:`MomentumDumping`, or a sequence of them (at most one attitude law, one dipole law each)
    control_period : None (continuous) or the sample period of a zero-order-hold controller, s

    The controller's torque command goes to the wheels if there are any, else to the
    CMGs, else to the thrusters (through the PWPF modulators), else to the magnetorquers
    (``m = B × u/|B|²``, the part normal to ``B``).
    """

    inertia: object = None
    hub: RigidBody | None = None
    wheels: Sequence[ReactionWheel] = ()
    cmgs: CMGCluster | None = None
    thrusters: Sequence[Thruster] = ()
    pwpf: PWPF = field(default_factory=PWPF)
    magnetorquers: Magnetorquers | None = None
    orbit: Orbit | None = None
    magnetic_field: object = None
    gravity_gradient: bool = False
    controller: object = None
    control_period: float | None = None
    #: The whole spacecraft as one rigid body (total inertia J, mass, centre of mass), derived.
    body: RigidBody = field(init=False, repr=False)

    def __post_init__(self):
        set_ = object.__setattr__
        set_(self, "wheels", tuple(self.wheels))
        set_(self, "thrusters", tuple(self.thrusters))
        _check_items(self.wheels, ReactionWheel, "wheels")
        _check_items(self.thrusters, Thruster, "thrusters")
        _check_type(self.cmgs, CMGCluster, "cmgs")
        _check_type(self.pwpf, PWPF, "pwpf")
        _check_type(self.magnetorquers, Magnetorquers, "magnetorquers")
        _check_type(self.orbit, Orbit, "orbit")
        set_(self, "body", self._total_body())
        if self.magnetic_field is not None and not isinstance(self.magnetic_field, DipoleField):
            b = as_array(self.magnetic_field, "magnetic_field")
            if b.shape != (3,):
                raise ValidationError(f"magnetic_field: must be a DipoleField or a (3,) uniform field (T), "
                                      f"got shape {b.shape}")
            set_(self, "magnetic_field", b)
        if isinstance(self.magnetic_field, DipoleField) and self.orbit is None:
            raise ValidationError("magnetic_field: a DipoleField needs an orbit (the field depends on the position)")
        if not isinstance(self.gravity_gradient, (bool, np.bool_)):
            raise ValidationError(f"gravity_gradient: must be True or False, got {self.gravity_gradient!r}")
        if self.gravity_gradient and self.orbit is None:
            raise ValidationError("gravity_gradient: needs an orbit")
        set_(self, "controller", self._laws())
        self._thruster_table()  # validates the thruster layout
        if self.control_period is not None:
            value = float(self.control_period)
            if not math.isfinite(value) or value <= 0.0:
                raise ValidationError(f"control_period: must be None (continuous) or a number > 0 (s), got {value}")
            set_(self, "control_period", value)

    # -- description -------------------------------------------------------------------

    def _total_body(self) -> RigidBody:
        if (self.inertia is None) == (self.hub is None):
            raise ValidationError("inertia: give exactly one of inertia (total, wheels included) or hub "
                                  "(without the wheels, which then need mass properties)")
        if self.inertia is not None:
            return self.inertia if isinstance(self.inertia, RigidBody) else RigidBody(self.inertia)
        _check_type(self.hub, RigidBody, "hub")
        if self.hub.mass is None:
            raise ValidationError("hub: needs a mass to be combined with the wheels")
        return RigidBody.composite([self.hub] + [w.part() for w in self.wheels])

    def _laws(self) -> tuple:
        laws = () if self.controller is None else (
            tuple(self.controller) if isinstance(self.controller, (list, tuple)) else (self.controller,))
        kinds = (QuaternionPD, RateDamping, ConstantTorque, BDot, MomentumDumping)
        for i, law in enumerate(laws):
            if not isinstance(law, kinds):
                raise ValidationError(f"controller: must be one of {', '.join(k.__name__ for k in kinds)} "
                                      f"(or a sequence of them), got {type(law).__name__} at {i}")
        attitude_laws = [law for law in laws if isinstance(law, _ATTITUDE_LAWS)]
        if len(attitude_laws) > 1 or sum(isinstance(x, BDot) for x in laws) > 1 \
                or sum(isinstance(x, MomentumDumping) for x in laws) > 1:
            raise ValidationError("controller: at most one torque law (QuaternionPD, RateDamping or ConstantTorque), "
                                  "one BDot "
                                  "and one MomentumDumping")
        if attitude_laws and self.route == "none":
            raise ValidationError(f"controller: {type(attitude_laws[0]).__name__} needs an actuator "
                                  "(wheels, cmgs, thrusters or magnetorquers)")
        for law in laws:
            if isinstance(law, (BDot, MomentumDumping)) and (self.magnetorquers is None or self.magnetic_field is None):
                raise ValidationError(f"controller: {type(law).__name__} needs magnetorquers and a magnetic_field")
            if isinstance(law, MomentumDumping) and not self.wheels:
                raise ValidationError("controller: MomentumDumping needs reaction wheels")
        if self.route == "magnetorquers" and attitude_laws and self.magnetic_field is None:
            raise ValidationError("controller: torque by magnetorquers needs a magnetic_field")
        return laws

    @property
    def route(self) -> str:
        """Which actuator receives the controller's torque: 'wheels', 'cmgs', 'thrusters', 'magnetorquers', 'none'."""
        for name, present in (("wheels", self.wheels), ("cmgs", self.cmgs), ("thrusters", self.thrusters),
                              ("magnetorquers", self.magnetorquers)):
            if present:
                return name
        return "none"

    @property
    def total_inertia(self) -> np.ndarray:
        """J: inertia of the whole spacecraft about its centre of mass, kg·m², body axes (wheels included)."""
        return self.body.inertia

    @functools.cached_property  # a frozen description: computed once, read-only
    def rate_inertia(self) -> np.ndarray:
        """J_ω = J − Σ I_s a aᵀ: the inertia the body rate answers to, kg·m² (wheel spins excluded)."""
        j = self.body.inertia.copy()
        for w in self.wheels:
            j -= w.inertia * np.outer(w.axis, w.axis)
        j.setflags(write=False)
        return j

    def layout(self) -> dict[str, slice]:
        """Slices of the state vector (see :mod:`tumble.spacecraft._kernel`)."""
        return _params.layout(len(self.wheels), 0 if self.cmgs is None else len(self.cmgs.momentum),
                              bool(self.thrusters))

    # -- the compiled model ------------------------------------------------------------

    def model(self, t0: float = 0.0) -> _params.SpacecraftModel:
        """The compiled parameters (:class:`tumble.spacecraft._params.SpacecraftModel`), control clock at ``t0``."""
        nw = len(self.wheels)
        axes = np.array([w.axis for w in self.wheels]).reshape(nw, 3)
        route = self.route
        allocation = np.linalg.pinv(axes.T) if route == "wheels" else np.zeros((nw, 3))
        wheels = np.array([[*w.axis, w.inertia, w.max_torque, w.max_speed, w.viscous, w.coulomb, w.coulomb_speed]
                           for w in self.wheels]).reshape(nw, 9)
        cmg = None
        if self.cmgs is not None:
            c = self.cmgs
            cmg = (np.array([c.robust_gain, c.robust_decay, c.momentum.max(), c.max_gimbal_rate]),
                   np.column_stack([c.gimbal_axes, c.spin_axes, c.transverse_axes, c.momentum]))
        field = self.magnetic_field
        laws = {type(x): x for x in self.controller}
        return _params.pack(
            self.total_inertia, self.rate_inertia,
            np.array([self.control_period or 0.0, float(t0), float(_ROUTES.get(route, 0))]),
            wheels=np.column_stack([wheels, allocation]), cmg=cmg, thrusters=self._thruster_table(),
            max_dipole=None if self.magnetorquers is None else self.magnetorquers.max_dipole,
            orbit=None if self.orbit is None else self.orbit.elements(),
            field=field.params() if isinstance(field, DipoleField) else None,
            uniform_field=field if isinstance(field, np.ndarray) else None,
            gravity_gradient=self.gravity_gradient, pd=self._pd_parameters(laws, self.rate_inertia),
            bdot=laws[BDot].gain if BDot in laws else None,
            dumping=laws[MomentumDumping].gain if MomentumDumping in laws else None,
        )

    def _thruster_table(self):
        """``(pwpf (8,), table (n_t, 5))`` of :func:`tumble.spacecraft._params.pack`, or None."""
        if not self.thrusters:
            return None
        com = np.zeros(3) if self.body.com is None else self.body.com
        torques = np.array([th.torque(com) for th in self.thrusters])
        axis = np.argmax(np.abs(torques), axis=1)
        sign = np.sign(torques[np.arange(len(axis)), axis])
        scale = np.zeros(3)
        for k in range(3):
            groups = [torques[(axis == k) & (sign == s)].sum(axis=0)[k] for s in (1.0, -1.0)]
            if 0.0 in groups:
                raise ValidationError(f"thrusters: the PWPF modulators need thrusters of both signs about each "
                                      f"body axis; none turns the spacecraft {'+-'[groups.index(0.0)]}{'xyz'[k]}")
            scale[k] = 0.5 * (groups[0] - groups[1])
        p = self.pwpf
        table = np.column_stack([torques, axis.astype(float), sign])
        return np.array([p.gain, p.time_constant, p.on, p.off, p.min_on_time, *scale]), table

    def _pd_parameters(self, laws, jw):
        """The ``pd`` block of :func:`tumble.spacecraft._params.pack`: ``u = C(ω_c − ω) + g ω × H + u₀``."""
        identity, zero = np.array([1.0, 0.0, 0.0, 0.0]), np.zeros((3, 3))
        if QuaternionPD in laws:
            law = laws[QuaternionPD]
            k, c = law.gains(jw)
            p, target, rate, torque, gyro, bias = np.linalg.solve(c, k), law.target, law.max_rate, law.max_torque, \
                1.0, np.zeros(3)
        elif RateDamping in laws:
            law = laws[RateDamping]
            c, p, target, rate, torque, gyro, bias = jw / law.time_constant, zero, identity, math.inf, \
                law.max_torque, 1.0, np.zeros(3)
        elif ConstantTorque in laws:
            c, p, target, rate, torque, gyro, bias = zero, zero, identity, math.inf, math.inf, 0.0, \
                laws[ConstantTorque].torque
        else:
            return None
        return np.concatenate([c.ravel(), p.ravel(), target, [rate, torque, gyro], bias])


def _check_type(value, cls, name):
    if value is not None and not isinstance(value, cls):
        raise ValidationError(f"{name}: must be a {cls.__name__} or None, got {type(value).__name__}")


def _check_items(values, cls, name):
    for i, value in enumerate(values):
        if not isinstance(value, cls):
            raise ValidationError(f"{name}[{i}]: must be a {cls.__name__}, got {type(value).__name__}")


# ------------------------------------------------------------------------------------------
# simulate
# ------------------------------------------------------------------------------------------


def simulate(spacecraft: Spacecraft, omega0, *, t, q0=None, wheel_speeds0=None, gimbal_angles0=None,
             method: str = "rk4", dt: float | None = None, rtol: float = 1e-10, atol: float = 1e-12,
             max_steps: int = 10**9, progress: Callable[[int, int], None] | None = None) -> Trajectory:
    """Integrate the attitude, rates and actuator states of a spacecraft through the times ``t``.

    Parameters
    ----------
    spacecraft : Spacecraft
    omega0 : (3,) or (N, 3) hub rate relative to inertial, rad/s, body axes (N spacecraft at once)
    t : (n,) output times, s, increasing
    q0 : (4,) or (N, 4) attitude, body → inertial, scalar first (default identity; normalised)
    wheel_speeds0 : (n_w,) or (N, n_w) wheel speeds relative to the hub, rad/s (default 0)
    gimbal_angles0 : (n_g,) or (N, n_g) CMG gimbal angles, rad (default 0)
    method : ``"rk4"`` (fixed step ``dt``) or ``"dop853"`` (adaptive; continuous control only)

    With ``control_period`` set, the controller is sampled with a zero-order hold:
    ``method="rk4"`` and a ``dt`` that divides the period and every output interval.

    Returns
    -------
    Trajectory
        ``q``, ``omega`` and ``inertia`` (the total ``J``), with ``extras``: ``wheel_speed``,
        ``wheel_momentum``, ``wheel_torque`` (motor), ``wheel_saturated``, ``wheel_work``,
        ``gimbal_angle``, ``gimbal_rate``, ``singularity``, ``thruster_firing``, ``pwpf_filter``,
        ``torque_command``, ``dipole``, ``magnetic_field``, ``gravity_gradient_torque``,
        ``actuator_torque``, ``total_momentum_inertial`` and ``total_energy`` (kinetic, hub and wheels), as apply.
        A :class:`SaturationWarning` is issued when a wheel reached its speed limit.
    """
    if not isinstance(spacecraft, Spacecraft):
        raise ValidationError(f"spacecraft: must be a Spacecraft, got {type(spacecraft).__name__}")
    if method not in METHODS:
        raise ValidationError(f"method: must be one of {METHODS} for a spacecraft (their steps end with the "
                              f"update of the controller), got {method!r}")
    integrate.check_options(method, dt=dt, rtol=rtol, atol=atol, max_steps=max_steps)
    times = as_array(t, "t")
    if times.ndim != 1 or times.size < 1 or np.any(np.diff(times) <= 0):
        raise ValidationError("t: must be a 1-D array of increasing output times (s)")
    _check_sampling(spacecraft, times, method, dt)
    y0 = _initial_state(spacecraft, omega0, q0, wheel_speeds0, gimbal_angles0)
    model = spacecraft.model(float(times[0]))
    for y in y0:
        _kernel.initialise(model, float(times[0]), y)
    solution = integrate.solve(model, y0, times, method=method, dt=dt, rtol=rtol, atol=atol,
                                    max_steps=max_steps, progress=progress)
    states, stats = solution.states, solution.statistics()
    return _trajectory(spacecraft, model, times, states, method, stats, dt, rtol, atol)


def _check_sampling(sc: Spacecraft, times, method, dt):
    period = sc.control_period
    if period is None:
        return
    if method != "rk4":
        raise ValidationError(f"method: a sampled controller (control_period = {period} s) needs the fixed-step "
                              f"'rk4', whose steps land on the sample times; got {method!r}")
    ratio = period / dt
    if abs(ratio - round(ratio)) > _WHOLE * ratio:
        raise ValidationError(f"dt: must divide control_period = {period} s into whole steps, got dt = {dt} "
                              f"({ratio:.6g} steps)")
    steps = np.diff(times) / dt
    bad = np.abs(steps - np.round(steps)) > _WHOLE * np.maximum(steps, 1.0)
    if bad.any():
        k = int(np.argmax(bad))
        raise ValidationError(f"dt: must divide every output interval into whole steps so that the steps land "
                              f"on the sample times; t[{k + 1}] − t[{k}] = {times[k + 1] - times[k]} s is "
                              f"{steps[k]:.6g} steps of {dt} s")


def _batch(value, name, width, n):
    arr = as_array(value, name, tail=(width,))
    if arr.ndim > 2:
        raise ValidationError(f"{name}: must have shape ({width},) or (N, {width}), got {arr.shape}")
    if arr.ndim == 2 and n not in (None, arr.shape[0]) and arr.shape[0] != 1:
        raise ValidationError(f"{name}: batch size {arr.shape[0]} does not match {n}")
    return arr


def _initial_state(sc: Spacecraft, omega0, q0, wheel_speeds0, gimbal_angles0) -> np.ndarray:
    nw = len(sc.wheels)
    ng = 0 if sc.cmgs is None else len(sc.cmgs.momentum)
    omega0 = _batch(omega0, "omega0", 3, None)
    q0 = attitude.identity() if q0 is None else _batch(q0, "q0", 4, None)
    speeds = np.zeros(nw) if wheel_speeds0 is None else _batch(wheel_speeds0, "wheel_speeds0", nw, None)
    gimbals = np.zeros(ng) if gimbal_angles0 is None else _batch(gimbal_angles0, "gimbal_angles0", ng, None)
    sizes = {a.shape[0] for a in (omega0, q0, speeds, gimbals) if a.ndim == 2} - {1}
    if len(sizes) > 1:
        raise ValidationError(f"omega0: batch sizes of omega0, q0, wheel_speeds0, gimbal_angles0 differ: "
                              f"{sorted(sizes)}")
    n = sizes.pop() if sizes else 1
    if np.any(np.linalg.norm(q0, axis=-1) == 0.0):
        raise ValidationError("q0: must be a non-zero quaternion [w, x, y, z] (it is normalised here)")
    lay = sc.layout()
    y0 = np.zeros((n, lay["pwpf_start"].stop if "pwpf_start" in lay else lay["dipole_command"].stop))
    y0[:, lay["q"]] = attitude.normalize(np.broadcast_to(q0, (n, 4)))
    y0[:, lay["omega"]] = np.broadcast_to(omega0, (n, 3))
    if nw:
        axes = np.array([w.axis for w in sc.wheels])
        spin = np.array([w.inertia for w in sc.wheels])
        y0[:, lay["wheel_momentum"]] = spin * (y0[:, lay["omega"]] @ axes.T + np.broadcast_to(speeds, (n, nw)))
    y0[:, lay["gimbal_angle"]] = np.broadcast_to(gimbals, (n, ng))
    return y0


def _trajectory(sc, model, times, states, method, stats, dt, rtol, atol) -> Trajectory:
    lay = sc.layout()
    nw = len(sc.wheels)
    ng = 0 if sc.cmgs is None else len(sc.cmgs.momentum)
    n_t, n_b, n_y = states.shape
    aux_lay = _params.aux_layout(nw, ng)
    aux = np.empty((n_b, n_t, aux_lay["dipole_command"].stop))
    for b in range(n_b):
        _kernel.evaluate(model, times, np.ascontiguousarray(states[:, b]), aux[b])
    aux = aux.transpose(1, 0, 2)
    one = n_b == 1

    def pick(a):
        return a[:, 0] if one else a

    extras = {}

    def add(name, data, dims, units, description):
        extras[name] = Extra(data=pick(data), dims=dims, units=units, description=description)

    q, omega = states[..., lay["q"]], states[..., lay["omega"]]
    if nw:
        add("wheel_speed", aux[..., aux_lay["wheel_speed"]], ("wheel",), "rad/s", "wheel speed relative to the hub")
        add("wheel_momentum", states[..., lay["wheel_momentum"]], ("wheel",), "N m s",
            "absolute angular momentum of each wheel about its axis")
        add("wheel_torque", aux[..., aux_lay["wheel_torque"]], ("wheel",), "N m",
            "motor torque on each wheel (after the torque and speed limits)")
        saturated = aux[..., aux_lay["wheel_saturated"]]
        add("wheel_saturated", saturated, ("wheel",), "1", "1 where the wheel is at its speed limit")
        add("wheel_work", states[..., lay["work"]][..., 0], (), "J", "work done on the wheels by motors and bearings")
        if saturated.any():
            wheels = sorted(set(np.nonzero(saturated)[-1].tolist()))
            first = times[np.nonzero(saturated.reshape(n_t, -1).any(axis=1))[0][0]]
            warnings.warn(f"reaction wheel(s) {wheels} reached the speed limit (first at t = {first:g} s): the "
                          "commanded torque was not delivered; see extras['wheel_saturated']",
                          SaturationWarning, stacklevel=3)
    if ng:
        add("gimbal_angle", states[..., lay["gimbal_angle"]], ("gyro",), "rad", "CMG gimbal angles")
        add("gimbal_rate", aux[..., aux_lay["gimbal_rate"]], ("gyro",), "rad/s", "CMG gimbal rates")
        add("singularity", aux[..., aux_lay["singularity"]][..., 0], (), "1",
            "CMG singularity measure sqrt(det(A A^T))/h^3 (0 at a singular configuration)")
    if sc.thrusters:
        out = states[..., lay["pwpf_output"]]
        table = sc._thruster_table()[1]
        firing = out[..., table[:, 3].astype(int)] == table[:, 4]
        add("thruster_firing", firing.astype(float), ("thruster",), "1", "1 while the thruster fires")
        add("pwpf_filter", states[..., lay["pwpf_filter"]], ("xyz",), "1", "PWPF filter outputs of the axes")
    if any(isinstance(law, _ATTITUDE_LAWS) for law in sc.controller):
        add("torque_command", aux[..., aux_lay["torque_command"]], ("xyz",), "N m",
            "controller torque command, body axes (the held value with a control period)")
    if sc.magnetorquers is not None:
        add("dipole_command", aux[..., aux_lay["dipole_command"]], ("xyz",), "A m2",
            "controller dipole command before the magnetorquer limits, body axes")
        add("dipole", aux[..., aux_lay["dipole"]], ("xyz",), "A m2", "magnetorquer dipole (after limits), body axes")
    if sc.magnetic_field is not None:
        add("magnetic_field", aux[..., aux_lay["field_body"]], ("xyz",), "T", "magnetic field, body axes")
    if sc.gravity_gradient:
        add("gravity_gradient_torque", aux[..., aux_lay["gravity_gradient"]], ("xyz",), "N m",
            "gravity-gradient torque, body axes")
    add("actuator_torque", aux[..., aux_lay["actuator_torque"]], ("xyz",), "N m",
        "torque of all actuators on the hub, body axes (wheels, gyros, thrusters, magnetorquers)")
    momentum_body = omega @ sc.rate_inertia.T
    if nw:
        momentum_body = momentum_body + states[..., lay["wheel_momentum"]] @ np.array([w.axis for w in sc.wheels])
    if ng:
        c, d = sc.cmgs, states[..., lay["gimbal_angle"]]
        spins = (np.cos(d)[..., None] * c.spin_axes + np.sin(d)[..., None] * c.transverse_axes)
        momentum_body = momentum_body + np.einsum("...i,...ij->...j", c.momentum * np.ones_like(d), spins)
    add("total_momentum_inertial", attitude.rotate(q, momentum_body), ("xyz",), "N m s",
        "total angular momentum (hub, wheels, gyro rotors), inertial axes")
    energy = 0.5 * np.einsum("...i,ij,...j->...", omega, sc.rate_inertia, omega)
    if nw:
        spin = np.array([w.inertia for w in sc.wheels])
        energy = energy + 0.5 * np.sum(states[..., lay["wheel_momentum"]] ** 2 / spin, axis=-1)
    add("total_energy", energy, (), "J",
        "kinetic energy of hub and wheels (gyro rotors' constant spin energy excluded)")
    info = {"n_steps": stats["n_steps"], "n_rhs": stats["n_rhs"]}
    if dt is not None and method == "rk4":
        info["dt"] = float(dt)
    else:
        info.update(rtol=float(rtol), atol=float(atol), n_rejected=stats["n_rejected"])
    if sc.control_period is not None:
        info["control_period"] = sc.control_period
    return Trajectory(t=times, q=pick(q), omega=pick(omega), inertia=sc.total_inertia, method=method,
                      info=info, extras=extras)
