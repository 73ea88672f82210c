"""Turning pydantic validation errors into clear lines, one a problem, each naming its key."""

from __future__ import annotations

import collections.abc
import difflib
import math
import numbers
import re
import stat
import sys
import types
import typing
from collections.abc import Iterable
from enum import Enum
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PlainValidator,
    ValidationError,
    ValidationInfo,
    WrapValidator,
    field_validator,
)

from deferred.errors import InputError, input_error

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

# Floats beyond this are refused (world units, intensities, rates): float32 shading has lost
# every digit by then and a product of two overflows to inf.
FLOAT_LIMIT = 1e9
# Integers become GLSL ints (32-bit) or array sizes.
INT_LIMIT = 2**31 - 1


def location(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def validation_problems(exc: ValidationError, where: str | None,
                        model: type[BaseModel] | None = None) -> list[InputError]:
    """Every error of ``exc`` as an :class:`InputError` naming its key (``where`` extended
    with the key's path), one per key. With the ``model`` that raised it, the errors of one
    value against each member of a union are one problem (the most specific), and an
    unknown key names the closest known one."""
    problems: dict[tuple, tuple[int, InputError]] = {}
    for error in exc.errors():
        loc, site, parent = _key_path(model, tuple(error["loc"]))
        problem = _problem({**error, "loc": loc}, where, parent)
        # one value against a union's members: the error found deepest inside it says most
        group = loc[:site] if site is not None else loc
        depth = len(loc)
        if group in problems and problems[group][0] >= depth:
            continue
        problems[group] = (depth, problem)
    return [problem for _, problem in problems.values()]


def validation_error(exc: ValidationError, where: str | None,
                     model: type[BaseModel] | None = None) -> InputError:
    """The :class:`InputError` of :func:`validation_problems`: one problem, or all of them."""
    return input_error(validation_problems(exc, where, model))


def _problem(error: dict, where: str | None, parent: type[BaseModel] | None) -> InputError:
    loc = tuple(error["loc"])
    if error["type"] == "missing" and loc and isinstance(loc[-1], int) and \
            isinstance(error.get("input"), list | tuple):
        # a list one value short is the list's problem, not a "missing key" at its end
        given = error["input"]
        error = {**error, "type": "too_short",
                 "msg": f"expected more than the {len(given)} value"
                        f"{'s' if len(given) != 1 else ''} given"}
        loc = loc[:-1]
    lax = error.get("ctx", {}).get("error")
    if isinstance(lax, LaxValueError) and isinstance(lax.problem, Problem):
        # found inside the field's value: name where, and show what is there
        loc = (*loc, *lax.problem.path)
        error = {**error, "input": lax.problem.value}
    message = _message(error)
    if error["type"] == "extra_forbidden" and parent is not None and loc:
        message += did_you_mean(loc[-1], parent.model_fields)
    return InputError(message, join_where(where, location(loc)))


def _key_path(model: type[BaseModel] | None, loc: tuple
              ) -> tuple[tuple, int | None, type[BaseModel] | None]:
    """``loc`` without pydantic's tags naming a union's member (``scale.float``), the length
    of the path to the union's value (``None``: no union), and the model holding the last
    key (``None`` where not known)."""
    annotation: Any = model
    out: list = []
    site = None
    parent = None
    for part in loc:
        annotation = _optional_member(_bare(annotation))
        if typing.get_origin(annotation) in (typing.Union, types.UnionType) and \
                isinstance(part, str):
            site = len(out) if site is None else site
            members = [m for m in typing.get_args(annotation) if m is not type(None)]
            annotation = next((m for m in members if getattr(m, "__name__", str(m)) == part or
                               str(m).replace("typing.", "") == part), None)
            continue
        out.append(part)
        parent = None
        if isinstance(annotation, type) and issubclass(annotation, BaseModel) and \
                isinstance(part, str):
            parent = annotation
            field = annotation.model_fields.get(part)
            annotation = field.annotation if field is not None else None
        elif isinstance(part, int) and typing.get_origin(annotation) in (
                tuple, list, collections.abc.Sequence):
            arguments = typing.get_args(annotation)
            if typing.get_origin(annotation) is tuple and not (
                    len(arguments) == 2 and arguments[1] is Ellipsis):
                annotation = arguments[part] if part < len(arguments) else None
            else:
                annotation = arguments[0] if arguments else None
        elif typing.get_origin(annotation) in (dict, collections.abc.Mapping):
            arguments = typing.get_args(annotation)
            annotation = arguments[1] if len(arguments) == 2 else None
        else:
            annotation = None
    return tuple(out), site, parent


def _optional_member(annotation: Any) -> Any:
    """``X`` of ``X | None`` (pydantic names no member of an optional value)."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        members = [m for m in typing.get_args(annotation) if m is not type(None)]
        if len(members) == 1:
            return _bare(members[0])
    return annotation


def closest(name: object, choices: Iterable[str]) -> str | None:
    """The choice closest to ``name`` (a misspelling of it), or ``None`` when none is close."""
    if not isinstance(name, str) or not name:
        return None
    found = difflib.get_close_matches(name[:200], list(choices), n=1, cutoff=0.6)
    return found[0] if found else None


def did_you_mean(name: object, choices: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` with the choice closest to ``name``; ``""`` when none is
    close."""
    match = closest(name, choices)
    return f" (did you mean '{match}'?)" if match is not None else ""


def parse_toml(text: str, name: str) -> dict[str, Any]:
    """The tables of TOML ``text``; ``InputError`` naming ``name`` where it is malformed,
    nested too deep, or holds an integer of more digits than Python converts."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"malformed TOML: {exc}", name) from None
    except RecursionError:
        raise InputError("malformed TOML: arrays or tables nested too deep", name) from None
    except ValueError:
        raise InputError(f"malformed TOML: {number_too_long(text)}", name) from None


def number_too_long(text: str) -> str:
    """Where ``text`` (JSON, TOML) holds an integer of more digits than Python converts (a
    ``ValueError`` from the parser): its line and column, its digits and the most read."""
    limit = sys.get_int_max_str_digits() if hasattr(sys, "get_int_max_str_digits") else 4300
    found = re.search(rf"\d{{{limit + 1},}}", text)
    if found is None:
        return "a number too long to read"
    line = text.count("\n", 0, found.start()) + 1
    column = found.start() - (text.rfind("\n", 0, found.start()) + 1) + 1
    return (f"line {line}, column {column}: a number of {len(found.group()):,} digits (at "
            f"most {limit:,} are read)")


def join_where(where: str | None, key: str) -> str | None:
    """``scene.toml`` + ``camera.fov`` -> ``scene.toml: camera.fov``; a key path is extended."""
    if not where:
        return key or None
    if not key:
        return where
    return f"{where}.{key}" if ": " in where else f"{where}: {key}"


def _message(error: dict) -> str:
    message = error["msg"]
    if error["type"] == "extra_forbidden":
        message = "unknown parameter"
    elif error["type"] == "missing":
        message = "missing required key"
    elif error["type"] == "value_error":
        message = message.removeprefix("Value error, ")
    if error["type"] not in ("extra_forbidden", "missing") and "input" in error and \
            not isinstance(error["input"], dict):
        got = repr(error["input"])
        message += f" (got {got if len(got) <= 80 else got[:60] + ' ... ' + got[-15:]})"
    return message


MIN_DIRECTION_LENGTH = 1e-6  # shorter: squaring its components to normalise it underflows


def _nonzero(value: tuple[float, float, float]) -> tuple[float, float, float]:
    if not any(value):
        raise ValueError("must not be the zero vector")
    if math.hypot(*value) < MIN_DIRECTION_LENGTH:
        raise ValueError(f"is too short to give a direction (length under "
                         f"{MIN_DIRECTION_LENGTH:g})")
    return value


# A direction: three floats, at least MIN_DIRECTION_LENGTH long (normalised where it is used).
NonZeroVec3 = Annotated[tuple[float, float, float], AfterValidator(_nonzero)]


def lax_problem(value: Any, annotation: Any) -> str | None:
    """Why ``value`` only fits ``annotation`` through one of pydantic's lax conversions (a
    boolean as a number, a number or string as a boolean, a string as a number), or a number is
    not finite or out of bounds; ``None`` when it fits as it is (or pydantic decides)."""
    origin = typing.get_origin(annotation)
    if origin is Annotated:
        return lax_problem(value, typing.get_args(annotation)[0])
    if origin in (typing.Union, types.UnionType):
        members = typing.get_args(annotation)
        problems = [lax_problem(value, member) for member in members]
        if any(problem is None for problem in problems):
            return None
        # None is a default, not a shape to ask for: "expected nothing" says nothing useful
        if len(members) > 1 and type(None) in members:
            members, problems = zip(*[(member, problem) for member, problem
                                      in zip(members, problems, strict=True)
                                      if member is not type(None)], strict=True)
        # the member of the value's shape (a list or a scalar) says what is wrong with it
        shaped = [problem for member, problem in zip(members, problems, strict=True)
                  if _is_sequence(value) == (typing.get_origin(_bare(member)) in (tuple, list))]
        return (shaped or problems)[0]
    if annotation is type(None):
        return None if value is None else f"expected nothing, not {value!r}"
    if origin is Literal or isinstance(annotation, type) and issubclass(annotation, Enum):
        choices = typing.get_args(annotation) if origin is Literal else \
            tuple(member.value for member in annotation)
        return None if value in choices else f"expected one of {', '.join(map(repr, choices))}"
    if annotation is bool:
        return None if isinstance(value, bool) else "expected true or false"
    if annotation in (int, float):
        # numbers.Real takes numpy scalars (float32, int64) from the Python API
        if isinstance(value, bool | np.bool_):
            return "expected a number, not true or false"
        if isinstance(value, str):
            return "expected a number, not a string"
        if not isinstance(value, numbers.Real):
            return f"expected a number, not {type(value).__name__}"
        if not math.isfinite(float(value)):
            return "must be a finite number"
        if annotation is int and isinstance(value, numbers.Integral):
            return f"must be within +-{INT_LIMIT}" if abs(int(value)) > INT_LIMIT else None
        if abs(float(value)) > FLOAT_LIMIT:
            return f"must be within +-{FLOAT_LIMIT:g}"
        return None
    if annotation is str:
        return None if isinstance(value, str) else "expected a string"
    sequences = (tuple, list, collections.abc.Sequence)
    if origin in sequences and not _is_sequence(value):
        return f"expected {_sequence_shape(annotation)}, not {_kind(value)}"
    if origin in sequences:
        arguments = typing.get_args(annotation)
        if origin is not tuple or (len(arguments) == 2 and arguments[1] is Ellipsis):
            arguments = (arguments[0],) * len(value) if arguments else ()
        for index, (element, element_type) in enumerate(zip(value, arguments, strict=False)):
            problem = lax_problem(element, element_type)
            if problem is not None:
                return Problem.within(problem, index, element)
    if origin in (dict, collections.abc.Mapping) and isinstance(value, dict):
        arguments = typing.get_args(annotation)
        for key, element in value.items() if len(arguments) == 2 else ():
            problem = lax_problem(element, arguments[1])
            if problem is not None:
                return Problem.within(problem, key, element)
    if isinstance(annotation, type) and issubclass(annotation, StrictValues):
        return None  # a nested model checks its own fields
    if isinstance(annotation, type) and issubclass(annotation, BaseModel) and \
            isinstance(value, dict):
        for name, field in annotation.model_fields.items():
            if name in value:
                problem = lax_problem(value[name], field.annotation)
                if problem is not None:
                    return Problem.within(problem, name, value[name])
    return None


class Problem(str):
    """A :func:`lax_problem` message found inside a value: ``path`` says where (list indices,
    keys, field names) and ``value`` what is there, so an error names ``light[0].type`` and
    shows ``3``, not the whole list of tables."""

    path: tuple = ()
    value: Any = None

    @classmethod
    def within(cls, problem: str, part: Any, element: Any) -> Problem:
        made = cls(problem)
        inner = problem if isinstance(problem, Problem) else None
        made.path = (part, *(inner.path if inner else ()))
        made.value = inner.value if inner else element
        return made


class LaxValueError(ValueError):
    """A field's value refused by :func:`lax_problem` (its message a :class:`Problem`)."""

    def __init__(self, problem: str):
        super().__init__(str(problem))
        self.problem = problem


