"""The material interface: what the frame asks of every material, and the parts it composes.

A material is a class with a unique ``name``, a pydantic ``Params`` model (defaults, ranges, a
one-line description per field), a ``surface_shader`` (a GLSL file defining ``Surface
material_surface(SurfaceInput i)``, ``common/surface.glsl``) lit by a ``shading_model``, and the
G-buffer data it writes. What it does beyond that is composed of parts, each optional, each a
plain object given as a class attribute rather than a hook overridden:

- ``techniques`` (:mod:`deferred.interfaces.techniques`): the passes it contributes, per object
  and phase and once per scene; by default its surface's G-buffer pass and forward lit pass;
- ``shadow`` (:mod:`deferred.interfaces.shadow_casting`): how its objects cast shadows (the
  mesh by default) and draw into deep opacity maps;
- ``motion`` and ``simulation`` (:mod:`deferred.interfaces.simulation`): how far it draws beyond
  the mesh, and a state per object over time.

Register with ``@deferred.api.materials.register`` or the entry-point group
``deferred.materials``. Parameters become uniforms by name (:mod:`deferred.params`): field
``fur_length`` is ``u_fur_length``; ``uniform_overrides`` maps a field to ``None`` (not a
uniform: a pass count, a file, a define) or to a function giving the uniforms it becomes.
"""

from __future__ import annotations

import sys
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import moderngl
from pydantic import Field

from deferred.core.passes import Phase, RenderPass
from deferred.errors import InputError
from deferred.gbuffer.layout import (
    GBUFFER_COLOR_TARGETS,
    GBUFFER_TARGETS,
    GBufferData,
    GBufferLayout,
    data_write_file,
)
from deferred.gbuffer.surface_id import surface_id
from deferred.interfaces import registry
from deferred.interfaces.shadow_casting import ShadowCaster
from deferred.interfaces.simulation import Motion, Simulation
from deferred.interfaces.techniques import SurfacePasses, Technique
from deferred.interfaces.work import RenderWork, WorkObject
from deferred.io.cost import Work
from deferred.memo import kept_while
from deferred.params import Params, UniformOverrides, params_uniforms, validate_params
from deferred.revision import Revisioned
from deferred.validation import join_where, require_regular_file

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


# Hooks of the material base class that became composed parts: a class defining one is refused
# when it is made (at its registration or before), saying what to write instead.
MOVED_HOOKS: dict[str, str] = {
    **{f"{phase}_passes": (
        f"a material's passes come from its techniques: add "
        f"`techniques = (*Material.techniques, PhasePasses(Phase.{phase.upper()}, build))`, "
        "`build(material, obj)` returning the passes (or a Technique of your own)"
        + ("; to change the surface's own passes, give SurfacePasses(vertex=..., inputs=..., "
           f"{phase.replace('geometry', 'gbuffer')}=MyPass) in place of the default "
           "SurfacePasses()" if phase in ("geometry", "forward") else ""))
       for phase in ("geometry", "screen", "stipple", "material", "forward")},
    **{name: (f"shadow casting is the material's `shadow`: write `shadow = MyCaster()`, a "
              f"ShadowCaster subclass defining {new}")
       for name, new in (("draw_shadow", "draw(frame, obj, view)"),
                         ("opacity_shadows", "opacity_shadows(obj)"),
                         ("deferred_opacity", "deferred_opacity"),
                         ("opacity_layer", "opacity_layer(obj)"),
                         ("draw_opacity", "draw_opacity(frame, obj, view, stage)"))},
    "motion_extent": "write `motion = ReachMotion(\"<parameter>\")`, or a Motion subclass "
                     "defining extent(obj)",
    **{name: "a time the material cannot reach is its simulation's to refuse: write "
             "`simulation = MySimulation()`, a Simulation subclass defining "
             "check_time(obj, time, where)" for name in ("check_time", "check_time_for")},
}


