"""The ``[[spacecraft.controller]]`` tables: the control laws of a spacecraft, each chosen by its ``kind``.

Each table has the arguments of the law of :mod:`tumble.spacecraft.control` it
builds (SI units, body axes; the equations are there and in
``docs/spacecraft.md``):

=====================  =====================================================================
``kind``               law
=====================  =====================================================================
``quaternion_pd``      :class:`~tumble.spacecraft.QuaternionPD`: ``natural_frequency``,
                       ``damping_ratio``, ``max_rate``, ``max_torque``, target
``mrp_feedback``       :class:`~tumble.spacecraft.MRPFeedback`:
                       ``u = −K σ − P (ω + K_I z) + ω × H``, ``z = K ∫σ dt + J ω``:
                       ``K`` (N m), ``P`` (N m s; a number or a 3×3 matrix), ``Ki``
                       (1/(N m s), optional: the integral term), target
``rate_damping``       :class:`~tumble.spacecraft.RateDamping`: ``time_constant``, ``max_torque``
``constant_torque``    :class:`~tumble.spacecraft.ConstantTorque`: ``torque``
``bdot``               :class:`~tumble.spacecraft.BDot`: ``gain``
``momentum_dumping``   :class:`~tumble.spacecraft.MomentumDumping`: ``gain``
``wheel_torques``      :class:`~tumble.spacecraft.WheelTorques`: motor torques of the wheels,
                       N m: ``torques`` one per wheel (constant), or with ``times`` (s) one
                       row per time, ``interpolation`` ``"linear"`` or ``"previous"``
=====================  =====================================================================

Every law takes ``period`` (s, > 0): its own sample period, its command held
in between; omitted, the spacecraft's ``control_period`` (continuous without
one). See ``docs/spacecraft.md``, "Laws at their own rates".

The target of the regulators is an attitude (body → inertial): ``target``, a
quaternion ``[w, x, y, z]``, or ``target_euler``, Euler angles as in
``[initial]``'s ``euler`` (default: the identity). Python laws are code and
have no table: scenario files are data.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, ClassVar, Literal, Union, cast

import numpy as np
from pydantic import Field, field_validator

from tumble import attitude
from tumble.scenario._values import _FlatOrRows, _Limit, _Matrix, _Number, _Positive, _Quaternion, _Table, _Vector
from tumble.scenario.tables import EulerAngles
from tumble.spacecraft import control

__all__ = ["Controller", "Regulator"]


class _Law(_Table):
    """A control law: ``period``, its own sample period (s, > 0), or the spacecraft's ``control_period``."""

    period: _Positive | None = None


class Regulator(_Law):
    """A law that regulates the attitude to a target: ``target`` (quaternion ``[w, x, y, z]``, body → inertial)
    or ``target_euler`` (Euler angles, degrees by default), not both; default the identity."""

    target: _Quaternion | None = None
    target_euler: EulerAngles | None = None

    @field_validator("target_euler")
    @classmethod
    def _one_target(cls, target_euler, info):
        if target_euler is not None and info.data.get("target") is not None:
            raise ValueError("give the target as target or as target_euler, not both")
        return target_euler

    def argument_keys(self, prefix: str) -> dict[str, str]:
        keys = super().argument_keys(prefix)
        if self.target_euler is not None:
            keys["target"] = f"{prefix}.target_euler"
            keys.update(self.target_euler.argument_keys(f"{prefix}.target_euler"))
        return keys

    def target_quaternion(self) -> np.ndarray:
        """The commanded attitude: ``target`` or the quaternion of ``target_euler`` (identity when neither)."""
        if self.target_euler is not None:
            return self.target_euler.quaternion()
        return attitude.identity() if self.target is None else np.array(self.target)


class PDTable(Regulator):
    kind: Literal["quaternion_pd"]
    natural_frequency: _Positive
    damping_ratio: _Positive = 1.0 / math.sqrt(2.0)
    max_rate: _Limit = math.inf
    max_torque: _Limit = math.inf

    def build(self) -> control.QuaternionPD:
        return control.QuaternionPD(self.natural_frequency, self.damping_ratio, target=self.target_quaternion(),
                                    max_rate=self.max_rate, max_torque=self.max_torque, period=self.period)


class MRPTable(Regulator):
    """MRP feedback: ``K`` (N m, > 0), ``P`` (N m s: a number > 0 or a symmetric positive-definite 3×3 matrix,
    body axes), ``Ki`` (1/(N m s), > 0; omitted: no integral term). With ``Ki`` the integral ``∫σ dt`` (s)
    is a state: ``[initial]`` ``attitude_error_integral`` (default 0)."""

    kind: Literal["mrp_feedback"]
    K: _Positive
    P: _FlatOrRows[_Positive, _Matrix]
    Ki: _Positive | None = None

    def build(self) -> control.MRPFeedback:
        return control.MRPFeedback(self.K, self.P, Ki=self.Ki, target=self.target_quaternion(), period=self.period)


class RateDampingTable(_Law):
    kind: Literal["rate_damping"]
    time_constant: _Positive
    max_torque: _Limit = math.inf

    def build(self) -> control.RateDamping:
        return control.RateDamping(self.time_constant, self.max_torque, period=self.period)


class ConstantTorqueTable(_Law):
    kind: Literal["constant_torque"]
    torque: _Vector

    def build(self) -> control.ConstantTorque:
        return control.ConstantTorque(cast(Any, self.torque), period=self.period)  # array_like: converted there


class BDotTable(_Law):
    kind: Literal["bdot"]
    gain: _Positive

    def build(self) -> control.BDot:
        return control.BDot(self.gain, period=self.period)


class DumpingTable(_Law):
    kind: Literal["momentum_dumping"]
    gain: _Positive

    def build(self) -> control.MomentumDumping:
        return control.MomentumDumping(self.gain, period=self.period)


class WheelTorquesTable(_Law):
    """Motor torques commanded to the wheels directly (N m, in the order of the wheels): ``torques`` one per
    wheel, constant; or ``times`` (s, strictly increasing) and ``torques`` one row per time, interpolated
    ``"linear"`` (default) or ``"previous"`` (zero-order hold), the end rows held outside."""

    kind: Literal["wheel_torques"]
    torques: _FlatOrRows[Annotated[list[_Number], Field(min_length=1)],
                         Annotated[list[Annotated[list[_Number], Field(min_length=1)]], Field(min_length=1)]]
    times: Annotated[list[_Number], Field(min_length=1)] | None = None
    interpolation: Literal["linear", "previous"] | None = None
    renamed: ClassVar[dict[str, str]] = {"t": "times"}

    @field_validator("interpolation")
    @classmethod
    def _samples_interpolated(cls, interpolation, info):
        if interpolation is not None and info.data.get("times") is None and "times" in info.data:
            raise ValueError("only with times: constant torques are not interpolated")
        return interpolation

    def build(self) -> control.WheelTorques:
        return control.WheelTorques(self.torques, self.times, period=self.period,
                                    **({} if self.interpolation is None else {"interpolation": self.interpolation}))


#: One ``[[spacecraft.controller]]`` entry, chosen by ``kind``.
Controller = Annotated[Union[PDTable, MRPTable, RateDampingTable, ConstantTorqueTable, BDotTable, DumpingTable,
                             WheelTorquesTable],
                       Field(discriminator="kind")]
