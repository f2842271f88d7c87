"""The environment table (:class:`tumble.spacecraft.environment_table.Environment`): its columns, and the
compiled reader every environment part of the spacecraft uses.

One row per sample time; inertial = GCRS axes, SI units. The index of each
column's first component is a module constant, so that compiled code names
what it reads.

Interpolation between the samples (step ``h``, ``s`` the fraction of the
step): the position by cubic Hermite on the sampled positions and velocities
(error ``h⁴ |r⁽⁴⁾| / 384 ≈ h⁴ n⁴ |r| / 384``: 0.3 mm at 10 s in LEO), the
velocity as its derivative (error ``O(h³)``), every other column linearly
(error ``h² |x''| / 8``: for the IGRF field, which turns at about twice the
orbit rate and more, 1.2e-4 of |B| (4 nT) measured at 10 s on a 400 km orbit;
for the Sun's direction 1e-13 rad), the Sun's and the Moon's directions then
normalised.
The shadow fraction is linear between samples, so an eclipse edge is smeared
over one step (the conical penumbra of a LEO orbit lasts ~9 s).
"""

import math

import numpy as np
from numba import njit

from tumble import _quat
from tumble.kernels.spacecraft._base import Program, inline

#: position of the craft r, m (3)
POSITION = 0
#: velocity of the craft v, m/s (3)
VELOCITY = 3
#: unit vector from the craft to the Sun ŝ (3)
SUN_DIRECTION = 6
#: distance from the craft to the Sun |s|, m (1)
SUN_DISTANCE = 9
#: fraction of the solar disc seen, ν ∈ [0, 1] (1)
SHADOW = 10
#: geomagnetic field B, T (3)
MAGNETIC_FIELD = 11
#: atmospheric mass density ρ, kg/m³ (1)
DENSITY = 14
#: velocity relative to the co-rotating atmosphere v − ω⊕ × r, m/s (3)
VELOCITY_AIR = 15
#: unit vector from the craft to the Moon (3)
MOON_DIRECTION = 18
#: number of columns
WIDTH = 21

#: name → (first column, number of components)
COLUMNS = {
    "position": (POSITION, 3),
    "velocity": (VELOCITY, 3),
    "sun_direction": (SUN_DIRECTION, 3),
    "sun_distance": (SUN_DISTANCE, 1),
    "shadow": (SHADOW, 1),
    "magnetic_field": (MAGNETIC_FIELD, 3),
    "density": (DENSITY, 1),
    "velocity_air": (VELOCITY_AIR, 3),
    "moon_direction": (MOON_DIRECTION, 3),
}

# -- the compiled reader ---------------------------------------------------------------------------------
#
# The part "environment_table" carries the table in its parameter block: [step, rows, then rows × WIDTH],
# the samples at t = 0, step, 2 step, ... (s from the epoch, the simulation's t = 0). Every environment part
# reads it through these functions: interval() once, then the columns it needs.

STEP = 0     # the sample step h, s
ROWS = 1     # the number of rows n
TABLE = 2    # the first row


def program(step: float, table: np.ndarray) -> Program:
    """The table part's :class:`~tumble.kernels.spacecraft._base.Program`: a uniform ``step`` (s) and the
    rows ``table`` (n, :data:`WIDTH`) of times 0, step, ..."""
    return Program("environment_table", np.concatenate([[step, len(table)], np.ravel(table)]).astype(np.float64))


@inline
def interval(d, p, t):
    """``(row, s)``: the row offset in ``d`` of the sample at or before ``t`` (s) and the fraction
    ``s = t/h − k`` ∈ [0, 1] of the step to the next (the end intervals extend past the table)."""
    h = d[p + STEP]
    last = int(d[p + ROWS]) - 2
    k = min(max(int(math.floor(t / h)), 0), last)
    return p + TABLE + k * WIDTH, t / h - k


@inline
def linear(d, row, s, column):
    """Column ``column`` linearly interpolated: ``(1 − s) x_k + s x_{k+1}``."""
    return (1.0 - s) * d[row + column] + s * d[row + WIDTH + column]


