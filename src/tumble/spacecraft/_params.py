"""The compiled spacecraft model's parameters (:class:`SpacecraftModel`) and the layouts of its
state and diagnostic vectors; the equations are in :mod:`tumble.spacecraft._kernel`."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

#: Where the controller's torque command goes (``SpacecraftModel.data[29]``).
ROUTE_NONE, ROUTE_WHEELS, ROUTE_CMGS, ROUTE_THRUSTERS, ROUTE_MAGNETORQUERS = 0, 1, 2, 3, 4
#: A step end counts as a sample time when within this fraction of the control period of k·period.
SAMPLE_TOLERANCE = 1e-9


class SpacecraftModel(NamedTuple):
    """Compiled parameters of a spacecraft (shared by every member of a batch).

    All numbers live in one flat float64 array ``data`` (one array, so that
    passing the model around the inlined kernels costs one reference count,
    not one per component); the integer fields are counts and offsets into
    it. A component the spacecraft lacks has the flag ``None`` (otherwise
    ``True``), and the kernels compile without it. Blocks of ``data``:

    ==============  ====================================================================
    offset          content
    ==============  ====================================================================
    0               J (9), total inertia, kg·m²; 9: J_ω (9); 18: J_ω⁻¹ (9)
    27              control period (s; 0: continuous), start time (s), torque route
    ``o_wheels``    per wheel (12): axis (3), I_s, max torque, max speed, viscous,
                    Coulomb, Coulomb smoothing speed, allocation row (3): u = −row·u_c
    ``o_cmg``       λ₀, μ, h̄, max gimbal rate; per gyro (10): g, s0, g × s0, h_g
    ``o_thrusters`` K_m, τ_m, u_on, u_off, min on-time, axis torques (3);
                    per thruster (5): torque (3), axis, sign
    ``o_dipole``    max dipole (3), A·m²
    ``o_orbit``     Kepler elements (7); ``o_field``: dipole-field parameters (6)
                    or a uniform inertial field (3), T
    ``o_pd``        C (9), C⁻¹K (9), target quaternion (4), max rate, max torque,
                    gyroscopic compensation (1 or 0), bias torque (3)
    ``o_bdot``      B-dot gain; ``o_dumping``: momentum-dumping gain
    ==============  ====================================================================
    """

    data: np.ndarray
    n_wheels: int
    n_gyros: int
    n_thrusters: int
    o_wheels: int
    o_cmg: int
    o_thrusters: int
    o_dipole: int
    o_orbit: int
    o_field: int
    o_pd: int
    o_bdot: int
    o_dumping: int
    cmg: bool | None
    thrusters: bool | None
    magnetorquers: bool | None
    dipole_field: bool | None
    uniform_field: bool | None
    gravity_gradient: bool | None
    pd: bool | None
    bdot: bool | None
    dumping: bool | None

    @property
    def provides(self) -> frozenset[str]:
        """Capabilities (:data:`tumble._protocol.CAPABILITIES`): a right-hand side and the body rate."""
        return frozenset({"rhs", "body_rate"})

    @property
    def calls_python(self) -> bool:
        """False: every part of the spacecraft runs compiled."""
        return False


WHEEL_STRIDE, GYRO_STRIDE, THRUSTER_STRIDE = 12, 10, 5


def pack(inertia, rate_inertia, settings, *, wheels=None, cmg=None, thrusters=None, max_dipole=None,
         orbit=None, field=None, uniform_field=None, gravity_gradient=False, pd=None, bdot=None,
         dumping=None) -> SpacecraftModel:
    """Assemble a :class:`SpacecraftModel` from its blocks (see its docstring; ``None``: absent).

    wheels : (n_w, 12); cmg : (law (4,), gyros (n_g, 10)); thrusters : (pwpf (8,), table (n_t, 5))
    """
    blocks = [np.ravel(inertia), np.ravel(rate_inertia), np.ravel(np.linalg.inv(rate_inertia)), settings]
    offsets = {}

    def put(name, *arrays):
        offsets[name] = sum(b.size for b in blocks)
        blocks.extend(np.ravel(a) for a in arrays)

    wheels = np.zeros((0, WHEEL_STRIDE)) if wheels is None else wheels
    put("o_wheels", wheels)
    put("o_cmg", *(cmg or ()))
    put("o_thrusters", *(thrusters or ()))
    put("o_dipole", *([] if max_dipole is None else [max_dipole]))
    put("o_orbit", *([] if orbit is None else [orbit]))
    put("o_field", *[f for f in (field, uniform_field) if f is not None])
    put("o_pd", *([] if pd is None else [pd]))
    put("o_bdot", *([] if bdot is None else [[bdot]]))
    put("o_dumping", *([] if dumping is None else [[dumping]]))
    flag = {True: True, False: None}
    return SpacecraftModel(
        data=np.ascontiguousarray(np.concatenate(blocks), dtype=np.float64),
        n_wheels=int(wheels.shape[0]), n_gyros=0 if cmg is None else int(cmg[1].shape[0]),
        n_thrusters=0 if thrusters is None else int(thrusters[1].shape[0]), **offsets,
        cmg=flag[cmg is not None], thrusters=flag[thrusters is not None],
        magnetorquers=flag[max_dipole is not None], dipole_field=flag[field is not None],
        uniform_field=flag[uniform_field is not None], gravity_gradient=flag[bool(gravity_gradient)],
        pd=flag[pd is not None], bdot=flag[bdot is not None], dumping=flag[dumping is not None],
    )


def layout(n_wheels: int, n_gyros: int, thrusters: bool) -> dict[str, slice]:
    """Slices of the state vector (see the module docstring)."""
    sizes = [("q", 4), ("omega", 3), ("wheel_momentum", n_wheels), ("gimbal_angle", n_gyros), ("work", 1),
             ("torque_command", 3), ("dipole_command", 3)]
    if thrusters:
        sizes += [("pwpf_filter", 3), ("pwpf_output", 3), ("pwpf_start", 3)]
    out, i = {}, 0
    for name, n in sizes:
        out[name] = slice(i, i + n)
        i += n
    return out


def aux_layout(n_wheels: int, n_gyros: int) -> dict[str, slice]:
    """Slices of the diagnostic vector written by :func:`evaluate` (one sample)."""
    sizes = [("wheel_speed", n_wheels), ("wheel_torque", n_wheels), ("wheel_saturated", n_wheels),
             ("gimbal_rate", n_gyros), ("singularity", 1 if n_gyros else 0), ("dipole", 3),
             ("field_body", 3), ("gravity_gradient", 3), ("actuator_torque", 3), ("torque_command", 3),
             ("dipole_command", 3)]
    out, i = {}, 0
    for name, n in sizes:
        out[name] = slice(i, i + n)
        i += n
    return out
