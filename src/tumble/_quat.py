"""Scalar quaternion and rotation kernels, compiled with Numba.

This is the one implementation of the quaternion algebra in ``tumble``: the
batched public API in :mod:`tumble.attitude` and every integrator call these
functions. They take and return plain floats (tuples), so LLVM keeps them in
registers inside hot loops.

Convention (``docs/conventions.md``): Hamilton quaternions, scalar first
``q = (w, x, y, z)``, mapping body to inertial axes, ``v_I = q ⊗ v_B ⊗ q*``.
"""

from __future__ import annotations

import math

from numba import njit

# Below this rotation angle (rad) the exp/log maps use Taylor series; the
# truncation error of the series used is below 1e-17 there.
_SMALL_ANGLE = 1e-4


@njit(cache=True)
def qmul(aw, ax, ay, az, bw, bx, by, bz):
    """Hamilton product ``a ⊗ b`` of two quaternions given by components."""
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


@njit(cache=True)
def qmul_vector(aw, ax, ay, az, vx, vy, vz):
    """``a ⊗ [0, v]``: the Hamilton product with a pure quaternion (a vector ``v``).

    The terms of :func:`qmul` with ``b_w = 0`` left out: the same values (up to
    the sign of a zero) in 12 multiplications instead of 16, which the
    quaternion kinematics ``q̇ = ½ q ⊗ [0, ω]`` evaluate at every stage.
    """
    return (
        -ax * vx - ay * vy - az * vz,
        aw * vx + ay * vz - az * vy,
        aw * vy - ax * vz + az * vx,
        aw * vz + ax * vy - ay * vx,
    )


@njit(cache=True)
def qrotate(qw, qx, qy, qz, vx, vy, vz):
    """Rotate ``v`` by the unit quaternion ``q``: ``q ⊗ v ⊗ q*`` (= R(q) v).

    Uses ``t = 2 q_v × v``, ``v' = v + w t + q_v × t`` (30 flops).
    """
    tx = 2.0 * (qy * vz - qz * vy)
    ty = 2.0 * (qz * vx - qx * vz)
    tz = 2.0 * (qx * vy - qy * vx)
    return (
        vx + qw * tx + (qy * tz - qz * ty),
        vy + qw * ty + (qz * tx - qx * tz),
        vz + qw * tz + (qx * ty - qy * tx),
    )


@njit(cache=True)
def qrotate_inv(qw, qx, qy, qz, vx, vy, vz):
    """Rotate ``v`` by the conjugate of ``q``: ``q* ⊗ v ⊗ q`` (= R(q)ᵀ v)."""
    return qrotate(qw, -qx, -qy, -qz, vx, vy, vz)


@njit(cache=True)
def qnorm(qw, qx, qy, qz):
    """Euclidean norm of a quaternion, safe against overflow and underflow of the squares.

    The plain ``sqrt(w² + x² + y² + z²)`` is used unless the sum of squares
    leaves [1e-290, 1e290]; then the components are first scaled by the
    largest magnitude.
    """
    n2 = qw * qw + qx * qx + qy * qy + qz * qz
    if 1e-290 <= n2 <= 1e290:
        return math.sqrt(n2)
    s = max(abs(qw), abs(qx), abs(qy), abs(qz))
    if not (0.0 < s < math.inf):  # zero, inf or nan: nothing to rescale
        return math.sqrt(n2)
    qw, qx, qy, qz = qw / s, qx / s, qy / s, qz / s
    return s * math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)


@njit(cache=True)
def qunit(qw, qx, qy, qz):
    """Unit quaternion ``q / |q|`` of a non-zero, finite ``q``, for any magnitude of its components.

    ``|q|`` itself overflows when the components are near the float64 maximum
    (``|[1e308, 1e308, 1e308, 1e308]| = 2e308``) and the squares underflow
    below 1e-154, so outside the range where :func:`qnorm` is plain the
    components are first divided by the largest magnitude ``s``:
    ``q / |q| = (q/s) / |q/s|`` with ``1 ≤ |q/s| ≤ 2``.
    """
    n2 = qw * qw + qx * qx + qy * qy + qz * qz
    if not 1e-290 <= n2 <= 1e290:
        s = max(abs(qw), abs(qx), abs(qy), abs(qz))
        if 0.0 < s < math.inf:  # zero, inf or nan: nothing to rescale
            qw, qx, qy, qz = qw / s, qx / s, qy / s, qz / s
            n2 = qw * qw + qx * qx + qy * qy + qz * qz
    n = math.sqrt(n2)
    return (qw / n, qx / n, qy / n, qz / n)


