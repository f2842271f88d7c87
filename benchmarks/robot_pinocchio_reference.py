"""Reference joint torques for tests/test_robot.py, computed once with Pinocchio 4.1.0 (NumPy 2.4.6).

Panda: pinocchio.buildModelFromUrdf("examples/robots/panda.urdf") (Pinocchio's own URDF parser).
PUMA 560: a Pinocchio model built here from the standard DH table of examples/robots/puma560.toml:
joint i is a revolute-Z joint placed at Tz(d_{i-1}) Tx(a_{i-1}) Rx(alpha_{i-1}) in joint i-1's frame;
the link inertia given in DH frame i (= joint frame i moved by Tz(d_i) Tx(a_i) Rx(alpha_i)) is moved to joint frame i.
"""
import numpy as np
import pinocchio as pin
import tomllib

np.set_printoptions(precision=17)


def report(model, states):
    data = model.createData()
    for q, qd, qdd in states:
        tau = pin.rnea(model, data, np.array(q), np.array(qd), np.array(qdd))
        print("q", q, "qd", qd, "qdd", qdd)
        print("tau", [float(x) for x in tau])


def dh(a, alpha, d):
    return pin.SE3(np.eye(3), np.array([0, 0, d])) * pin.SE3(np.eye(3), np.array([a, 0, 0])) * \
        pin.SE3(pin.utils.rotate("x", alpha), np.zeros(3))


panda = pin.buildModelFromUrdf("examples/robots/panda.urdf")
panda.gravity.linear[:] = [0, 0, -9.81]
print(pin.__version__, np.__version__)
print("panda")
report(panda, [
    ([0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398], [0.0] * 7, [0.0] * 7),
    ([0.3, -0.5, 0.7, -1.9, 0.4, 1.2, -0.6], [0.5, -0.4, 0.3, 0.8, -1.1, 0.6, 1.4], [1.0, -2.0, 0.5, 1.5, -0.7, 2.2, -1.3]),
])

doc = tomllib.load(open("examples/robots/puma560.toml", "rb"))
puma = pin.Model()
parent, placement = 0, pin.SE3.Identity()
for k, row in enumerate(doc["link"]):
    jid = puma.addJoint(parent, pin.JointModelRZ(), placement, row["name"])
    post = dh(row.get("a", 0.0), row.get("alpha", 0.0), row.get("d", 0.0))
    I = np.array(row["inertia"])
    com = np.array(row.get("com", [0.0, 0.0, 0.0]))
    inertia = pin.Inertia(row["mass"], post.rotation @ com + post.translation, post.rotation @ I @ post.rotation.T)
    puma.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
    parent, placement = jid, post
puma.gravity.linear[:] = [0, 0, -9.81]
print("puma")
report(puma, [
    ([0.0, 0.7853981633974483, 3.141592653589793, 0.0, 0.7853981633974483, 0.0], [0.0] * 6, [0.0] * 6),
    ([0.2, -0.4, 0.6, -0.8, 1.0, -1.2], [1.0, 0.5, -0.5, 0.8, -0.3, 1.2], [0.3, -0.6, 0.9, -1.2, 1.5, -1.8]),
])
