"""Spacecraft attitude dynamics and control: a rigid hub with reaction wheels, control moment gyros,
thrusters, magnetorquers, a nutation damper, flexible appendages and fuel slosh, in a Keplerian orbit with gravity
gradient and a dipole
magnetic field (or the environment sampled along a Kepler or TLE orbit: :class:`Environment`), under feedback control laws (compiled or Python; continuous or sampled with a zero-order
hold). A :class:`Spacecraft` is a model of :func:`tumble.simulate`.

    >>> import numpy as np, tumble
    >>> from tumble import spacecraft as sc
    >>> craft = sc.Spacecraft(inertia=np.diag([10.0, 12.0, 8.0]),
    ...                       wheels=sc.pyramid_wheels(inertia=0.01, max_torque=0.1),
    ...                       controller=sc.QuaternionPD(natural_frequency=0.2, target=[0.0, 0.0, 0.0, 1.0]))
    >>> traj = tumble.simulate(craft, [0.0, 0.0, 0.0], t=np.linspace(0.0, 60.0, 61), method="rk4", dt=0.1)
    >>> traj.wheel_speed.shape
    (61, 4)

Conventions and equations: ``docs/spacecraft.md``; the orbit, LVLH, gravity gradient and the
geomagnetic field: ``docs/spacecraft_environment.md``; passive stability (major-axis rule,
gravity-gradient regions, nutation damper): ``docs/passive_stability.md``.
"""

from tumble._moved import moved
from tumble.spacecraft.actuators import PWPF, CMGCluster, Magnetorquers, ReactionWheel, Thruster, pyramid_wheels
from tumble.spacecraft.control import (BDot, ConstantTorque, MomentumDumping, MRPFeedback, PythonLaw, QuaternionPD,
                                       RateDamping, WheelTorques)
from tumble.spacecraft.damper import SphericalDamper
from tumble.spacecraft.environment import DipoleField, ResidualDipole
from tumble.spacecraft.environment_table import Environment, SpaceWeather
from tumble.spacecraft.flexible_modes import FlexibleModes
from tumble.spacecraft.flight_software import FlightSoftware, Sampling
from tumble.spacecraft.model import SaturationWarning, SingularityWarning, Spacecraft
from tumble.spacecraft.orbit import Orbit, attitude_in_lvlh, lvlh_quaternion
from tumble.spacecraft.slosh import SloshPendulum
from tumble.spacecraft.passive import gravity_gradient_stability, spin_stability
from tumble.spacecraft.tle import TLE

__all__ = [
    "BDot", "CMGCluster", "ConstantTorque", "DipoleField", "Environment", "FlexibleModes", "FlightSoftware",
    "MRPFeedback",
    "Magnetorquers",
    "MomentumDumping", "Orbit", "PWPF", "PythonLaw", "QuaternionPD", "RateDamping", "ReactionWheel", "ResidualDipole",
    "Sampling",
    "SaturationWarning", "SingularityWarning", "SloshPendulum", "SpaceWeather", "Spacecraft", "SphericalDamper", "TLE",
    "Thruster",
    "WheelTorques",
    "attitude_in_lvlh", "gravity_gradient_stability", "lvlh_quaternion",
    "pyramid_wheels", "spin_stability",
]

# The figures moved to tumble.viz: the old names warn and work for one release.
__getattr__ = moved(__name__, {"gravity_gradient_stability_figure": "tumble.viz.passive",
                               "save_spacecraft_figure": "tumble.viz.spacecraft", "spacecraft_figure": "tumble.viz.spacecraft"})
