"""Value types of scenario files and the base of every table.

Numbers are strict: a TOML integer or float, never a string or a boolean,
and finite (``nan`` and ``inf`` are refused) unless a type says otherwise.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Annotated, ClassVar, Literal, TypeVar, Union

from pydantic import BaseModel, ConfigDict, Discriminator, Field, Tag

_Number = Annotated[float, Field(strict=True, allow_inf_nan=False)]  # a TOML integer is accepted too
_Positive = Annotated[_Number, Field(gt=0.0)]
_Limit = Annotated[float, Field(strict=True, gt=0.0)]  # inf allowed: TOML's inf means "no limit"
_Vector = Annotated[list[_Number], Field(min_length=3, max_length=3)]
_Matrix = Annotated[list[_Vector], Field(min_length=3, max_length=3)]
_Quaternion = Annotated[list[_Number], Field(min_length=4, max_length=4)]
_Bool = Annotated[bool, Field(strict=True)]
_Text = Annotated[str, Field(strict=True)]
_Axis = Literal["x", "y", "z"]

#: The tags of :data:`_FlatOrRows`: not keys of a file (an error's key path leaves them out).
SHAPE_TAGS = ("<flat>", "<rows>")


def _shape_of(value) -> str:
    """``"<rows>"`` for an array whose first entry is an array, else ``"<flat>"``."""
    return SHAPE_TAGS[isinstance(value, list) and bool(value) and isinstance(value[0], list)]


_Flat = TypeVar("_Flat")
_Rows = TypeVar("_Rows")

#: ``_FlatOrRows[flat, rows]``: a value written either as ``flat`` (a number, or an array of numbers) or as
#: ``rows`` (an array of arrays), chosen by what the file wrote, so that a bad value gets the one rule of the
#: form it meant (a gain that is a number or a matrix; one torque per wheel, or a row of them per time).
_FlatOrRows = Annotated[Union[Annotated[_Flat, Tag(SHAPE_TAGS[0])], Annotated[_Rows, Tag(SHAPE_TAGS[1])]],
                        Discriminator(_shape_of)]


class _Table(BaseModel):
    """A TOML table: unknown keys are refused, values are immutable once validated.

    A table feeds the arguments of a library constructor; :meth:`argument_keys`
    says which key of the file is behind each argument, so that a
    :class:`tumble.ValidationError` naming an argument (its ``.field``) is
    reported against the key (:func:`tumble.scenario._errors.keyed`).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    #: Library argument name → key of this table, where the two differ.
    renamed: ClassVar[dict[str, str]] = {}

    def argument_keys(self, prefix: str) -> dict[str, str]:
        """Map each library argument this table feeds to its full key path under ``prefix``."""
        keys = {name: f"{prefix}.{name}" for name in type(self).model_fields}
        keys.update({arg: f"{prefix}.{key}" for arg, key in self.renamed.items()})
        return keys


class _InertiaOrMoments(_Table):
    """A table that gives an inertia as ``inertia`` (3×3, kg m²) or as ``moments`` (its diagonal, kg m²):
    the library's ``inertia`` argument is reported against whichever of the two keys the file gave.
    A subclass declares both fields and checks that exactly one is given."""

    if TYPE_CHECKING:
        moments: object  # the subclass's field (None when the file gives inertia)

    def argument_keys(self, prefix: str) -> dict[str, str]:
        keys = super().argument_keys(prefix)
        if self.moments is not None:
            keys["inertia"] = f"{prefix}.moments"
        return keys
