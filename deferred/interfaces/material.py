"""The material interface: plain parameter data, GLSL files, and the passes a material contributes.

A material is a class with a unique ``name``, a pydantic ``Params`` model (defaults, ranges, a
one-line description per field) and a ``surface_shader``: a GLSL file defining
``Surface material_surface(SurfaceInput i)`` (``common/surface.glsl``). With only that, the base
class gives it a G-buffer pass (geometry phase) and a forward lit pass (forward pipeline). Materials
that need more (stipple, shells, composition) override the ``*_passes`` hooks, and may add passes
once per scene (``scene_passes``); they never edit the pipeline. Register with
``@deferred.api.materials.register`` or the entry-point group ``deferred.materials``.

Parameters become uniforms by name (:mod:`deferred.params`): field ``fur_length`` is
``u_fur_length``; ``uniform_overrides`` maps a field to ``None`` (not a uniform: a pass count, a
file, a define) or to a function giving the uniforms it becomes.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import moderngl
import numpy as np
from pydantic import Field

from deferred.core.passes import ObjectPass, Phase, RenderPass
from deferred.errors import InputError
from deferred.gbuffer.layout import (
    DEPTH,
    GBUFFER_COLOR_TARGETS,
    GBufferData,
    GBufferLayout,
    data_write_file,
)
from deferred.gbuffer.surface_id import surface_id
from deferred.gl.targets import COMPOSITE
from deferred.interfaces import registry
from deferred.memo import kept_while
from deferred.params import Params, UniformOverrides, params_uniforms, validate_params
from deferred.revision import Revisioned
from deferred.validation import require_regular_file

if sys.version_info >= (3, 11):
    from importlib.resources.abc import Traversable
else:  # Python 3.10
    from importlib.abc import Traversable

if TYPE_CHECKING:
    from deferred.core.frame import Frame
    from deferred.core.protocols import SceneObjectLike


class MaterialParams(Params):
    """Base of every material's parameter model: unknown keys are errors."""


class BlinnPhongParams(MaterialParams):
    """The Blinn-Phong parameters the G-buffer stores (a mixin: redefine a field to change its
    default)."""

    specular_intensity: float = Field(0.5, ge=0.0, le=1.0, description="Blinn-Phong intensity")
    specular_exponent: float = Field(32.0, ge=1.0, le=2048.0, description="Blinn-Phong exponent")


class GBufferPass(ObjectPass):
    """Geometry phase: the material's surface written into the G-buffer: the core targets and
    the G-buffer data the material declares (``Material.gbuffer_targets``)."""

    fragment = "gbuffer/geometry.frag"
    depth = DEPTH

    def __init__(self, name: str, phase: Phase, obj: SceneObjectLike, **options: Any):
        options.setdefault("colors", obj.material.gbuffer_targets())
        super().__init__(name, phase, obj, **options)


class ForwardLitPass(ObjectPass):
    """Forward pipeline: the material's surface lit by every light in one pass (``lequal``:
    Forward+ lays the same depth down in its pre-pass first)."""

    fragment = "forward/lit.frag"
    colors = (COMPOSITE,)
    depth = DEPTH
    depth_func = "lequal"


SHADOW_CASTER_VERTEX = "shadows/caster.vert"
SHADOW_CASTER_FRAGMENT = "shadows/caster.frag"


# A vertex shader of the camera (``u_view``, ``u_projection``) compiled with these defines
# draws from the light instead, reading :attr:`ShadowView.camera_uniforms`: how a material's
# own vertex stage (fur shells, displaced strands) becomes its shadow caster's.
SHADOW_CASTER_DEFINES = {"u_view": "u_shadow_view", "u_projection": "u_shadow_projection",
                         "SHADOW_CASTER": "1"}


