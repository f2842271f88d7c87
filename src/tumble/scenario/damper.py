"""The damper table: a spherical viscous nutation damper, ``[damper]`` of a rigid body and ``[spacecraft.damper]``.

A sphere of moment of inertia ``J`` in a spherical cavity at the centre of
mass, coupled to the hub by a viscous film: the torque on the sphere is
``−c (ω_d − ω)`` and the hub gets the opposite (:mod:`tumble.spacecraft.damper`;
Hughes, *Spacecraft Attitude Dynamics*, ch. 5). Its initial rate ``ω_d``
(rad/s, body axes; default the hub's) is the initial state ``damper_omega0``
of :func:`tumble.simulate`.
"""

from __future__ import annotations

from tumble.scenario._values import _Positive, _Table
from tumble.spacecraft import SphericalDamper

__all__ = ["SphericalDamperTable"]


class SphericalDamperTable(_Table):
    """A spherical viscous nutation damper (:class:`tumble.spacecraft.SphericalDamper`): sphere ``inertia``
    J (kg m², about any diameter) and ``damping`` c (N m s)."""

    inertia: _Positive
    damping: _Positive

    def build(self) -> SphericalDamper:
        return SphericalDamper(self.inertia, self.damping)
