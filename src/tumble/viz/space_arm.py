"""Demonstration: a two-link arm on a free-floating hub swings through a commanded manoeuvre; the hub turns.

:func:`demo_space_arm` builds the space manipulator of :data:`HUB` and
:data:`ARM` (:func:`tumble.robot.space_manipulator`: the hub is the floating
base, no gravity, no external force), starts it at rest, and drives the two
joints along a quintic (minimum-jerk) path from 0 to :data:`TARGET` in
:data:`MANOEUVRE` s with a PD law on the tracking error,
``τ = K_p (q_ref − q) + K_d (q̇_ref − q̇)`` (N·m). The joint torques are
internal: the total linear and angular momentum stay zero, so the hub turns
and moves against the arm (Dubowsky & Papadopoulos 1993: the hub's rate is
``−H_b⁻¹ H_bm q̇``, the generalised Jacobian). The hub's net rotation after
the arm has stopped is not undone by bringing the arm back along another
path: it depends on the path (the system is non-holonomic), which is how a
free-floating robot reorients its base with its arm alone.

It writes ``space_arm.nc`` (the trajectory) and ``space_arm.png``: the hub's
rotation angle and the joint angles against their reference, and the total
momentum (the drift of an exact zero).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from tumble.rigid_body import RigidBody
from tumble.robot.chain import SerialChain
from tumble.robot.link import Link
from tumble.robot.space import space_manipulator
from tumble.robot.tree import RobotTree
from tumble.simulate import simulate
from tumble._files import write_atomic
from tumble.viz._output import out_directory

__all__ = ["demo_space_arm", "space_arm", "reference"]

#: The hub: a 100 kg box 1 × 1 × 0.8 m (inertia about its centre, kg m²).
HUB: dict[str, Any] = dict(mass=100.0, inertia=np.diag([13.67, 13.67, 16.67]))
#: The arm, mounted at MOUNT on the hub's +x face: two links turning about the hub's z axis, each with its
#: mass (kg), length (m, the next joint's offset), centre of mass along the link (m) and moment about z (kg m²).
ARM = (dict(mass=12.0, length=1.5, com=0.75, inertia=2.25), dict(mass=8.0, length=1.2, com=0.6, inertia=0.96))
MOUNT = (0.5, 0.0, 0.0)  # m, hub axes
TARGET = np.array([np.pi / 2, -np.pi / 2])  # rad: the joint angles at the end of the manoeuvre
MANOEUVRE, DURATION = 8.0, 10.0  # s
GAINS = (400.0, 120.0)  # K_p (N m / rad), K_d (N m s / rad)
_SAMPLES = 501
_TOLERANCE = 1e-11


def space_arm() -> RobotTree:
    """The hub and arm of the module's constants as one floating-base :class:`~tumble.robot.RobotTree`."""
    links = [Link(joint="revolute", axis=np.array((0.0, 0.0, 1.0)),
                  origin_position=np.array((0.0 if k == 0 else ARM[k - 1]["length"], 0.0, 0.0)),
                  mass=a["mass"], com=np.array((a["com"], 0.0, 0.0)),
                  inertia=np.diag([0.01, a["inertia"], a["inertia"]]),
                  name=("shoulder", "elbow")[k]) for k, a in enumerate(ARM)]
    hub = RigidBody(HUB["inertia"], mass=HUB["mass"])
    return space_manipulator(hub, SerialChain(links), mount_position=MOUNT, name="two-link arm on a free hub")


def reference(t: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """The commanded joint angles (rad) and rates (rad/s) at times ``t`` (s): a quintic from 0 to
    :data:`TARGET` over :data:`MANOEUVRE` s, zero rate and acceleration at both ends, then held."""
    u = np.clip(np.asarray(t, dtype=float) / MANOEUVRE, 0.0, 1.0)
    s = u**3 * (10.0 - 15.0 * u + 6.0 * u * u)
    s_dot = 30.0 * u * u * (1.0 - u) ** 2 / MANOEUVRE
    return np.multiply.outer(s, TARGET), np.multiply.outer(s_dot, TARGET)


def _law(t, q, qd):
    """The PD law on the joints (the floating base's q and qd lead with the hub's 7 and 6 coordinates)."""
    q_ref, qd_ref = reference(t)
    return GAINS[0] * (q_ref - q[7:]) + GAINS[1] * (qd_ref - qd[6:])


def demo_space_arm(out_dir: str | os.PathLike[str]) -> dict:
    """Run the manoeuvre (dop853, rtol = atol = 1e-11, :data:`DURATION` s from rest) and write
    ``space_arm.nc`` and ``space_arm.png`` in ``out_dir`` (an existing directory).

    Returns the hub's rotation angle at the end (rad, about its z axis), the largest joint tracking
    error (rad), the largest total angular (N m s) and linear (N s) momentum, the steps taken and the
    paths written.
    """
    out_directory(out_dir)
    t = np.linspace(0.0, DURATION, _SAMPLES)
    run = simulate(space_arm(), q0=[0.0, 0.0], t=t, torque=_law, method="dop853", rtol=_TOLERANCE,
                   atol=_TOLERANCE)
    q_hub = run.base_attitude
    hub_angle = np.unwrap(2.0 * np.arctan2(q_hub[:, 3], q_hub[:, 0]))  # rotation about z from the start
    tracking = run.joint_position - reference(t)[0]
    nc, png = Path(out_dir) / "space_arm.nc", Path(out_dir) / "space_arm.png"
    run.save(nc)
    figure = _figure(run, hub_angle)
    write_atomic(png, lambda tmp: figure.savefig(tmp, format="png", dpi=120))
    return {"hub_rotation_rad": float(hub_angle[-1]), "max_tracking_error_rad": float(np.abs(tracking).max()),
            "max_angular_momentum": float(np.abs(run.angular_momentum).max()),
            "max_linear_momentum": float(np.abs(run.linear_momentum).max()), "steps": int(run.info["n_steps"]),
            "written": [str(nc), str(png)]}


def _figure(run, hub_angle):
    from matplotlib.figure import Figure

    figure = Figure(figsize=(8.0, 7.0), layout="constrained")
    joints, hub, momentum = figure.subplots(3, 1, sharex=True)
    q_ref = reference(run.t)[0]
    for k, name in enumerate(("shoulder", "elbow")):
        line, = joints.plot(run.t, np.degrees(run.joint_position[:, k]), label=name)
        joints.plot(run.t, np.degrees(q_ref[:, k]), ":", color=line.get_color(), label=f"{name} commanded")
    joints.set_ylabel("joint angle (deg)")
    joints.set_title("a two-link arm on a free-floating hub: the joints follow a commanded path (PD law)")
    joints.legend(ncol=2, fontsize="small")
    hub.plot(run.t, np.degrees(hub_angle))
    hub.set_ylabel("hub rotation about z (deg)")
    hub.set_title(f"the hub turns against the arm: {np.degrees(hub_angle[-1]):.2f} deg at the end")
    for label, h in (("angular, N m s", run.angular_momentum), ("linear, N s", run.linear_momentum)):
        momentum.plot(run.t, np.linalg.norm(h, axis=-1), label=label)
    momentum.set_yscale("symlog", linthresh=1e-15)
    momentum.set_ylabel("|total momentum|")
    momentum.set_xlabel("time (s)")
    momentum.set_title("total momentum, zero at the start: the joint torques are internal")
    momentum.legend(fontsize="small")
    return figure
