"""Every model kind on the GPU (tumble.integrate._cuda's protocol kernel), without a GPU.

Each case runs ``tumble.simulate(..., device="cuda")`` under Numba's CUDA
simulator (``NUMBA_ENABLE_CUDASIM=1``, read when Numba is imported: in a child
process) and compares it with the CPU's run bit for bit: the simulator rounds
as the CPU does (no fused multiply–adds), and each thread's steps are the
method's own compiled ``advance``. So the simulator checks the driver (launch,
landing on the output times, each member's rows of the workspace, the model's
transfer, the output) and the front door. That the same kernel compiles for a
GPU, calls no Python and allocates nothing, it cannot see: the PTX tests below
compile it for sm_90 with NVVM, where the CUDA toolkit is installed.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from helpers import compile_ptx, nvvm_available

import tumble
from tumble import robot, torques
from tumble.axisymmetric import AxisymmetricBody
from tumble.flexible import FlexibleBody, Mode
from tumble.fluid import KirchhoffBody
from tumble.ins import GimbaledGyro
from tumble.simulate import as_model
from tumble.slosh import Pendulum, SloshBody
from tumble.spacecraft import FlexibleModes, FlightSoftware, MRPFeedback, QuaternionPD, Spacecraft, pyramid_wheels
from tumble.variable import Human, Motion, VariableBody

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])  # kg·m², body axes
TARGET = [np.cos(0.2), 0.0, np.sin(0.2), 0.0]
T = np.array([0.0, 0.02, 0.06, 0.12])  # 2, 4 and 6 steps of DT (a sampled controller needs whole steps)
DT = 0.01
OMEGA0 = np.array([[0.3, 1.0, -0.4], [-0.5, 0.2, 0.9]])  # two members, rad/s, body axes
EPS = np.finfo(np.float64).eps
TORQUE = torques.ConstantBody([0.05, -0.02, 0.1]) + torques.ConstantInertial([0.0, 0.03, -0.01])


def branching_tree():
    """A free hub (floating base) with two arms on opposite sides, of two links and of one: a small tree that
    branches."""
    def arm_link(mass, origin, com):
        return robot.Link(joint="revolute", axis=(0, 0, 1), origin_position=origin, mass=mass, com=com,
                          inertia=np.diag([0.01, 0.3, 0.3]) * mass)

    hub = robot.Link(joint="floating", mass=50.0, com=(0.0, 0.0, 0.0), inertia=np.diag([20.0, 25.0, 8.0]))
    links = [hub, arm_link(4.0, (0.5, 0.0, 0.0), (0.5, 0.0, 0.0)), arm_link(2.0, (1.0, 0.0, 0.0), (0.4, 0.0, 0.0)),
             arm_link(3.0, (-0.5, 0.0, 0.0), (-0.3, 0.0, 0.0))]
    return robot.RobotTree(links, [-1, 0, 1, 0])


def growing_body():
    """A body whose inertia grows by 20 % a second while a shape momentum turns on: a VariableBody of splines."""
    def inertia(t):
        return INERTIA * (1.0 + 0.2 * np.asarray(t))[:, None, None]

    def shape_momentum(t):
        return np.outer(np.sin(np.asarray(t)), [0.5, -0.2, 0.3])

    return VariableBody.from_functions(inertia, shape_momentum, t_span=(0.0, 1.0), dt=0.01)


def cases():
    """name -> (model, method, torque, initial state): one of each model kind, two members each."""
    flexible = FlexibleBody(INERTIA, [Mode(3.0, 0.02, [0.3, 0.5, 0.2]), Mode(7.0, 0.01, [0.1, -0.4, 0.6])])
    slosh = SloshBody(tumble.RigidBody(INERTIA, mass=10.0), Pendulum(mass=2.0, length=0.5, hinge=[0.3, -0.2, 0.4],
                                                                       damping=0.1))
    wheels_mrp = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02),
                            controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))
    held_pd = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02, max_torque=0.1),
                         controller=QuaternionPD(0.2, 0.8, target=TARGET), control_period=0.02)
    modes = FlexibleModes([[0.3, 0.5, 0.2], [0.1, -0.4, 0.6]], [3.0, 7.0], [0.02, 0.01])
    flexible_craft = Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), flexible_modes=modes,
                                controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))
    rigid = [tumble.RigidBody(INERTIA), tumble.RigidBody(np.diag([1.0, 2.0, 2.5]))]
    added_mass = np.diag([5.0, 8.0, 12.0, 1.0, 1.5, 2.0])
    added_mass[0, 4] = added_mass[4, 0] = 0.8  # surge–pitch coupling: B ≠ 0
    fluid = KirchhoffBody(tumble.RigidBody(INERTIA, mass=10.0), added_mass)
    oblate = AxisymmetricBody(tumble.RigidBody(np.diag([8.0, 8.0, 12.0])))  # kg·m², body axes
    wheel_speeds = {"wheel_speeds0": [[10.0, -5.0, 3.0, 0.0], [0.0, 20.0, -8.0, 4.0]]}
    diver = Human.de_leva().moving({"left_shoulder_abduction": Motion(np.pi, [(0.0, 1.0, 0.0)])}, t_span=(0.0, 1.0))
    gyro = GimbaledGyro(spin_inertia=2e-3, transverse_inertia=1.5e-3, inner_gimbal=(4e-4, 5e-4, 3e-4),
                        outer_gimbal=1e-3, imbalance=0.01, spin_friction=1e-4)
    return {
        "flexible, rk4": (flexible, "rk4", TORQUE, {"eta0": [[0.1, -0.05], [0.0, 0.2]], "eta_rate0": [0.3, 0.0]}),
        "flexible, cf4": (flexible, "cf4", None, {"eta0": [[0.1, -0.05], [0.0, 0.2]]}),
        "fluid, cf4": (fluid, "cf4", None, {"velocity0": [[1.0, 0.2, -0.3], [0.0, -0.5, 0.4]]}),
        "slosh, rk4": (slosh, "rk4", TORQUE, {"direction0": [[0.0, 0.0, -1.0], [0.3, 0.1, -1.0]],
                                              "rate0": [0.2, -0.1, 0.0]}),
        "spacecraft: wheels, MRP feedback, rk4": (wheels_mrp, "rk4", None, wheel_speeds),
        "spacecraft: wheels, sampled PD, cf4": (held_pd, "cf4", TORQUE, wheel_speeds),
        "spacecraft: wheels, MRP feedback, flexible modes, rk4": (flexible_craft, "rk4", TORQUE,
                                                                  {**wheel_speeds, "eta0": [[0.1, -0.05], [0.0, 0.2]]}),
        "rigid, one body each, cf4": (rigid, "cf4", TORQUE, {}),
        # the frame does not spin with the body, whose attitude is no state: rk4 only (cf4 needs a body rate)
        "axisymmetric body in a non-spinning frame, rk4": (oblate, "rk4", TORQUE, {}),
        "variable inertia, rk4": (growing_body(), "rk4", TORQUE, {}),
        "variable inertia, cf4": (growing_body(), "cf4", None, {}),
        "moving human, rk4": (diver, "rk4", None, {}),
        "moving human, cf4": (diver, "cf4", TORQUE, {}),
        # the gimbal's state has no body rate (cf4's need): rk4 only; its omega is the rotor's rate
        "gimbaled gyro, rk4": (gyro, "rk4", None, {"spin": [[100.0], [-60.0]], "theta0": [[1.0], [0.6]],
                                                   "phi_dot0": [[0.5], [-0.2]]}),
        # robots provide no body rate (cf4's need): rk4 only
        "robot: planar two-link chain, rk4": (robot.load(tumble.examples.directory() / "robots/planar_2link.toml"),
                                              "rk4", [1.0, -0.5], {"q0": [[0.3, -0.5], [1.0, 0.2]],
                                                                   "qd0": [[0.1, 0.4], [-0.3, 0.0]]}),
        "robot: a branching tree on a free hub, rk4": (branching_tree(), "rk4", [0.3, -0.2, 0.5], {
            "q0": [[0.4, -0.6, 0.2], [0.1, 0.2, -0.3]], "qd0": [[0.1, -0.2, 0.0], [0.3, 0.0, 0.4]],
            "base_omega0": [[0.0, 0.0, 0.05], [0.02, -0.01, 0.0]], "base_velocity0": [0.1, 0.0, -0.05]}),
    }


def _run(device, name):
    """The run's positions and rates: ``q`` and ``omega`` (the bodies), or a robot's joint coordinates and rates
    (with a floating base, the base's attitude and rates first); and its statistics."""
    model, method, torque, state = cases()[name]
    if isinstance(model, robot.RobotTree):
        traj = tumble.simulate(model, t=T, method=method, dt=DT, torque=torque, device=device, **state)
        base = model.floating_base
        motion = {"q": np.concatenate([traj.base_attitude, traj.joint_position], axis=-1) if base
                  else traj.joint_position,
                  "omega": np.concatenate([traj.base_omega, traj.base_velocity, traj.joint_velocity], axis=-1)
                  if base else traj.joint_velocity}
    else:
        rate = {} if isinstance(model, GimbaledGyro) else {"omega0": OMEGA0}  # a gimbal starts from its rates
        traj = tumble.simulate(model, t=T, method=method, dt=DT, torque=torque, device=device, **rate, **state)
        motion = {"q": traj.q, "omega": traj.omega}
    return {**motion, **{k: traj.info[k] for k in ("n_steps", "n_rhs")}}


#: The cases whose model keeps its attitude in its state (``Model.attitude_in_state``): with ``output="device"``
#: their ``q`` and ``omega`` are made on the GPU, the rest on the host by ``to_host()``.
LEFT_ON_THE_GPU = [name for name, (model, *_) in cases().items()
                   if not isinstance(model, list) and as_model(model).attitude_in_state]

#: The body rate on the GPU is the kernel's (``body_rate``): a slice of the state, but for these, where the host
#: computes ``ω = W [K; P]`` with NumPy's ``@`` and ``ω = I(t)⁻¹ (L_B − A)`` with ``numpy.linalg.solve``, the
#: kernel by sums in order and Cramer's rule (tumble.kernels.variable.angular_rate).
RATES_BY_OTHER_SUMS = {"fluid, cf4", "variable inertia, rk4", "variable inertia, cf4", "moving human, rk4",
                       "moving human, cf4"}


def _left_on_the_gpu(name):
    """``simulate(..., output="device")`` of case ``name``: its ``q`` and ``omega`` as the GPU holds them, and its
    whole trajectory copied back (``to_host()``): ``q``, ``omega``, the totals and every extra, by name."""
    model, method, torque, state = cases()[name]
    traj = tumble.simulate(model, OMEGA0, t=T, method=method, dt=DT, torque=torque, device="cuda", output="device",
                           **state)
    assert traj.on_device and traj.rest_on_host
    host = traj.to_host()
    return {"device q": traj.q.copy_to_host(), "device omega": traj.omega.copy_to_host(), **_fields(host)}


def _fields(traj):
    """A trajectory's sampled arrays by name: ``q``, ``omega``, ``energy``, ``momentum_body`` and each extra."""
    return {"q": traj.q, "omega": traj.omega, "energy": traj.energy, "momentum_body": traj.momentum_body,
            **{f"extra {name}": e.data for name, e in traj.extras.items()}}


# In the child, with the simulator on: each case's GPU run into one .npz.
_CHILD = """
import os
import sys
import numpy as np
import runpy
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(sys.argv[1]))))  # tests/: its helpers
module = runpy.run_path(sys.argv[1])
out = {}
for i, name in enumerate(module["cases"]()):
    for key, value in module["_run"]("cuda", name).items():
        out[f"{i}/{key}"] = value
    if name in module["LEFT_ON_THE_GPU"]:
        for key, value in module["_left_on_the_gpu"](name).items():
            out[f"{i}/left/{key}"] = value
np.savez(sys.argv[2], **out)
"""


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """name -> the simulated GPU run's arrays and statistics, every case in one child process."""
    out = tmp_path_factory.mktemp("cuda_models") / "gpu.npz"
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(tumble.__file__).parents[1]), env.get("PYTHONPATH", "")])
    subprocess.run([sys.executable, "-c", _CHILD, __file__, str(out)], env=env, check=True, timeout=900)
    with np.load(out) as runs:
        return {name: {key.removeprefix(f"{i}/"): runs[key] for key in runs.files if key.startswith(f"{i}/")}
                for i, name in enumerate(cases())}