@inline
def linear3(d, row, s, column):
    return linear(d, row, s, column), linear(d, row, s, column + 1), linear(d, row, s, column + 2)


@inline
def position(d, p, row, s):
    """The position (m, GCRS) by cubic Hermite interpolation of the samples' positions and velocities::

        r = (2s³ − 3s² + 1) r_k + (s³ − 2s² + s) h v_k + (3s² − 2s³) r_{k+1} + (s³ − s²) h v_{k+1}
    """
    h = d[p + STEP]
    s2 = s * s
    s3 = s2 * s
    a, b, c, e = 2.0 * s3 - 3.0 * s2 + 1.0, (s3 - 2.0 * s2 + s) * h, 3.0 * s2 - 2.0 * s3, (s3 - s2) * h
    n = row + WIDTH
    return (a * d[row + POSITION] + b * d[row + VELOCITY] + c * d[n + POSITION] + e * d[n + VELOCITY],
            a * d[row + POSITION + 1] + b * d[row + VELOCITY + 1] + c * d[n + POSITION + 1] + e * d[n + VELOCITY + 1],
            a * d[row + POSITION + 2] + b * d[row + VELOCITY + 2] + c * d[n + POSITION + 2] + e * d[n + VELOCITY + 2])


@inline
def velocity(d, p, row, s):
    """The velocity (m/s, GCRS): the time derivative of :func:`position`."""
    h = d[p + STEP]
    s2 = s * s
    a, b, c, e = (6.0 * s2 - 6.0 * s) / h, 3.0 * s2 - 4.0 * s + 1.0, (6.0 * s - 6.0 * s2) / h, 3.0 * s2 - 2.0 * s
    n = row + WIDTH
    return (a * d[row + POSITION] + b * d[row + VELOCITY] + c * d[n + POSITION] + e * d[n + VELOCITY],
            a * d[row + POSITION + 1] + b * d[row + VELOCITY + 1] + c * d[n + POSITION + 1] + e * d[n + VELOCITY + 1],
            a * d[row + POSITION + 2] + b * d[row + VELOCITY + 2] + c * d[n + POSITION + 2] + e * d[n + VELOCITY + 2])


@inline
def direction(d, row, s, column):
    """A unit-vector column, linearly interpolated and normalised."""
    x, y, z = linear3(d, row, s, column)
    norm = math.sqrt(x * x + y * y + z * z)
    return x / norm, y / norm, z / norm


# The parts' entry points: compiled functions of their own (not inlined), so that a spacecraft without an
# environment carries none of their code in its right-hand side, only the presence test that skips the call.

@njit(cache=True)
def field_body(d, p, t, qw, qx, qy, qz):
    """The field ``B`` (T) of the table part at ``d[p:]`` at ``t``, in body axes of the attitude ``q``."""
    row, s = interval(d, p, t)
    b1, b2, b3 = linear3(d, row, s, MAGNETIC_FIELD)
    return _quat.qrotate_inv(qw, qx, qy, qz, b1, b2, b3)


@njit(cache=True)
def position_at(d, p, t):
    """The position (m, GCRS) of the table part at ``d[p:]`` at ``t``."""
    row, s = interval(d, p, t)
    return position(d, p, row, s)


@njit(cache=True)
def read(block, t, out):
    """The rows of the table part's parameter ``block`` interpolated at the times ``t`` into ``out``
    (len(t), WIDTH): position and velocity by cubic Hermite, the directions linear and normalised, the rest
    linear — what the compiled parts read."""
    for i in range(t.shape[0]):
        row, s = interval(block, 0, t[i])
        for c in range(WIDTH):
            out[i, c] = linear(block, row, s, c)
        out[i, POSITION], out[i, POSITION + 1], out[i, POSITION + 2] = position(block, 0, row, s)
        out[i, VELOCITY], out[i, VELOCITY + 1], out[i, VELOCITY + 2] = velocity(block, 0, row, s)
        for c in (SUN_DIRECTION, MOON_DIRECTION):
            out[i, c], out[i, c + 1], out[i, c + 2] = direction(block, row, s, c)
