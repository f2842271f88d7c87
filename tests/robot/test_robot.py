"""tumble.robot: inverse and forward dynamics of serial chains against closed forms, identities and peers."""

import numpy as np
import pytest

import tumble
from tumble import ValidationError, robot

# The tests here compile or share the robot's kernels (tumble.kernels.featherstone and the chain model's
# integrators, ~50 CPU s on a cold Numba cache); the robot's modules run on one xdist worker (tests/conftest.py).
pytestmark = pytest.mark.slow

ROBOTS = tumble.examples.directory() / "robots"
EXAMPLES = ["planar_2link.toml", "puma560.toml", "panda.toml", "panda.urdf"]

# Closed forms, identities and the peer's numbers agree to rounding: measured
# ≤ 9e-15 N·m on torques of ≤ 40 N·m and ≤ 8e-14 rad/s² on accelerations
# (forward dynamics effectively solves with M, whose condition number reaches
# 8e4 for the PUMA, 8e2 for the Panda), so 1e-12 leaves an order of margin and
# still catches any wrong term (the smallest Coriolis terms exceed 1e-4).
TOL = 1e-12
# Peer numbers (Pinocchio), the criterion: joint torques to 1e-10.
PEER_TOL = 1e-10
# Corke's published PUMA 560 gravity load is printed to 4 decimals.
PUBLISHED_TOL = 5e-5


@pytest.fixture(scope="module")
def chains():
    return {name: robot.load(ROBOTS / name) for name in EXAMPLES}


def random_states(n, batch, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.5, 1.5, (3, batch, n))


# -- the planar two-link arm in closed form ---------------------------------------


def planar_closed_form(q, qd, qdd, g=9.81):
    """Spong, Hutchinson & Vidyasagar (2006) §7.3.2: two uniform rods, l = 1 m, m = 1 kg, lc = l/2, I = m l²/12."""
    m, l, lc, inertia = 1.0, 1.0, 0.5, 1.0 / 12.0
    c2, s2 = np.cos(q[1]), np.sin(q[1])
    m11 = m * lc**2 + inertia + m * (l**2 + lc**2 + 2 * l * lc * c2) + inertia
    m12 = m * (lc**2 + l * lc * c2) + inertia
    m22 = m * lc**2 + inertia
    h = -m * l * lc * s2
    M = np.array([[m11, m12], [m12, m22]])
    C = np.array([h * qd[1] * (2 * qd[0] + qd[1]), -h * qd[0] ** 2])
    G = np.array([(m * lc + m * l) * g * np.cos(q[0]) + m * lc * g * np.cos(q[0] + q[1]),
                  m * lc * g * np.cos(q[0] + q[1])])
    return M, C, G


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_planar_arm_matches_closed_form(chains, seed):
    chain = chains["planar_2link.toml"]
    q, qd, qdd = random_states(2, 1, seed)[:, 0]
    M, C, G = planar_closed_form(q, qd, qdd)
    np.testing.assert_allclose(robot.rnea(chain, q, qd, qdd), M @ qdd + C + G, rtol=0, atol=TOL)
    np.testing.assert_allclose(robot.mass_matrix(chain, q), M, rtol=0, atol=TOL)
    np.testing.assert_allclose(robot.coriolis(chain, q, qd), C, rtol=0, atol=TOL)
    np.testing.assert_allclose(robot.gravity_torques(chain, q), G, rtol=0, atol=TOL)
    np.testing.assert_allclose(robot.forward_dynamics(chain, q, qd, M @ qdd + C + G), qdd, rtol=0, atol=TOL)