@pytest.mark.slow
@pytest.mark.parametrize("name", list(cases()))
def test_simulated_gpu_equals_cpu(simulated, name):
    gpu, cpu = simulated[name], _run("cpu", name)
    np.testing.assert_array_equal(gpu["q"], cpu["q"])
    np.testing.assert_array_equal(gpu["omega"], cpu["omega"])
    assert int(gpu["n_steps"]) == cpu["n_steps"] == 2 * 12  # two members, 2 + 4 + 6 steps each
    assert int(gpu["n_rhs"]) == cpu["n_rhs"] == 4 * 2 * 12
    # the members differ, and they moved: the comparison sees each one's own path
    assert np.abs(cpu["omega"][-1, 0] - cpu["omega"][-1, 1]).max() > 1e-2
    assert np.abs(cpu["omega"][-1] - cpu["omega"][0]).max() > 1e-4


@pytest.mark.slow
@pytest.mark.parametrize("name", LEFT_ON_THE_GPU)
def test_results_left_on_the_gpu_equal_the_cpus(simulated, name):
    # output="device": q and omega made on the GPU; to_host() gives the CPU's whole trajectory, bit for bit
    left = {key.removeprefix("left/"): value for key, value in simulated[name].items() if key.startswith("left/")}
    model, method, torque, state = cases()[name]
    cpu = _fields(tumble.simulate(model, OMEGA0, t=T, method=method, dt=DT, torque=torque, **state))
    assert {key for key in left if not key.startswith("device ")} == set(cpu)
    for key, value in cpu.items():
        np.testing.assert_array_equal(left[key], value, err_msg=key)
    np.testing.assert_array_equal(left["device q"], cpu["q"])
    if name in RATES_BY_OTHER_SUMS:  # the same rate by other sums: a few units in the last place
        scale = np.abs(cpu["omega"]).max()
        np.testing.assert_allclose(left["device omega"], cpu["omega"], rtol=0, atol=8 * EPS * scale)
    else:  # a slice of the state
        np.testing.assert_array_equal(left["device omega"], cpu["omega"])


