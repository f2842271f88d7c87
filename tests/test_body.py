"""Tests of tumble.rigid_body: shapes against textbook formulas, principal axes, composites, validation."""

import pickle

import numpy as np
import pytest

from tumble._validate import ValidationError
from tumble.rigid_body import Part, RigidBody, principal_axes

# Closed-form values computed with a handful of float operations agree to a
# few ulps; 1e-14 relative leaves room for ~50 roundings.
RTOL_EXACT = 1e-14
# Sums of a few parts (parallel-axis terms, rotations R I Rᵀ) of order 1e-13.
RTOL_SUM = 1e-13
# Sums over the 8000 points of a grid: rounding grows like √n eps to ~1e-14; 1e-12 is safe.
RTOL_CLOUD = 1e-12
# Eigenvectors of a 3×3 tensor whose moments differ by ≥ 30 %: error ≈ eps |I| / gap.
ATOL_AXES = 1e-12

M = 2.5  # kg


def rel_err(actual, expected):
    """max |actual − expected| / max |expected|."""
    expected = np.asarray(expected)
    return np.abs(np.asarray(actual) - expected).max() / np.abs(expected).max()


def random_rotation(seed):
    """A random proper rotation matrix (QR of a Gaussian matrix, det fixed to +1)."""
    q, r = np.linalg.qr(np.random.default_rng(seed).standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def rot_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


# -- shapes against the textbook table ---------------------------------------

R_, L_, A, B, C = 0.3, 1.7, 0.4, 0.9, 1.3

SHAPES = [
    ("sphere", lambda: RigidBody.sphere(mass=M, radius=R_), [0.4 * M * R_**2] * 3),
    ("hollow_sphere", lambda: RigidBody.hollow_sphere(mass=M, radius=R_), [2 / 3 * M * R_**2] * 3),
    (
        "cylinder_z",
        lambda: RigidBody.cylinder(mass=M, radius=R_, length=L_),
        [M * (3 * R_**2 + L_**2) / 12] * 2 + [M * R_**2 / 2],
    ),
    (
        "cylinder_x",
        lambda: RigidBody.cylinder(mass=M, radius=R_, length=L_, axis="x"),
        [M * R_**2 / 2] + [M * (3 * R_**2 + L_**2) / 12] * 2,
    ),
    (
        "hollow_cylinder_y",
        lambda: RigidBody.hollow_cylinder(mass=M, inner_radius=0.2, outer_radius=R_, length=L_, axis="y"),
        [M * (3 * (0.2**2 + R_**2) + L_**2) / 12, M * (0.2**2 + R_**2) / 2, M * (3 * (0.2**2 + R_**2) + L_**2) / 12],
    ),
    (
        "hollow_cylinder_thin",
        lambda: RigidBody.hollow_cylinder(mass=M, inner_radius=R_, outer_radius=R_, length=L_),
        [M * (6 * R_**2 + L_**2) / 12] * 2 + [M * R_**2],
    ),
    (
        "box",
        lambda: RigidBody.box(mass=M, size=(A, B, C)),
        [M * (B**2 + C**2) / 12, M * (A**2 + C**2) / 12, M * (A**2 + B**2) / 12],
    ),
    (
        "ellipsoid",
        lambda: RigidBody.ellipsoid(mass=M, semi_axes=(A, B, C)),
        [M * (B**2 + C**2) / 5, M * (A**2 + C**2) / 5, M * (A**2 + B**2) / 5],
    ),
]


@pytest.mark.parametrize("make, diagonal", [s[1:] for s in SHAPES], ids=[s[0] for s in SHAPES])
def test_shape_matches_textbook_formula(make, diagonal):
    body = make()
    assert rel_err(body.inertia, np.diag(diagonal)) <= RTOL_EXACT
    assert rel_err(body.moments, np.sort(diagonal)) <= RTOL_EXACT
    assert body.mass == M
    np.testing.assert_array_equal(body.com, np.zeros(3))


def test_hollow_cylinder_with_no_bore_is_the_solid_cylinder():
    tube = RigidBody.hollow_cylinder(mass=M, inner_radius=0.0, outer_radius=R_, length=L_, axis="x")
    solid = RigidBody.cylinder(mass=M, radius=R_, length=L_, axis="x")
    assert rel_err(tube.inertia, solid.inertia) <= RTOL_EXACT


def test_rod_is_a_part_with_zero_axial_inertia():
    rod = RigidBody.rod(mass=M, length=L_, axis="y")
    assert isinstance(rod, Part)
    assert rel_err(rod.inertia, np.diag([M * L_**2 / 12, 0.0, M * L_**2 / 12])) <= RTOL_EXACT


def test_rod_in_a_composite_and_alone():
    rod = RigidBody.rod(mass=0.1, length=0.5, axis="x")
    disc = RigidBody.cylinder(mass=0.4, radius=0.1, length=0.01, axis="x")
    body = RigidBody.composite([rod, disc.placed((0.25, 0.0, 0.0))])  # disc at the end of the rod
    com_x = 0.4 * 0.25 / 0.5
    ixx = 0.4 * 0.1**2 / 2
    iyy = 0.1 * 0.5**2 / 12 + 0.4 * (3 * 0.1**2 + 0.01**2) / 12 + 0.1 * 0.4 / 0.5 * 0.25**2
    assert rel_err(body.com, [com_x, 0.0, 0.0]) <= RTOL_EXACT
    assert rel_err(body.inertia, np.diag([ixx, iyy, iyy])) <= RTOL_SUM
    with pytest.raises(ValidationError, match="inertia: must be positive definite"):
        RigidBody.composite([rod])


# -- principal axes -------------------------------------------------------------


@pytest.mark.parametrize("seed", range(5))
def test_principal_decomposition_reconstructs_the_tensor(seed):
    rng = np.random.default_rng(seed)
    moments = np.sort(rng.uniform(1.0, 2.0, 3))  # any three in [1, 2] meet the triangle inequality
    r = random_rotation(seed)
    body = RigidBody(r @ np.diag(moments) @ r.T)
    axes = body.axes
    assert rel_err(body.moments, moments) <= RTOL_EXACT
    assert np.all(np.diff(body.moments) >= 0.0)
    assert rel_err(axes @ np.diag(body.moments) @ axes.T, body.inertia) <= RTOL_EXACT
    assert np.abs(axes.T @ axes - np.eye(3)).max() <= RTOL_EXACT
    assert abs(np.linalg.det(axes) - 1.0) <= RTOL_EXACT
    # deterministic sign: the largest component of the first two axes is positive
    for i in range(2):
        assert axes[np.abs(axes[:, i]).argmax(), i] > 0.0
    np.testing.assert_array_equal(RigidBody(body.inertia).axes, axes)


def test_principal_body_is_diagonal_with_com_in_principal_axes():
    r = random_rotation(11)
    body = RigidBody(r @ np.diag([1.0, 1.5, 2.0]) @ r.T, mass=M, com=[0.1, -0.2, 0.3])
    p = body.principal()
    np.testing.assert_array_equal(p.inertia, np.diag(body.moments))
    np.testing.assert_array_equal(p.axes, np.eye(3))
    assert rel_err(p.com, body.axes.T @ body.com) <= RTOL_EXACT
    assert p.mass == body.mass


@pytest.mark.parametrize("seed", range(5))
def test_rotated_box_keeps_moments_and_its_axes_map_back(seed):
    box = RigidBody.box(mass=M, size=(0.1, 0.2, 0.3))
    r = random_rotation(seed)
    turned = box.rotated(r)
    assert rel_err(turned.moments, box.moments) <= RTOL_EXACT
    assert rel_err(turned.inertia, r.T @ box.inertia @ r) <= RTOL_EXACT
    # v_old = R v_new: each principal axis of the turned box, mapped back, is ± the box's axis
    cosines = np.sum((r @ turned.axes) * box.axes, axis=0)
    assert np.abs(np.abs(cosines) - 1.0).max() <= ATOL_AXES


def test_rotated_convention_new_axes_are_old_axes_rotated_by_r():
    body = RigidBody(np.diag([1.0, 2.0, 2.5]), mass=M, com=[0.0, 0.7, 0.0])
    turned = body.rotated(rot_z(np.pi / 2))  # new x axis = old y axis
    assert rel_err(np.diag(turned.inertia), [2.0, 1.0, 2.5]) <= RTOL_EXACT
    assert np.abs(turned.com - [0.7, 0.0, 0.0]).max() <= RTOL_EXACT * 0.7
    quat = [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]  # the same rotation, [w, x, y, z]
    assert rel_err(body.rotated(quat).inertia, turned.inertia) <= RTOL_EXACT


def test_symmetry_kind():
    assert RigidBody.sphere(mass=M, radius=R_).symmetry() == "spherical"
    assert RigidBody.cylinder(mass=M, radius=1.0, length=0.1).symmetry() == "oblate"
    assert RigidBody.cylinder(mass=M, radius=0.1, length=1.0).symmetry() == "prolate"
    assert RigidBody.box(mass=M, size=(A, B, C)).symmetry() == "asymmetric"


# -- composites -------------------------------------------------------------------


def test_two_spheres_match_the_reduced_mass_formula():
    m1, m2, r1, r2 = 1.0, 3.0, 0.1, 0.2
    p1, p2 = np.array([0.3, -0.2, 0.5]), np.array([-0.4, 0.6, 0.1])
    s1, s2 = RigidBody.sphere(mass=m1, radius=r1), RigidBody.sphere(mass=m2, radius=r2)
    body = RigidBody.composite([s1.placed(p1), s2.placed(p2)])
    d = p2 - p1
    mu = m1 * m2 / (m1 + m2)  # two-body parallel axis: I = I1 + I2 + μ (|d|² E − d dᵀ)
    expected = s1.inertia + s2.inertia + mu * (d @ d * np.eye(3) - np.outer(d, d))
    assert body.mass == m1 + m2
    assert rel_err(body.com, (m1 * p1 + m2 * p2) / (m1 + m2)) <= RTOL_EXACT
    assert rel_err(body.inertia, expected) <= RTOL_SUM


def test_point_masses_equal_a_composite_of_point_parts():
    masses = np.array([1.0, 2.0, 0.5, 1.5])
    positions = np.array([[0.1, 0.0, 0.0], [0.0, 0.3, 0.0], [0.0, 0.0, -0.2], [0.2, 0.2, 0.2]])
    cloud = RigidBody.point_masses(masses, positions)
    parts = [Part(mass=m, com=p, inertia=np.zeros((3, 3))) for m, p in zip(masses, positions)]
    com = masses @ positions / masses.sum()
    d = positions - com
    expected = sum(m * (v @ v * np.eye(3) - np.outer(v, v)) for m, v in zip(masses, d))
    assert rel_err(cloud.com, com) <= RTOL_EXACT
    assert rel_err(cloud.inertia, expected) <= RTOL_SUM
    assert rel_err(RigidBody.composite(parts).inertia, expected) <= RTOL_SUM


def test_box_from_two_half_boxes():
    box = RigidBody.box(mass=M, size=(A, B, C))
    half = RigidBody.box(mass=M / 2, size=(A / 2, B, C))
    body = RigidBody.composite([half.placed((-A / 4, 0.0, 0.0)), half.placed((A / 4, 0.0, 0.0))])
    assert body.mass == M
    assert np.abs(body.com).max() <= RTOL_SUM * A
    assert rel_err(body.inertia, box.inertia) <= RTOL_SUM


def test_box_from_two_rotated_half_boxes():
    # A half box of edges (B, A/2, C) turned 90° about z has edges (A/2, B, C) in the composite.
    box = RigidBody.box(mass=M, size=(A, B, C))
    half = RigidBody.box(mass=M / 2, size=(B, A / 2, C))
    quarter_turn = rot_z(np.pi / 2)
    quat = [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)]  # the same rotation, [w, x, y, z]
    body = RigidBody.composite(
        [half.placed((-A / 4, 0.0, 0.0), rotation=quarter_turn), half.placed((A / 4, 0.0, 0.0), rotation=quat)]
    )
    assert rel_err(body.inertia, box.inertia) <= RTOL_SUM