def test_planar_arm_tip_wrench_is_minus_jacobian_transpose(chains):
    """A wrench (f, n) on the tip, in tip axes: τ = −Jᵀ F_base − [1, 1] n_z at rest without gravity."""
    chain = chains["planar_2link.toml"]
    q = np.array([0.4, -1.1])
    wrench = np.array([2.0, -3.0, 0.0, 0.0, 0.0, 0.7])
    s1, c1, s12, c12 = np.sin(q[0]), np.cos(q[0]), np.sin(q.sum()), np.cos(q.sum())
    J = np.array([[-s1 - s12, -s12], [c1 + c12, c12]])
    f_base = np.array([[c12, -s12], [s12, c12]]) @ wrench[:2]
    expected = -J.T @ f_base - wrench[5]
    zero = np.zeros(2)
    tau = robot.rnea(chain, q, zero, zero, gravity=np.zeros(3), f_ext=wrench)
    np.testing.assert_allclose(tau, expected, rtol=0, atol=TOL)
    # forward dynamics with the same wrench undoes it
    qdd = robot.forward_dynamics(chain, q, zero, tau, gravity=np.zeros(3), f_ext=wrench)
    np.testing.assert_allclose(qdd, zero, rtol=0, atol=TOL)


def test_modified_dh_describes_the_same_planar_arm(chains):
    """Craig's frames sit on the joints (com at +l/2 from joint i), the standard ones at the link ends (−l/2)."""
    rod = np.diag([1e-4, 1.0 / 12.0, 1.0 / 12.0])
    rows = [dict(a=0.0, mass=1.0, com=[0.5, 0, 0], inertia=rod), dict(a=1.0, mass=1.0, com=[0.5, 0, 0], inertia=rod)]
    modified = robot.SerialChain.from_dh(rows, convention="modified", gravity=(0.0, -9.81, 0.0))
    standard = chains["planar_2link.toml"]
    Q, QD, QDD = random_states(2, 4, seed=5)
    np.testing.assert_allclose(robot.rnea(modified, Q, QD, QDD), robot.rnea(standard, Q, QD, QDD), rtol=0, atol=TOL)
    # link frame 2 of Craig = the elbow = link frame 1 of the standard table
    np.testing.assert_allclose(robot.link_poses(modified, Q)[:, 1, :3, 3], robot.link_poses(standard, Q)[:, 0, :3, 3],
                               rtol=0, atol=TOL)


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_prismatic_dh_joint(convention):
    """A vertical slider (d = q + 0.3) carrying 2 kg under a revolute joint: τ₂ = m (q̈ + g), frame at height d."""
    rows = [dict(mass=1.0, inertia=np.eye(3)),
            dict(joint="prismatic", d=0.3, theta=0.4, mass=2.0, inertia=0.1 * np.eye(3))]
    chain = robot.SerialChain.from_dh(rows, convention=convention)
    q, qd, qdd = np.array([0.7, 0.2]), np.array([0.0, 0.5]), np.array([0.0, 1.5])
    np.testing.assert_allclose(robot.rnea(chain, q, qd, qdd)[1], 2.0 * (1.5 + 9.81), rtol=0, atol=TOL)
    T = robot.link_poses(chain, q)
    np.testing.assert_allclose(T[1, 2, 3], 0.5, rtol=0, atol=TOL)
    np.testing.assert_allclose(T[1, :2, :2], [[np.cos(1.1), -np.sin(1.1)], [np.sin(1.1), np.cos(1.1)]], rtol=0,
                               atol=TOL)


@pytest.mark.parametrize("name", ["puma560.toml", "panda.toml"])
def test_revolute_dh_offsets_shift_the_joint_variable(name):
    """``theta`` of a revolute row is an offset, θ = q + theta: the table with offsets at q is the table
    without them at q + theta (standard DH for the PUMA, modified for the Panda)."""
    import tomllib

    doc = tomllib.loads((ROBOTS / name).read_text())
    offsets = np.linspace(-0.9, 1.2, len(doc["link"]))
    shifted = [{**row, "theta": float(x)} for row, x in zip(doc["link"], offsets)]
    kwargs = dict(convention=doc["convention"], check_triangle=doc.get("check_triangle", True))
    plain, offset = robot.SerialChain.from_dh(doc["link"], **kwargs), robot.SerialChain.from_dh(shifted, **kwargs)
    Q, QD, QDD = random_states(plain.dof, 4, seed=13)
    np.testing.assert_allclose(robot.rnea(offset, Q, QD, QDD), robot.rnea(plain, Q + offsets, QD, QDD), rtol=0,
                               atol=TOL)
    np.testing.assert_allclose(robot.link_poses(offset, Q), robot.link_poses(plain, Q + offsets), rtol=0, atol=TOL)
    assert np.abs(robot.rnea(offset, Q, QD, QDD) - robot.rnea(plain, Q, QD, QDD)).max() > 0.1  # offsets matter


