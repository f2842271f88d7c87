"""Tests of tumble.attitude against closed forms, identities and scipy.spatial.transform."""

import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tumble import attitude as att
from tumble._validate import ValidationError

# Tolerances (absolute, on quantities of order 1: unit quaternions, rotation
# matrices, unit vectors, angles in rad).
ULP_TOL = 1e-15  # a few roundings of one closed-form expression
ALGEBRA_TOL = 1e-14  # a chain of products / conversions of unit quantities
ROUND_TRIP_TOL = 1e-12  # conversions and comparisons with scipy (brief's figure)

SEQUENCES = ["xyz", "xzy", "yxz", "yzx", "zxy", "zyx", "xyx", "xzx", "yxy", "yzy", "zxz", "zyz"]
ALL_SEQUENCES = SEQUENCES + [s.upper() for s in SEQUENCES]


def random_quaternions(rng, n):
    """n unit quaternions, uniform on SO(3), normalised with NumPy (not with tumble)."""
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def same_rotation(p, q):
    """Largest component difference between p and ±q, the sign chosen row by row."""
    sign = np.sign(np.sum(p * q, axis=-1, keepdims=True))
    sign[sign == 0] = 1.0
    return np.abs(p - sign * q).max()


@pytest.fixture
def rng():
    return np.random.default_rng(20240611)


# ---------------------------------------------------------------- algebra


def test_identity_is_neutral_and_product_is_associative(rng):
    p, q, r = (random_quaternions(rng, 200) for _ in range(3))
    one = att.identity(200)
    assert att.identity().tolist() == [1.0, 0.0, 0.0, 0.0]
    assert att.identity((2, 3)).shape == (2, 3, 4)
    np.testing.assert_array_equal(att.multiply(one, q), q)  # exact: products with 0 and 1
    np.testing.assert_array_equal(att.multiply(q, one), q)
    lhs = att.multiply(att.multiply(p, q), r)
    rhs = att.multiply(p, att.multiply(q, r))
    np.testing.assert_allclose(lhs, rhs, rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(att.multiply(q, att.conjugate(q)), one, rtol=0, atol=ALGEBRA_TOL)


def test_product_composes_rotation_matrices(rng):
    p, q = random_quaternions(rng, 100), random_quaternions(rng, 100)
    np.testing.assert_allclose(
        att.to_matrix(att.multiply(p, q)), att.to_matrix(p) @ att.to_matrix(q), rtol=0, atol=ALGEBRA_TOL
    )


def test_hamilton_units():
    """i ⊗ j = k, j ⊗ k = i, k ⊗ i = j, i ⊗ i = -1 (Hamilton, not JPL)."""
    i, j, k = np.eye(4)[1:]
    np.testing.assert_array_equal(att.multiply(i, j), k)
    np.testing.assert_array_equal(att.multiply(j, k), i)
    np.testing.assert_array_equal(att.multiply(k, i), j)
    np.testing.assert_array_equal(att.multiply(i, i), [-1.0, 0.0, 0.0, 0.0])


def test_normalize_unit_norm_and_extreme_scales(rng):
    q = rng.normal(size=(50, 4))
    for scale in (1.0, 1e-200, 1e200):  # squares would under/overflow without rescaling
        u = att.normalize(scale * q)
        np.testing.assert_allclose(np.linalg.norm(u, axis=-1), 1.0, rtol=0, atol=ULP_TOL)
        np.testing.assert_allclose(u, q / np.linalg.norm(q, axis=-1, keepdims=True), rtol=0, atol=ULP_TOL)


# ---------------------------------------------------------------- rotating vectors, matrices


def test_quarter_turn_about_z_maps_x_to_y():
    q = att.from_rotvec([0.0, 0.0, np.pi / 2])
    h = np.sqrt(0.5)
    np.testing.assert_allclose(q, [h, 0.0, 0.0, h], rtol=0, atol=ULP_TOL)
    np.testing.assert_allclose(att.rotate(q, [1.0, 0.0, 0.0]), [0.0, 1.0, 0.0], rtol=0, atol=ULP_TOL)
    np.testing.assert_allclose(att.rotate_inverse(q, [0.0, 1.0, 0.0]), [1.0, 0.0, 0.0], rtol=0, atol=ULP_TOL)
    expected = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    np.testing.assert_allclose(att.to_matrix(q), expected, rtol=0, atol=ULP_TOL)
    np.testing.assert_allclose(att.angle(q), np.pi / 2, rtol=0, atol=ULP_TOL)


def test_rotate_matches_matrix_and_sandwich_product(rng):
    q = random_quaternions(rng, 100) * rng.uniform(0.5, 2.0, size=(100, 1))  # not unit: used as q/|q|
    v = rng.normal(size=(100, 3))
    R = att.to_matrix(q)
    R_v, RT_v = np.einsum("nij,nj->ni", R, v), np.einsum("nji,nj->ni", R, v)
    np.testing.assert_allclose(att.rotate(q, v), R_v, rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(att.rotate_inverse(q, v), RT_v, rtol=0, atol=ALGEBRA_TOL)
    u = att.normalize(q)
    v_quat = np.concatenate([np.zeros((100, 1)), v], axis=1)
    sandwich = att.multiply(att.multiply(u, v_quat), att.conjugate(u))
    np.testing.assert_allclose(sandwich[:, 0], 0.0, rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(att.rotate(q, v), sandwich[:, 1:], rtol=0, atol=ALGEBRA_TOL)


def test_to_matrix_is_proper_orthonormal_and_matches_scipy(rng):
    q = random_quaternions(rng, 100)
    R = att.to_matrix(q)
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3), R.shape),
                               rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, rtol=0, atol=ALGEBRA_TOL)
    scipy_R = Rotation.from_quat(q, scalar_first=True).as_matrix()
    np.testing.assert_allclose(R, scipy_R, rtol=0, atol=ROUND_TRIP_TOL)


