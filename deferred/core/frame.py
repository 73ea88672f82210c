"""The per-frame context passes run against, and the resources that live across frames."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import moderngl
import numpy as np

from deferred.errors import DeferredError, InputError, RenderError, gl_error
from deferred.gl.context import GLContext
from deferred.gl.shaderlib import ShaderLibrary
from deferred.gl.targets import FrameTargets
from deferred.gl.uniforms import ProgramUniforms, StableValues, gl_value
from deferred.scene.meshes import GpuMesh, MeshData

if TYPE_CHECKING:
    from deferred.core.passes import RenderPass
    from deferred.interfaces.material import Material
    from deferred.lighting.buffer import LightBuffer
    from deferred.lighting.lists import LightLists
    from deferred.scene.model import Scene, SceneObject

# Blend modes by name: passes say what they want, not GL enums.
BLEND_MODES = {
    "add": (moderngl.ONE, moderngl.ONE),
    # alpha stays coverage: a over background (0) gives a, over a surface (1) stays 1
    "alpha": (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE,
              moderngl.ONE_MINUS_SRC_ALPHA),
    "premultiplied": (moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA),
    # colour times the source (a tint over what is there); alpha kept
    "multiply": (moderngl.DST_COLOR, moderngl.ZERO, moderngl.ZERO, moderngl.ONE),
}
DEPTH_FUNCS = {"less": "<", "lequal": "<=", "gequal": ">=", "greater": ">", "equal": "==",
               "always": "1"}


class Resources:
    """GPU objects that outlive one frame: meshes, textures loaded from files, helper geometry."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._meshes: dict[int, GpuMesh] = {}
        self._mesh_refs: list[MeshData] = []  # keep ids stable while cached
        self._cached: dict[Any, Any] = {}
        self._fullscreen_vaos: dict[int, moderngl.VertexArray] = {}
        # (pass, colours, depth) framebuffer requests already checked against the pass's
        # declarations: declarations are fixed once the graph is compiled and targets are only
        # ever added, so a request that passed once passes for the renderer's life
        self.checked_framebuffers: dict[tuple, Any] = {}

    def gpu_mesh(self, mesh: MeshData) -> GpuMesh:
        gpu = self._meshes.get(id(mesh))
        if gpu is None:
            gpu = GpuMesh(self.ctx, mesh)
            self._meshes[id(mesh)] = gpu
            self._mesh_refs.append(mesh)
        return gpu

    def cached(self, key: Any, create: Callable[[moderngl.Context], Any]) -> Any:
        """A GPU object kept for the renderer's life (anything with ``release()``);
        ``create(ctx)`` makes it the first time ``key`` is asked for."""
        made = self._cached.get(key)
        if made is None:
            made = create(self.ctx)
            self._cached[key] = made
        return made

    def texture(self, key: Any, create: Callable[[moderngl.Context], moderngl.Texture]
                ) -> moderngl.Texture:
        """A cached texture (see :meth:`cached`)."""
        return self.cached(key, create)

    def image_texture(self, path: Path, srgb: bool = True,
                      where: str | None = None) -> moderngl.Texture:
        """The image at ``path`` as a mipmapped texture (cached); ``where`` (the scene key)
        names it in a read error."""
        from deferred.io.images import read_image

        def create(ctx: moderngl.Context) -> moderngl.Texture:
            pixels = read_image(path, srgb_to_linear=srgb, where=where,
                                max_size=ctx.info["GL_MAX_TEXTURE_SIZE"])
            height, width, _ = pixels.shape
            texture = ctx.texture((width, height), 4, np.ascontiguousarray(
                pixels[::-1]).astype(np.float16).tobytes(), dtype="f2")
            texture.build_mipmaps()
            texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            return texture

        return self.texture(("image", str(path), srgb), create)

    def fullscreen_vertex_array(self, program: moderngl.Program) -> moderngl.VertexArray:
        # Full-screen triangles are generated from gl_VertexID; a VAO with no buffers draws them.
        vao = self._fullscreen_vaos.get(program.glo)
        if vao is None:
            vao = self.ctx.vertex_array(program, [])
            self._fullscreen_vaos[program.glo] = vao
        return vao

    def release(self) -> None:
        for gpu in self._meshes.values():
            gpu.release()
        self._meshes.clear()
        self._mesh_refs.clear()
        for made in self._cached.values():
            made.release()
        self._cached.clear()
        for vao in self._fullscreen_vaos.values():
            vao.release()
        self._fullscreen_vaos.clear()


