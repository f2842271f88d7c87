"""Passive attitude stability: the major-axis rule for spinners and the gravity-gradient stability regions.

**Major-axis rule.** A rigid body spins steadily about any principal axis;
the spin is (Lyapunov) stable about the axes of largest and smallest moment
and unstable about the intermediate one (:mod:`tumble.analytic`). With
internal energy dissipation (flexible parts, fuel, a nutation damper) the
body loses kinetic energy ``T = L²/(2 I_spin)`` at fixed ``|L|``, so it drifts
towards the state of least energy for its momentum: a spin about the axis of
*largest* moment. Only a major-axis spin is stable (Hughes, *Spacecraft
Attitude Dynamics*, ch. 5; Wie, *Space Vehicle Dynamics and Control*,
ch. 6; Explorer 1, 1958, is the classic failure: see
:mod:`tumble.spacecraft.damper`).

**Gravity gradient.** A body on a circular orbit (rate ``n``) with principal
axes 1 (roll, along-track), 2 (pitch, minus the orbit normal) and 3 (yaw,
nadir) held on the LVLH axes is in equilibrium. With the inertia ratios
(Hughes, ch. 9; Wie, ch. 6)::

    k_R = (I₂ − I₃)/I₁        k_Y = (I₂ − I₁)/I₃

the linearised motion is a pitch oscillation ``θ̈ + 3n² (I₁ − I₃)/I₂ θ = 0``
and a coupled roll/yaw pair with characteristic equation::

    s⁴ + (1 + 3k_R + k_R k_Y) n² s² + 4 k_R k_Y n⁴ = 0

It is stable (all roots imaginary) where

    pitch:     k_R > k_Y                       (I₁ > I₃)
    roll/yaw:  k_R k_Y > 0  and  1 + 3k_R + k_R k_Y > 4 √(k_R k_Y)

The part of the stable set with ``k_R, k_Y > 0`` (``I₂ > I₁ > I₃``: the
largest moment about the orbit normal, the smallest about the vertical) is
the *Lagrange region*, stable even with energy dissipation (the equilibrium is
a minimum of the Hamiltonian). The part with ``k_R, k_Y < 0`` is the
*DeBra–Delp region* (DeBra & Delp, J. Astronaut. Sci. 8, 1961): gyroscopic
stability only, lost to dissipation.
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tumble import attitude
from tumble._validate import ValidationError, as_array
from tumble.analytic import classify_axes
from tumble.body import RigidBody
from tumble.simulate import simulate
from tumble.spacecraft import damper as _damper
from tumble.spacecraft.model import Spacecraft
from tumble.spacecraft.orbit import Orbit, attitude_in_lvlh, lvlh_quaternion
from tumble.torques import GravityGradient
from tumble._files import write_atomic
from tumble.trajectory import Trajectory

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = [
    "EXPLORER1",
    "Explorer1",
    "GravityGradientStability",
    "SpinStability",
    "demo_explorer1",
    "demo_gravity_gradient",
    "explorer1_figure",
    "gravity_gradient_libration",
    "gravity_gradient_stability",
    "gravity_gradient_stability_figure",
    "spin_stability",
]

# An axis is principal when |I â − (â·Iâ) â| <= _PRINCIPAL_RTOL · max moment,
# and its moment counts as the largest when within _PRINCIPAL_RTOL of it
# (RigidBody.symmetry's tolerance for equal moments).
_PRINCIPAL_RTOL = 1e-9
LAGRANGE, DEBRA_DELP, UNSTABLE = "Lagrange", "DeBra-Delp", "unstable"


class SpinStability(NamedTuple):
    """Stability of a steady spin about a principal axis.

    moment           : moment of inertia about the spin axis, kg·m²
    role             : ``"major"``, ``"intermediate"`` or ``"minor"`` (``"major"`` when
                       the moment equals the largest, ``"minor"`` when it equals the
                       smallest and not the largest)
    rigid            : ``"stable"``, ``"unstable"`` or ``"neutral"``, the rigid body
                       (:func:`tumble.analytic.classify_axes`)
    with_dissipation : True only for a major-axis spin (the major-axis rule)
    """

    moment: float
    role: str
    rigid: str
    with_dissipation: bool


def _as_body(body) -> RigidBody:
    if isinstance(body, RigidBody):
        return body
    return RigidBody(as_array(body, "body", tail=(3, 3)), check_triangle=False)


def spin_stability(body: RigidBody | ArrayLike, axis: ArrayLike) -> SpinStability:
    """Is a spin about ``axis`` (body axes, any length) stable, as a rigid body and with energy dissipation?

    ``body``: a :class:`~tumble.RigidBody` or a (3, 3) inertia tensor (kg·m²,
    body axes). The axis must be a principal axis (a spin about any other axis
    is not steady): ValidationError otherwise.
    """
    body = _as_body(body)
    a = as_array(axis, "axis", tail=(3,))
    if a.ndim != 1 or not np.linalg.norm(a) > 0.0:
        raise ValidationError(f"axis: must be a non-zero vector of shape (3,), got {a.tolist()}")
    a = a / np.linalg.norm(a)
    ia = body.inertia @ a
    moment = float(a @ ia)
    largest = float(body.moments[-1])
    if np.linalg.norm(ia - moment * a) > _PRINCIPAL_RTOL * largest:
        raise ValidationError(f"axis: must be a principal axis of the body (I a is not parallel to a for "
                              f"a = {a.tolist()}); a spin about another axis is not steady")
    k = int(np.argmin(np.abs(body.moments - moment)))
    if largest - moment <= _PRINCIPAL_RTOL * largest:
        role = "major"
    elif moment - body.moments[0] <= _PRINCIPAL_RTOL * largest:
        role = "minor"
    else:
        role = "intermediate"
    return SpinStability(moment=moment, role=role, rigid=classify_axes(body)[k], with_dissipation=role == "major")


class GravityGradientStability(NamedTuple):
    """Linear stability of the LVLH-held attitude of a body on a circular orbit.

    k_roll, k_yaw          : k_R = (I₂ − I₃)/I₁, k_Y = (I₂ − I₁)/I₃
    pitch_stable           : k_R > k_Y (I₁ > I₃)
    roll_yaw_stable        : k_R k_Y > 0 and 1 + 3k_R + k_R k_Y > 4 √(k_R k_Y)
    stable                 : both
    region                 : ``"Lagrange"`` (stable, k_R, k_Y > 0), ``"DeBra-Delp"``
                             (stable, k_R, k_Y < 0) or ``"unstable"``
    pitch_frequency        : ω_p/n = √(3 (I₁ − I₃)/I₂), nan when pitch is unstable
    roll_yaw_frequencies   : (2,) ω/n of the roll/yaw modes, descending, nan when unstable
    """

    k_roll: float
    k_yaw: float
    pitch_stable: bool
    roll_yaw_stable: bool
    stable: bool
    region: str
    pitch_frequency: float
    roll_yaw_frequencies: np.ndarray


def _roll_yaw_conditions(kr, ky):
    """The roll/yaw stability conditions on arrays of (k_R, k_Y): (b, c, stable) of s⁴ + b s² + c."""
    b = 1.0 + 3.0 * kr + kr * ky
    c = 4.0 * kr * ky
    with np.errstate(invalid="ignore"):
        stable = (c > 0.0) & (b > np.sqrt(np.maximum(c, 0.0)) * 2.0)  # b > 2√c = 4√(k_R k_Y)
    return b, c, stable


def _moments(inertia) -> np.ndarray:
    if isinstance(inertia, RigidBody):
        inertia = inertia.inertia
    i = as_array(inertia, "inertia")
    if i.shape == (3,):
        i = np.diag(i)
    if i.shape != (3, 3):
        raise ValidationError(f"inertia: must be the moments (3,) or a diagonal tensor (3, 3), got shape {i.shape}")
    off = np.abs(i - np.diag(np.diag(i))).max()
    if off > _PRINCIPAL_RTOL * np.abs(i).max():
        raise ValidationError("inertia: the body axes must be principal axes (roll, pitch, yaw) for the "
                              f"LVLH attitude to be an equilibrium; largest off-diagonal term {off:.3g} kg m^2")
    m = np.diag(i).copy()
    if not np.all(m > 0.0):
        raise ValidationError(f"inertia: moments must be > 0, got {m.tolist()}")
    return m


def gravity_gradient_stability(inertia: RigidBody | ArrayLike) -> GravityGradientStability:
    """Classify the gravity-gradient stability of a body held on the LVLH axes of a circular orbit.

    ``inertia``: the moments ``(I₁, I₂, I₃)`` about roll (along-track), pitch
    (minus the orbit normal) and yaw (nadir), kg·m², as a (3,) array, a diagonal (3, 3)
    tensor or a :class:`~tumble.RigidBody` whose body axes are those.
    Frequencies in units of the orbit rate ``n`` (module docstring).
    """
    i1, i2, i3 = _moments(inertia)
    kr, ky = (i2 - i3) / i1, (i2 - i1) / i3
    pitch = bool(kr > ky)
    b, c, roll_yaw = _roll_yaw_conditions(np.float64(kr), np.float64(ky))
    roll_yaw = bool(roll_yaw)
    if pitch and roll_yaw:
        region = LAGRANGE if kr > 0.0 else DEBRA_DELP
    else:
        region = UNSTABLE
    pitch_frequency = math.sqrt(3.0 * (i1 - i3) / i2) if pitch else math.nan
    if roll_yaw:
        root = math.sqrt(b * b - 4.0 * c)
        freqs = np.sqrt([(b + root) / 2.0, (b - root) / 2.0])
    else:
        freqs = np.full(2, np.nan)
    return GravityGradientStability(k_roll=float(kr), k_yaw=float(ky), pitch_stable=pitch,
                                    roll_yaw_stable=roll_yaw, stable=pitch and roll_yaw, region=region,
                                    pitch_frequency=pitch_frequency, roll_yaw_frequencies=freqs)


def gravity_gradient_stability_figure(spacecraft_inertia: RigidBody | ArrayLike | None = None, *,
                                      label: str = "spacecraft", resolution: int = 801) -> Figure:
    """The gravity-gradient stability regions in the (k_R, k_Y) plane, with a spacecraft placed on it.

    Shaded: the Lagrange region (stable, also with dissipation) and the
    DeBra–Delp region (gyroscopically stable only); hatched lines: the pitch
    boundary ``k_R = k_Y`` and the roll/yaw boundary
    ``1 + 3k_R + k_R k_Y = 4 √(k_R k_Y)``. Physical bodies lie in
    ``|k_R|, |k_Y| ≤ 1`` (triangle inequality). ``spacecraft_inertia`` (as in
    :func:`gravity_gradient_stability`) is marked with its region.
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.figure import Figure

    k = np.linspace(-1.0, 1.0, resolution)
    kr, ky = np.meshgrid(k, k)  # k_R along x, k_Y along y
    _, _, roll_yaw = _roll_yaw_conditions(kr, ky)
    stable = roll_yaw & (kr > ky)
    region = np.where(stable & (kr > 0), 2, np.where(stable & (kr < 0), 1, 0))

    fig = Figure(figsize=(6.4, 6.0), layout="constrained")
    ax = fig.add_subplot()
    colours = ListedColormap(["white", "tab:orange", "tab:green"])
    ax.pcolormesh(kr, ky, region, cmap=colours, vmin=0, vmax=2, shading="auto", alpha=0.45, rasterized=True)
    ax.plot([-1, 1], [-1, 1], color="k", lw=1.0, label="pitch boundary $k_R = k_Y$")
    b, c, _ = _roll_yaw_conditions(kr, ky)
    with np.errstate(invalid="ignore"):
        margin = np.where(kr * ky > 0, b - 2.0 * np.sqrt(np.abs(c)), np.nan)
    ax.contour(kr, ky, margin, levels=[0.0], colors="tab:red", linewidths=1.0)
    ax.plot([], [], color="tab:red", lw=1.0, label=r"roll/yaw boundary $1 + 3k_R + k_Rk_Y = 4\sqrt{k_Rk_Y}$")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.axvline(0.0, color="0.5", lw=0.6)
    ax.text(0.55, 0.18, "Lagrange\n(stable)", ha="center", fontsize=10)
    ax.annotate("DeBra–Delp\n(gyroscopic)", xy=(-0.06, -0.55), xytext=(-0.6, -0.75), ha="center", fontsize=9,
                arrowprops={"arrowstyle": "->", "lw": 0.8})
    ax.text(-0.55, 0.5, "unstable", ha="center", color="0.3")
    if spacecraft_inertia is not None:
        s = gravity_gradient_stability(spacecraft_inertia)
        ax.plot(s.k_roll, s.k_yaw, "k*", ms=14, label=f"{label}: {s.region}")
    ax.set_xlim(-1, 1)
    ax.set_ylim(-1, 1)
    ax.set_aspect("equal")
    ax.set_xlabel(r"$k_R = (I_2 - I_3)/I_1$  (1 roll, 2 pitch, 3 yaw)")
    ax.set_ylabel(r"$k_Y = (I_2 - I_1)/I_3$")
    ax.set_title("Gravity-gradient stability of the LVLH attitude (circular orbit)")
    ax.legend(loc="upper left", fontsize=8)
    return fig