# -- identities on every example robot ---------------------------------------------


@pytest.mark.parametrize("name", EXAMPLES)
def test_identities(chains, name):
    chain = chains[name]
    n = chain.dof
    Q, QD, QDD = random_states(n, 8, seed=len(name))
    tau = robot.rnea(chain, Q, QD, QDD)
    # the batch equals the single calls
    np.testing.assert_array_equal(tau[3], robot.rnea(chain, Q[3], QD[3], QDD[3]))
    # forward dynamics inverts inverse dynamics
    np.testing.assert_allclose(robot.forward_dynamics(chain, Q, QD, tau), QDD, rtol=0, atol=TOL)
    np.testing.assert_allclose(robot.forward_dynamics(chain, Q[3], QD[3], tau[3]), QDD[3], rtol=0, atol=TOL)
    # gravity and Coriolis terms
    G = robot.gravity_torques(chain, Q)
    zero = np.zeros_like(Q)
    np.testing.assert_array_equal(G, robot.rnea(chain, Q, zero, zero))
    np.testing.assert_allclose(robot.coriolis(chain, Q, QD), robot.rnea(chain, Q, QD, zero) - G, rtol=0, atol=TOL)
    # M from the CRBA = columns of rnea(q, 0, e_i) − g(q); symmetric positive definite; T = ½ q̇ᵀ M q̇
    M = robot.mass_matrix(chain, Q)
    np.testing.assert_array_equal(M[3], robot.mass_matrix(chain, Q[3]))
    for b in (0, 5):
        columns = robot.rnea(chain, np.repeat(Q[b:b + 1], n, 0), np.zeros((n, n)), np.eye(n)) - G[b]
        np.testing.assert_allclose(M[b], columns.T, rtol=0, atol=TOL)
    np.testing.assert_array_equal(M, np.swapaxes(M, -1, -2))
    assert (np.linalg.eigvalsh(M)[:, 0] > 0.0).all()
    kinetic = 0.5 * np.einsum("bi,bij,bj->b", QD, M, QD)
    np.testing.assert_allclose(robot.kinetic_energy(chain, Q, QD), kinetic, rtol=TOL, atol=0)
    # τ = M q̈ + C q̇ + g
    np.testing.assert_allclose(tau, np.einsum("bij,bj->bi", M, QDD) + robot.coriolis(chain, Q, QD) + G,
                               rtol=0, atol=TOL)


@pytest.mark.parametrize("name", EXAMPLES)
def test_gravity_torques_are_the_gradient_of_the_potential(chains, name):
    """g(q) = ∂V/∂q, by central differences (error O(h²) ≈ 1e-9 at h = 1e-5 on V ≈ 10–100 J)."""
    chain = chains[name]
    q = random_states(chain.dof, 1, seed=7)[0, 0]
    h = 1e-5
    steps = q + h * np.eye(chain.dof)[:, None, :] * np.array([1.0, -1.0])[None, :, None]  # (n, ±, n)
    V = robot.potential_energy(chain, steps.reshape(-1, chain.dof)).reshape(chain.dof, 2)
    np.testing.assert_allclose(robot.gravity_torques(chain, q), (V[:, 0] - V[:, 1]) / (2 * h), rtol=0, atol=1e-7)


def test_dh_and_urdf_descriptions_of_the_panda_agree(chains):
    dh, urdf = chains["panda.toml"], chains["panda.urdf"]
    Q, QD, QDD = random_states(7, 8, seed=11)
    np.testing.assert_allclose(robot.rnea(dh, Q, QD, QDD), robot.rnea(urdf, Q, QD, QDD), rtol=0, atol=TOL)
    np.testing.assert_allclose(robot.mass_matrix(dh, Q), robot.mass_matrix(urdf, Q), rtol=0, atol=TOL)
    np.testing.assert_allclose(robot.link_poses(dh, Q), robot.link_poses(urdf, Q), rtol=0, atol=TOL)
    wrench = np.array([1.0, -2.0, 3.0, 0.1, -0.2, 0.3])
    np.testing.assert_allclose(robot.rnea(dh, Q, QD, QDD, f_ext=wrench), robot.rnea(urdf, Q, QD, QDD, f_ext=wrench),
                               rtol=0, atol=TOL)