@dataclass
class FrameStats:
    draw_calls: int = 0
    draws_by_pass: dict[str, int] = field(default_factory=dict)
    # CPU seconds of this thread inside the GL calls that do the drawing (draws, dispatches,
    # clears, framebuffer binds, copies; llvmpipe runs vertex work and binning there, and a
    # framebuffer bind hands the last one's scene to the rasteriser): the bench subtracts them
    # from the frame's thread time to get the framework's own CPU time
    gl_call_seconds: float = 0.0


@dataclass(slots=True)
class MaterialInputs:
    """A material's uniforms and textures for one frame, and which of them its programs
    declare (strict mode checks that each is declared by at least one)."""

    material: Material
    uniforms: dict[str, Any]
    textures: dict[str, moderngl.Texture]
    params: Any = None  # the material's params they were made from
    # kept across frames (KeptMaterialInputs); its uniforms are then StableValues
    kept: bool = False
    declared: set[str] = field(default_factory=set)
    programs: list[str] = field(default_factory=list)


class KeptMaterialInputs:
    """Materials' inputs kept from one frame to the next while their params are the same
    object (params are replaced whole, never changed in place), for materials whose inputs
    are a function of the params (:meth:`Material.keeps_inputs`): a scene of 400 materials
    made 400 uniform dicts a frame otherwise."""

    def __init__(self) -> None:
        self._kept: dict[int, MaterialInputs] = {}

    def start_frame(self, scene: Scene) -> None:
        """Drop the materials no object of ``scene`` has (replaced on their objects), once
        they outnumber the objects: a scene that keeps its materials pays one comparison."""
        if len(self._kept) > len(scene.objects):
            present = {id(obj.material) for obj in scene.objects}
            self._kept = {key: inputs for key, inputs in self._kept.items() if key in present}

    def of(self, material: Material, frame: Frame) -> MaterialInputs:
        key = id(material)
        kept = self._kept.get(key)
        if kept is not None and kept.material is material and kept.params is material.params:
            return kept
        keep = material.keeps_inputs()
        uniforms = material.uniforms(frame)
        inputs = MaterialInputs(material, StableValues(uniforms) if keep else uniforms,
                                material.textures(frame), params=material.params, kept=keep)
        if keep:
            self._kept[key] = inputs
        return inputs

    def release(self) -> None:  # the textures are Resources', released there
        self._kept.clear()


class ObjectTransforms:
    """Every object's transform uniforms (``u_model`` and ``u_model_normal_matrix``, the
    inverse transpose of the model's 3x3, as GL bytes; ``u_surface_id``), made for all objects
    at once and kept while the objects hold. The camera's view is apart (``u_view``,
    ``shaders/common/object_transform.glsl``), so a camera that moves remakes none of them: the
    batched inverse and the conversions cost about 3 us an object when they are remade."""

    def __init__(self) -> None:
        self._key: tuple | None = None
        self._values: dict[int, dict[str, Any]] = {}

    def of(self, objects: list[SceneObject]) -> dict[int, dict[str, Any]]:
        """id(object) -> its uniforms."""
        if not objects:
            return {}
        surface_ids = [float(obj.material.surface_id()) for obj in objects]
        # what the values are made of (contents, not identities: a model may be written in
        # place), and which object each belongs to
        key = (b"".join([obj.model.tobytes() for obj in objects]), surface_ids,
               [id(obj) for obj in objects])
        if key != self._key:
            models = np.stack([obj.model for obj in objects])
            self._values = self._make(objects, models, surface_ids)
            self._key = key
        return self._values

    @staticmethod
    def _make(objects: list[SceneObject], models: np.ndarray,
              surface_ids: list[float]) -> dict[int, dict[str, Any]]:
        normals = np.transpose(np.linalg.inv(models[:, :3, :3]), (0, 2, 1))

        def column_major(matrices: np.ndarray) -> bytes:  # GLSL's order, all at once
            return np.ascontiguousarray(np.transpose(matrices, (0, 2, 1)),
                                        dtype=np.float32).tobytes()

        model_bytes, normal_bytes = column_major(models), column_major(normals)
        values = {}
        for index, (obj, surface_id) in enumerate(zip(objects, surface_ids, strict=True)):
            values[id(obj)] = StableValues(  # replaced whole when they change
                u_model=model_bytes[64 * index:64 * index + 64],
                u_model_normal_matrix=normal_bytes[36 * index:36 * index + 36],
                u_surface_id=surface_id)
        return values


