"""Measurements on trajectories: flips of the intermediate axis, Poincaré sections and Lyapunov exponents.

==========================================  ==========================================================
``flip_times(traj, body)``                  times of the sign changes of the intermediate-axis rate
``intermediate_rate(traj, body)``           ``ω₂ = ω·e₂`` along a trajectory
``poincare_section(traj, gravity, ...)``    crossings of a heavy top's state with a plane (``docs/chaos.md``)
``lyapunov_exponents(body, gravity, ...)``  finite-time Lyapunov exponents, the largest or the spectrum
==========================================  ==========================================================
"""

from tumble.measure._flips import flip_times, intermediate_rate
from tumble.measure._lyapunov import LyapunovExponents, lyapunov_exponents
from tumble.measure._poincare import PoincareSection, poincare_section

__all__ = ["LyapunovExponents", "PoincareSection", "flip_times", "intermediate_rate", "lyapunov_exponents",
           "poincare_section"]
