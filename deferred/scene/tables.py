"""The tables of a scene file, validated (pydantic): what each key may hold, its default and a
one-line description. The loader (:mod:`deferred.scene.loader`) builds the scene from them;
``deferred schema`` writes their JSON Schema (:mod:`deferred.scene.schema`)."""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from deferred.names import LightPath, ShadowAllocation
from deferred.scene.camera import CameraModel
from deferred.scene.shadow_budget import OPACITY_SCALES
from deferred.scene.tracks import INTERPOLATIONS
from deferred.scene.transform import (
    MIN_SCALE,
    Quaternion,
    RotationOrder,
    Transform,
    nonzero_quaternion,
    one_rotation,
    scale_too_small,
)
from deferred.validation import Radiance, StrictValues

Vec3 = tuple[float, float, float]
LISTS = ("object", "group", "light", "effect", "event", "track")  # lists of tables, item by item


class _Strict(StrictValues):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class PlacementModel(_Strict):
    """The placement keys of an ``[[object]]``, a ``[[group]]``: local to ``parent``."""

    parent: str | None = Field(None, max_length=1000,
                               description="the name of an object or group this one is placed "
                                           "in (its position, rotation and scale are local to it)")
    position: Vec3 = (0.0, 0.0, 0.0)
    rotation: Vec3 = Field((0.0, 0.0, 0.0), description="Euler degrees, turned in "
                                                       "rotation_order (X, then Y, then Z)")
    rotation_order: RotationOrder = Field("XYZ", description="the axis turned about first, "
                                          "then the second, then the third")
    quaternion: Quaternion | None = Field(None, description="[x, y, z, w] instead of rotation")
    scale: float | Vec3 = Field(1.0, description="one number, or one per axis")

    @field_validator("quaternion")
    @classmethod
    def _unit(cls, quaternion: Quaternion | None) -> Quaternion | None:
        return nonzero_quaternion(quaternion)

    @model_validator(mode="after")
    def _check_scale(self) -> PlacementModel:
        scale = np.broadcast_to(np.asarray(self.scale, dtype=float), (3,))
        if np.any(scale == 0.0):
            raise ValueError("scale must not be zero")
        if scale_too_small(scale):  # its normal matrix would overflow float32
            raise ValueError(f"scale must be at least {MIN_SCALE:g} in size")
        return self

    @model_validator(mode="after")
    def _one_rotation(self) -> PlacementModel:
        one_rotation(self.rotation, self.quaternion)
        return self

    def transform(self) -> Transform:
        """The placement as the scene graph holds it (validated here already)."""
        return Transform.model_construct(position=self.position, rotation=self.rotation,
                                         rotation_order=self.rotation_order,
                                         quaternion=self.quaternion, scale=self.scale)


class ObjectModel(PlacementModel):
    """An ``[[object]]`` table: a mesh drawn with a material, placed in its parent."""

    name: str | None = Field(None, max_length=1000,
                             description="label: printable, no control characters")
    mesh: str
    material: str = Field("standard", description="a registered material; on a glTF mesh, "
                                                  "given: it replaces the file's materials")
    params: dict[str, Any] = Field(default_factory=dict)
    node: str | None = Field(None, max_length=1000,
                             description="a glTF mesh's node (by name): it and its children "
                                         "alone")
    animation: str | None = Field(None, max_length=1000,
                                  description="a glTF mesh's animation, by name or index "
                                              "(default the first; 'none': none)")

    @field_validator("name")
    @classmethod
    def _printable(cls, name: str | None) -> str | None:
        return printable_label(name)


class GroupModel(PlacementModel):
    """A ``[[group]]`` table: a named node without a mesh that objects, lights, the camera and
    other groups may be placed in."""

    name: str = Field(max_length=1000, description="label: printable, no control characters")

    @field_validator("name")
    @classmethod
    def _printable(cls, name: str) -> str:
        return printable_label(name)


def printable_label(name: str | None) -> str | None:
    # a label goes into file names, messages and contact sheets
    if name is not None and (not name or any(ord(c) < 32 or ord(c) == 127 for c in name)):
        raise ValueError("must be printable text: no control characters (newline, tab, "
                         "NUL) and not empty")
    return name


