"""The ``[[torque]]`` tables: external torques on a body, each chosen by its ``kind``, summed.

Each table builds a :mod:`tumble.torques` model (``build(body)``); the
entries of a file are added (:class:`tumble.torques.TorqueModel` supports
``+``). Torques in body axes unless the kind says inertial; N m.
"""

from __future__ import annotations

import functools
import operator
from collections.abc import Sequence
from typing import Annotated, ClassVar, Literal, Union

from pydantic import Field

from tumble import torques
from tumble.rigid_body import RigidBody
from tumble.scenario._errors import keyed
from tumble.scenario._values import _Number, _Positive, _Table, _Vector
from tumble.scenario.orbit import OrbitTable

__all__ = ["Torque", "build_torque"]


class ConstantBodyTorque(_Table):
    """``value``: a torque fixed in the body, N m, body axes."""

    kind: Literal["constant_body"]
    value: _Vector
    renamed: ClassVar[dict[str, str]] = {"torque": "value"}

    def build(self, body: RigidBody) -> torques.TorqueModel:
        return torques.ConstantBody(self.value)


class ConstantInertialTorque(_Table):
    """``value``: a torque fixed in inertial space, N m, inertial axes."""

    kind: Literal["constant_inertial"]
    value: _Vector
    renamed: ClassVar[dict[str, str]] = {"torque": "value"}

    def build(self, body: RigidBody) -> torques.TorqueModel:
        return torques.ConstantInertial(self.value)


class TabulatedTorque(_Table):
    """Torque samples ``values`` (N m) at ``times`` (s), as :class:`tumble.torques.Tabulated`."""

    kind: Literal["tabulated"]
    times: Annotated[list[_Number], Field(min_length=1)]
    values: Annotated[list[_Vector], Field(min_length=1)]
    frame: Literal["body", "inertial"] | None = None
    interpolation: Literal["linear", "previous"] | None = None
    renamed: ClassVar[dict[str, str]] = {"t": "times", "torque": "values"}

    def build(self, body: RigidBody) -> torques.TorqueModel:
        options = self.model_dump(include={"frame", "interpolation"}, exclude_none=True)
        return torques.Tabulated(self.times, self.values, **options)


class GravityTorque(_Table):
    """Uniform gravity on a body pivoting about a fixed point, as :class:`tumble.torques.Gravity`:
    ``mass`` (kg), ``com`` (m, centre of mass relative to the pivot, body axes), ``g`` (m/s², inertial)."""

    kind: Literal["gravity"]
    mass: _Positive
    com: _Vector
    g: _Vector | None = None

    def build(self, body: RigidBody) -> torques.TorqueModel:
        return torques.Gravity(self.mass, self.com, *([] if self.g is None else [self.g]))


class GravityGradientTorque(_Table):
    """Gravity gradient on the body on the Kepler orbit ``orbit`` (:mod:`tumble.scenario.orbit`), as
    :class:`tumble.torques.GravityGradient` (the body's own inertia; the orbit's t = 0 at the scenario's t = 0)."""

    kind: Literal["gravity_gradient"]
    orbit: OrbitTable

    def argument_keys(self, prefix: str) -> dict[str, str]:
        return {**super().argument_keys(prefix), **self.orbit.argument_keys(f"{prefix}.orbit")}

    def build(self, body: RigidBody) -> torques.TorqueModel:
        return torques.GravityGradient(self.orbit.build(), body)


#: One ``[[torque]]`` entry, chosen by ``kind``.
Torque = Annotated[Union[ConstantBodyTorque, ConstantInertialTorque, TabulatedTorque, GravityTorque,
                         GravityGradientTorque],
                   Field(discriminator="kind")]


def build_torque(entries: Sequence, body: RigidBody, prefix: str = "torque") -> torques.TorqueModel | None:
    """The sum of the torque models of ``entries`` on ``body`` (None when there are none); a refusal by the
    library is reported against the key of entry ``prefix[i]``."""
    models = []
    for i, entry in enumerate(entries):
        with keyed(entry.argument_keys(f"{prefix}[{i}]"), f"{prefix}[{i}]"):
            models.append(entry.build(body))
    return functools.reduce(operator.add, models) if models else None
