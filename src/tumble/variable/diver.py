"""Twisting somersaults: a :class:`~tumble.variable.human.Human` in flight, and how to count its turns.

In the air (no torque about the centre of mass, air resistance neglected) a
diver's angular momentum ``L`` is fixed in space. The motion is described by
the orientation angles of M. R. Yeadon, "The simulation of aerial movement —
I. The determination of orientation angles from film data", J. Biomech.
23(1) (1990) 59–66, taken relative to a frame F fixed in space whose first
axis is ``L̂``::

    R_FB = R_x(φ) R_y(θ) R_z(ψ)          (intrinsic x–y–z; B: x right, y forward, z head)

with ``F_x = ±L̂``, the sign making it the trunk's right-pointing axis at the
start (so a backward somersault has ``φ̇ > 0`` and a forward one ``φ̇ < 0``).
``φ`` is the **somersault** angle (the azimuth of the long axis about ``L``),
``θ`` the **tilt** (``sin θ = F_x·ẑ_B``: the angle between the long axis and the
plane perpendicular to ``L``) and ``ψ`` the **twist** about the long axis.
Somersaults and twists are counted as the unwrapped changes
``Δφ/2π`` and ``Δψ/2π``. F's third axis is the trunk's long axis at the start,
less its component along ``L̂``.

For a rigid axisymmetric body (``I_x = I_y = I_s`` transverse, ``I_z = I_l``
long) at constant tilt, the somersault rate is ``φ̇ = |L|/I_s`` and the twist
rate ``ψ̇ = ω_z − φ̇ sin θ = |L| sin θ (1/I_l − 1/I_s)``, so exactly::

    twists per somersault = ψ̇/φ̇ = sin θ (I_s/I_l − 1)

the rule of thumb of the twisting-somersault literature (e.g. C. Frohlich,
"Do springboard divers violate angular momentum conservation?", Am. J. Phys.
47(7) (1979) 583–592; M. R. Yeadon, "The biomechanics of twisting
somersaults. Part I: rigid body motions", J. Sports Sci. 11 (1993) 187–198),
derived above for the axisymmetric body. For a real body
``I_x ≠ I_y`` and it holds only approximately (``docs/diver.md``).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, NamedTuple, cast

import numpy as np
from numpy.typing import ArrayLike

from tumble import analytic, attitude, simulate
from tumble._validate import ValidationError, as_array
from tumble.rigid_body import RigidBody
from tumble.trajectory import Trajectory
from tumble.variable.body import angular_velocity
from tumble.variable.human import Human, Motion

__all__ = ["Dive", "OrientationAngles", "dive_513xd", "orientation_angles", "simulate_dive", "twist_rule",
           "twist_rule_sweep", "twisting_somersault"]


class OrientationAngles(NamedTuple):
    """Yeadon's somersault ``φ``, tilt ``θ`` and twist ``ψ`` (n,), rad; ``φ`` and ``ψ`` unwrapped."""

    somersault: np.ndarray
    tilt: np.ndarray
    twist: np.ndarray

    @property
    def somersaults(self) -> float:
        """Number of somersaults turned (signed, + backward): ``(φ[-1] − φ[0]) / 2π``."""
        return float((self.somersault[-1] - self.somersault[0]) / (2.0 * np.pi))

    @property
    def twists(self) -> float:
        """Number of twists turned (signed, + about the head axis ẑ_B): ``(ψ[-1] − ψ[0]) / 2π``."""
        return float((self.twist[-1] - self.twist[0]) / (2.0 * np.pi))


def orientation_angles(q: ArrayLike, momentum_inertial: ArrayLike) -> OrientationAngles:
    """Somersault, tilt and twist of the attitudes ``q`` (n, 4) (B → inertial) about ``L`` (3,), any units.

    See the module docstring for the definitions.
    """
    q = as_array(q, "q", tail=(4,))
    if q.ndim != 2:
        raise ValidationError(f"q: must have shape (n, 4), got {q.shape}")
    axis = as_array(momentum_inertial, "momentum_inertial", tail=(3,))
    norm = np.linalg.norm(axis)
    if axis.shape != (3,) or norm == 0.0:
        raise ValidationError("momentum_inertial: must be one non-zero vector (3,)")
    e1 = axis / norm
    if e1 @ attitude.rotate(q[0], [1.0, 0.0, 0.0]) < 0.0:   # somersault axis along the trunk's x at the start
        e1 = -e1
    head = attitude.rotate(q[0], [0.0, 0.0, 1.0])
    e3 = head - (head @ e1) * e1
    if np.linalg.norm(e3) < 1e-9:   # the long axis along L: take the chest axis to fix the azimuth
        chest = attitude.rotate(q[0], [0.0, 1.0, 0.0])
        e3 = np.cross(e1, chest - (chest @ e1) * e1)
    e3 /= np.linalg.norm(e3)
    frame = attitude.from_matrix(np.column_stack([e1, np.cross(e3, e1), e3]))
    angles = attitude.to_euler(attitude.multiply(attitude.conjugate(frame), q), "XYZ")
    return OrientationAngles(np.unwrap(angles[:, 0]), angles[:, 1], np.unwrap(angles[:, 2]))


