"""Reference numbers for tests/robot/test_robot.py and tests/robot/test_robot_urdf.py, computed once with Pinocchio 4.1.0.

Run from the repository root: ``python benchmarks/robot_pinocchio_reference.py`` (NumPy 2.4.6).

Panda: pinocchio.buildModelFromUrdf("src/tumble/examples/robots/panda.urdf") (Pinocchio's own URDF parser).
PUMA 560: a Pinocchio model built here from the standard DH table of src/tumble/examples/robots/puma560.toml:
joint i is a revolute-Z joint placed at Tz(d_{i-1}) Tx(a_{i-1}) Rx(alpha_{i-1}) in joint i-1's frame;
the link inertia given in DH frame i (= joint frame i moved by Tz(d_i) Tx(a_i) Rx(alpha_i)) is moved to joint frame i.
Peer arm: tests/test_robot_urdf.PEER_URDF through pinocchio.buildModelFromXML (its continuous joint has
Pinocchio coordinates (cos q, sin q)); rnea and aba with the wrench as the fext of the last joint, and crba.
"""
import sys
import tomllib

import numpy as np
import pinocchio as pin

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


panda = pin.buildModelFromUrdf("src/tumble/examples/robots/panda.urdf")
panda.gravity.linear[:] = [0, 0, -9.81]
print(pin.__version__, np.__version__)
print("panda")
report(panda, [
    ([0.0, -0.785398, 0.0, -2.356194, 0.0, 1.570796, 0.785398], [0.0] * 7, [0.0] * 7),
    ([0.3, -0.5, 0.7, -1.9, 0.4, 1.2, -0.6], [0.5, -0.4, 0.3, 0.8, -1.1, 0.6, 1.4], [1.0, -2.0, 0.5, 1.5, -0.7, 2.2, -1.3]),
])

doc = tomllib.load(open("src/tumble/examples/robots/puma560.toml", "rb"))
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

sys.path.insert(0, "tests/robot")
from test_robot_urdf import PEER_STATE, PEER_URDF  # noqa: E402

arm = pin.buildModelFromXML(PEER_URDF)
arm.gravity.linear[:] = [0, 0, -9.81]
data = arm.createData()
q, qd, qdd, w = (np.array(PEER_STATE[k]) for k in ("q", "qd", "qdd", "f_ext"))
q_pin = np.array([np.cos(q[0]), np.sin(q[0]), *q[1:]])  # joint j1 is continuous: (cos, sin)
fext = [pin.Force.Zero() for _ in range(arm.njoints)]
fext[-1] = pin.Force(w[:3], w[3:])  # linear, angular: in the frame of the last joint (URDF link "d")
print("peer arm", [j.shortname() for j in arm.joints])
print({"tau": [float(x) for x in pin.rnea(arm, data, q_pin, qd, qdd)],
       "tau_wrench": [float(x) for x in pin.rnea(arm, data, q_pin, qd, qdd, fext)],
       "M": [[float(x) for x in row] for row in pin.crba(arm, data, q_pin)],
       "aba_wrench": [float(x) for x in pin.aba(arm, data, q_pin, qd, qdd, fext)]})
