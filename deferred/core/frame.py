"""The frame a pass runs against: its GL device, shaders and targets, the scene and camera, the
uniform binder and the pass runner.

What the frame holds for the layers above it it does not name: per-frame resources are on its
``blackboard`` by name (the light buffer, the light lists; Filament's blackboard), those that
bind themselves to every program are its ``binding_sources``, and an object's transforms and
its material's inputs come from its ``inputs`` (:class:`deferred.core.protocols.ObjectInputs`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import moderngl
import numpy as np

from deferred.core.protocols import BindingSource, ObjectInputs, PassLike, SceneLike
from deferred.errors import DeferredError, InputError, RenderError, gl_error
from deferred.gl.context import GLContext
from deferred.gl.device import Device
from deferred.gl.resources import Resources
from deferred.gl.shaderlib import ShaderLibrary
from deferred.gl.targets import FrameTargets
from deferred.gl.uniforms import gl_value


def plugin_note(render_pass: PassLike) -> str:
    """`` (plugin <package>)`` where the pass, or its object's material, is a plugin's class
    (not the framework's), for its errors; else nothing."""
    material = getattr(getattr(render_pass, "obj", None), "material", None)
    for cls in (type(render_pass), type(material) if material is not None else None):
        module = getattr(cls, "__module__", "") or ""
        if cls is not None and module.partition(".")[0] not in ("deferred", "builtins"):
            return f" (plugin {module.partition('.')[0]})"
    return ""


class OfferedUniforms(dict):
    """Uniforms a pass offers its program: set where the program declares them, and in strict
    mode no error where it does not (an effect's parameters, offered to each of its passes:
    :meth:`deferred.interfaces.effect.Effect.uniforms`). ``owner`` names who offers them: in
    strict mode each must be declared by at least one program of the frame it is offered to."""

    __slots__ = ("owner",)

    def __init__(self, values: Mapping[str, Any] = (), owner: str = ""):
        super().__init__(values)
        self.owner = owner


@dataclass(slots=True)
class MaterialInputs:
    """A material's uniforms and textures for one frame, and which of them its programs
    declare (strict mode checks that each is declared by at least one)."""

    material: Any  # a Material (deferred.interfaces.material)
    uniforms: dict[str, Any]
    textures: dict[str, moderngl.Texture]
    params: Any = None  # the material's params they were made from
    # kept across frames (deferred.render.caches.KeptMaterialInputs); its uniforms are then
    # StableValues
    kept: bool = False
    declared: set[str] = field(default_factory=set)
    programs: list[str] = field(default_factory=list)
    # strict mode: the programs bound with these inputs this frame, by GL name
    bound: dict[int, Any] = field(default_factory=dict)


class Frame:
    """What a pass sees while it runs: GL (through :attr:`device`), shaders, targets, scene,
    camera, the frame's ``time`` in seconds (animated materials read it in ``prepare``) and the
    per-frame resources on its :attr:`blackboard`.

    In ``strict`` mode, a uniform or sampler a pass sets by name that its program does not
    declare is an error, and so is a material uniform that none of the material's programs
    declares: a misspelt name fails instead of being silently ignored. Uniforms every pass is
    offered (camera, object transform, binding sources, :class:`OfferedUniforms` for uniforms
    or textures) are never errors. The other way round, an active uniform of a program (one
    it uses) that nothing set in the frame when the program is bound is an error too (it
    reads 0), unless its declaration gives it a value (an initializer, a layout binding).

    The device's state, framebuffer and draw calls are the frame's own methods (the same
    functions: a pass of many objects pays no extra call a draw).
    """

    # the device's calls, the frame's own (Device: the same bound methods)
    set_state: Callable[..., None]
    set_depth_offset: Callable[[tuple[float, float]], None]
    draw_mesh: Callable[..., None]
    draw_fullscreen: Callable[..., None]
    dispatch: Callable[[moderngl.ComputeShader, tuple[int, int, int]], None]
    barrier: Callable[[], None]
    gl_call: Callable[[Callable[[], Any]], Any]
    count_draw: Callable[[], None]
    # the inputs' calls: an object's transforms, a material's inputs this frame
    object_uniforms: Callable[[Any], dict[str, Any]]
    material_inputs: Callable[[Any], MaterialInputs]

    def __init__(self, gl: GLContext, shaders: ShaderLibrary, targets: FrameTargets,
                 resources: Resources, scene: SceneLike, inputs: ObjectInputs, *,
                 strict: bool = False, time: float = 0.0, time_gl_calls: bool = False,
                 blackboard: Mapping[str, Any] | None = None,
                 binding_sources: Sequence[BindingSource] = (),
                 checked_framebuffers: dict[tuple, Any] | None = None,
                 jitter: tuple[float, float] = (0.0, 0.0), sample_index: int = 0,
                 history_kept: bool = False,
                 previous_view_projection: np.ndarray | None = None,
                 kept_camera_values: dict[str, Any] | None = None):
        self.gl = gl
        self.ctx = gl.ctx
        self.time = float(time)  # seconds: the scene's timeline is applied at this time
        self.strict = strict
        self.shaders = shaders
        self.targets = targets
        self.resources = resources
        self.scene = scene
        self.blackboard: dict[str, Any] = dict(blackboard or {})
        self.binding_sources: list[BindingSource] = list(binding_sources)
        self.inputs = inputs
        inputs.frame = self
        # (pass, colours, depth) framebuffer requests already checked against the pass's
        # declarations, kept by the renderer: declarations are fixed once the graph is compiled
        # and targets are only ever added, so a request that passed once passes for its life
        self.checked_framebuffers = {} if checked_framebuffers is None else checked_framebuffers
        self.object_uniforms = inputs.object_uniforms
        self.material_inputs = inputs.material_inputs
        self.width = targets.width
        self.height = targets.height
        aspect = self.width / self.height
        self.view = scene.camera.view()
        self.projection = scene.camera.projection(aspect)
        self.inverse_projection = scene.camera.inverse_projection(aspect)
        self.jitter = jitter  # pixels: the image moved by a fraction of a pixel (samples)
        # the projection without the jitter, and the camera's view-projection without it this
        # frame and the last (motion vectors: common/motion.glsl)
        self.unjittered_projection = self.projection
        self.view_projection = np.asarray(self.projection) @ np.asarray(self.view)
        self.previous_view_projection = self.view_projection if previous_view_projection \
            is None else np.asarray(previous_view_projection)
        # samples since a temporal effect's history started (0: none kept; the stipple
        # pattern's parity and other per-sample patterns follow it), and whether this frame
        # carries the last frame's history on (deferred.render.temporal)
        self.sample_index = int(sample_index)
        self.history_kept = bool(history_kept)
        if jitter != (0.0, 0.0):
            # clip x gains P02 z and w is -z, so NDC x moves by -P02 everywhere: a sub-pixel
            # shift of the whole image (P12 likewise in y)
            projection = np.array(self.projection)
            projection[0, 2] -= 2.0 * jitter[0] / self.width
            projection[1, 2] -= 2.0 * jitter[1] / self.height
            self.projection = projection
            self.inverse_projection = np.linalg.inv(projection)
        # the camera's uniforms as GL takes them: one dict for every pass of the frame; the
        # last frame's dict where they are the same (``kept_camera_values``), which a program
        # still holding it is not even looked through for (ProgramUniforms.set_shared)
        values = {name: gl_value(value) for name, value in self.camera_uniforms().items()}
        self.camera_values = kept_camera_values if kept_camera_values == values else values
        self.device = device = Device(gl.ctx, targets, resources, time_gl_calls)
        self.stats = device.stats
        self.set_state = device.set_state
        self.set_depth_offset = device.set_depth_offset
        self.draw_mesh = device.draw_mesh
        self.draw_fullscreen = device.draw_fullscreen
        self.gl_call = device.gl_call
        self.count_draw = device.count_draw
        self.dispatch = device.dispatch
        self.barrier = device.barrier
        self.current_pass: PassLike | None = None
        # strict mode: each owner of offered uniforms -> (names, what its programs declare)
        self.offers: dict[str, tuple[set[str], set[str]]] = {}
        if strict:  # the checks wrap the calls: the default path pays nothing for them
            self.bind = self._bind_strict
            self.bind_compute = self._bind_compute_strict

    # -- passes --------------------------------------------------------------------------------
    def run_pass(self, render_pass: PassLike, check_errors: bool = True) -> None:
        """Clear the targets ``render_pass`` creates, run it, and name it in any failure (a GL
        error too, unless ``check_errors`` is off: :meth:`check_errors` then does it for a run
        of passes)."""
        self.current_pass = render_pass
        draws_before = self.stats.draw_calls
        try:
            for name in render_pass.creates:
                self.device.clear(name)
            render_pass.execute(self)
        except InputError:
            raise
        except DeferredError as exc:
            if str(exc).startswith(f"pass {render_pass.name}:"):
                raise
            raise type(exc)(f"pass {render_pass.name}: {exc}") from exc
        except Exception as exc:  # noqa: BLE001 - whatever a plugin's pass raises, say which
            raise RenderError(f"pass {render_pass.name}: {type(exc).__name__}: {exc}"
                              f"{plugin_note(render_pass)}") from exc
        if check_errors:
            error = self.ctx.error
            if error != "GL_NO_ERROR":
                raise gl_error(f"pass {render_pass.name}", error, (self.width, self.height))
        draws = self.stats.draw_calls - draws_before
        if draws:
            by_pass = self.stats.draws_by_pass
            by_pass[render_pass.name] = by_pass.get(render_pass.name, 0) + draws

    def check_errors(self, passes: list[PassLike]) -> None:
        """Raise the GL error, if any, that ``passes`` (run in order without checks) left,
        naming the pass: with more than one, they run again one by one, each checked, and the
        first to raise it is named (or all of them, where none does again). Reading the error
        flag after every pass is a large part of a draw's CPU time (benchmarks/README.md)."""
        error = self.ctx.error
        if error == "GL_NO_ERROR":
            return
        for _ in range(8):  # a driver may keep more than one flag: clear them all first
            if self.ctx.error == "GL_NO_ERROR":
                break
        if len(passes) > 1:
            for render_pass in passes:
                self.run_pass(render_pass)
        names = passes[0].name if len(passes) == 1 else \
            f"{passes[0].name} .. {passes[-1].name} ({len(passes)} passes)"
        raise gl_error(f"pass {names}", error, (self.width, self.height))

    # -- uniforms ------------------------------------------------------------------------------
    def moved_since_last_frame(self, obj: Any) -> bool:
        """Whether a temporal history follows a moving camera or a moving ``obj`` this frame
        (its model differs from the frame before's); False without a history."""
        if not self.history_kept:
            return False
        if not np.array_equal(self.previous_view_projection, self.view_projection):
            return True
        previous = (getattr(self.inputs, "previous_models", None) or {}).get(obj.node)
        return previous is not None and not np.array_equal(previous, obj.model)

    def camera_uniforms(self) -> dict[str, Any]:
        return {
            "u_projection": self.projection,
            "u_inverse_projection": self.inverse_projection,
            "u_view": self.view,
            "u_resolution": (float(self.width), float(self.height)),
            "u_near_far": (self.scene.camera.near, self.scene.camera.far),
            "u_view_projection": self.view_projection,
            "u_previous_view_projection": self.previous_view_projection,
            "u_sample_index": self.sample_index,
        }

    def _check_declared(self, program: moderngl.Program | moderngl.ComputeShader, what: str,
                        names: list[str], material: MaterialInputs | None = None) -> None:
        """Strict mode: every name a pass sets on ``program`` is declared by it."""
        declared = self.shaders.declared_uniforms(program)
        unknown = [n for n in names if n not in declared]
        if unknown:
            raise RenderError(f"{what} {self.shaders.describe(program)} declares no "
                              f"uniform {', '.join(repr(n) for n in unknown)}")
        if material is not None:
            material.declared |= declared
            material.programs.append(self.shaders.describe(program))
            material.bound[program.glo] = program

    def bind(self, program: moderngl.Program, uniforms: dict[str, Any] | None = None,
             textures: dict[str, moderngl.Texture] | None = None, *,
             offered: dict[str, Any] | None = None,
             material: MaterialInputs | None = None) -> None:
        """Set uniforms and bind textures on ``program``.

        ``uniforms`` and ``textures`` are what the pass means to set: in strict mode each must
        be declared by the program. The camera's values (:attr:`camera_values`), the binding
        sources', the ``offered`` values (an object's transforms, :meth:`object_uniforms`) and
        the ``material``'s are set where the program has them; of one name, the pass's wins
        over the material's, and the material's over a source's. A value the program holds
        already is not written again; ``StableValues`` are planned once (``set_stable``).
        """
        program_uniforms = self.shaders.uniforms(program)
        program_uniforms.set_shared("camera", self.camera_values)
        # in order, a later value of a name winning (no merged copies: a pass of many objects
        # binds once a draw): the binding sources', the object's, the material's, the pass's
        unit = 0
        for source in self.binding_sources:
            unit = source.bind(program_uniforms, unit)
        if offered:
            program_uniforms.set_stable(offered)
        if material is not None:
            if material.uniforms:
                program_uniforms.set_stable(material.uniforms)  # kept inputs are StableValues
            if material.textures:
                unit = program_uniforms.bind_samplers(material.textures, unit)
        if uniforms:
            program_uniforms.set(uniforms)
        if textures:
            program_uniforms.bind_samplers(textures, unit)

    def _bind_strict(self, program: moderngl.Program, uniforms: dict[str, Any] | None = None,
                     textures: dict[str, moderngl.Texture] | None = None, *,
                     offered: dict[str, Any] | None = None,
                     material: MaterialInputs | None = None) -> None:
        """:meth:`bind` in strict mode: what the pass sets is declared, and what the program
        uses is set."""
        names = [*textures] if textures and textures.__class__ is not OfferedUniforms else []
        if uniforms:
            if uniforms.__class__ is not OfferedUniforms:
                names[:0] = uniforms
            elif uniforms.owner:
                self._note_offer(program, uniforms)
        self._check_declared(program, "program", names, material)
        Frame.bind(self, program, uniforms, textures, offered=offered, material=material)
        self._check_set(program)

    def _bind_compute_strict(self, shader: moderngl.ComputeShader, uniforms: dict[str, Any],
                             textures: dict[str, moderngl.Texture], *,
                             offered: dict[str, Any] | None = None) -> None:
        self._check_declared(shader, "compute shader", [*uniforms, *textures])
        Frame.bind_compute(self, shader, uniforms, textures, offered=offered)
        self._check_set(shader)

    def _note_offer(self, program: moderngl.Program, values: OfferedUniforms) -> None:
        names, declared = self.offers.setdefault(values.owner, (set(), set()))
        names.update(values)
        declared |= self.shaders.declared_uniforms(program)

    def _check_set(self, program: moderngl.Program | moderngl.ComputeShader) -> None:
        """Strict mode: every uniform ``program`` uses has a value (one nothing set reads 0:
        a parameter, pass uniform, built-in or texture the GLSL expects and nobody gives)."""
        unset = self.shaders.unset_uniforms(program)
        if unset:
            where = ", ".join(f"'{name}' ({self.shaders.declaration(program, name)})"
                              for name in unset)
            raise RenderError(f"program {self.shaders.describe(program)}: nothing sets uniform "
                              f"{where}, which it uses (it reads 0)")

    def check_offers(self) -> None:
        """Strict mode, at the end of a frame: each offered uniform (an effect's parameter) is
        declared by at least one program it was offered to."""
        for owner, (names, declared) in self.offers.items():
            unused = sorted(names - declared)
            if unused:
                raise RenderError(f"{owner}: no program of its passes declares uniform "
                                  f"{', '.join(repr(n) for n in unused)}")

    def set_uniforms(self, program: moderngl.Program, values: dict[str, Any]) -> None:
        """Set the values ``program`` has (no strict check: :meth:`bind` does that); a value
        the program holds already is not written again."""
        self.shaders.uniforms(program).set(values)

    def bind_compute(self, shader: moderngl.ComputeShader, uniforms: dict[str, Any],
                     textures: dict[str, moderngl.Texture], *,
                     offered: dict[str, Any] | None = None) -> None:
        """Set a compute shader's uniforms and samplers (strict mode as :meth:`bind`); the
        binding sources are not offered (a compute pass binds what it reads itself)."""
        shader_uniforms = self.shaders.uniforms(shader)
        shader_uniforms.set_shared("camera", self.camera_values)
        shader_uniforms.set({**(offered or {}), **uniforms})
        shader_uniforms.bind_samplers(textures, 0)

    # -- targets -------------------------------------------------------------------------------
    def target(self, name: str) -> moderngl.Texture:
        """The texture of target ``name``, which the running pass must declare."""
        render_pass = self.current_pass
        if render_pass is not None and name not in render_pass.reads and \
                name not in render_pass.writes and name not in render_pass.creates:
            raise RenderError(f"target '{name}' is used but not declared in the pass's reads, "
                              "writes or creates")
        if name not in self.targets:
            raise RenderError(f"target '{name}' does not exist (targets: "
                              f"{', '.join(self.targets.specs)})")
        return self.targets[name]

    def target_samplers(self, names) -> dict[str, moderngl.Texture]:
        """Targets by the sampler names shaders use for them: ``u_<target name>``."""
        return {f"u_{name}": self.target(name) for name in names} if names else {}

    def use_framebuffer(self, colors: tuple[str, ...] | list[str], depth: str | None = None,
                        depth_write: bool = True) -> moderngl.Framebuffer:
        """Bind the framebuffer of these targets, which the running pass must declare."""
        colors = tuple(colors)
        request = (id(self.current_pass), colors, depth)
        checked = self.checked_framebuffers
        if request not in checked:
            for name in (*colors, *((depth,) if depth else ())):
                self.target(name)  # declared by the pass, and existing
            checked[request] = self.current_pass  # kept alive: its id stays its own
        return self.device.use_framebuffer(colors, depth, depth_write)