# -- independently computed and published values -------------------------------------
#
# Reference torques computed once with Pinocchio 4.1.0 (NumPy 2.4.6) by
# benchmarks/robot_pinocchio_reference.py (run from the repository root):
#   Panda: model = pinocchio.buildModelFromUrdf("examples/robots/panda.urdf") (Pinocchio's own URDF
#          parser), model.gravity.linear = (0, 0, -9.81), tau = pinocchio.rnea(model, data, q, qd, qdd).
#   PUMA 560: a pinocchio.Model built joint by joint from the DH rows of examples/robots/puma560.toml:
#          joint i = JointModelRZ placed at Tz(d) Tx(a) Rx(alpha) of row i-1 in joint i-1's frame; the
#          link's pinocchio.Inertia(mass, R c + p, R I Rᵀ), (R, p) = Tz(d) Tx(a) Rx(alpha) of row i.
PEER_CASES = [
    ("panda.urdf", [0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398], [0.0] * 7, [0.0] * 7,
     [-5.551115123125783e-17, -1.771378227990962, -0.6440002231433408, 18.573588778066053,
      0.633846197802294, 1.693684735327046, 1.617035850281882e-17]),
    ("panda.urdf", [0.3, -0.5, 0.7, -1.9, 0.4, 1.2, -0.6], [0.5, -0.4, 0.3, 0.8, -1.1, 0.6, 1.4],
     [1.0, -2.0, 0.5, 1.5, -0.7, 2.2, -1.3],
     [3.3717780427597326, -8.304059600777709, -6.182940720209714, 19.810131100444806,
      1.0216660818013867, 1.4502881457934618, -0.0571095838123204]),
    ("panda.toml", [0.3, -0.5, 0.7, -1.9, 0.4, 1.2, -0.6], [0.5, -0.4, 0.3, 0.8, -1.1, 0.6, 1.4],
     [1.0, -2.0, 0.5, 1.5, -0.7, 2.2, -1.3],
     [3.3717780427597326, -8.304059600777709, -6.182940720209714, 19.810131100444806,
      1.0216660818013867, 1.4502881457934618, -0.0571095838123204]),
    ("puma560.toml", [0.2, -0.4, 0.6, -0.8, 1.0, -1.2], [1.0, 0.5, -0.5, 0.8, -0.3, 1.2],
     [0.3, -0.6, 0.9, -1.2, 1.5, -1.8],
     [1.0334840831934886, 32.16860613560576, -0.9441295299290471, -0.0046594124400126825,
      -0.023080754207674345, -8.518703202922292e-05]),
]


@pytest.mark.parametrize("name, q, qd, qdd, expected", PEER_CASES, ids=[c[0] for c in PEER_CASES])
def test_torques_match_pinocchio(chains, name, q, qd, qdd, expected):
    np.testing.assert_allclose(robot.rnea(chains[name], q, qd, qdd), expected, rtol=0, atol=PEER_TOL)


def test_puma560_gravity_load_matches_corke():
    """Corke, *Robotics, Vision and Control* (2nd ed. 2017), ch. 9, gravity term:
    ``p560.gravload(qn)`` = 0 31.6399 6.0351 0 0.0283 0."""
    chain = robot.load(ROBOTS / "puma560.toml")
    qn = [0.0, np.pi / 4, np.pi, 0.0, np.pi / 4, 0.0]
    np.testing.assert_allclose(robot.gravity_torques(chain, qn), [0.0, 31.6399, 6.0351, 0.0, 0.0283, 0.0],
                               rtol=0, atol=PUBLISHED_TOL)


# -- the model ---------------------------------------------------------------------------


