"""Problems of a scenario file, each reported as ``FILE: KEY: RULE``.

Three sources of problems, one message format:

* TOML syntax (:func:`toml_problem`): the position in the file;
* the schema (:func:`describe`): pydantic's error, in the words of a TOML file;
* the library (:func:`keyed`): a :class:`tumble.ValidationError` raised while
  the model is built or run names the argument it refuses in its ``.field``;
  each table's argument → key table (:meth:`_Table.argument_keys`) gives the
  key behind it. No message text is parsed here.
"""

from __future__ import annotations

import difflib
import re
import tomllib
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any, get_args

from tumble._validate import ValidationError
from tumble.scenario._values import SHAPE_TAGS, _Table

__all__ = ["ScenarioError"]


class ScenarioError(ValidationError):
    """A scenario that cannot be read or breaks a rule.

    ``problems`` holds ``(where, rule)`` pairs: ``where`` is a key path such as
    ``"body.inertia"`` or ``"torque[1].times"``, a TOML position such as
    ``"line 3, column 7"``, or ``""`` for the file as a whole. ``str(error)``
    has one line per problem: ``FILE: WHERE: RULE``. ``field`` and ``rule``
    are those of the first problem.
    """

    def __init__(self, source: str, problems: list[tuple[str, str]]):
        self.source = source
        self.problems = tuple(problems)
        super().__init__("\n".join(f"{source}: {where}: {rule}" if where else f"{source}: {rule}"
                                   for where, rule in self.problems))

    @property
    def field(self) -> str:
        """The key of the first problem (``""`` for the file as a whole)."""
        return self.problems[0][0] if self.problems else ""

    @property
    def rule(self) -> str:
        """The rule of the first problem."""
        return self.problems[0][1] if self.problems else str(self)


@contextmanager
def keyed(keys: Mapping[str, str], fallback: str) -> Iterator[None]:
    """Report a library :class:`~tumble.ValidationError` against the scenario key behind its ``.field``.

    ``keys`` maps argument names to key paths; an index or attribute after the
    argument (``positions[2]``) is kept (``body.positions[2]``). An error whose
    field is not in ``keys`` is reported whole against ``fallback``. The
    :class:`ScenarioError` raised has no file yet: :func:`in_file` adds it.
    """
    try:
        yield
    except ScenarioError:
        raise
    except ValidationError as exc:
        argument = re.split(r"[.\[]", exc.field, maxsplit=1)[0]  # the argument: the field up to . or [
        if exc.field and argument in keys:
            problem = (keys[argument] + exc.field[len(argument):], exc.rule)
        else:
            problem = (fallback, str(exc))
        raise ScenarioError("", [problem]) from exc


@contextmanager
def in_file(source: str) -> Iterator[None]:
    """Name ``source`` in the :class:`ScenarioError` raised inside (by :func:`keyed` or a rule of a table)."""
    try:
        yield
    except ScenarioError as exc:
        if exc.source:
            raise
        raise ScenarioError(source, list(exc.problems)) from exc.__cause__


# --------------------------------------------------------------------------
# TOML and schema errors, in the words of a TOML file
# --------------------------------------------------------------------------

_TOML_POSITION = re.compile(r"\s*\(at (line \d+, column \d+|end of document)\)$")

_TYPE_RULES = {
    "float_type": "must be a number",
    "int_type": "must be an integer",
    "bool_type": "must be true or false",
    "string_type": "must be a string",
    "list_type": "must be an array",
    "model_type": "must be a table",
    "model_attributes_type": "must be a table",
    "finite_number": "must be finite",
}
_BOUND_RULES = {"greater_than": (">", "gt"), "greater_than_equal": (">=", "ge"), "less_than_equal": ("<=", "le")}


def toml_problem(exc: tomllib.TOMLDecodeError) -> tuple[str, str]:
    """``(position, rule)`` of a TOML syntax error."""
    message = str(exc)
    match = _TOML_POSITION.search(message)
    where = match.group(1) if match else ""
    return where, f"invalid TOML: {message[:match.start()] if match else message}"