def special_quaternions():
    """Identity, half turns about the axes and a diagonal, and angles near 0 and π."""
    h = np.sqrt(0.5)
    eps = 1e-9
    return np.array(
        [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
            [0.0, h, h, 0.0],
            [np.cos(eps / 2), np.sin(eps / 2), 0.0, 0.0],
            [np.cos((np.pi - eps) / 2), 0.0, np.sin((np.pi - eps) / 2), 0.0],
            [-np.cos((np.pi - eps) / 2), 0.0, 0.0, np.sin((np.pi - eps) / 2)],
        ]
    )


def test_matrix_round_trip(rng):
    q = np.concatenate([special_quaternions(), random_quaternions(rng, 500)])
    back = att.from_matrix(att.to_matrix(q))
    assert np.all(back[:, 0] >= 0.0)
    assert same_rotation(back, q) < ALGEBRA_TOL
    scipy_q = Rotation.from_matrix(att.to_matrix(q)).as_quat(scalar_first=True)
    assert same_rotation(back, scipy_q) < ROUND_TRIP_TOL


def test_from_matrix_accepts_within_tol_and_refuses_beyond():
    R = att.to_matrix(att.from_rotvec([0.3, -0.2, 0.1]))
    nudge = np.zeros((3, 3))
    nudge[0, 1] = 1e-8  # |RᵀR - 1| ≈ 1e-8 < default tol 1e-6
    q = att.from_matrix(R + nudge)
    assert att.relative_angle(q, att.from_rotvec([0.3, -0.2, 0.1])) < 1e-7  # O(nudge)
    with pytest.raises(ValidationError, match="R: must be orthonormal"):
        att.from_matrix(R + nudge, tol=1e-9)


# ---------------------------------------------------------------- rotation vectors and angles


