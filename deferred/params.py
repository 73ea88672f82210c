"""Validated parameters (materials, effects) and the uniforms they become.

Every parameter model forbids unknown keys and is frozen. A field ``foo`` becomes the uniform
``u_foo`` when its value is a number, a boolean or a tuple of 2 to 4 numbers; strings and
``None`` are not uniforms. ``overrides`` maps a field to ``None`` (not a uniform: a pass count,
a define, a file) or to a function of the value giving the uniforms it becomes.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from pydantic import BaseModel, ConfigDict, ValidationError

from deferred.validation import StrictValues, validation_error

UniformOverrides = dict[str, Callable[[Any], dict[str, Any]] | None]

# Uniforms the framework sets on every pass (camera, transforms, ids, light buffer): a parameter
# must not shadow one.
RESERVED_UNIFORMS = frozenset({
    "u_projection", "u_inverse_projection", "u_view", "u_resolution", "u_near_far", "u_model",
    "u_model_normal_matrix", "u_surface_id", "u_light_count", "u_lights",
    "u_model_view", "u_normal_matrix",  # the names before the view and model were apart
    "u_light_offset", "u_volume_scale",
    # motion vectors and per-sample patterns (common/motion.glsl, materials/techniques/stipple.glsl)
    "u_previous_model", "u_view_projection", "u_previous_view_projection", "u_sample_index"})


class Params(StrictValues):
    """Base of every parameter model: unknown keys are errors, values never change, numbers are
    finite and nothing is converted from another type (:class:`StrictValues`)."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    def model_copy(self, *, update: Mapping[str, Any] | None = None,
                   deep: bool = False) -> Params:
        """A copy with ``update``'s values, validated as a scene file's are (pydantic's
        ``model_copy`` takes them unchecked: ``specular_exponent=-5`` would render);
        ``InputError`` naming the key."""
        if not update:
            return super().model_copy(deep=deep)
        return validate_params(type(self), {**self.model_dump(), **update}, None)


def validate_params(model: type[Params], values: dict[str, Any], where: str | None) -> Params:
    """``model(**values)``; a validation error is an ``InputError`` naming the key (an
    ``InputErrors`` naming each, for several), an unknown one with the closest known."""
    try:
        return model(**values)
    except ValidationError as exc:
        raise validation_error(exc, where, model) from None


def uniform_value(value: Any) -> bool:
    """Whether a parameter value maps to a GLSL uniform as it is."""
    if isinstance(value, bool | int | float):
        return True
    return isinstance(value, tuple) and 2 <= len(value) <= 4 and \
        all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)


def params_uniforms(params: BaseModel, overrides: UniformOverrides) -> dict[str, Any]:
    """``u_<field>`` for every field of ``params`` that is a uniform (see the module doc)."""
    out: dict[str, Any] = {}
    for name in type(params).model_fields:
        value = getattr(params, name)
        if name in overrides:
            override = overrides[name]
            if override is not None:
                out.update(override(value))
        elif uniform_value(value):
            out[f"u_{name}"] = value
    reserved = RESERVED_UNIFORMS.intersection(out)
    if reserved:
        raise ValueError(f"{type(params).__name__}: parameters would set the framework's "
                         f"uniform {', '.join(sorted(reserved))}; rename them or map them with "
                         "uniform_overrides")
    return out