def test_output_device_is_refused_for_a_model_whose_attitude_is_not_its_state():
    chain = robot.load(tumble.examples.directory() / "robots/planar_2link.toml")
    with pytest.raises(tumble.ValidationError, match=r"^output: 'device' keeps on the GPU the results of rigid "
                                                     r"bodies and the q and omega of the models whose attitude is "
                                                     r"their state's \(docs/gpu.md\); a SerialChain's outputs are "
                                                     r"made on the host: use output='host'$"):
        tumble.simulate(chain, q0=[0.3, -0.5], t=T, method="rk4", dt=DT, device="cuda", output="device")


@pytest.mark.parametrize(("make", "message"), [
    (lambda: Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), control_period=0.1,
                        controller=QuaternionPD(0.2, 0.8, target=TARGET),
                        flight_software=FlightSoftware(1e-5, 1e-8, star_tracker_sigma=5e-5)),
     r"^flight_software: the flight software's MEKF allocates its matrices at every sample, which code on the "
     r"GPU cannot \(device='cuda'\); use device='cpu'$"),
    (lambda: Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), controller=lambda t, q, w, h: -w),
     r"^controller: a Python function cannot run on the GPU \(device='cuda'\)"),
    (lambda: FlexibleBody(INERTIA, [Mode(3.0, 0.02, [0.3, 0.5, 0.2])]),
     r"^torque: a Python function cannot run on the GPU \(device='cuda'\)"),
    (growing_body, r"^torque: a Python function cannot run on the GPU \(device='cuda'\)"),
])
def test_what_cannot_run_on_a_gpu_is_refused_naming_the_part(make, message):
    # refused before anything is compiled or launched, with or without a GPU
    model = make()
    torque = (lambda t, q, w: -w) if isinstance(model, (FlexibleBody, VariableBody)) else None
    with pytest.raises(tumble.ValidationError, match=message):
        tumble.simulate(model, OMEGA0[0], t=T, method="rk4", dt=DT, torque=torque, device="cuda")