def _kind(value: Any) -> str:
    """What a value is, as a scene file says it: ``a string``, ``a number``, ``a table``."""
    if isinstance(value, str):
        return "a string"
    if isinstance(value, bool | np.bool_):
        return "true or false"
    if isinstance(value, numbers.Real):
        return "a number"
    if isinstance(value, dict):
        return "a table"
    return type(value).__name__


def _sequence_shape(annotation: Any) -> str:
    """What a sequence annotation asks for: ``3 numbers`` for a fixed tuple of numbers,
    else ``a list``."""
    arguments = typing.get_args(annotation)
    if typing.get_origin(annotation) is tuple and arguments and Ellipsis not in arguments and \
            all(_bare(argument) in (int, float) for argument in arguments):
        return f"{len(arguments)} numbers"
    return "a list"


def _bare(annotation: Any) -> Any:
    return typing.get_args(annotation)[0] if typing.get_origin(annotation) is Annotated \
        else annotation


def _is_sequence(value: Any) -> bool:
    """A list, a tuple or a 1-D numpy array (the Python API's vectors)."""
    return isinstance(value, list | tuple) or (isinstance(value, np.ndarray) and value.ndim == 1)


# A field whose own validators convert its input first (a plugin's BeforeValidator on a
# parameter) is left to them.
_OWN_CONVERSION = (BeforeValidator, PlainValidator, WrapValidator)