def test_placed_honours_the_part_com_offset():
    r = random_rotation(3)
    body = RigidBody(np.diag([1.0, 1.2, 1.4]), mass=M, com=[0.1, 0.2, -0.3])
    part = body.placed((1.0, -2.0, 0.5), rotation=r)
    assert rel_err(part.com, np.array([1.0, -2.0, 0.5]) + r @ body.com) <= RTOL_EXACT
    assert rel_err(part.inertia, r @ body.inertia @ r.T) <= RTOL_EXACT
    again = part.placed((0.0, 1.0, 0.0), rotation=r.T)  # placing a part composes the transforms
    assert rel_err(again.com, np.array([0.0, 1.0, 0.0]) + r.T @ part.com) <= RTOL_EXACT
    assert rel_err(again.inertia, body.inertia) <= RTOL_EXACT


def test_parallel_axis_against_a_point_cloud():
    """A solid box as an n³ grid of cell-centre point masses, turned and moved, about a point P.

    Each cell of edges h adds exactly m_cell h²/12 per transverse edge to the
    continuum moments (∫ x² over a cell = h x_c² + h³/12; linear terms are
    exact), so the grid inertia is the box's minus m diag(h_y² + h_z², …)/12.
    """
    size, n = np.array([0.3, 0.2, 0.1]), 20
    r, position, point = random_rotation(5), np.array([0.4, -0.1, 0.25]), np.array([-0.3, 0.5, 0.2])
    h = size / n
    cells = [(np.arange(n) + 0.5) * hi - si / 2 for hi, si in zip(h, size)]
    grid = np.stack(np.meshgrid(*cells, indexing="ij"), axis=-1).reshape(-1, 3)
    points = position + grid @ r.T
    m_cell = M / n**3
    d = points - point
    cloud = m_cell * (np.sum(d * d) * np.eye(3) - d.T @ d)
    correction = M * np.diag((h @ h - h**2)) / 12
    box = RigidBody.box(mass=M, size=size)
    body = RigidBody.composite([box.placed(position, rotation=r)])
    assert rel_err(body.com, position) <= RTOL_EXACT
    assert rel_err(body.inertia_about(point) - r @ correction @ r.T, cloud) <= RTOL_CLOUD
    grid_body = RigidBody.point_masses(np.full(n**3, m_cell), grid)
    assert rel_err(grid_body.inertia + correction, box.inertia) <= RTOL_CLOUD