def test_a_robot_under_a_python_torque_law_is_refused_naming_torque():
    chain = robot.load(tumble.examples.directory() / "robots/planar_2link.toml")
    with pytest.raises(tumble.ValidationError, match=r"^torque: a Python function cannot run on the GPU "
                                                     r"\(device='cuda'\); use the compiled models or device='cpu'$"):
        tumble.simulate(chain, q0=[0.3, -0.5], t=T, method="rk4", dt=DT, torque=lambda t, q, qd: -qd, device="cuda")


def test_a_compiled_model_without_a_device_path_is_refused_naming_device():
    # every model kind of simulate runs on a GPU; the heavy top's tangent equations (tumble.measure) do not
    from tumble.integrate import _cuda
    from tumble.kernels.tangent import TangentModel

    kernel = TangentModel(np.ones(3), np.array([0.0, 0.0, 1.0]), 1)
    assert "cuda" not in kernel.provides
    with pytest.raises(tumble.ValidationError, match=r"^device: 'cuda' cannot run a TangentModel: its compiled "
                                                     r"model does not run on a GPU$"):
        _cuda.check(kernel, "rk4", "a TangentModel")


def test_an_axisymmetric_body_under_a_python_torque_is_refused_on_a_gpu_naming_torque():
    body = AxisymmetricBody(tumble.RigidBody(np.diag([8.0, 8.0, 12.0])))
    with pytest.raises(tumble.ValidationError, match=r"^torque: a Python function cannot run on the GPU "
                                                     r"\(device='cuda'\)"):
        tumble.simulate(body, OMEGA0[0], t=T, method="rk4", dt=DT, torque=lambda t, q, w: -w, device="cuda")