class CameraTable(CameraModel):
    """The ``[camera]`` table: :class:`CameraModel` and the node it is placed in."""

    parent: str | None = Field(None, max_length=1000,
                               description="the name of an object or group whose space "
                                           "position, target and up are in")


class EventModel(_Strict):
    """An ``[[event]]`` table: from ``time`` on, ``object``'s material takes ``params``."""

    time: float = Field(ge=0.0, allow_inf_nan=False, description="seconds")
    object: str = Field(description="the name (label) of a scene object")
    params: dict[str, Any] = Field(description="material parameters, merged over the object's")


class TrackModel(_Strict):
    """A ``[[track]]`` table: keys moving the camera, a light or an object
    (:mod:`deferred.scene.tracks`)."""

    target: str = Field(description="what moves: 'camera', 'object:NAME', 'light:INDEX' (0 is "
                                    "the first [[light]]) or 'light:NAME'")
    interpolation: Literal[INTERPOLATIONS] = Field(
        "linear", description="between keys: step (hold), linear, or smooth (cubic Hermite, "
                              "Catmull-Rom tangents, zero at the first and last keys)")
    keys: list[dict[str, Any]] = Field(
        min_length=1, description="{ time = seconds, and the properties set then }, in rising "
                                  "time")


class TypedModel(BaseModel):
    """A ``[[light]]`` or ``[[effect]]`` table: its type, then that type's parameters."""

    model_config = ConfigDict(extra="allow")
    type: str


class ShadowsModel(_Strict):
    """The ``[shadows]`` table: the shadow atlas and its budget (:class:`ShadowBudget`)."""

    atlas_size: int = Field(4096, description="texels on a side of the shadow atlas (a power "
                                              "of two, 256..16384)")
    max_shadowed_lights: int = Field(16, ge=1, le=64, description="lights given shadow maps, "
                                     "in scene order; the rest are unshadowed")
    opacity_scale: float = Field(0.25, description="texels on a side of the fur's deep "
                                 "opacity maps per shadow-map texel (1, 0.5, .. 1/16)")
    allocation: ShadowAllocation = Field(
        ShadowAllocation.COVERAGE, description="how large each spot and point light's maps are: "
        "coverage (by the part of the screen its shadowed region covers, at most its "
        "shadow_resolution; maps shrink before lights are left out) or fixed (its "
        "shadow_resolution)")
    cascade_updates: Literal["every_frame", "staggered"] | None = Field(
        None, description="while the camera moves, a directional light's cascades all drawn "
                          "every frame, or the nearest every frame and the farther in turn "
                          "(staggered: a frame depends on those before it; not for farm "
                          "renders); unset: every frame, the viewer staggered")

    @field_validator("opacity_scale")
    @classmethod
    def _fraction(cls, value: float) -> float:
        if value not in OPACITY_SCALES:
            raise ValueError("must be 1, 0.5, 0.25, 0.125 or 0.0625")
        return value

    @field_validator("atlas_size")
    @classmethod
    def _power_of_two(cls, value: int) -> int:
        if not 256 <= value <= 16384 or value & (value - 1):
            raise ValueError("must be a power of two in 256..16384")
        return value


class SceneModel(_Strict):
    size: tuple[int, int] = (1280, 720)
    background: Radiance | Literal["environment"] = Field(
        (0.02, 0.02, 0.025), description="linear RGB behind everything, each >= 0, or "
                                         "\"environment\": the environment light's map")
    exposure: float = Field(1.0, gt=0.0)
    tonemap: Literal["reinhard", "aces", "none"] = "aces"
    light_path: LightPath | None = Field(
        None, description="how lights reach the pixels (deferred.lighting.paths); default the "
                          "fastest the context allows")
    camera: CameraTable = Field(default_factory=CameraTable)
    shadows: ShadowsModel = Field(default_factory=ShadowsModel)
    ssao: dict[str, Any] | None = Field(
        None, description="screen-space ambient occlusion (the same as [[effect]] type 'ssao')")
    object: list[ObjectModel] = Field(default_factory=list)
    group: list[GroupModel] = Field(default_factory=list)
    light: list[TypedModel] = Field(default_factory=list)
    effect: list[TypedModel] = Field(default_factory=list)
    event: list[EventModel] = Field(default_factory=list)
    track: list[TrackModel] = Field(default_factory=list)
