"""Turning pydantic validation errors into one clear line naming the key."""

from __future__ import annotations

from typing import Annotated

from pydantic import AfterValidator, ValidationError


def location(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def format_validation_error(exc: ValidationError, where: str | None) -> tuple[str, str | None]:
    """(message, where) for the first error; ``where`` is extended with the key's path."""
    errors = exc.errors()
    first = errors[0]
    key = location(tuple(first["loc"]))
    return _message(first, len(errors)), join_where(where, key)


def join_where(where: str | None, key: str) -> str | None:
    """``scene.toml`` + ``camera.fov`` -> ``scene.toml: camera.fov``; a key path is extended."""
    if not where:
        return key or None
    if not key:
        return where
    return f"{where}.{key}" if ": " in where else f"{where}: {key}"


def _message(first: dict, count: int) -> str:
    message = first["msg"]
    if first["type"] == "extra_forbidden":
        message = "unknown parameter"
    elif first["type"] == "missing":
        message = "missing required key"
    elif "input" in first and not isinstance(first["input"], dict):
        message += f" (got {first['input']!r})"
    if count > 1:
        message += f" (and {count - 1} more problem{'s' if count > 2 else ''})"
    return message


def _nonzero(value: tuple[float, float, float]) -> tuple[float, float, float]:
    if not any(value):
        raise ValueError("must not be the zero vector")
    return value


# A direction: three floats, not all zero (normalised where it is used).
NonZeroVec3 = Annotated[tuple[float, float, float], AfterValidator(_nonzero)]
