"""Bodies that change shape: divers, gymnasts, astronauts (time-varying inertia).

A deformable body is described in a body frame B (the trunk of a diver) by its
inertia ``I(t)`` about the current centre of mass and the angular momentum
``A(t)`` of the shape change relative to B, so that ``L_B = I(t) ω + A(t)``
and ``dL_B/dt + ω × L_B = τ_B``. See ``docs/variable_inertia.md`` (equations,
API) and ``docs/diver.md`` (the segment model of a human body, the twisting
somersault; :mod:`tumble.variable.diver`, :mod:`tumble.variable.demo`).

    >>> from tumble.variable import Human, Motion, simulate_variable
    >>> body = Human.de_leva().variable_body(
    ...     {"left_shoulder_abduction": Motion(3.14, [(0.2, 0.6, 0.0)])}, t_span=(0.0, 1.0))
"""

from tumble.variable.body import VariableBody
from tumble.variable.human import Human, Motion, Segment
from tumble.variable.simulate import METHODS, angular_velocity, shape_power, simulate_variable

__all__ = ["METHODS", "Human", "Motion", "Segment", "VariableBody", "angular_velocity", "shape_power",
           "simulate_variable"]
