"""The material interface: plain parameter data, GLSL files, and the passes a material contributes.

A material is a class with a unique ``name``, a pydantic ``Params`` model (defaults, ranges, a
one-line description per field) and a ``surface_shader``: a GLSL file defining
``Surface material_surface(SurfaceInput i)`` (``common/surface.glsl``). With only that, the base
class gives it a G-buffer pass (geometry phase) and a forward lit pass (forward pipeline). Materials
that need more (stipple, shells, composition) override the ``*_passes`` hooks; they never edit the
pipeline. Register with ``@deferred.registry.materials.register`` or the entry-point group
``deferred.materials``.
"""

from __future__ import annotations

from importlib.resources.abc import Traversable
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import moderngl
from pydantic import BaseModel, ConfigDict, ValidationError

from .errors import InputError
from .gbuffer import DEPTH, GBUFFER_COLOR_TARGETS
from .passes import ObjectPass, Phase, RenderPass
from .targets import COMPOSITE
from .validation import format_validation_error

if TYPE_CHECKING:
    from .frame import Frame
    from .scene import SceneObject


class MaterialParams(BaseModel):
    """Base of every material's parameter model: unknown keys are errors."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class GBufferPass(ObjectPass):
    """Geometry phase: the material's surface written into the G-buffer."""

    fragment = "gbuffer/geometry.frag"
    colors = GBUFFER_COLOR_TARGETS
    depth = DEPTH


class ForwardLitPass(ObjectPass):
    """Forward pipeline: the material's surface lit by every light in one pass."""

    fragment = "forward/lit.frag"
    colors = (COMPOSITE,)
    depth = DEPTH


class Material:
    name: ClassVar[str]
    Params: ClassVar[type[MaterialParams]] = MaterialParams
    surface_shader: ClassVar[str] = ""
    shader_root: ClassVar[Traversable | Path | None] = None  # extra GLSL root (plugins)
    type_id: ClassVar[int] = 0  # set by the registry; written to the G-buffer's material id

    def __init__(self, params: MaterialParams | None = None, base_dir: Path | None = None):
        self.params = params if params is not None else self.Params()
        self.base_dir = base_dir

    @classmethod
    def from_dict(cls, values: dict[str, Any], base_dir: Path | None = None,
                  where: str | None = None) -> Material:
        """Validate ``values`` against ``Params``; errors name the offending key."""
        try:
            params = cls.Params(**values)
        except ValidationError as exc:
            raise InputError(*format_validation_error(exc, where)) from None
        material = cls(params, base_dir)
        material.check_files(where)
        return material

    def check_files(self, where: str | None) -> None:
        """Raise ``InputError`` for parameters naming files that do not exist."""

    def resolve_path(self, value: str | Path) -> Path:
        path = Path(value)
        if not path.is_absolute() and self.base_dir is not None:
            path = self.base_dir / path
        return path

    # -- shader inputs -----------------------------------------------------------------------
    @classmethod
    def shader_folder(cls) -> str:
        """The folder of the material's own GLSL (that of ``surface_shader``)."""
        return cls.surface_shader.rpartition("/")[0]

    def defines(self, obj: SceneObject) -> dict[str, str]:
        """Preprocessor defines of this material's programs for ``obj``."""
        return {"SURFACE_FILE": f'"{self.surface_shader}"'}

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        return {}

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        return {}

    # -- passes per phase --------------------------------------------------------------------
    def geometry_passes(self, obj: SceneObject) -> list[RenderPass]:
        return [GBufferPass(f"{obj.label}.gbuffer", Phase.GEOMETRY, obj)]

    def screen_passes(self, obj: SceneObject) -> list[RenderPass]:
        return []

    def stipple_passes(self, obj: SceneObject) -> list[RenderPass]:
        return []

    def material_passes(self, obj: SceneObject) -> list[RenderPass]:
        return []

    def forward_passes(self, obj: SceneObject) -> list[RenderPass]:
        return [ForwardLitPass(f"{obj.label}.forward", Phase.FORWARD, obj)]

    def passes(self, phase: Phase, obj: SceneObject) -> list[RenderPass]:
        hooks = {Phase.GEOMETRY: self.geometry_passes, Phase.SCREEN: self.screen_passes,
                 Phase.STIPPLE: self.stipple_passes, Phase.MATERIAL: self.material_passes,
                 Phase.FORWARD: self.forward_passes}
        return hooks[phase](obj) if phase in hooks else []

    @classmethod
    def describe_params(cls) -> list[dict[str, Any]]:
        """Name, type, default, range and doc of each parameter (for ``deferred materials``)."""
        return describe_model(cls.Params)


def describe_model(model: type[BaseModel]) -> list[dict[str, Any]]:
    rows = []
    for name, field in model.model_fields.items():
        bounds = []
        for meta in field.metadata:
            for attr, symbol in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
                value = getattr(meta, attr, None)
                if value is not None:
                    bounds.append(f"{symbol} {value}")
        annotation = field.annotation
        type_name = getattr(annotation, "__name__", None) or str(annotation).replace(
            "typing.", "")
        rows.append({"name": name, "type": type_name, "default": field.default,
                     "range": ", ".join(bounds), "doc": field.description or ""})
    return rows
