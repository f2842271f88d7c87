"""Bodies that change shape: divers, gymnasts, astronauts (time-varying inertia).

A deformable body is described in a body frame B (the trunk of a diver) by its
inertia ``I(t)`` about the current centre of mass and the angular momentum
``A(t)`` of the shape change relative to B, so that ``L_B = I(t) ω + A(t)``
and ``dL_B/dt + ω × L_B = τ_B``. A :class:`VariableBody` (samples of ``I`` and
``A``) and a :class:`MovingHuman` (a segment model moving its joints through
prescribed angles) are models of :func:`tumble.simulate`. See
``docs/variable_inertia.md`` (equations, API) and ``docs/diver.md`` (the
segment model of a human body, the twisting somersault;
:mod:`tumble.variable.diver`; the figures and demo: :mod:`tumble.viz.diver`).

    >>> import numpy as np, tumble
    >>> from tumble.variable import Human, Motion
    >>> diver = Human.de_leva().moving({"left_shoulder_abduction": Motion(3.14, [(0.2, 0.6, 0.0)])},
    ...                                t_span=(0.0, 1.0))
    >>> traj = tumble.simulate(diver, omega0=[5.0, 0.0, 0.0], t=np.linspace(0.0, 1.0, 11))
"""

from tumble.variable.body import VariableBody, angular_velocity, shape_power
from tumble.variable.human import Human, Motion, MovingHuman, Segment

__all__ = ["Human", "Motion", "MovingHuman", "Segment", "VariableBody", "angular_velocity", "shape_power"]
