"""The spacecraft is compiled once: a new composition of parts, torque terms and control law is data.

``SpacecraftModel`` has one Numba type for every spacecraft (each part's field an int64, −1 when absent; the
torque program always arrays), so a spacecraft of other parts runs the integrators compiled for the first one.
Counted two ways: Numba's ``numba:compile`` events (fired by every compilation that the disk cache does not
answer) and the signatures of the compiled diagnostics (one per model type, cache hits included).
"""

from datetime import datetime, timezone

import numba
import numpy as np
import pytest
from numba.core import event

import tumble
from tumble import torques
from tumble.kernels import spacecraft as kernel
from tumble.kernels.spacecraft import _assembly
from tumble.spacecraft import (CMGCluster, Environment, FlexibleModes, MRPFeedback, Orbit, QuaternionPD,
                               ResidualDipole, SloshPendulum, Spacecraft, pyramid_wheels)
from tumble.spacecraft.surfaces import Drag, SolarPressure, box_facets

# The tests marked slow compile the spacecraft's kernels on a cold Numba cache (its assembled right-hand side
# alone ~25 CPU s, in every process that compiles a spacecraft driver); the spacecraft's modules run on one xdist
# worker (tests/conftest.py, KINDS), so that one process pays it.

INERTIA = np.array([[10.0, 0.3, -0.2], [0.3, 12.0, 0.1], [-0.2, 0.1, 8.0]])
T = np.linspace(0.0, 2.0, 3)
TARGET = [np.cos(0.2), 0.0, np.sin(0.2), 0.0]


def wheels_and_mrp():
    return Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02),
                      controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))


def wheels_cmgs_pd_dipole():
    return Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02, max_torque=0.1), cmgs=CMGCluster.pyramid(1.0),
                      magnetic_field=[2e-5, -1e-5, 3e-5], residual_dipole=ResidualDipole([0.5, 0.0, -0.2]),
                      controller=QuaternionPD(0.2, 0.8, target=TARGET))


def wheels_mrp_and_modes():
    return Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02),
                      flexible_modes=FlexibleModes([[0.0, 0.3, 0.5]], [2.0]),
                      controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))


def wheels_mrp_and_tanks():
    return Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02),
                      slosh=[SloshPendulum(2.0, 0.3, [0.4, 0.0, 0.0], 0.5), SloshPendulum(1.0, 0.2, [0.0, -0.3, 0.1])],
                      controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))


def environment_parts():
    env = Environment.sample(Orbit.circular(400e3, 0.9), datetime(2026, 6, 1, tzinfo=timezone.utc), duration=10.0,
                             step=5.0)
    faces = box_facets([1.0, 2.0, 1.5], centre_of_mass=[0.05, 0.0, -0.02], specular=0.2, diffuse=0.3, absorbed=0.5)
    return Spacecraft(inertia=INERTIA, wheels=pyramid_wheels(0.02), environment=env, gravity_gradient=True,
                      solar_pressure=SolarPressure(faces), drag=Drag(faces),
                      controller=MRPFeedback(K=1.0, P=5.0, target=TARGET))


def test_one_assembly_per_state_rank():
    """The right-hand side, the projection, the diagnostics and the start sample share one assembly of the
    compiled functions: however the arguments are spelled, a second assembly would compile them all again."""
    first = _assembly.assemble(1, False)
    assert first is _assembly.assemble(1, False, False) is _assembly.assemble(np.int64(1), 0, device=False)
    assert _assembly.assemble(2, False) is not first and _assembly.assemble(1, False, True) is not first


@pytest.mark.slow
def test_every_composition_has_one_numba_type():
    first = wheels_and_mrp().compile(None, 0.0)
    second = wheels_cmgs_pd_dipole().compile(torques.ConstantBody([1e-3, 0.0, -2e-3]), 0.0)
    assert numba.typeof(first) == numba.typeof(second) == numba.typeof(environment_parts().compile(None, 0.0))


@pytest.mark.slow
def test_a_new_composition_compiles_nothing():
    tumble.simulate(wheels_and_mrp(), [0.01, -0.02, 0.03], t=T, method="rk4", dt=0.1)
    signatures = len(kernel.evaluate.signatures)
    in_orbit = environment_parts()            # sampling the environment is not the spacecraft's compilation
    with event.install_recorder("numba:compile") as compiles:
        traj = tumble.simulate(wheels_cmgs_pd_dipole(), [0.01, -0.02, 0.03], t=T, method="rk4", dt=0.1,
                               torque=torques.ConstantBody([1e-3, 0.0, -2e-3]))
        env_traj = tumble.simulate(in_orbit, [0.01, -0.02, 0.03], t=T, method="rk4", dt=0.1)
        flexible = tumble.simulate(wheels_mrp_and_modes(), [0.01, -0.02, 0.03], eta0=[0.1], t=T, method="rk4",
                                   dt=0.1)
        sloshing = tumble.simulate(wheels_mrp_and_tanks(), [0.01, -0.02, 0.03],
                                   direction0=[1.0, 0.0, 0.0, 0.0, 0.0, 1.0], rate0=[0.0, 0.1, 0.0, 0.1, 0.0, 0.0],
                                   t=T, method="rk4", dt=0.1)
    assert [e.data["dispatcher"].py_func.__qualname__ for e in compiles.buffer if e.is_start] == []
    assert len(kernel.evaluate.signatures) == signatures
    np.testing.assert_array_equal(traj.external_torque[-1], [1e-3, 0.0, -2e-3])  # the new parts ran
    assert np.abs(traj.residual_dipole_torque).max() > 0.0
    assert np.abs(env_traj.solar_pressure_torque).max() > 0.0 and np.abs(env_traj.drag_torque).max() > 0.0
    assert np.abs(flexible.modal_rate).max() > 0.0
    assert np.abs(sloshing.pendulum_rate).max() > 0.0