def test_methods_without_a_device_kernel_are_refused():
    with pytest.raises(tumble.ValidationError, match=r"^device: 'cuda' runs the methods 'rk4', 'cf4'; "
                                                     r"got method='splitting2'$"):
        tumble.simulate(tumble.RigidBody(INERTIA), OMEGA0[0], t=T, method="splitting2", dt=DT, device="cuda")


# Each kind once, and each method once: a spacecraft is one compiled type whatever its parts and laws (the
# sampled laws' code is in every spacecraft kernel), so the spacecraft compiles with rk4 and cf4 with the rigid
# body (a spacecraft's PTX takes about 50 CPU s, and NVVM's output is not cached); the simulator runs every case.
@pytest.mark.slow
@pytest.mark.skipif(not nvvm_available(), reason="no NVVM (CUDA toolkit) to compile with")
@pytest.mark.parametrize("name", ["flexible, rk4", "slosh, rk4", "fluid, cf4", "spacecraft: wheels, MRP feedback, rk4",
                                  "rigid, one body each, cf4", "robot: planar two-link chain, rk4",
                                  "variable inertia, rk4", "moving human, cf4", "gimbaled gyro, rk4",
                                  "axisymmetric body in a non-spinning frame, rk4"])
def test_protocol_kernel_compiles_for_a_gpu(monkeypatch, name):
    """The protocol kernel of each kind types and compiles for sm_90: nothing in it calls Python or allocates."""
    from numba import typeof

    from tumble.integrate import _cuda

    model, method, torque, state = cases()[name]
    kernel = as_model(model).compile(torque, 0.0)
    scheme = _cuda.SCHEMES[method]
    n = _state_size(kernel)
    work = tuple(np.zeros((2, *w.shape)) for w in _cuda._workspace_of_one(scheme, kernel, np.zeros(n)))
    signature = tuple(typeof(a) for a in (scheme, kernel, np.zeros((2, n)), T, np.zeros(3, np.int64), T[1:],
                                          np.zeros((4, 2, n)), work))
    ptx = compile_ptx(monkeypatch, _cuda._protocol_kernel, signature)
    assert ptx.count(".entry") == 1
    assert "fma.rn.f64" in ptx  # NVVM's contraction: the GPU's results differ from the CPU's in the last bits


def _state_size(kernel):
    from numba import njit

    from tumble._protocol import state_size

    return njit(lambda k: state_size(k))(kernel)


@pytest.mark.slow
@pytest.mark.skipif(not nvvm_available(), reason="no NVVM (CUDA toolkit) to compile with")
@pytest.mark.parametrize("name", ["flexible, rk4", "fluid, cf4", "variable inertia, rk4"])
def test_attitude_and_rate_kernel_compiles_for_a_gpu(monkeypatch, name):
    """The kernel that makes q and omega of states left on the GPU (tumble.integrate._cuda_outputs) types and
    compiles for sm_90 with the kind's body_rate: a slice, sums of the state, Cramer's rule on a spline."""
    from numba import typeof

    from tumble.integrate import _cuda_outputs

    model, method, torque, state = cases()[name]
    kernel = as_model(model).compile(torque, 0.0)
    n = _state_size(kernel)
    signature = tuple(typeof(a) for a in (kernel, np.zeros((4, 2, n)), np.zeros((4, 2, 4)), np.zeros((4, 2, 3))))
    ptx = compile_ptx(monkeypatch, _cuda_outputs._attitude_and_rate_kernel, signature)
    assert ptx.count(".entry") == 1
    assert "malloc" not in ptx