class StrictValues(BaseModel):
    """Base of every model read from a scene: numbers are finite and bounded, booleans are
    true or false, nothing is converted from another type (``shells = true`` is not 1)."""

    model_config = ConfigDict(allow_inf_nan=False)

    @field_validator("*", mode="before")
    @classmethod
    def _no_lax_conversion(cls, value: Any, info: ValidationInfo) -> Any:
        field = cls.model_fields.get(info.field_name) if info.field_name else None
        if field is None or any(isinstance(m, _OWN_CONVERSION) for m in field.metadata):
            return value
        problem = lax_problem(value, field.annotation)
        if problem is not None:
            raise LaxValueError(problem)
        return value


# Colours (linear RGB): an albedo or tint reflects at most what arrives; light may be brighter.
UnitFloat = Annotated[float, Field(ge=0.0, le=1.0)]
NonNegativeFloat = Annotated[float, Field(ge=0.0)]
Albedo = tuple[UnitFloat, UnitFloat, UnitFloat]
Radiance = tuple[NonNegativeFloat, NonNegativeFloat, NonNegativeFloat]


def require_regular_file(path: Path, what: str, where: str | None) -> None:
    """``InputError`` unless ``path`` is a regular file: missing, a folder, or a device or pipe
    (``/dev/zero``, a FIFO: reading one never ends or gives nonsense) are each said so. The
    path is named unless ``where`` already does."""
    named = "" if where is not None and str(path) in where else f": {path}"
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise InputError(f"{what} not found{named}", where) from None
    except OSError as exc:
        raise InputError(f"cannot read {what}{named}: {exc.strerror or exc}", where) from None
    if stat.S_ISDIR(mode):
        raise InputError(f"{what} is a folder, not a file{named}", where)
    if not stat.S_ISREG(mode):
        raise InputError(f"{what} is not a regular file (a device or pipe){named}", where)