# --- a gravity-gradient-stabilised satellite ----------------------------------------------------------

#: Moments (roll, pitch, yaw), kg·m², of a small satellite with a nadir boom (k_R = 0.958, k_Y = 0.5: Lagrange).
GG_SATELLITE = (120.0, 125.0, 10.0)
#: Its orbit: circular, 700 km, sun-synchronous inclination.
GG_ORBIT = Orbit.circular(700e3, inclination=math.radians(98.19))


def gravity_gradient_libration(moments: ArrayLike, orbit: Orbit, angles: ArrayLike, *, orbits: float = 10.0,
                               samples_per_orbit: int = 200) -> Trajectory:
    """Simulate a body released at roll/pitch/yaw ``angles`` (rad) from the LVLH attitude, at rest in LVLH.

    ``moments``: (roll, pitch, yaw) principal moments, kg·m² (body axes =
    principal axes); gravity-gradient torque of ``orbit``; ``dop853`` at
    rtol 1e-11. The body rate at release is the LVLH frame's, ``(0, −n, 0)``
    in LVLH axes. Read the angles back with
    :func:`tumble.spacecraft.orbit.attitude_in_lvlh`.
    """
    roll, pitch, yaw = as_array(angles, "angles", tail=(3,))
    q_lvlh_b = attitude.from_euler("ZYX", [yaw, pitch, roll])
    omega0 = attitude.rotate_inverse(q_lvlh_b, [0.0, -orbit.mean_motion, 0.0])
    q0 = attitude.multiply(lvlh_quaternion(*orbit.state(0.0)), q_lvlh_b)
    inertia = np.diag(_moments(moments))
    t = np.linspace(0.0, orbits * orbit.period, int(math.ceil(orbits * samples_per_orbit)) + 1)
    return simulate(inertia, omega0, q0=q0, t=t, rtol=1e-11, atol=1e-14, torque=GravityGradient(orbit, inertia))


