"""The light interface: a light type's parameters, GLSL function and records.

A light type is a class with a unique ``name`` (the scene file's ``type``), a pydantic ``Params``
model, a GLSL file defining ``vec3 <glsl_function>(LightRecord light, Surface s, vec3 P, vec3 V)``
and a ``record(view)`` method packing the light into four vec4s in view space
(``common/lighting.glsl`` documents the layout). The same record feeds both pipelines: the deferred
pass reads it per instance, the forward pass loops over all records per fragment.

``volume`` says how the deferred pass bounds a light: ``"fullscreen"`` (directional, ambient) or
``"sphere"`` (the record's ``position.xyz`` is the centre and ``position.w`` the radius), so that
cost follows the pixels a light touches.

A type with more data than the record's type-specific slots declares it: ``data``, a tuple of
:class:`LightDatum`, each one more ``vec4`` of the record after its four. Its GLSL reads them by
name through a struct generated for the type (``<glsl_function>_data(light)``,
:mod:`deferred.lighting.dispatch`), so no value hides in another field's spare components and
nothing reads past what the type declares; ``deferred params light`` lists them.

A type whose GLSL reads textures (an environment's maps, an area light's LTC tables) gives
them from :meth:`Light.textures`, bound wherever lights are evaluated, as a shading model's
are; a light naming files checks them in :meth:`Light.check_files` (paths relative to the
scene file's folder, ``base_dir``).
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from pydantic import Field, field_validator

from deferred.names import LightVolume, ShadowProjection
from deferred.params import Params, validate_params
from deferred.revision import Revisioned
from deferred.validation import Radiance

if sys.version_info >= (3, 11):
    from importlib.resources.abc import Traversable
else:  # Python 3.10
    from importlib.abc import Traversable

if TYPE_CHECKING:
    import moderngl

    from deferred.core.frame import Frame

Vec3 = tuple[float, float, float]
RECORD_VEC4S = 4  # color, position, direction, extra: every light's


@dataclass(frozen=True)
class LightDatum:
    """One ``vec4`` of a light type's own data, stored after the record's four: ``name`` is
    its field in the type's generated GLSL struct (an identifier), ``description`` what its
    components hold (``deferred params light`` shows it)."""

    name: str
    description: str

    def __post_init__(self) -> None:
        if not (isinstance(self.name, str) and self.name.isidentifier() and self.name.isascii()):
            raise ValueError(f"light datum name {self.name!r} is not a GLSL identifier")


def check_light_data(cls: type) -> str | None:
    """What is wrong with a light type's ``data`` declaration (said after "which"), or None."""
    data = getattr(cls, "data", ())
    if not isinstance(data, tuple) or not all(isinstance(d, LightDatum) for d in data):
        return "has a data that is not a tuple of deferred.api.LightDatum"
    names = [d.name for d in data]
    if len(set(names)) != len(names):
        return f"declares the light datum names {names}, some twice"
    if data and not (isinstance(cls.glsl_function, str) and cls.glsl_function.isidentifier()):
        return "declares data but its glsl_function is not an identifier"
    return None


class LightParams(Params):
    """Base of every light's parameter model: a colour and its intensity."""

    color: Radiance = Field((1.0, 1.0, 1.0), description="linear RGB colour, each >= 0")
    intensity: float = Field(1.0, ge=0.0, description="multiplier of color")


MIN_SHADOW_RESOLUTION, MAX_SHADOW_RESOLUTION = 64, 8192


class ShadowParams(LightParams):
    """The parameters of a light that may cast shadows (a mixin of directional, spot and point
    lights). Biases are in shadow-map texels at the shaded point (their world size there), so
    they hold for any resolution, cascade and distance."""

    shadows: bool = Field(False, description="cast shadows (a slot of the shadow atlas)")
    shadow_resolution: int = Field(1024, description="texels on a side of each map (a power "
                                   f"of two, {MIN_SHADOW_RESOLUTION}..{MAX_SHADOW_RESOLUTION})")
    shadow_bias: float = Field(1.0, ge=0.0, le=16.0,
                               description="depth bias toward the light, in texels")
    normal_bias: float = Field(1.0, ge=0.0, le=16.0,
                               description="offset along the surface normal, in texels")
    shadow_filter: Literal["pcf", "soft"] = Field("pcf", description="pcf (3x3 hardware "
                                        "comparisons) or soft (a wide Poisson disk)")
    shadow_softness: float = Field(4.0, ge=1.0, le=32.0,
                                   description="soft filter: the disk's radius, in texels")

    @field_validator("shadow_resolution")
    @classmethod
    def _power_of_two(cls, value: int) -> int:
        if not MIN_SHADOW_RESOLUTION <= value <= MAX_SHADOW_RESOLUTION or value & (value - 1):
            raise ValueError(f"must be a power of two in {MIN_SHADOW_RESOLUTION}.."
                             f"{MAX_SHADOW_RESOLUTION}")
        return value