def test_inertia_about():
    sphere = RigidBody.sphere(mass=M, radius=R_)
    np.testing.assert_array_equal(sphere.inertia_about(sphere.com), sphere.inertia)
    surface = sphere.inertia_about([0.0, 0.0, R_])  # 7/5 m r² across, 2/5 m r² along the offset
    assert rel_err(surface, np.diag([1.4, 1.4, 0.4]) * M * R_**2) <= RTOL_EXACT
    with pytest.raises(ValidationError, match="inertia_about: needs the body's mass and com"):
        RigidBody(np.eye(3), mass=M).inertia_about([0.0, 0.0, 0.0])


def test_t_handle():
    body = RigidBody.t_handle()
    mh, lh, mb, lb, r = 0.03, 0.08, 0.02, 0.08, 0.004  # the documented defaults
    mu = mh * mb / (mh + mb)  # the two cylinders' centres are lh/2 apart along x
    across_handle = mh * (3 * r**2 + lh**2) / 12 + mu * (lh / 2) ** 2
    ixx = mh * r**2 / 2 + mb * (3 * r**2 + lb**2) / 12
    iyy = across_handle + mb * r**2 / 2
    izz = across_handle + mb * (3 * r**2 + lb**2) / 12
    assert rel_err(body.inertia, np.diag([ixx, iyy, izz])) <= RTOL_SUM
    assert rel_err(body.com, [(mh * lh / 2 + mb * lh) / (mh + mb), 0.0, 0.0]) <= RTOL_EXACT
    i1, i2, i3 = body.moments
    assert i1 > 0.0 and (i2 - i1) / i3 > 0.1 and (i3 - i2) / i3 > 0.1  # clearly distinct
    assert body.symmetry() == "asymmetric"