def _libration_figure(traj: Trajectory, orbit: Orbit, moments) -> Figure:
    from matplotlib.figure import Figure

    rel = attitude_in_lvlh(traj, orbit)
    s = gravity_gradient_stability(moments)
    fig = Figure(figsize=(7.5, 4.2), layout="constrained")
    ax = fig.add_subplot()
    for name, values in (("roll", rel.roll), ("pitch", rel.pitch), ("yaw", rel.yaw)):
        ax.plot(traj.t / orbit.period, np.degrees(values), lw=1.0, label=name)
    ax.set_xlabel("time (orbits)")
    ax.set_ylabel("angle from LVLH (deg)")
    freqs = ", ".join(f"{f:.3f}" for f in s.roll_yaw_frequencies)
    ax.set_title(f"Gravity-gradient libration, moments {tuple(moments)} kg m$^2$ ({s.region} region)\n"
                 f"linear theory: pitch {s.pitch_frequency:.3f} n, roll/yaw {freqs} n", fontsize=10)
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(alpha=0.3)
    return fig


def _check_dir(out_dir) -> None:
    if not os.path.isdir(out_dir):
        raise ValidationError(f"out_dir: {os.fspath(out_dir)!r} is not an existing directory")


def _save_png(fig, path) -> None:
    write_atomic(path, lambda tmp_path: fig.savefig(tmp_path, format="png", dpi=120))