class Material(Revisioned):
    """A material: a unique ``name``, a validated ``Params`` model and a GLSL surface function
    (``surface_shader``, ``Surface material_surface(SurfaceInput i)``) lit by ``shading_model``,
    writing the core G-buffer and its ``gbuffer_data``.

    What the frame asks of every material is here: its passes (:meth:`passes`,
    :meth:`scene_passes`), its programs' defines (:meth:`defines`), its uniforms and textures,
    its G-buffer data and id, what it holds (:meth:`held_memory`), and its composed parts:
    ``techniques`` (the passes), ``shadow`` (how its objects cast shadows), ``motion`` (how far
    it draws beyond the mesh) and ``simulation`` (a state per object over time, or none).
    Every parameter becomes a ``u_<field>`` uniform unless ``uniform_overrides`` says otherwise.
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
    # the composed parts: the passes, shadow casting, motion beyond the mesh, a simulation
    techniques: ClassVar[tuple[Technique, ...]] = (SurfacePasses(),)
    shadow: ClassVar[ShadowCaster] = ShadowCaster()
    motion: ClassVar[Motion] = Motion()
    simulation: ClassVar[Simulation | None] = None
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

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        for hook, instead in MOVED_HOOKS.items():
            if hook in cls.__dict__:
                raise TypeError(f"material class {cls.__module__}.{cls.__qualname__} defines "
                                f"{hook}, which the framework no longer asks: {instead} "
                                "(docs/writing-a-material.md)")

    def __init__(self, params: MaterialParams | None = None, base_dir: Path | None = None):
        self.params = params if params is not None else self.Params()
        self.base_dir = base_dir
        # where the params came from (``scene.toml: object[0].params``): what a problem found
        # later, reading a file the params name, is said under (:meth:`key_where`)
        self.where: str | None = None

    @classmethod
    def from_dict(cls, values: dict[str, Any], base_dir: Path | None = None,
                  where: str | None = None) -> Material:
        """Validate ``values`` against ``Params``; errors name the offending key."""
        material = cls(validate_params(cls.Params, values, where), base_dir)
        material.where = where
        registry.shading_models.get(material.shading_model,
                                    f"{where}: shading model" if where else "shading model")
        material.check_files(where)
        return material

    def check_files(self, where: str | None) -> None:
        """Raise ``InputError`` for parameters naming files that do not exist."""

    def key_where(self, key: str) -> str:
        """What an error about parameter ``key`` names: ``scene.toml: object[0].params.key``
        for a material from a scene file, ``key`` alone for one made in Python."""
        return join_where(self.where, key) or key

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
        budget = model.gbuffer_budget
        if budget is not None:
            used = sum(spec.bytes_per_pixel for spec in GBUFFER_TARGETS.values()) + \
                sum(data.spec.bytes_per_pixel for data in merged.values())
            if used > budget:
                raise InputError(f"material {self.name}: its G-buffer takes {used} bytes a "
                                 f"pixel, over its shading model {model.name}'s budget of "
                                 f"{budget}")
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
        """Bytes this material will hold for ``obj`` (textures it loads) by what they are,
        counted with the render targets and its simulation's state against the memory budget
        before the first frame: a key names the thing (``texture /path/fur.png``), so a texture
        objects share counts once. Files are sized by their headers. By default nothing."""
        return {}

    @classmethod
    def frame_memory(cls, objects: Sequence[SceneObjectLike],
                     size: tuple[int, int]) -> dict[str, int]:
        """Bytes this material's scene-wide resources hold for a frame of ``size`` besides the
        pass graph's targets (storage buffers sized by the frame: glass's per-pixel lists),
        for ``objects``, the scene's objects of this material; counted with
        :meth:`held_memory` against the memory budget before the first frame. By default
        nothing."""
        return {}

    def work(self, obj: WorkObject, job: RenderWork) -> list[Work]:
        """The work this material's passes do for ``obj`` in a render ``job``, as the cost
        model counts it (:mod:`deferred.interfaces.work`): by default its mesh drawn once a
        sample. A material drawing more (shells, tubes, strokes) counts it here; its
        simulation counts its own (``Simulation.work``)."""
        return [obj.surface_work()]

    # -- passes ------------------------------------------------------------------------------
    def passes(self, phase: Phase, obj: SceneObjectLike) -> list[RenderPass]:
        """The passes of ``obj`` in ``phase``: its techniques', in their order."""
        return [render_pass for technique in self.techniques
                for render_pass in technique.passes(self, phase, obj)]

    @classmethod
    def scene_passes(cls, objects: Sequence[SceneObjectLike],
                     phase: Phase) -> list[RenderPass]:
        """Passes this material adds once per scene in ``phase``: its techniques'; ``objects``
        are the scene's objects of this material."""
        return [render_pass for technique in cls.techniques
                for render_pass in technique.scene_passes(objects, phase)]


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