@njit(cache=True)
def qto_matrix(qw, qx, qy, qz, out):
    """Write the rotation matrix R(q) (body → inertial) of a unit quaternion into the 3×3 ``out``."""
    xx, yy, zz = qx * qx, qy * qy, qz * qz
    xy, xz, yz = qx * qy, qx * qz, qy * qz
    wx, wy, wz = qw * qx, qw * qy, qw * qz
    out[0, 0] = 1.0 - 2.0 * (yy + zz)
    out[0, 1] = 2.0 * (xy - wz)
    out[0, 2] = 2.0 * (xz + wy)
    out[1, 0] = 2.0 * (xy + wz)
    out[1, 1] = 1.0 - 2.0 * (xx + zz)
    out[1, 2] = 2.0 * (yz - wx)
    out[2, 0] = 2.0 * (xz - wy)
    out[2, 1] = 2.0 * (yz + wx)
    out[2, 2] = 1.0 - 2.0 * (xx + yy)


@njit(cache=True)
def qfrom_matrix(m):
    """Unit quaternion (w ≥ 0) of a 3×3 rotation matrix, by Shepperd's method.

    The largest of the four candidates ``4w², 4x², 4y², 4z²`` is used as the
    pivot, so the result is accurate to rounding for every rotation
    (S. W. Shepperd, J. Guidance Control 1(3), 1978).
    """
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr >= m[0, 0] and tr >= m[1, 1] and tr >= m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + tr)
        w = 0.25 * s
        x = (m[2, 1] - m[1, 2]) / s
        y = (m[0, 2] - m[2, 0]) / s
        z = (m[1, 0] - m[0, 1]) / s
    elif m[0, 0] >= m[1, 1] and m[0, 0] >= m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        w = (m[2, 1] - m[1, 2]) / s
        x = 0.25 * s
        y = (m[0, 1] + m[1, 0]) / s
        z = (m[0, 2] + m[2, 0]) / s
    elif m[1, 1] >= m[2, 2]:
        s = 2.0 * math.sqrt(1.0 - m[0, 0] + m[1, 1] - m[2, 2])
        w = (m[0, 2] - m[2, 0]) / s
        x = (m[0, 1] + m[1, 0]) / s
        y = 0.25 * s
        z = (m[1, 2] + m[2, 1]) / s
    else:
        s = 2.0 * math.sqrt(1.0 - m[0, 0] - m[1, 1] + m[2, 2])
        w = (m[1, 0] - m[0, 1]) / s
        x = (m[0, 2] + m[2, 0]) / s
        y = (m[1, 2] + m[2, 1]) / s
        z = 0.25 * s
    n = qnorm(w, x, y, z)
    if w < 0.0:
        n = -n
    return (w / n, x / n, y / n, z / n)


@njit(cache=True)
def mdet(m):
    """``det m`` of a 3×3 matrix, by cofactors along its first row."""
    return (m[0, 0] * (m[1, 1] * m[2, 2] - m[1, 2] * m[2, 1]) - m[0, 1] * (m[1, 0] * m[2, 2] - m[1, 2] * m[2, 0])
            + m[0, 2] * (m[1, 0] * m[2, 1] - m[1, 1] * m[2, 0]))


@njit(cache=True)
def orthonormality(m):
    """``(max |mᵀm − 1|, det m)`` of a 3×3 matrix: how far it is from a rotation (0 and +1 for one)."""
    err = 0.0
    for i in range(3):
        for j in range(3):
            d = m[0, i] * m[0, j] + m[1, i] * m[1, j] + m[2, i] * m[2, j] - (1.0 if i == j else 0.0)
            err = max(err, abs(d))
    return err, mdet(m)


@njit(cache=True)
def qexp(rx, ry, rz):
    """Unit quaternion of the rotation vector ``r`` (axis × angle, rad).

    ``q = (cos(θ/2), sin(θ/2) r/θ)`` with ``θ = |r|``; a Taylor series of
    ``sin(θ/2)/θ`` is used for ``θ < 1e-4``.
    """
    theta2 = rx * rx + ry * ry + rz * rz
    theta = math.sqrt(theta2)
    if theta < _SMALL_ANGLE:
        s = 0.5 - theta2 / 48.0
        c = 1.0 - theta2 / 8.0 + theta2 * theta2 / 384.0
    else:
        s = math.sin(0.5 * theta) / theta
        c = math.cos(0.5 * theta)
    return (c, s * rx, s * ry, s * rz)


@njit(cache=True)
def qlog(qw, qx, qy, qz):
    """Rotation vector (rad) of a unit quaternion, angle in [0, π].

    ``θ = 2 atan2(|q_v|, |w|)`` (the ``atan2`` form keeps full accuracy for
    small and near-π angles); the sign of ``q`` is chosen so that ``w ≥ 0``.
    """
    if qw < 0.0:
        qw, qx, qy, qz = -qw, -qx, -qy, -qz
    sv = math.sqrt(qx * qx + qy * qy + qz * qz)
    theta = 2.0 * math.atan2(sv, qw)
    if sv < 0.5 * _SMALL_ANGLE:
        # θ/sv = 2 atan(sv/w)/sv = 2/w (1 − sv²/(3 w²) + …) for small sv
        k = 2.0 / qw * (1.0 - sv * sv / (3.0 * qw * qw))
    else:
        k = theta / sv
    return (k * qx, k * qy, k * qz)