def demo_gravity_gradient(out_dir: str | os.PathLike[str]) -> dict:
    """A boom satellite (:data:`GG_SATELLITE`) released 5° pitch, 3° roll, 2° yaw off LVLH, 10 orbits.

    Writes ``gravity_gradient.nc`` (the trajectory), ``gravity_gradient.png``
    (roll, pitch, yaw from LVLH against orbits),
    ``passive_gg_regions.png`` (the stability regions with the satellite) and
    ``gravity_gradient.html`` (the offline viewer, :mod:`tumble.viewer`) in
    ``out_dir``, atomically. Returns the stability classification, the
    linear-theory frequencies (units of the orbit rate), the largest angle
    from LVLH (deg) and the paths written.
    """
    _check_dir(out_dir)
    angles = np.radians([3.0, 5.0, 2.0])
    traj = gravity_gradient_libration(GG_SATELLITE, GG_ORBIT, angles)
    rel = attitude_in_lvlh(traj, GG_ORBIT)
    s = gravity_gradient_stability(GG_SATELLITE)
    paths = {key: os.path.join(out_dir, name) for key, name in
             (("nc", "gravity_gradient.nc"), ("png", "gravity_gradient.png"), ("regions", "passive_gg_regions.png"),
              ("html", "gravity_gradient.html"))}
    traj.save(paths["nc"])
    traj.to_html(paths["html"])
    _save_png(_libration_figure(traj, GG_ORBIT, GG_SATELLITE), paths["png"])
    _save_png(gravity_gradient_stability_figure(GG_SATELLITE, label="boom satellite"), paths["regions"])
    return {
        "region": s.region,
        "k_roll": s.k_roll,
        "k_yaw": s.k_yaw,
        "pitch_frequency": s.pitch_frequency,
        "roll_yaw_frequencies": s.roll_yaw_frequencies.tolist(),
        "orbit_period_s": GG_ORBIT.period,
        "max_angle_deg": float(np.degrees(np.max(np.abs([rel.roll, rel.pitch, rel.yaw])))),
        **paths,
    }