def twist_rule(tilt: float | np.ndarray, somersault_inertia: float | np.ndarray,
               long_inertia: float | np.ndarray) -> float | np.ndarray:
    """Twists per somersault of the rule of thumb, ``sin θ (I_s/I_l − 1)`` (exact for an axisymmetric body)."""
    return np.sin(tilt) * (somersault_inertia / long_inertia - 1.0)


# -- a diver in flight --------------------------------------------------------------------


class Dive(NamedTuple):
    """A simulated flight: the trajectory of a :class:`~tumble.variable.MovingHuman` (extras: joint angles, shape
    energy; energy: the whole kinetic energy), its angles and counts."""

    trajectory: Trajectory
    angles: OrientationAngles
    momentum: float

    @property
    def somersaults(self) -> float:
        return self.angles.somersaults

    @property
    def twists(self) -> float:
        return self.angles.twists

    @property
    def momentum_drift(self) -> float:
        """``max |(|L(t)| − |L(t₀)|)| / |L(t₀)|`` of ``L = I(t)ω + A(t)`` recomputed from the output."""
        L = np.linalg.norm(self.trajectory.extras["angular_momentum"].data, axis=-1)
        return float(np.abs(L / L[0] - 1.0).max())


def simulate_dive(human: Human, angles: Mapping | None, *, momentum: float, t: ArrayLike, tilt: float = 0.0,
                  method: str = "dop853", sample_dt: float = 2e-3, **solver: Any) -> Dive:
    """The flight of ``human`` moving its joints through ``angles``, torque-free.

    The angular momentum ``L_N = (momentum, 0, 0)`` (kg·m²/s; inertial x, the
    initial somersault axis); at ``t[0]`` the trunk is upright but tilted by
    ``tilt`` (rad) about its antero-posterior axis. ``I(t)``, ``A(t)`` are
    sampled every ``sample_dt`` (s) (:meth:`Human.moving`); the flight is
    ``tumble.simulate`` of that :class:`~tumble.variable.MovingHuman` with
    ``method`` and the ``solver`` options it reads (``rtol``, ``atol`` for
    ``"dop853"``, default 1e-10 both; ``dt`` for a fixed step).
    """
    times = as_array(t, "t")
    body = human.moving(angles, t_span=(times[0], times[-1]), dt=sample_dt)
    q0 = attitude.from_rotvec([0.0, float(tilt), 0.0])
    momentum_inertial = np.array([float(momentum), 0.0, 0.0])
    momentum_body = attitude.rotate_inverse(q0, momentum_inertial)
    omega0 = angular_velocity(body.inertia(times[0]), body.shape_momentum(times[0]), momentum_body)
    if method == "dop853":
        solver = {"rtol": 1e-10, "atol": 1e-10, **solver}
    traj = simulate(body, omega0, q0=q0, t=times, method=method, **solver)
    q = cast(np.ndarray, traj.q)  # a moving human has an attitude
    return Dive(traj, orientation_angles(q, momentum_inertial), float(momentum))


def _both(prefix, motion):
    return {f"left_{prefix}": motion, f"right_{prefix}": motion}


# -- the experiments of docs/diver.md -----------------------------------------------------------------

#: Angular momentum of experiments (a) and (b), kg·m²/s: about 0.8 somersault/s in a layout
#: with the arms overhead (I_x = 15.8 kg·m²).
MOMENTUM = 80.0


def twisting_somersault(human: Human | None = None, *, duration: float = 2.0, n: int = 801) -> Dive:
    """Experiment (a): a layout somersault, arms overhead, acquires twist when the left arm drops.

    From 0.2 s to 0.6 s the left shoulder adducts from 180° (overhead) to 0°
    (at the side); the right arm stays overhead.
    """
    human = Human.de_leva() if human is None else human
    angles = {"left_shoulder_abduction": Motion(np.pi, [(0.2, 0.6, 0.0)]), "right_shoulder_abduction": np.pi}
    return simulate_dive(human, angles, momentum=MOMENTUM, t=np.linspace(0.0, duration, n))