def test_published_inertias_need_the_triangle_opt_out():
    doc_rows = [dict(alpha=np.pi / 2, mass=4.8, inertia=np.diag([0.066, 0.086, 0.0125]), name="elbow")]
    with pytest.raises(ValidationError, match=r"link 'elbow'\.inertia: .*triangle inequality"):
        robot.SerialChain.from_dh(doc_rows)
    chain = robot.SerialChain.from_dh(doc_rows, check_triangle=False)
    np.testing.assert_array_equal(chain.links[0].inertia, np.diag([0.066, 0.086, 0.0125]))


@pytest.mark.parametrize("row, message", [
    (dict(mass=-1.0), r"link 'joint1'\.mass: must be >= 0"),
    (dict(inertia=[[1, 2, 0], [0, 1, 0], [0, 0, 1]]), r"link 'joint1'\.inertia: must be symmetric"),
    (dict(inertia=np.diag([1.0, 1.0, -1.0])), r"link 'joint1'\.inertia: must be positive semi-definite"),
    (dict(joint="ball"), r"link 'joint1'\.joint: must be one of"),
    (dict(a=np.nan), r"links\[0\]\.a: must be finite"),
    (dict(limits=[1.0, -1.0]), r"lower <= upper"),
    (dict(color="red"), r"links\[0\]: unknown key\(s\) \['color'\]"),
])
def test_bad_dh_rows_are_refused_naming_the_field(row, message):
    with pytest.raises(ValidationError, match=message):
        robot.SerialChain.from_dh([row])


@pytest.mark.parametrize("text, message", [
    ('check_triangle = "false"\n[[link]]\nmass = 1.0', r"arm\.toml: check_triangle must be true or false, got 'false'"),
    ('convention = "craig"\n[[link]]\nmass = 1.0', r"convention: must be 'standard' or 'modified'"),
    ('colour = "red"\n[[link]]\nmass = 1.0', r"arm\.toml: unknown key\(s\) \['colour'\]"),
    ('name = "empty"', r"arm\.toml: needs at least one \[\[link\]\] table"),
    ('[[link]\nmass = 1.0', r"arm\.toml: malformed TOML"),
])
def test_bad_robot_files_are_refused_naming_the_key(tmp_path, text, message):
    path = tmp_path / "arm.toml"
    path.write_text(text)
    with pytest.raises(ValidationError, match=message):
        robot.load(path)


def test_bad_states_are_refused_naming_the_input(chains):
    chain = chains["puma560.toml"]
    q = np.zeros(6)
    with pytest.raises(ValidationError, match=r"qd: must have shape \(6,\) or \(B, 6\)"):
        robot.rnea(chain, q, np.zeros(5), q)
    with pytest.raises(ValidationError, match=r"qdd: must be finite \(found nan at index 2\)"):
        robot.rnea(chain, q, q, [0, 0, np.nan, 0, 0, 0])
    with pytest.raises(ValidationError, match=r"tau: must be finite"):
        robot.forward_dynamics(chain, q, q, [0, 0, 0, np.inf, 0, 0])
    with pytest.raises(ValidationError, match=r"f_ext: must have shape"):
        robot.rnea(chain, q, q, q, f_ext=np.zeros(3))


def test_singular_chain_is_reported():
    """A last link with no mass and no inertia makes M singular: forward dynamics says so instead of returning NaN."""
    chain = robot.SerialChain.from_dh([dict(a=1.0, mass=1.0, inertia=np.eye(3)), dict(a=1.0)])
    with pytest.raises(ValidationError, match=r"forward_dynamics: the result is not finite .* singular"):
        robot.forward_dynamics(chain, np.zeros(2), np.zeros(2), np.ones(2))


def test_limits_and_immutability(chains):
    chain = chains["panda.toml"]
    assert chain.within_limits(np.zeros(7)) is False  # joint 4 must be in [-3.0718, -0.0698]
    q = np.array([[0, 0, 0, -1.0, 0, 1.0, 0], [0, 0, 0, -1.0, 0, 4.0, 0]])
    np.testing.assert_array_equal(chain.within_limits(q), [True, False])
    np.testing.assert_array_equal(chain.lower[3:5], [-3.0718, -2.8973])
    with pytest.raises(AttributeError):
        chain.gravity = np.zeros(3)
    with pytest.raises(ValueError):
        chain.links[0].com[0] = 1.0