def test_t_handle_one_liner():
    body = RigidBody.composite(
        [
            RigidBody.cylinder(mass=0.2, radius=0.01, length=0.1, axis="x").placed(position=(0.05, 0, 0)),
            RigidBody.cylinder(mass=0.1, radius=0.01, length=0.08, axis="y").placed(position=(0.1, 0, 0)),
        ]
    )
    assert body.symmetry() == "asymmetric"
    assert rel_err(body.com, [(0.2 * 0.05 + 0.1 * 0.1) / 0.3, 0.0, 0.0]) <= RTOL_EXACT


# -- validation ---------------------------------------------------------------------

GOOD = np.diag([1.0, 2.0, 2.5])
SKEW = GOOD + np.array([[0.0, 1e-9, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
NO_MASS = RigidBody(GOOD)

BAD = [
    (lambda: RigidBody(SKEW), "inertia: must be symmetric"),
    (lambda: RigidBody(np.where(GOOD == 2.0, np.nan, GOOD)), "inertia: must be finite"),
    (lambda: RigidBody(np.where(GOOD == 2.0, np.inf, GOOD)), "inertia: must be finite"),
    (lambda: RigidBody(np.eye(2)), "inertia: must have shape"),
    (lambda: RigidBody(np.stack([GOOD, GOOD])), "inertia: must have shape"),
    (lambda: RigidBody(np.diag([0.0, 1.0, 1.0])), "inertia: must be positive definite"),
    (lambda: RigidBody(np.diag([-1.0, 2.0, 2.0])), "inertia: must be positive definite"),
    (lambda: RigidBody(np.diag([1.0, 1.0, 2.5])), "inertia: principal moments break the triangle inequality"),
    (lambda: RigidBody(GOOD, mass=-1.0), "mass: must be a finite number > 0"),
    (lambda: RigidBody(GOOD, mass=0.0), "mass: must be a finite number > 0"),
    (lambda: RigidBody(GOOD, mass=np.inf), "mass: must be a finite number > 0"),
    (lambda: RigidBody(GOOD, com=[0.0, 1.0]), "com: must have shape"),
    (lambda: RigidBody(GOOD, com=[0.0, np.nan, 0.0]), "com: must be finite"),
    (lambda: RigidBody.composite([NO_MASS.placed()]), "mass: a body placed as a part of a composite needs a mass"),
    (lambda: RigidBody.composite([NO_MASS]), "mass: a body placed as a part of a composite needs a mass"),
    (lambda: RigidBody.composite([]), "parts: a composite needs at least one part"),
    (lambda: RigidBody.composite([GOOD]), r"parts\[0\]: must be a Part or a RigidBody"),
    (lambda: Part(mass=1.0, com=[0, 0, 0], inertia=-np.eye(3)), "inertia: must be positive semi-definite"),
    (lambda: NO_MASS.rotated(np.diag([1.0, 1.0, -1.0])), "rotation: must be a proper rotation"),
    (lambda: NO_MASS.rotated(1.001 * np.eye(3)), "rotation: must be orthonormal"),
    (lambda: NO_MASS.rotated([1.0, 0.1, 0.0, 0.0]), "rotation: a quaternion .* must have unit norm"),
    (lambda: NO_MASS.rotated([1.0, 0.0, 0.0]), "rotation: must be a 3x3 rotation matrix or a unit quaternion"),
    (lambda: RigidBody.cylinder(mass=1.0, radius=0.1, length=1.0, axis="w"), "axis: must be 'x', 'y' or 'z'"),
    (lambda: RigidBody.sphere(mass=1.0, radius=-0.1), "radius: must be a finite number > 0"),
    (lambda: RigidBody.box(mass=1.0, size=(1.0, 0.0, 1.0)), "size: each entry must be > 0"),
    (
        lambda: RigidBody.hollow_cylinder(mass=1.0, inner_radius=0.2, outer_radius=0.1, length=1.0),
        "inner_radius: must satisfy 0 <= inner_radius <= outer_radius",
    ),
    (lambda: RigidBody.point_masses([1.0, 1.0], np.eye(3)), r"positions: must have shape \(n, 3\)"),
    (lambda: RigidBody.point_masses([1.0, -1.0, 1.0], np.eye(3)), "masses: each must be > 0"),
    (lambda: RigidBody.point_masses([1.0, 1.0], np.eye(3)[:2]), "inertia: must be positive definite"),
    (lambda: RigidBody.t_handle(bar_mass=0.0), "bar_mass: must be a finite number > 0"),
]


@pytest.mark.parametrize("make, message", BAD, ids=[m.split(":")[0] + f"-{i}" for i, (_, m) in enumerate(BAD)])
def test_bad_input_is_refused_with_the_rule_named(make, message):
    with pytest.raises(ValidationError, match=message):
        make()


def test_symmetry_tolerance_and_exact_symmetrization():
    nearly = GOOD + np.array([[0.0, 1e-13, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])  # 4e-14 × max |I|
    body = RigidBody(nearly)
    np.testing.assert_array_equal(body.inertia, body.inertia.T)


def test_triangle_opt_out_accepts_the_data():
    body = RigidBody(np.diag([1.0, 1.0, 2.5]), check_triangle=False)
    np.testing.assert_array_equal(body.moments, [1.0, 1.0, 2.5])
    # derived bodies keep the opt-out
    assert rel_err(body.rotated(random_rotation(0)).moments, body.moments) <= RTOL_EXACT


def test_triangle_tolerance_accepts_a_flat_plate():
    plate = np.diag([1.0, 1.5, 2.5 * (1 + 1e-12)])  # I1 + I2 = I3 to within 1e-12
    np.testing.assert_array_equal(RigidBody(plate).moments, np.diag(plate))


# -- immutability and the protocol --------------------------------------------------


def test_arrays_are_read_only_and_the_body_is_frozen():
    body = RigidBody.box(mass=M, size=(A, B, C))
    for arr in (body.inertia, body.moments, body.axes, body.com):
        assert not arr.flags.writeable
        with pytest.raises(ValueError):
            arr[0] = 1.0
    with pytest.raises(AttributeError):
        body.mass = 1.0
    part = body.placed((1.0, 0.0, 0.0))
    assert not part.com.flags.writeable and not part.inertia.flags.writeable


def test_input_arrays_are_copied():
    inertia, com = GOOD.copy(), np.array([0.1, 0.2, 0.3])
    body = RigidBody(inertia, mass=M, com=com)
    inertia[0, 0], com[0] = 9.0, 9.0
    assert body.inertia[0, 0] == 1.0 and body.com[0] == 0.1


def test_equality_hash_repr_and_pickle():
    a = RigidBody(GOOD, mass=M, com=[0.0, 0.0, 1.0], name="a")
    b = RigidBody(GOOD.copy(), mass=M, com=[0.0, 0.0, 1.0], name="b")
    assert a == b and hash(a) == hash(b)  # the name is a label, not compared
    assert a != RigidBody(GOOD, mass=2 * M, com=[0.0, 0.0, 1.0])
    assert a != RigidBody(GOOD, mass=M)
    assert repr(a) == "RigidBody(moments=[1, 2, 2.5] kg m^2, mass=2.5 kg, name='a')"
    restored = pickle.loads(pickle.dumps(a))
    assert restored == a and restored.name == "a"


def test_principal_axes_of_a_batch_equal_rigid_body_one_by_one():
    # The vectorised validation used for batches gives, member by member, exactly
    # what RigidBody computes (same eigen-solver, same sign rule).
    rng = np.random.default_rng(11)
    r, _ = np.linalg.qr(rng.standard_normal((6, 3, 3)))
    inertia = r @ (rng.uniform(1.0, 1.9, (6, 3))[..., None] * np.swapaxes(r, -1, -2))
    sym, moments, axes = principal_axes(inertia)
    for k in range(6):
        body = RigidBody(inertia[k])
        assert np.array_equal(body.moments, moments[k]) and np.array_equal(body.axes, axes[k])
        assert np.array_equal(body.inertia, sym[k])
    bad = inertia.copy()
    bad[4] = np.diag([1.0, 1.0, 3.0])  # breaks I1 + I2 >= I3
    with pytest.raises(ValidationError, match=r"^inertia\[4\]: principal moments break the triangle inequality"):
        principal_axes(bad)


def _principal_axes_numpy(inertia):
    """The rule of principal_axes written with NumPy alone (LAPACK's eigh for every tensor): the reference."""
    sym = 0.5 * (inertia + np.swapaxes(inertia, -1, -2))
    moments, axes = np.linalg.eigh(sym)
    m0, m1, m2 = moments.T.copy()
    tol = 16 * np.finfo(float).eps * np.abs(m2)
    lower, upper = m1 - m0 <= tol, m2 - m1 <= tol
    moments[lower & upper] = ((m0 + m1 + m2) / 3.0)[lower & upper, None]
    moments[lower & ~upper, :2] = (0.5 * (m0 + m1))[lower & ~upper, None]
    moments[upper & ~lower, 1:] = (0.5 * (m1 + m2))[upper & ~lower, None]
    largest = np.abs(axes).argmax(axis=-2)[..., None, :]
    axes = axes * np.sign(np.take_along_axis(axes, largest, axis=-2))
    axes[..., :, 2] *= np.sign(np.linalg.det(axes))[..., None]
    return sym, moments, axes


def test_principal_axes_equal_their_rule_in_numpy_bit_for_bit():
    # The compiled passes (symmetrization, merged double moments, sign rule, right-handed frame) and the
    # diagonal tensors' decomposition without eigh, against the same rule with LAPACK for every tensor, on
    # asymmetric, symmetric and spherical bodies in rotated axes, diagonal tensors with every pattern of
    # equal moments (LAPACK's order of equal eigenvalues), entries 1e-13-asymmetric, eigenvectors whose
    # components tie in magnitude, and entries near the largest and smallest allowed magnitudes.
    rng = np.random.default_rng(5)
    r, _ = np.linalg.qr(rng.standard_normal((400, 3, 3)))
    moments = rng.uniform(1.0, 1.9, (400, 3))
    moments[100:200, 1] = moments[100:200, 2]                 # symmetric tops, split by rounding when rotated
    moments[200:250] = moments[200:250, :1]                   # spheres
    inertia = r @ (moments[..., None] * np.swapaxes(r, -1, -2))
    levels = np.array([1.0, 1.5, 1.5 + 2 ** -52, 1.9])
    inertia[300:350] = np.eye(3) * levels[rng.integers(0, 4, (50, 1, 3))]   # diagonal, ties of every kind
    inertia[350:360] *= 1e140
    inertia[360:370] *= 1e-140
    inertia[370:] += 1e-13 * rng.standard_normal((30, 3, 3))  # asymmetric within the tolerance
    inertia[399] = [[2.0, 0.5, 0.5], [0.5, 2.0, 0.5], [0.5, 0.5, 2.0]]   # moments 1.5, 1.5, 3
    sym, m, axes = principal_axes(inertia)
    ref = _principal_axes_numpy(inertia)
    assert np.array_equal(sym, ref[0]) and np.array_equal(m, ref[1]) and np.array_equal(axes, ref[2])
    assert np.all(m[200:250] == m[200:250, :1])               # a sphere's three moments merged (were 2 of 3)
    equal = (np.diff(m, axis=1) == 0).sum(axis=1)
    assert np.all(equal[100:200] == 1) and np.all(equal[:100] == 0)   # symmetric tops, asymmetric bodies
    np.testing.assert_allclose(np.linalg.det(axes), 1.0, rtol=0, atol=1e-14)


def test_a_large_batch_shares_its_eigen_decompositions_between_threads_and_gets_the_same_bits():
    import numba

    from tumble import _inertia

    if numba.get_num_threads() < 2:
        pytest.skip("one Numba thread: the batch is decomposed on one")
    n = 2 * _inertia._THREADED + 5  # two shares or more, of unequal sizes
    rng = np.random.default_rng(8)
    r, _ = np.linalg.qr(rng.standard_normal((n, 3, 3)))
    inertia = r @ (rng.uniform(1.0, 1.9, (n, 3))[..., None] * np.swapaxes(r, -1, -2))
    inertia[::7] = np.eye(3) * rng.uniform(1.0, 1.9, (len(inertia[::7]), 1, 3))  # diagonal ones between
    got, ref = principal_axes(inertia), _principal_axes_numpy(inertia)
    assert all(np.array_equal(a, b) for a, b in zip(got, ref))


def test_a_batch_trajectory_shares_the_batch_tensors():
    import tumble

    inertia = np.diag([1.0, 2.0, 2.5]) * np.ones((3, 1, 1))
    traj = tumble.simulate(inertia, np.ones((3, 3)), t=[0.0, 0.1], method="rk4", dt=0.05)
    np.testing.assert_array_equal(traj.inertia, inertia)
    assert not traj.inertia.flags.writeable
    again = tumble.simulate(traj.inertia, np.ones((3, 3)), t=[0.0, 0.1], method="rk4", dt=0.05)
    assert np.array_equal(again.omega, traj.omega)