# --- Explorer 1 ------------------------------------------------------------------------------------------


class Explorer1(NamedTuple):
    """An Explorer-1-like spinner: a uniform cylinder spinning about its long (minor) axis z, with a damper.

    Explorer 1 (launched 31 January 1958): 13.97 kg, 2.03 m long, 0.152 m in
    diameter, spun at about 750 rpm about its long axis (NASA/JPL mission
    facts). Its energy sink was four flexible whip antennas; here it is a
    spherical damper (:mod:`tumble.spacecraft.damper`) sized so that the
    flat spin comes within the first orbit (114.8 min), as observed.
    """

    mass: float = 13.97
    length: float = 2.03
    radius: float = 0.0762
    spin: float = 750.0 * 2.0 * math.pi / 60.0
    nutation0: float = math.radians(0.5)
    damper_inertia: float = 3e-4
    duration: float = 6900.0

    def hub(self) -> RigidBody:
        """The cylinder (without the damper sphere), long axis z."""
        return RigidBody.cylinder(mass=self.mass, radius=self.radius, length=self.length, axis="z")

    def locked_moments(self) -> tuple[float, float]:
        """``(I_s, I_t)``: axial and transverse moments with the damper sphere locked to the hub, kg·m²."""
        hub = self.hub()
        return hub.inertia[2, 2] + self.damper_inertia, hub.inertia[0, 0] + self.damper_inertia

    def damper(self) -> _damper.SphericalDamper:
        """The damper tuned for the initial spin (:meth:`SphericalDamper.tuned`)."""
        return _damper.SphericalDamper.tuned(self.damper_inertia, *self.locked_moments(), self.spin)

    def spacecraft(self) -> Spacecraft:
        """The hub with its damper, a model of :func:`tumble.simulate`."""
        return Spacecraft(hub=self.hub(), damper=self.damper())

    def omega0(self) -> np.ndarray:
        """Body rate (rad/s) with spin ``spin`` and nutation angle ``nutation0`` between L and the z axis."""
        i_s, i_t = self.locked_moments()
        return np.array([i_s * self.spin * math.tan(self.nutation0) / i_t, 0.0, self.spin])


#: The demo's Explorer 1.
EXPLORER1 = Explorer1()