class Light(Revisioned):
    """A light type: a ``name``, a validated ``Params`` model, a GLSL function
    (``glsl_file``, ``glsl_function``: ``vec3 f(LightRecord light, Surface s, vec3 P, vec3 V)``)
    and how it packs itself for the GPU (:meth:`record`: four ``vec4`` in view space).
    ``volume`` says whether it lights the whole screen or a sphere around it.

    A type whose ``Params`` derive from :class:`ShadowParams` and that names a
    ``shadow_projection`` casts shadows when ``shadows = true``: the framework writes the
    light's shadow slot into its record's ``extra.w`` (so a record leaves ``extra.w`` alone),
    and the GLSL function multiplies what it returns by its projection's
    ``light_shadow_<projection>(...)`` (``lighting/shadows.glsl``).
    """

    name: ClassVar[str]
    Params: ClassVar[type[LightParams]] = LightParams
    glsl_file: ClassVar[str] = ""
    glsl_function: ClassVar[str] = ""
    volume: ClassVar[LightVolume] = LightVolume.FULLSCREEN
    # how its shadow maps are made, where its Params are ShadowParams (None: it casts none)
    shadow_projection: ClassVar[ShadowProjection | None] = None
    shader_root: ClassVar[Traversable | Path | None] = None
    # the type's own vec4s after the record's four (read in GLSL through a generated struct)
    data: ClassVar[tuple[LightDatum, ...]] = ()
    # an area light: its GLSL calls shade_area (the shading models' area answers are compiled)
    area: ClassVar[bool] = False
    type_id: ClassVar[int] = 0  # set by the registry
    # a node of the scene graph (or its label) whose space position and direction are in;
    # None: the world (each frame's state holds the light placed in the world)
    parent: Any = None

    def __init__(self, params: LightParams | None = None, base_dir: Path | None = None):
        self.params = params if params is not None else self.Params()
        self.base_dir = base_dir  # the scene file's folder: relative file parameters' root

    @classmethod
    def from_dict(cls, values: dict[str, Any], where: str | None = None,
                  base_dir: Path | None = None) -> Light:
        light = cls(validate_params(cls.Params, values, where), base_dir)
        light.check_files(where)
        return light

    def check_files(self, where: str | None) -> None:
        """Raise ``InputError`` (naming ``where``'s key) for parameters naming files that are
        not there or not readable images; nothing by default."""

    def resolve_path(self, value: str | Path) -> Path:
        """A file parameter's path: relative ones from the scene file's folder."""
        path = Path(value)
        return path if path.is_absolute() or self.base_dir is None else self.base_dir / path

    @classmethod
    def textures(cls, frame: Frame) -> dict[str, moderngl.Texture]:
        """Samplers the type's GLSL reads (made from the frame's lights of this type), bound
        wherever lights are evaluated; none by default."""
        return {}

    def emitter_radius(self) -> float:
        """The radius of the disc the light emits from (0: a point); an area light's sizes its
        soft shadows (``shadow_filter = "pcss"``)."""
        return 0.0

    @property
    def casts_shadows(self) -> bool:
        """Whether this light asks for shadow maps (``shadows = true`` on a type that has a
        ``shadow_projection``)."""
        return self.shadow_projection is not None and bool(getattr(self.params, "shadows", False))

    def radiance(self) -> np.ndarray:
        return np.asarray(self.params.color, dtype=np.float64) * self.params.intensity

    @classmethod
    def record_vec4s(cls) -> int:
        """``vec4``s of one record: the four every light has and the type's ``data``."""
        return RECORD_VEC4S + len(cls.data)

    def record(self, view: np.ndarray) -> np.ndarray:
        """(4 + len(data), 4) float32: color, position, direction, extra (view space; see
        lighting.glsl), then the type's data in its declared order. A function of ``params``
        and ``view`` alone: the light buffer packs the records again only when one of them
        changes (``LightBuffer.upload``)."""
        raise NotImplementedError

    @classmethod
    def records(cls, lights: list[Light], view: np.ndarray) -> np.ndarray:
        """``(len(lights), 4 + len(data), 4)`` float32: :meth:`record` of each light of this
        type. A type with many lights a frame (point, spot) overrides it with numpy over all of
        them (a ``record`` call per light is slow at a thousand lights:
        benchmarks/README.md)."""
        width = cls.record_vec4s()
        return np.stack([np.asarray(light.record(view), dtype=np.float32).reshape(width, 4)
                         for light in lights]) if lights else np.zeros((0, width, 4), np.float32)


def view_point(view: np.ndarray, point) -> np.ndarray:
    """A world-space point in view space (``view`` is the 4x4 world-to-view matrix)."""
    return (view @ np.append(np.asarray(point, dtype=np.float64), 1.0))[:3]


def view_points(view: np.ndarray, points: np.ndarray) -> np.ndarray:
    """:func:`view_point` of ``(n, 3)`` points."""
    return points @ view[:3, :3].T + view[:3, 3]


def view_directions(view: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """:func:`view_direction` of ``(n, 3)`` directions."""
    d = directions @ view[:3, :3].T
    return d / np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)


def radiances(lights: list[Light]) -> np.ndarray:
    """:meth:`Light.radiance` of each light, ``(n, 3)``."""
    return np.array([light.params.color for light in lights], np.float64) * \
        np.array([light.params.intensity for light in lights], np.float64)[:, None]


def view_direction(view: np.ndarray, direction) -> np.ndarray:
    """A world-space direction in view space, normalised (rotation only)."""
    d = view[:3, :3] @ np.asarray(direction, dtype=np.float64)
    return d / max(np.linalg.norm(d), 1e-12)
