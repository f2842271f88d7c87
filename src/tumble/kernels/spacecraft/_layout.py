"""Where things are in the compiled spacecraft: the kinds of part, the hub block, the core diagnostics, and
each part's place ``(p, n, s, a)`` packed into one int64 field of the model (:data:`ABSENT` when the spacecraft
has no such part; see :mod:`tumble.kernels.spacecraft`)."""

from __future__ import annotations

import functools
from typing import NamedTuple

from numba import njit

from tumble._validate import ValidationError

#: The kinds of part, in the order of their state slices.
PARTS = ("hold", "wheels", "cmgs", "thrusters", "magnetorquers", "damper", "pd", "mrp", "mrp_integral",
         "python_law", "bdot", "dumping", "wheel_table", "wheel_python", "dipole_field", "uniform_field",
         "gravity_gradient", "residual_dipole", "environment_table", "solar_pressure", "drag",
         "flight_software", "flexible_modes", "slosh")

#: The fields of ``SpacecraftModel`` before the parts' (one int64 per kind of :data:`PARTS` follows them).
CORE_FIELDS = ("data", "route", "size", "aux_size", "torque_at", "torque_terms", "python_calls")

#: The field of a kind the spacecraft lacks.
ABSENT = -1

# The hub's block at the start of data:
J = 0              # J (9), total inertia about the centre of mass, kg·m², row-major
J_RATE = 9         # J_ω (9)
J_RATE_INV = 18    # J_ω⁻¹ (9)
PERIOD = 27        # control period, s (0: continuous)
START = 28         # the control clock's start t₀, s
HUB_SIZE = 29

# The "hold" part's parameters: the sample period of each law group (s; 0: evaluated in the right-hand side), that
# of the group of bit 1 << k (TORQUE_LAW, DIPOLE_LAW, WHEEL_LAW) at HOLD_PERIODS + k; its state: u_c (3), m_c (3),
# then one motor torque per wheel when a wheel-torque law is present.
HOLD_PERIODS = 0
TORQUE_LAW, DIPOLE_LAW, WHEEL_LAW = 1, 2, 4
LAW_GROUPS = 3
HELD_TORQUE, HELD_DIPOLE, HELD_WHEELS = 0, 3, 6

# The core block of the diagnostics:
AUX_ENERGY = 0            # kinetic energy of hub and parts, J (1)
AUX_MOMENTUM = 1          # H, N·m·s, body axes (3)
AUX_TORQUE_COMMAND = 4    # u_c, N·m (3)
AUX_DIPOLE_COMMAND = 7    # m_c before the limits, A·m² (3)
AUX_FIELD = 10            # B, T, body axes (3)
AUX_GRAVITY = 13          # gravity-gradient torque, N·m (3)
AUX_ACTUATOR = 16         # Σ τ_k, N·m (3)
AUX_EXTERNAL = 19         # the torque program of torque=, N·m (3)
AUX_CORE = 22


class Slices(NamedTuple):
    """Where one part is in a compiled model: parameter offset, count, state offset, diagnostics offset."""

    p: int
    n: int
    s: int
    a: int


# The bits of a packed Slices: p in bits 0–30, n in 31–40, s in 41–51, a in 52–62 (the sign bit stays clear).
_BITS = ((0, 31), (31, 10), (41, 11), (52, 11))


def pack(where: Slices) -> int:
    """``(p, n, s, a)`` as one int64 (the field of a part in ``SpacecraftModel``); each must fit its bits."""
    value = 0
    for (shift, bits), x, name in zip(_BITS, where, Slices._fields):
        if not 0 <= x < 1 << bits:
            raise ValidationError(f"{name}: a part of a spacecraft needs 0 <= {name} < 2**{bits} (its offsets and "
                                  f"count), got {x}")
        value |= x << shift
    return value


def unpack(value: int) -> Slices:
    """The :class:`Slices` of a packed int64."""
    return Slices(*((value >> shift) & ((1 << bits) - 1) for shift, bits in _BITS))


@functools.lru_cache(maxsize=None)
def locator(kind: str):
    """Compiled ``(has, where)`` of the part ``kind``: ``has(model)`` is True when the spacecraft carries it,
    ``where(model) -> (p, n, s, a)`` unpacks its place (meaningful only when it does). Runtime reads of one
    int64 field: the composition is data, not part of the model's Numba type."""
    field = len(CORE_FIELDS) + PARTS.index(kind)
    (_, b0), (s1, b1), (s2, b2), (s3, b3) = _BITS
    m0, m1, m2, m3 = (1 << b0) - 1, (1 << b1) - 1, (1 << b2) - 1, (1 << b3) - 1

    @njit
    def has(model):
        return model[field] >= 0

    @njit
    def where(model):
        v = model[field]
        return v & m0, (v >> s1) & m1, (v >> s2) & m2, (v >> s3) & m3

    return has, where