def explorer1_figure(traj: Trajectory, spacecraft: Explorer1 = EXPLORER1) -> Figure:
    """(a) nutation angle (deg, log scale) with the energy-sink estimate; (b) spin about the long axis and
    transverse rate; (c) kinetic energy of hub + damper and the flat-spin floor ``L²/(2 I_t)``."""
    from matplotlib.figure import Figure

    dm = spacecraft.damper()
    i_s, i_t = spacecraft.locked_moments()
    tau = _damper.energy_sink_time_constant(i_s, i_t, dm, spacecraft.spin)
    assert traj.omega is not None  # the hub's rate
    theta = _damper.nutation_angle(traj, [0.0, 0.0, 1.0])
    energy = traj.energy
    momentum = np.linalg.norm(traj.momentum_body[0])
    minutes = traj.t / 60.0

    fig = Figure(figsize=(7.5, 8.0), layout="constrained")
    ax = fig.subplots(3, 1, sharex=True)
    ax[0].semilogy(minutes, np.degrees(theta), lw=1.2, label="simulated")
    estimate = spacecraft.nutation0 * np.exp(traj.t / tau)
    early = estimate < 0.5
    ax[0].semilogy(minutes[early], np.degrees(estimate[early]), "k--", lw=1.0,
                   label=f"energy-sink estimate, τ = {tau:.0f} s")
    ax[0].axhline(90.0, color="0.5", lw=0.6)
    ax[0].set_ylabel("nutation angle (deg)")
    ax[0].legend(loc="lower right", fontsize=8)
    ax[1].semilogy(minutes, np.abs(traj.omega[:, 2]), lw=1.0, label=r"spin about the long axis $|\omega_z|$")
    ax[1].semilogy(minutes, np.hypot(traj.omega[:, 0], traj.omega[:, 1]), lw=1.0,
                   label=r"transverse rate $\sqrt{\omega_x^2 + \omega_y^2}$")
    ax[1].set_ylim(bottom=1e-4)
    ax[1].set_ylabel("rate (rad/s)")
    ax[1].legend(loc="center right", fontsize=8)
    ax[2].semilogy(minutes, energy, lw=1.2, label="kinetic energy (hub + damper)")
    ax[2].axhline(momentum**2 / (2.0 * i_t), color="k", ls="--", lw=1.0,
                  label=r"flat spin $L^2/(2I_t)$ (least energy for $|L|$)")
    ax[2].set_ylabel("energy (J)")
    ax[2].set_xlabel("time (min)")
    ax[2].legend(loc="upper right", fontsize=8)
    for a in ax:
        a.grid(alpha=0.3)
    fig.suptitle("Explorer 1: a spin about the minor axis decays into a flat spin", fontsize=11)
    return fig


def demo_explorer1(out_dir: str | os.PathLike[str], spacecraft: Explorer1 = EXPLORER1) -> dict:
    """Simulate the Explorer 1 flat spin and compare its nutation time constant with the energy-sink estimate.

    Integrates hub + damper (:meth:`Explorer1.spacecraft` through :func:`tumble.simulate`,
    dop853, rtol 1e-12) for ``spacecraft.duration`` s, writes
    ``explorer1.nc``, ``explorer1.png`` and ``explorer1.html`` (the offline viewer,
    :mod:`tumble.viewer`) in ``out_dir`` atomically, and
    returns: the time constant measured (fit of ln θ for θ between 2θ₀ and
    0.2 rad) and estimated (s), the final nutation angle (deg) and spin axis
    (unit ``L`` in body axes), the relative drift of ``|L|`` and of the
    inertial ``L``, the largest energy increase between samples (relative;
    ≤ 0 when the energy falls monotonically), and the paths.
    """
    _check_dir(out_dir)
    dm = spacecraft.damper()
    t = np.linspace(0.0, spacecraft.duration, int(round(spacecraft.duration * 2)) + 1)
    craft = spacecraft.spacecraft()
    traj = simulate(craft, spacecraft.omega0(), t=t, rtol=1e-12, atol=1e-12)
    theta = _damper.nutation_angle(traj, [0.0, 0.0, 1.0])
    i_s, i_t = spacecraft.locked_moments()
    momentum = traj.momentum_inertial
    size = np.linalg.norm(momentum, axis=-1)
    energy = traj.energy
    final_axis = traj.momentum_body[-1] / size[-1]
    paths = {name: os.path.join(out_dir, f"explorer1.{name}") for name in ("nc", "png", "html")}
    traj.save(paths["nc"])
    traj.to_html(paths["html"], model=craft)
    _save_png(explorer1_figure(traj, spacecraft), paths["png"])
    return {
        "time_constant_s": _damper.measured_time_constant(t, theta, window=(2 * spacecraft.nutation0, 0.2)),
        "time_constant_estimate_s": _damper.energy_sink_time_constant(i_s, i_t, dm, spacecraft.spin),
        "final_nutation_deg": float(np.degrees(theta[-1])),
        "final_spin_axis_body": final_axis.tolist(),
        "momentum_drift": float(np.max(np.abs(size / size[0] - 1.0))),
        "momentum_vector_drift": float(np.max(np.linalg.norm(momentum - momentum[0], axis=-1)) / size[0]),
        "max_energy_increase": float(np.max(np.diff(energy)) / energy[0]),
        "energy_initial_J": float(energy[0]),
        "energy_final_J": float(energy[-1]),
        **paths,
    }