@pytest.mark.parametrize("theta", [0.0, 1e-9, 1e-5, 0.7, 2.0, np.pi - 1e-9, np.pi])
def test_rotvec_round_trip_and_closed_form(rng, theta):
    axes = rng.normal(size=(50, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    r = theta * axes
    q = att.from_rotvec(r)
    closed = np.concatenate([np.full((50, 1), np.cos(theta / 2)), np.sin(theta / 2) * axes], axis=1)
    np.testing.assert_allclose(q, closed, rtol=0, atol=ULP_TOL)
    back = att.to_rotvec(q)
    if theta == np.pi:  # a half turn about r is one about -r: either may come back
        back *= np.sign(np.sum(back * r, axis=-1, keepdims=True))
    np.testing.assert_allclose(back, r, rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(att.angle(q), theta, rtol=0, atol=ALGEBRA_TOL)
    scipy_rot = Rotation.from_rotvec(r)
    assert same_rotation(q, scipy_rot.as_quat(scalar_first=True)) < ROUND_TRIP_TOL
    if theta < np.pi:
        np.testing.assert_allclose(back, scipy_rot.as_rotvec(), rtol=0, atol=ROUND_TRIP_TOL)


def test_small_angle_rotvec_keeps_relative_accuracy():
    r = np.array([1e-9, -2e-9, 3e-10])
    np.testing.assert_allclose(att.to_rotvec(att.from_rotvec(r)), r, rtol=ULP_TOL, atol=0)


def test_rotvec_beyond_pi_wraps_to_angle_below_pi():
    axis = np.array([0.0, 0.6, 0.8])
    back = att.to_rotvec(att.from_rotvec((np.pi + 0.25) * axis))
    np.testing.assert_allclose(back, -(np.pi - 0.25) * axis, rtol=0, atol=ALGEBRA_TOL)
    back = att.to_rotvec(-att.from_rotvec(0.25 * axis))  # -q: same rotation
    np.testing.assert_allclose(back, 0.25 * axis, rtol=0, atol=ALGEBRA_TOL)


def test_relative_angle(rng):
    p = random_quaternions(rng, 100)
    theta = rng.uniform(0.0, np.pi, size=100)
    axes = rng.normal(size=(100, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    q = att.multiply(p, att.from_rotvec(theta[:, None] * axes))
    np.testing.assert_allclose(att.relative_angle(p, q), theta, rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(att.relative_angle(q, p), theta, rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(att.relative_angle(p, -p), 0.0, rtol=0, atol=ALGEBRA_TOL)


# ---------------------------------------------------------------- Euler angles


def random_euler_angles(rng, seq, n, margin=0.05):
    """Angles inside to_euler's ranges, the second at least ``margin`` rad from gimbal lock."""
    a = rng.uniform(-np.pi, np.pi, size=(n, 3))
    if seq[0].lower() == seq[2].lower():
        a[:, 1] = rng.uniform(margin, np.pi - margin, size=n)
    else:
        a[:, 1] = rng.uniform(-np.pi / 2 + margin, np.pi / 2 - margin, size=n)
    return a


@pytest.mark.parametrize("degrees", [False, True])
@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_euler_round_trip_and_scipy(rng, seq, degrees):
    a = random_euler_angles(rng, seq, 200)
    if degrees:
        a = np.rad2deg(a)
    q = att.from_euler(seq, a, degrees=degrees)
    scipy_rot = Rotation.from_euler(seq, a, degrees=degrees)
    assert same_rotation(q, scipy_rot.as_quat(scalar_first=True)) < ROUND_TRIP_TOL
    with warnings.catch_warnings():
        warnings.simplefilter("error", att.GimbalLockWarning)
        back = att.to_euler(q, seq, degrees=degrees)
    np.testing.assert_allclose(back, a, rtol=0, atol=ROUND_TRIP_TOL)
    np.testing.assert_allclose(back, scipy_rot.as_euler(seq, degrees=degrees), rtol=0, atol=ROUND_TRIP_TOL)


@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_euler_of_random_rotations_in_range_and_scipy(rng, seq):
    q = random_quaternions(rng, 300)
    a = att.to_euler(q, seq)
    assert np.all((a[:, [0, 2]] > -np.pi) & (a[:, [0, 2]] <= np.pi))
    if seq[0].lower() == seq[2].lower():
        assert np.all((a[:, 1] >= 0.0) & (a[:, 1] <= np.pi))
    else:
        assert np.all(np.abs(a[:, 1]) <= np.pi / 2)
    np.testing.assert_allclose(a, Rotation.from_quat(q, scalar_first=True).as_euler(seq), rtol=0,
                               atol=ROUND_TRIP_TOL)
    assert same_rotation(att.from_euler(seq, a), q) < ROUND_TRIP_TOL


def test_euler_meaning_intrinsic_and_extrinsic():
    """Intrinsic XYZ is R_x(a) R_y(b) R_z(c); extrinsic xyz is R_z(c) R_y(b) R_x(a)."""
    a, b, c = 0.3, -0.4, 1.1
    qx, qy, qz = (att.from_rotvec(t * e) for t, e in zip((a, b, c), np.eye(3)))
    intrinsic = att.multiply(att.multiply(qx, qy), qz)
    extrinsic = att.multiply(att.multiply(qz, qy), qx)
    np.testing.assert_allclose(att.from_euler("XYZ", [a, b, c]), intrinsic, rtol=0, atol=ULP_TOL)
    np.testing.assert_allclose(att.from_euler("xyz", [a, b, c]), extrinsic, rtol=0, atol=ULP_TOL)


def gimbal_lock_angles(seq):
    """Five angle triples for ``seq``: three exactly or nearly (1e-9 rad) at gimbal lock, two far from it."""
    lock = [0.0, np.pi] if seq[0].lower() == seq[2].lower() else [-np.pi / 2, np.pi / 2]
    return np.array(
        [
            [0.3, lock[0], 0.5],
            [-2.0, lock[1], 2.9],
            [1.0, lock[1] - np.sign(lock[1]) * 1e-9, -0.7],
            [0.3, 0.5 * (lock[0] + lock[1]) + 0.4, 0.5],
            [0.3, 0.5 * (lock[0] + lock[1]) - 0.4, 0.5],
        ]
    )


@pytest.mark.parametrize("seq", ALL_SEQUENCES)
def test_gimbal_lock_warns_once_and_reproduces_rotation(seq):
    q = att.from_euler(seq, gimbal_lock_angles(seq))
    with pytest.warns(att.GimbalLockWarning, match="3 of 5 rotations") as record:
        a = att.to_euler(q, seq)
    assert len(record) == 1
    np.testing.assert_array_equal(a[:3, 2], 0.0)  # third angle set to zero at lock
    err = att.relative_angle(att.from_euler(seq, a), q)
    assert np.all(err[[0, 1, 3, 4]] < ROUND_TRIP_TOL)  # exact lock or far from it: exact
    assert err[2] < 1e-9  # 1e-9 rad from lock: error of the order of that distance
    scipy_rot = Rotation.from_quat(q[:2], scalar_first=True)
    with pytest.warns(UserWarning, match="Gimbal lock"):
        np.testing.assert_allclose(a[:2], scipy_rot.as_euler(seq), rtol=0, atol=ROUND_TRIP_TOL)


# ---------------------------------------------------------------- scipy interop


def test_scipy_round_trip(rng):
    q = random_quaternions(rng, 20).reshape(4, 5, 4)
    rot = att.to_scipy(3.0 * q)  # scaled: scipy normalises like tumble
    np.testing.assert_allclose(rot.as_matrix(), att.to_matrix(q), rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(att.from_scipy(rot), q, rtol=0, atol=ALGEBRA_TOL)
    np.testing.assert_allclose(att.from_scipy(Rotation.from_rotvec([0.0, 0.0, np.pi / 2])),
                               att.from_rotvec([0.0, 0.0, np.pi / 2]), rtol=0, atol=ULP_TOL)


# ---------------------------------------------------------------- batches


def test_batched_shapes_equal_elementwise(rng):
    q = random_quaternions(rng, 10).reshape(2, 5, 4)
    p = random_quaternions(rng, 5)  # (5, 4) broadcasts against (2, 5, 4)
    v = rng.normal(size=(2, 5, 3))
    batched = {
        "multiply": att.multiply(p, q),
        "rotate": att.rotate(q, v),
        "rotate_inverse": att.rotate_inverse(q, v),
        "to_matrix": att.to_matrix(q),
        "from_matrix": att.from_matrix(att.to_matrix(q)),
        "normalize": att.normalize(2.0 * q),
        "conjugate": att.conjugate(q),
        "to_rotvec": att.to_rotvec(q),
        "from_rotvec": att.from_rotvec(v),
        "angle": att.angle(q),
        "relative_angle": att.relative_angle(p, q),
        "to_euler": att.to_euler(q, "ZYX"),
        "from_euler": att.from_euler("zxz", v),
    }
    core = {"to_matrix": (3, 3), "angle": (), "relative_angle": (), "rotate": (3,), "rotate_inverse": (3,),
            "to_rotvec": (3,), "to_euler": (3,)}
    for name, out in batched.items():
        assert out.dtype == np.float64
        assert out.shape == (2, 5, *core.get(name, (4,))), name
    for i in range(2):
        for j in range(5):
            single = {
                "multiply": att.multiply(p[j], q[i, j]),
                "rotate": att.rotate(q[i, j], v[i, j]),
                "rotate_inverse": att.rotate_inverse(q[i, j], v[i, j]),
                "to_matrix": att.to_matrix(q[i, j]),
                "from_matrix": att.from_matrix(att.to_matrix(q[i, j])),
                "normalize": att.normalize(2.0 * q[i, j]),
                "conjugate": att.conjugate(q[i, j]),
                "to_rotvec": att.to_rotvec(q[i, j]),
                "from_rotvec": att.from_rotvec(v[i, j]),
                "angle": att.angle(q[i, j]),
                "relative_angle": att.relative_angle(p[j], q[i, j]),
                "to_euler": att.to_euler(q[i, j], "ZYX"),
                "from_euler": att.from_euler("zxz", v[i, j]),
            }
            for name, out in single.items():
                np.testing.assert_array_equal(batched[name][i, j], out, err_msg=name)  # same kernel: bitwise


def test_rotate_broadcasts_one_quaternion_over_vectors(rng):
    q = att.from_rotvec([0.1, 0.2, 0.3])
    v = rng.normal(size=(2, 5, 3))
    np.testing.assert_allclose(att.rotate(q, v), v @ att.to_matrix(q).T, rtol=0, atol=ALGEBRA_TOL)


# ---------------------------------------------------------------- bad input


BAD_INPUT = [
    (lambda: att.normalize([0.0, 0.0, 0.0, 0.0]), "q: must be non-zero"),
    (lambda: att.to_matrix(np.vstack([np.eye(4), np.zeros(4)])), r"q: must be non-zero .* at index 4"),
    (lambda: att.relative_angle([0, 0, 0, 0], [1, 0, 0, 0]), "p: must be non-zero"),
    (lambda: att.rotate([1.0, np.nan, 0.0, 0.0], [1.0, 0.0, 0.0]), "q: must be finite"),
    (lambda: att.from_rotvec([np.inf, 0.0, 0.0]), "r: must be finite"),
    (lambda: att.rotate([1.0, 0.0, 0.0, 0.0], [1.0, 0.0]), r"v: must have shape \(…, 3\)"),
    (lambda: att.multiply([1.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]), r"p: must have shape \(…, 4\)"),
    (lambda: att.multiply(np.ones((3, 4)), np.ones((2, 4))), "p, q: batch shapes must broadcast"),
    (lambda: att.from_matrix(np.diag([1.0, 1.0, 2.0])), "R: must be orthonormal"),
    (lambda: att.from_matrix(np.diag([1.0, 1.0, -1.0])), r"R: must have det = \+1"),
    (lambda: att.from_matrix(np.eye(3), tol=0.0), "tol: must be a finite number > 0"),
    (lambda: att.from_euler("xyy", [0.0, 0.0, 0.0]), "seq: consecutive axes must differ"),
    (lambda: att.to_euler([1.0, 0.0, 0.0, 0.0], "XXZ"), "seq: consecutive axes must differ"),
    (lambda: att.from_euler("xYz", [0.0, 0.0, 0.0]), "seq: must be all lowercase .* or all uppercase"),
    (lambda: att.from_euler("xy", [0.0, 0.0, 0.0]), "seq: must be three axes"),
    (lambda: att.to_euler([1.0, 0.0, 0.0, 0.0], "abc"), "seq: must be three axes"),
    (lambda: att.from_euler("xyz", [0.0, 0.0]), r"angles: must have shape \(…, 3\)"),
    (lambda: att.from_scipy([1.0, 0.0, 0.0, 0.0]), "rot: must be a scipy.spatial.transform.Rotation"),
]


@pytest.mark.parametrize(("call", "message"), BAD_INPUT)
def test_bad_input_names_field_and_rule(call, message):
    with pytest.raises(ValidationError, match=message):
        call()