def twist_rule_sweep(tilts: ArrayLike, human: Human | None = None, *, posture: Mapping | None = None,
                     duration: float = 20.0, n: int = 4001) -> dict:
    """Experiment (b): twists per somersault of a rigid posture against :func:`twist_rule`.

    For each initial tilt (rad) the rigid body of ``posture`` (default: layout,
    arms at the sides) is simulated with :func:`tumble.simulate` (dop853,
    rtol = atol = 1e-11) with ``L`` along inertial x, over the whole number of
    polhode periods (:func:`tumble.analytic.polhode_period`) that fits in
    ``duration`` s (at least one), with ``n`` output times. Over whole periods
    the measured ratio ``Δψ/Δφ`` is the long-run twists per somersault and the
    trapezoidal mean of the tilt is its exact mean (a periodic function).
    Returns a dict of arrays: ``tilt`` (initial), ``mean_tilt`` (rad),
    ``simulated``, ``rule`` (:func:`twist_rule` at the initial tilt, with
    ``I_s = I_x``), ``rule_mean_tilt`` (at the mean tilt), ``moments``
    ``I_x, I_y, I_z``, and ``axisymmetric``: the simulated ratio of the body
    ``diag(I_s, I_s, I_l)``, for which the rule is exact.
    """
    human = Human.de_leva() if human is None else human
    tilts = np.atleast_1d(as_array(tilts, "tilts"))
    inertia = human.inertia(posture)
    i_s, i_l = inertia[0, 0], inertia[2, 2]
    out = {"tilt": tilts, "rule": twist_rule(tilts, i_s, i_l), "moments": np.diag(inertia).copy()}
    out["simulated"], out["mean_tilt"] = _ratios(inertia, tilts, duration, n)
    out["rule_mean_tilt"] = twist_rule(out["mean_tilt"], i_s, i_l)
    out["axisymmetric"] = _ratios(np.diag([i_s, i_s, i_l]), tilts, duration, n)[0]
    return out


def _ratios(inertia, tilts, duration, n):
    """Measured ``Δψ/Δφ`` and mean tilt (rad) of the rigid body ``inertia`` started at each tilt with ``L``
    along inertial x, over whole polhode periods."""
    momentum = np.array([MOMENTUM, 0.0, 0.0])
    body = RigidBody(inertia)
    ratios, means = [], []
    for tilt in tilts:   # one body per run: the compiled single-body path, no parallel start-up
        q0 = attitude.from_rotvec([0.0, tilt, 0.0])
        omega0 = np.linalg.solve(inertia, attitude.rotate_inverse(q0, momentum))
        period = analytic.polhode_period(body, omega0)
        t = np.linspace(0.0, max(1, int(duration / period)) * period, n)
        traj = simulate(body, omega0, q0=q0, t=t, method="dop853", rtol=1e-11, atol=1e-11)
        a = orientation_angles(traj.q, momentum)
        ratios.append(a.twists / a.somersaults)
        means.append(np.mean(a.tilt[:-1]))   # trapezoid over whole periods of a periodic function
    return np.array(ratios), np.array(means)


def dive_513xd(human: Human | None = None, *, n: int = 681) -> Dive:
    """Experiment (c): a forward dive with 1½ somersaults and 2½ twists, in the spirit of 513XD.

    After W. Tong and H. R. Dullin, "A new twisting somersault: 513XD",
    J. Nonlinear Sci. 27 (2017) 1809–1830 (their dive has 1½ somersaults and 5
    twists; this arm schedule is ours, not theirs): take-off in a layout with
    the arms overhead, somersaulting forward; the left arm drops to the side
    (0.05–0.30 s), which tilts the body and starts the twist, and the right
    arm follows (0.30–0.50 s), so that the diver twists fast with both arms
    in; the left arm (1.15–1.40 s), then the right (1.30–1.55 s) rise again,
    which removes most of the tilt and stops the twist for a head-first entry
    with the arms overhead. The raising time and the angular momentum were
    chosen by a grid search for the smallest tilt after the arms are up with
    1½ somersaults in the flight time.
    """
    human = Human.de_leva() if human is None else human
    up, raise_left = np.pi, 1.15
    angles = {
        "left_shoulder_abduction": Motion(up, [(0.05, 0.30, 0.0), (raise_left, raise_left + 0.25, up)]),
        "right_shoulder_abduction": Motion(up, [(0.30, 0.50, 0.0), (raise_left + 0.15, raise_left + 0.40, up)]),
    }
    return simulate_dive(human, angles, momentum=-DIVE_MOMENTUM, t=np.linspace(0.0, DIVE_DURATION, n))


#: Flight time (s) and angular momentum (kg·m²/s, forward) of :func:`dive_513xd`.
DIVE_DURATION = 1.7
DIVE_MOMENTUM = 74.0