def describe(error: Mapping, root: type[_Table]) -> tuple[str, str]:
    """``(key path, rule)`` of one pydantic error raised while validating the table ``root``."""
    path, table = _locate(error["loc"], root)
    kind, ctx = error["type"], error.get("ctx") or {}
    got: Any = error.get("input")  # what the file gave, of any type
    if kind == "missing":
        rule = "missing required key"
    elif kind == "extra_forbidden":
        rule = "unknown key" + _hint(str(path[-1]), table)
    elif kind in ("union_tag_not_found", "union_tag_invalid"):  # the key choosing a table's kind
        tag_key = ctx["discriminator"].strip("'")
        path.append(tag_key)
        rule = ("missing required key" if kind == "union_tag_not_found"
                else f"must be one of {ctx['expected_tags']}, got {short(got[tag_key])}")
    elif kind in _TYPE_RULES:
        rule = f"{_TYPE_RULES[kind]}, got {short(got)}"
    elif kind in ("too_short", "too_long"):
        bound = "at least" if kind == "too_short" else "at most"
        limit = ctx.get("min_length", ctx.get("max_length"))
        rule = f"must have {bound} {limit} entries, got {ctx['actual_length']}"
    elif kind in _BOUND_RULES:
        sign, limit = _BOUND_RULES[kind]
        rule = f"must be {sign} {ctx[limit]}, got {short(got)}"
    elif kind == "literal_error":
        rule = f"must be {ctx['expected']}, got {short(got)}"
    elif kind == "value_error":
        rule = str(ctx["error"])
    else:
        rule = error["msg"]
    return _dotted(path), rule


def _locate(loc: tuple, root: type[_Table]) -> tuple[list, type[_Table] | None]:
    """Split a pydantic error location into the file's key path and the table holding its last key.

    Locations include the tags of union members (``"_Shape"``, ``"box"``,
    ``"tabulated"``, ``"quaternion_pd"``, ``"gimbal"``: see :func:`_tags`; the form of a value,
    :data:`~tumble.scenario._values.SHAPE_TAGS`), which are not keys of the file.
    """
    path, candidates, table = [], [root], None
    for part in loc:
        if isinstance(part, int):  # an index into an array
            path.append(part)
            continue
        if part in SHAPE_TAGS:  # the form of a value: a number or an array, an array or rows
            continue
        tagged = [cls for cls in candidates if part in _tags(cls)]
        if tagged:  # a union tag narrows down the table
            candidates = tagged
            continue
        path.append(part)
        table = candidates[0] if len(candidates) == 1 else None
        field = table.model_fields.get(part) if table is not None else None
        candidates = _tables_in(field.annotation) if field is not None else []
    return path, table


#: The keys whose value chooses a table among the members of a union: a body's ``shape``, a torque's or a
#: controller's ``kind``, a gyroscope's ``suspension``.
_TAG_KEYS = ("shape", "kind", "suspension")


def _tags(cls: type[_Table]) -> set[str]:
    """Union tags that select ``cls``: its own and its bases' class names, the value of the key that chooses it
    among its siblings (:data:`_TAG_KEYS`)."""
    tags = {base.__name__ for base in cls.__mro__ if issubclass(base, _Table)}
    for key in _TAG_KEYS:
        if key in cls.model_fields:
            tags.update(arg for arg in get_args(cls.model_fields[key].annotation) if isinstance(arg, str))
    return tags


def _tables_in(annotation) -> list[type[_Table]]:
    """The table classes an annotation can hold (through Optional, list, Union, Annotated)."""
    if isinstance(annotation, type) and issubclass(annotation, _Table):
        return [annotation]
    return [cls for arg in get_args(annotation) for cls in _tables_in(arg)]


def _hint(key: str, table: type[_Table] | None) -> str:
    """" (did you mean ...?)" or the keys the table takes."""
    if table is None:
        return ""
    keys = list(table.model_fields)
    close = difflib.get_close_matches(key, keys, n=1, cutoff=0.75)
    return f" (did you mean {close[0]!r}?)" if close else f" (this table takes: {', '.join(keys)})"


def _dotted(path: list) -> str:
    """``["body", "inertia", 1, 2]`` → ``"body.inertia[1][2]"``."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else part)
    return text


def short(value, limit: int = 40) -> str:
    """``repr(value)``, cut to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