@dataclass(frozen=True)
class ShadowView:
    """One shadow map being drawn (:meth:`Material.draw_shadow`): the light's world -> view
    and view -> clip matrices, where the light is (a world position, or ``None`` for a
    directional light) and the direction it shines (world, unit), for casters that shape
    themselves to it. ``opacity_maps``: the light has deep opacity maps this frame, which
    every material with ``opacity_shadows`` draws itself into (:meth:`Material.draw_opacity`)
    and through which the other surfaces take its shadow (``lighting/shadows.glsl``): such a
    volume may leave its translucent part out of the depth map."""

    view: np.ndarray
    projection: np.ndarray
    position: np.ndarray | None
    direction: np.ndarray
    opacity_maps: bool = False

    @property
    def uniforms(self) -> dict[str, Any]:
        """``u_shadow_view_projection``: what ``shadows/caster.vert`` reads."""
        return {"u_shadow_view_projection": self.projection @ self.view}

    @property
    def camera_uniforms(self) -> dict[str, Any]:
        """The light as the camera of a vertex shader compiled with
        :data:`SHADOW_CASTER_DEFINES`."""
        return {"u_shadow_view": self.view, "u_shadow_projection": self.projection}


class Material(Revisioned):
    """A material: a unique ``name``, a validated ``Params`` model and a GLSL surface function
    (``surface_shader``, ``Surface material_surface(SurfaceInput i)``) lit by ``shading_model``.

    The base class gives each object a G-buffer pass and a forward lit pass; the per-object
    hooks (:meth:`geometry_passes`, :meth:`stipple_passes`, :meth:`material_passes`,
    :meth:`forward_passes`, ...) and :meth:`scene_passes` add more. Every parameter becomes a
    ``u_<field>`` uniform unless ``uniform_overrides`` says otherwise.
    """

    name: ClassVar[str]
    Params: ClassVar[type[MaterialParams]] = MaterialParams
    surface_shader: ClassVar[str] = ""
    shader_root: ClassVar[Traversable | Path | None] = None  # extra GLSL root (plugins)
    type_id: ClassVar[int] = 0  # set by the registry; written to the G-buffer's id channel
    shading_model: str = "blinn_phong"  # the BRDF lights call (a registered shading model)
    gbuffer_data: tuple[GBufferData, ...] = ()  # extra per-pixel data (deferred.interfaces.shading)
    # field -> None (not a uniform) or value -> {uniform: value} (see the module documentation)
    uniform_overrides: ClassVar[UniformOverrides] = {}
    # parameters the material reads once, at t = 0 (a simulation's set-up): a scene timeline
    # may not change them
    timeline_fixed: ClassVar[tuple[str, ...]] = ()
    # parameters a timeline may raise but not lower: what they count has happened (droplets
    # fallen), and a simulation does not take it back
    timeline_growing: ClassVar[tuple[str, ...]] = ()
    # Whether uniforms() and textures() are a function of the params alone (textures made
    # through frame.resources, which last as long as the renderer): the renderer then keeps
    # them from frame to frame while the params are the same object. None: where the class
    # keeps Material's own uniforms and textures (Material.keeps_inputs). A material reading
    # the frame (its time, size or targets) in them leaves it unset or False.
    inputs_from_params: ClassVar[bool | None] = None
    # debug views (``deferred render --view <material>.<name>``): name -> (what it shows, the
    # parameters that make the material draw it)
    debug_views: ClassVar[dict[str, tuple[str, dict[str, Any]]]] = {}

    def __init__(self, params: MaterialParams | None = None, base_dir: Path | None = None):
        self.params = params if params is not None else self.Params()
        self.base_dir = base_dir

    @classmethod
    def from_dict(cls, values: dict[str, Any], base_dir: Path | None = None,
                  where: str | None = None) -> Material:
        """Validate ``values`` against ``Params``; errors name the offending key."""
        material = cls(validate_params(cls.Params, values, where), base_dir)
        registry.shading_models.get(material.shading_model,
                                    f"{where}: shading model" if where else "shading model")
        material.check_files(where)
        return material

    def check_files(self, where: str | None) -> None:
        """Raise ``InputError`` for parameters naming files that do not exist."""

    def resolve_path(self, value: str | Path) -> Path:
        path = Path(value)
        if not path.is_absolute() and self.base_dir is not None:
            path = self.base_dir / path
        return path

    def file_parameter(self, value: str | Path, what: str, key: str) -> Path:
        """A parameter naming a file (relative to the scene's folder), checked to be one:
        ``InputError`` naming ``key`` for an empty name, a missing file, a folder, a pipe or a
        device (each said so; a pipe would block the read for good)."""
        if not str(value).strip():
            raise InputError(f"is empty; name the {what}", key)
        path = self.resolve_path(value)
        require_regular_file(path, what, key)
        return path

    def motion_extent(self, obj: SceneObjectLike) -> float:
        """How far, in object units along the mesh's normals, what the material draws for
        ``obj`` reaches beyond the mesh (fur shells and fins, hair): motion vectors are drawn
        over the mesh pushed out that far (deferred.effects.taa), so the pixels of those
        layers move with the object."""
        return 0.0

    # -- shader inputs -----------------------------------------------------------------------
    @classmethod
    def shader_folder(cls) -> str:
        """The folder of the material's own GLSL (that of ``surface_shader``)."""
        return cls.surface_shader.rpartition("/")[0]

    def defines(self, obj: SceneObjectLike) -> dict[str, str]:
        """Preprocessor defines of this material's programs for ``obj``: a function of the
        params and ``obj.mesh`` only (an object pass keeps its program while those are the
        same objects; params are replaced whole, never changed in place)."""
        return dict(self._base_defines())  # a copy for the caller to extend

    @kept_while()  # the class, its shading model and so its data never change
    def _base_defines(self) -> dict[str, str]:
        names = [data.name for data in self.written_data()]
        return {"SURFACE_FILE": f'"{self.surface_shader}"',
                "GBUFFER_DATA_WRITE": f'"{data_write_file(names)}"'}

    @kept_while()  # the class, its shading model and so its data never change
    def written_data(self) -> tuple[GBufferData, ...]:
        """The G-buffer data this material's objects write: its own and its shading
        model's, by name."""
        model = registry.shading_models.get(self.shading_model)
        merged: dict[str, GBufferData] = {}
        for data in (*model.gbuffer_data, *self.gbuffer_data):
            if data.name in merged and merged[data.name] != data:
                raise InputError(f"material {self.name}: G-buffer data '{data.name}' is "
                                 "declared twice with different formats")
            merged[data.name] = data
        return tuple(merged.values())

    def gbuffer_targets(self) -> tuple[str, ...]:
        """The targets this material's G-buffer passes write: the core G-buffer, then its data
        (its own and its shading model's), in the order of ``gbuffer/write.glsl``'s outputs."""
        return (*GBUFFER_COLOR_TARGETS, *(data.name for data in self.written_data()))

    @kept_while("shading_model", "type_id")  # asked for by every object, every frame
    def surface_id(self) -> int:
        """The G-buffer id of this material's pixels: its shading model and its type id."""
        model_id = registry.shading_models.get(self.shading_model).type_id
        return surface_id(self.type_id, model_id)

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        """``u_<field>`` for every parameter that is a uniform (``uniform_overrides``)."""
        return dict(self._params_uniforms())

    @kept_while("params")  # params are frozen and replaced whole (a timeline event)
    def _params_uniforms(self) -> dict[str, Any]:
        return params_uniforms(self.params, self.uniform_overrides)

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        return {}

    @classmethod
    def keeps_inputs(cls) -> bool:
        """Whether the renderer may keep this material's inputs across frames: the
        ``inputs_from_params`` of the nearest class that sets it, unless a class below that
        one overrides ``uniforms`` or ``textures`` (it may read the frame: not kept)."""
        for klass in cls.__mro__:
            flag = klass.__dict__.get("inputs_from_params")
            if flag is not None:
                return flag
            if klass is Material:
                return True
            if "uniforms" in klass.__dict__ or "textures" in klass.__dict__:
                return False
        return False  # not a Material subclass's MRO (a mixin listed after it)

    def held_memory(self, obj: SceneObjectLike) -> dict[str, int]:
        """Bytes this material will hold for ``obj`` (textures, simulation state) by what they
        are, counted with the render targets against the memory budget before the first frame:
        a key names the thing (``texture /path/fur.png``), so a texture objects share counts
        once. Files are sized by their headers. By default nothing."""
        return {}

    def check_time(self, time: float, where: str) -> None:
        """Refuse (``InputError`` naming ``where``) a frame time this material cannot reach in
        bounded work, before any frame is rendered: a simulation stepping from 0 to it."""

    def check_time_for(self, obj: SceneObjectLike, time: float, where: str) -> None:
        """:meth:`check_time` for this material on ``obj``, whose mesh may set the work (a
        simulation of a strand a triangle); by default :meth:`check_time`."""
        self.check_time(time, where)

    # -- passes per phase --------------------------------------------------------------------
    def geometry_passes(self, obj: SceneObjectLike) -> list[RenderPass]:
        return [GBufferPass(f"{obj.label}.gbuffer", Phase.GEOMETRY, obj)]

    def screen_passes(self, obj: SceneObjectLike) -> list[RenderPass]:
        return []

    def stipple_passes(self, obj: SceneObjectLike) -> list[RenderPass]:
        return []

    def material_passes(self, obj: SceneObjectLike) -> list[RenderPass]:
        return []

    def forward_passes(self, obj: SceneObjectLike) -> list[RenderPass]:
        return [ForwardLitPass(f"{obj.label}.forward", Phase.FORWARD, obj)]

    @classmethod
    def scene_passes(cls, objects: list[SceneObjectLike], phase: Phase) -> list[RenderPass]:
        """Passes this material adds once per scene, not per object, in ``phase`` (scene-wide
        setup, screen or post effects of its own); ``objects`` are the scene's objects of this
        material. Passes of one name from several materials (a shared technique's) run once."""
        return []

    def draw_shadow(self, frame: Frame, obj: SceneObjectLike, view: ShadowView) -> None:
        """Draw ``obj``'s depth into the shadow map ``view`` (the framework has bound that
        tile of the shadow atlas, cleared it and set depth-only state: depth test, no culling,
        a slope-scaled depth offset). By default the mesh through ``shadows/caster.vert``; a
        material whose look is not its mesh (fur shells, displaced strands) draws that, with
        ``view.uniforms`` and a vertex stage of its own; one that casts no shadow draws
        nothing."""
        program = frame.shaders.program(SHADOW_CASTER_VERTEX, SHADOW_CASTER_FRAGMENT)
        frame.bind(program, view.uniforms, offered=frame.object_uniforms(obj))
        frame.draw_mesh(obj.mesh, program)

    # A volume that shadows itself through deep opacity maps (fur; deferred.lighting.shadows):
    # it draws them (draw_opacity) and its receivers compile with OPACITY_RECEIVER.
    opacity_shadows: bool = False
    # ... and its deferred passes read them too (the forward passes of such a material do)
    deferred_opacity: ClassVar[bool] = False

    def opacity_layer(self, obj: SceneObjectLike) -> float:
        """World thickness of ``obj``'s volume (the opacity layers span a few of the thickest)."""
        return 0.0

    def draw_opacity(self, frame: Frame, obj: SceneObjectLike, view: ShadowView,
                     stage: str) -> None:
        """Draw ``obj``'s volume into the deep opacity maps of ``view`` (materials with
        ``opacity_shadows``): ``stage`` "first", the light-view depth of its outer surface
        (which every point it draws lies inside) as (depth, -depth, 0, 0) into an RG32F target
        with min blending, no depth test: its front and its back along each texel; "density",
        its optical depth times the volume's density factor (what lies behind it keeps
        exp(-the layers' sum) of the light), added into the four layers behind that front
        (``u_opacity_first``, ``u_opacity_layers``), blended additively."""

    def passes(self, phase: Phase, obj: SceneObjectLike) -> list[RenderPass]:
        hooks = {Phase.GEOMETRY: self.geometry_passes, Phase.SCREEN: self.screen_passes,
                 Phase.STIPPLE: self.stipple_passes, Phase.MATERIAL: self.material_passes,
                 Phase.FORWARD: self.forward_passes}
        return hooks[phase](obj) if phase in hooks else []


def compose_layout(materials: Iterable[Material]) -> GBufferLayout:
    """The layout for a scene's materials; one name declared two ways is an error."""
    data: dict[str, GBufferData] = {}
    owners: dict[str, str] = {}
    for material in materials:
        for entry in material.written_data():
            if entry.name in data and data[entry.name] != entry:
                raise InputError(f"G-buffer data '{entry.name}' is declared as {entry.format} "
                                 f"{entry.channels} by {material.name} and as "
                                 f"{data[entry.name].format} {data[entry.name].channels} by "
                                 f"{owners[entry.name]}")
            data.setdefault(entry.name, entry)
            owners.setdefault(entry.name, material.name)
    return GBufferLayout(data)