class Frame:
    """What a pass sees while it runs: GL, shaders, targets, scene, camera and lights, and the
    frame's ``time`` in seconds (animated materials read it in ``prepare``).

    In ``strict`` mode, a uniform or sampler a pass sets by name that its program does not
    declare is an error, and so is a material uniform that none of the material's programs
    declares: a misspelt name fails instead of being silently ignored. Uniforms every pass is
    offered (camera, object transform, light buffer) are never errors.
    """

    def __init__(self, gl: GLContext, shaders: ShaderLibrary, targets: FrameTargets,
                 resources: Resources, scene: Scene, light_buffer: LightBuffer,
                 strict: bool = False, light_lists: LightLists | None = None,
                 time: float = 0.0, time_gl_calls: bool = False,
                 shading_models: list | None = None,
                 object_transforms: ObjectTransforms | None = None,
                 kept_inputs: KeptMaterialInputs | None = None):
        self.gl = gl
        self.time = float(time)  # seconds: the scene's timeline is applied at this time
        self.light_lists = light_lists
        self.strict = strict
        self.ctx = gl.ctx
        self.shaders = shaders
        self.targets = targets
        self.resources = resources
        self.scene = scene
        self.light_buffer = light_buffer
        self.width = targets.width
        self.height = targets.height
        aspect = self.width / self.height
        self.view = scene.camera.view()
        self.projection = scene.camera.projection(aspect)
        self.inverse_projection = scene.camera.inverse_projection(aspect)
        # the camera's uniforms as GL takes them: one dict for every pass of the frame
        self.camera_values = {name: gl_value(value)
                              for name, value in self.camera_uniforms().items()}
        self.stats = FrameStats()
        self.time_gl_calls = time_gl_calls  # FrameStats.gl_call_seconds
        # the scene's shading models (the renderer's, found once: a walk over every object)
        self._shading_models = shading_models
        self.current_pass: RenderPass | None = None
        self._materials: dict[int, MaterialInputs] = {}
        # the objects' transforms, kept by the renderer across frames (ObjectTransforms)
        self._object_transforms = object_transforms or ObjectTransforms()
        self._objects: dict[int, dict[str, Any]] | None = None
        # materials' inputs, kept by the renderer across frames (KeptMaterialInputs)
        self._kept_inputs = kept_inputs or KeptMaterialInputs()
        self._shading_textures: dict[str, moderngl.Texture] | None = None
        # what this frame set last: a pass stating the same is not set again (set_state)
        self._state: tuple | None = None
        self._framebuffers: dict[tuple, tuple[moderngl.Framebuffer, tuple]] = {}
        # whether GL's depth mask is the bound framebuffer's: a clear through another
        # framebuffer (moderngl's clear) sets GL's and binds this one back without it
        self._depth_mask_known = False
        # the last framebuffer request set in full, (key, depth_write, framebuffer, viewport):
        # the same request again, with nothing changed since, sets nothing (use_framebuffer)
        self._bound: tuple | None = None

    # -- passes --------------------------------------------------------------------------------
    def run_pass(self, render_pass: RenderPass, check_errors: bool = True) -> None:
        """Clear the targets ``render_pass`` creates, run it, and name it in any failure (a GL
        error too, unless ``check_errors`` is off: :meth:`check_errors` then does it for a run
        of passes)."""
        self.current_pass = render_pass
        draws_before = self.stats.draw_calls
        try:
            for name in render_pass.creates:
                self.gl_call(lambda name=name: self.targets.clear(name))
                self._depth_mask_known = False
                self._bound = None
            render_pass.execute(self)
        except InputError:
            raise
        except DeferredError as exc:
            if str(exc).startswith(f"pass {render_pass.name}:"):
                raise
            raise type(exc)(f"pass {render_pass.name}: {exc}") from exc
        except Exception as exc:  # noqa: BLE001 - whatever a plugin's pass raises, say which
            raise RenderError(f"pass {render_pass.name}: {type(exc).__name__}: {exc}") from exc
        if check_errors:
            error = self.ctx.error
            if error != "GL_NO_ERROR":
                raise gl_error(f"pass {render_pass.name}", error, (self.width, self.height))
        draws = self.stats.draw_calls - draws_before
        if draws:
            by_pass = self.stats.draws_by_pass
            by_pass[render_pass.name] = by_pass.get(render_pass.name, 0) + draws

    def check_errors(self, passes: list[RenderPass]) -> None:
        """Raise the GL error, if any, that ``passes`` (run in order without checks) left,
        naming the pass: with more than one, they run again one by one, each checked, and the
        first to raise it is named (or all of them, where none does again). Reading the error
        flag after every pass cost 3 us of a 20 us draw (a scene of 400 objects)."""
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
    def camera_uniforms(self) -> dict[str, Any]:
        return {
            "u_projection": self.projection,
            "u_inverse_projection": self.inverse_projection,
            "u_view": self.view,
            "u_resolution": (float(self.width), float(self.height)),
            "u_near_far": (self.scene.camera.near, self.scene.camera.far),
        }

    def object_uniforms(self, obj: SceneObject) -> dict[str, Any]:
        """The object's transforms and id (for every object at once, kept across frames while
        the objects hold: :class:`ObjectTransforms`)."""
        if self._objects is None:
            self._objects = self._object_transforms.of(self.scene.objects)
        return self._objects[id(obj)]

    def shading_textures(self) -> dict[str, moderngl.Texture]:
        """Samplers of the scene's shading models (ramps...), offered wherever lights run."""
        if self._shading_textures is None:
            self._shading_textures = {}
            models = self._shading_models
            for model in self.scene.shading_models() if models is None else models:
                self._shading_textures.update(model.textures(self))
        return self._shading_textures

    def material_inputs(self, material: Material) -> MaterialInputs:
        """``material``'s uniforms and textures, computed once per frame (or kept from the
        last: :class:`KeptMaterialInputs`)."""
        inputs = self._materials.get(id(material))
        if inputs is None:
            inputs = self._kept_inputs.of(material, self)
            if self.strict:  # what this frame's programs declare is the frame's own
                inputs = MaterialInputs(material, inputs.uniforms, inputs.textures,
                                        params=inputs.params, kept=inputs.kept)
            self._materials[id(material)] = inputs
        return inputs

    def bind(self, program: moderngl.Program, uniforms: dict[str, Any] | None = None,
             textures: dict[str, moderngl.Texture] | None = None, *,
             offered: dict[str, Any] | None = None,
             material: MaterialInputs | None = None) -> None:
        """Set uniforms and bind textures on ``program``.

        ``uniforms`` and ``textures`` are what the pass means to set: in strict mode each must
        be declared by the program. The camera's values (:attr:`camera_values`), the lights',
        ``offered`` values (an object's transforms, :meth:`object_uniforms`) and the
        ``material``'s are set where the program has them. A value the program holds already
        is not written again; ``StableValues`` are planned once (``set_stable``).
        """
        if self.strict:
            declared = self.shaders.declared_uniforms(program)
            unknown = [n for n in [*(uniforms or {}), *(textures or {})] if n not in declared]
            if unknown:
                raise RenderError(f"program {self.shaders.describe(program)} declares no "
                                  f"uniform {', '.join(repr(n) for n in unknown)}")
            if material is not None:
                material.declared |= declared
                material.programs.append(self.shaders.describe(program))
        program_uniforms = self.shaders.uniforms(program)
        program_uniforms.set_shared("camera", self.camera_values)
        # in order, a later value of a name winning (no merged copies: a pass of many objects
        # binds once a draw)
        if offered:
            program_uniforms.set_stable(offered)
        if material is not None and material.uniforms:
            program_uniforms.set_stable(material.uniforms)  # kept inputs are StableValues
        if uniforms:
            program_uniforms.set(uniforms)
        shading = self._shading_textures  # made once a frame (a method call a draw: 0.2 us)
        if shading is None:
            shading = self.shading_textures()
        own = material.textures if material is not None else None
        if shading or own or textures:  # most draws bind no sampler: no dict is made for them
            unit = self._bind_samplers(program_uniforms,
                                       {**shading, **(own or {}), **(textures or {})})
        else:
            unit = 0
        self.light_buffer.bind(program_uniforms, unit)
        if self.light_lists is not None:
            self.light_lists.bind(program_uniforms, unit + 1)

    @staticmethod
    def _bind_samplers(program_uniforms: ProgramUniforms,
                       samplers: dict[str, moderngl.Texture]) -> int:
        """Bind the samplers the program has to units 0, 1, ...; the next free unit."""
        unit = 0
        members = program_uniforms.members
        for name, texture in samplers.items():
            if name in members:
                texture.use(location=unit)
                program_uniforms.set_one(name, unit)
                unit += 1
        return unit

    def set_uniforms(self, program: moderngl.Program, values: dict[str, Any]) -> None:
        """Set the values ``program`` has (no strict check: :meth:`bind` does that); a value
        the program holds already is not written again."""
        self.shaders.uniforms(program).set(values)

    def bind_compute(self, shader: moderngl.ComputeShader, uniforms: dict[str, Any],
                     textures: dict[str, moderngl.Texture], *,
                     offered: dict[str, Any] | None = None) -> None:
        """Set a compute shader's uniforms and samplers (strict mode as :meth:`bind`)."""
        if self.strict:
            declared = self.shaders.declared_uniforms(shader)
            unknown = [n for n in [*uniforms, *textures] if n not in declared]
            if unknown:
                raise RenderError(f"compute shader {self.shaders.describe(shader)} declares "
                                  f"no uniform {', '.join(repr(n) for n in unknown)}")
        shader_uniforms = self.shaders.uniforms(shader)
        shader_uniforms.set_shared("camera", self.camera_values)
        shader_uniforms.set({**(offered or {}), **uniforms})
        for unit, (name, texture) in enumerate(textures.items()):
            if name in shader_uniforms.members:
                texture.use(location=unit)
                shader_uniforms.set_one(name, unit)

    def check_material_uniforms(self) -> None:
        """Strict mode, at the end of a frame: every uniform a material sets is declared by at
        least one of its programs."""
        for inputs in self._materials.values():
            if not inputs.programs:
                continue
            # Passes switched off by a parameter (no shells) leave their uniforms unused in
            # this frame: the material's shader folder still has to declare them.
            declared = inputs.declared | self.shaders.declared_in_folder(
                inputs.material.shader_folder())
            unused = [n for n in [*inputs.uniforms, *inputs.textures] if n not in declared]
            if unused:
                raise RenderError(
                    f"material {inputs.material.name}: no program of it declares uniform "
                    f"{', '.join(repr(n) for n in unused)} (programs: "
                    f"{', '.join(dict.fromkeys(inputs.programs))})")

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

    # -- drawing -------------------------------------------------------------------------------
    def count_draw(self) -> None:
        """Count a draw call of the running pass (passes drawing by other means call it)."""
        self.stats.draw_calls += 1

    def gl_call(self, call: Callable[[], Any]) -> Any:
        """Run a drawing GL call, its time counted apart (``FrameStats.gl_call_seconds``)
        when the frame measures it."""
        if not self.time_gl_calls:
            return call()
        start = time.thread_time()
        try:
            return call()
        finally:
            self.stats.gl_call_seconds += time.thread_time() - start

    def draw_mesh(self, mesh: MeshData, program: moderngl.Program, instances: int = 1) -> None:
        vertex_array = self.resources.gpu_mesh(mesh).vertex_array(program)
        if self.time_gl_calls:  # gl_call inlined: no closure a draw
            start = time.thread_time()
            vertex_array.render(moderngl.TRIANGLES, instances=instances)
            self.stats.gl_call_seconds += time.thread_time() - start
        else:
            vertex_array.render(moderngl.TRIANGLES, instances=instances)
        self.stats.draw_calls += 1

    def draw_fullscreen(self, program: moderngl.Program, instances: int = 1) -> None:
        vao = self.resources.fullscreen_vertex_array(program)
        self.gl_call(lambda: vao.render(moderngl.TRIANGLES, vertices=3, instances=instances))
        self.count_draw()

    def use_framebuffer(self, colors: tuple[str, ...] | list[str], depth: str | None = None,
                        depth_write: bool = True) -> moderngl.Framebuffer:
        key = (tuple(colors), depth)
        request = (id(self.current_pass), key)
        checked = self.resources.checked_framebuffers
        if request not in checked:
            for name in (*colors, *((depth,) if depth else ())):
                self.target(name)  # declared by the pass, and existing
            checked[request] = self.current_pass  # kept alive: its id stays its own
        bound = self._bound
        # one pass of many objects after another: the same request, still bound, no clear
        # since, and the framebuffer's mask and viewport as this frame left them (a pass may
        # have set them on it): nothing to look up or set, 1.2 -> 0.7 us
        if bound is not None and bound[0] == key and bound[1] == depth_write:
            fbo = bound[2]
            if self.ctx.fbo is fbo and fbo.depth_mask == depth_write and \
                    fbo.viewport == bound[3]:
                return fbo
        known = self._framebuffers.get(key)
        if known is None:  # once a frame: the targets' scissor is set on it then
            fbo = self.targets.framebuffer(colors, depth)
            known = self._framebuffers[key] = (fbo, (0, 0, *fbo.size))
        fbo, full = known
        if self.ctx.fbo is not fbo:  # binding a framebuffer ends llvmpipe's scene: GL work
            self.gl_call(fbo.use)  # which sets GL's depth mask to the framebuffer's
            self._depth_mask_known = True
        # the framebuffer keeps its mask: set only when it changes, not a GL call a draw
        if fbo.depth_mask != depth_write or not self._depth_mask_known:
            fbo.depth_mask = depth_write
            self._depth_mask_known = True
        if fbo.viewport != full:
            fbo.viewport = full
        self._bound = (key, depth_write, fbo, full)
        return fbo

    def set_state(self, depth_test: bool = False, depth_func: str = "less",
                  cull: str | None = None, blend: str | None = None,
                  depth_offset: tuple[float, float] = (0.0, 0.0)) -> None:
        """Set the fixed-function state a pass needs; every pass states all of it. The frame
        sets GL state only here and in :meth:`set_depth_offset`, so a pass stating what the
        last one did sets nothing (one program drawing many objects)."""
        state = (depth_test, depth_func, cull, blend, depth_offset)
        if state == self._state:
            return
        self._state = state
        self.ctx.polygon_offset = depth_offset
        flags = moderngl.NOTHING
        if depth_test:
            flags |= moderngl.DEPTH_TEST
            self.ctx.depth_func = DEPTH_FUNCS[depth_func]
        if cull:
            flags |= moderngl.CULL_FACE
            self.ctx.cull_face = cull
        if blend:
            flags |= moderngl.BLEND
            self.ctx.blend_func = BLEND_MODES[blend]
            self.ctx.blend_equation = moderngl.FUNC_ADD
        self.ctx.enable_only(flags)

    def set_depth_offset(self, depth_offset: tuple[float, float]) -> None:
        """Change only the depth offset (``glPolygonOffset``) of the state the pass set, for
        draws of one pass that differ in it (the root shell)."""
        if self._state is None or self._state[4] != depth_offset:
            self.ctx.polygon_offset = depth_offset
        if self._state is not None:
            self._state = (*self._state[:4], depth_offset)
