"""What a renderer keeps from frame to frame, and what it gives each frame: the source of an
object's inputs, and the shading models' samplers as a binding source.

:class:`ObjectTransforms` holds every object's transform uniforms while the objects hold;
:class:`KeptMaterialInputs` a material's uniforms and textures while its params hold;
:class:`FrameInputs` gives a frame's passes both (:class:`deferred.core.protocols.ObjectInputs`)
and, in strict mode, checks at the end of the frame that every uniform a material sets is
declared by one of its programs and that its surface code writes the G-buffer data it
declares; :class:`ShadingTextures` binds the scene's shading models'
samplers to every program.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import moderngl
import numpy as np

from deferred.core.frame import MaterialInputs
from deferred.errors import DeferredError, RenderError
from deferred.gbuffer.layout import data_write_file
from deferred.gl.uniforms import StableValues

if TYPE_CHECKING:
    from deferred.core.frame import Frame
    from deferred.gl.shaderlib import Source
    from deferred.gl.uniforms import ProgramUniforms
    from deferred.interfaces.light import Light
    from deferred.interfaces.material import Material
    from deferred.interfaces.shading import ShadingModel
    from deferred.scene.state import FrameState, ObjectState


class KeptMaterialInputs:
    """Materials' inputs kept from one frame to the next while their params are the same
    object (params are replaced whole, never changed in place), for materials whose inputs
    are a function of the params (:meth:`Material.keeps_inputs`): a scene of 400 materials
    made 400 uniform dicts a frame otherwise."""

    def __init__(self) -> None:
        self._kept: dict[Material, MaterialInputs] = {}  # materials hash by identity

    def start_frame(self, scene: FrameState) -> None:
        """Drop the materials no object of ``scene`` has (replaced on their objects), once
        they outnumber the objects: a scene that keeps its materials pays one comparison."""
        if len(self._kept) > len(scene.objects):
            present = {obj.material for obj in scene.objects}
            self._kept = {key: inputs for key, inputs in self._kept.items() if key in present}

    def of(self, material: Material, frame: Frame) -> MaterialInputs:
        kept = self._kept.get(material)
        if kept is not None and kept.params is material.params:
            return kept
        keep = material.keeps_inputs()
        uniforms = material.uniforms(frame)
        inputs = MaterialInputs(material, StableValues(uniforms) if keep else uniforms,
                                material.textures(frame), params=material.params, kept=keep)
        if keep:
            self._kept[material] = inputs
        return inputs

    def release(self) -> None:  # the textures are Resources', released there
        self._kept.clear()


class ObjectTransforms:
    """Every object's transform uniforms (``u_model`` and ``u_model_normal_matrix``, the
    inverse transpose of the model's 3x3, as GL bytes; ``u_surface_id``), made for all objects
    at once and kept while the objects' states hold (their versions: a state's world matrix
    and material are fixed, so the same versions give the same values). The camera's view is
    apart (``u_view``, ``shaders/common/object_transform.glsl``), so a camera that moves
    remakes none of them (the batched inverse and the conversions are most of an object's CPU
    time when remade)."""

    def __init__(self) -> None:
        self._key: tuple | None = None
        self._values: dict[Any, dict[str, Any]] = {}

    def of(self, objects: tuple[ObjectState, ...],
           previous: dict[Any, np.ndarray] | None = None) -> dict[Any, dict[str, Any]]:
        """The object's node -> its uniforms; ``previous`` the world matrices of the last
        frame by node (``u_previous_model``; an object missing there, or with none given,
        its own model). Matrices are read-only values: the same array is the same matrix."""
        if not objects:
            return {}
        # the last frame's models where they differ (none without a temporal history)
        befores = None
        if previous:
            befores = [previous.get(obj.node, obj.model) for obj in objects]
        key = ([obj.version for obj in objects],
               None if befores is None else [id(before) for before in befores])
        if key != self._key:
            models = np.stack([obj.model for obj in objects])
            surface_ids = [float(obj.material.surface_id()) for obj in objects]
            self._values = self._make(objects, models, surface_ids,
                                      models if befores is None else np.stack(befores))
            self._key = key
            self._held = befores  # the arrays whose ids are in the key stay alive with it
        return self._values

    @staticmethod
    def _make(objects: tuple[ObjectState, ...], models: np.ndarray,
              surface_ids: list[float], befores: np.ndarray) -> dict[Any, dict[str, Any]]:
        normals = np.transpose(np.linalg.inv(models[:, :3, :3]), (0, 2, 1))

        def column_major(matrices: np.ndarray) -> bytes:  # GLSL's order, all at once
            return np.ascontiguousarray(np.transpose(matrices, (0, 2, 1)),
                                        dtype=np.float32).tobytes()

        model_bytes, normal_bytes = column_major(models), column_major(normals)
        before_bytes = column_major(befores)
        values = {}
        for index, (obj, surface_id) in enumerate(zip(objects, surface_ids, strict=True)):
            values[obj.node] = StableValues(  # replaced whole when they change
                u_model=model_bytes[64 * index:64 * index + 64],
                u_model_normal_matrix=normal_bytes[36 * index:36 * index + 36],
                u_previous_model=before_bytes[64 * index:64 * index + 64],
                u_surface_id=surface_id)
        return values


class FrameInputs:
    """One frame's objects' transforms and materials' inputs (each material's made once a
    frame, or kept from the last), for the frame's passes."""

    def __init__(self, scene: FrameState, transforms: ObjectTransforms, kept: KeptMaterialInputs,
                 strict: bool = False, previous_models: dict[Any, np.ndarray] | None = None):
        self.scene = scene
        self.previous_models = previous_models
        self.strict = strict
        self.frame: Frame | None = None  # set by the frame it serves (Frame.__init__)
        self._transforms = transforms
        self._kept = kept
        self._objects: dict[Any, dict[str, Any]] | None = None  # by node
        self._materials: dict[Material, MaterialInputs] = {}

    def object_uniforms(self, obj: ObjectState) -> dict[str, Any]:
        """The object's transforms and id (for every object at once, kept across frames while
        the objects' states hold: :class:`ObjectTransforms`)."""
        if self._objects is None:
            self._objects = self._transforms.of(self.scene.objects, self.previous_models)
        return self._objects[obj.node]

    def material_inputs(self, material: Material) -> MaterialInputs:
        """``material``'s uniforms and textures, computed once per frame (or kept from the
        last: :class:`KeptMaterialInputs`)."""
        inputs = self._materials.get(material)
        if inputs is None:
            inputs = self._kept.of(material, self.frame)
            if self.strict:  # what this frame's programs declare is the frame's own
                inputs = MaterialInputs(material, inputs.uniforms, inputs.textures,
                                        params=inputs.params, kept=inputs.kept)
            self._materials[material] = inputs
        return inputs

    def check_material_uniforms(self) -> None:
        """Strict mode, at the end of a frame: every uniform a material sets is declared by at
        least one of its programs, and so is every uniform an effect offers its passes
        (:meth:`Frame.check_offers`)."""
        self.frame.check_offers()
        self.check_gbuffer_data()
        shaders = self.frame.shaders
        for inputs in self._materials.values():
            if not inputs.programs:
                continue
            # Passes switched off by a parameter (no shells) leave their uniforms unused in
            # this frame: the material's shader folder still has to declare them.
            declared = inputs.declared | shaders.declared_in_folder(
                inputs.material.shader_folder())
            unused = [n for n in [*inputs.uniforms, *inputs.textures] if n not in declared]
            if unused:
                raise RenderError(
                    f"material {inputs.material.name}: no program of it declares uniform "
                    f"{', '.join(repr(n) for n in unused)} (programs: "
                    f"{', '.join(dict.fromkeys(inputs.programs))})")


    def check_gbuffer_data(self) -> None:
        """Strict mode, at the end of a frame: each material's programs that write its
        G-buffer data (the generated ``gbuffer_write_data``) assign every datum it declares
        somewhere in their own GLSL: a datum left unassigned is written undefined (black on
        one driver, speckled on another)."""
        shaders = self.frame.shaders
        for inputs in self._materials.values():
            names = [data.name for data in inputs.material.written_data()]
            if not names:
                continue
            for program in inputs.bound.values():
                fragment = shaders.sources(program).get("fragment_shader")
                if fragment is None or not any(file.startswith(_DATA_WRITE_FOLDER)
                                               for file, _ in fragment.line_map):
                    continue
                unwritten = unwritten_data(fragment, names)
                if unwritten:
                    material = inputs.material
                    raise RenderError(
                        f"material {material.name}: its surface code "
                        f"({material.surface_shader or shaders.describe(program)}) never "
                        f"writes the G-buffer data {', '.join(repr(n) for n in unwritten)} it "
                        f"declares (set s.data.{unwritten[0]} in material_surface; unset, it "
                        f"is undefined); program {shaders.describe(program)}")


_DATA_WRITE_FOLDER = data_write_file(["x"]).rpartition("/")[0] + "/"
_COMMENTS = re.compile(r"/\*.*?\*/|//[^\n]*", re.DOTALL)
# an assignment (or a compound one) to a field, a swizzle or an element of it: ".sheen.rgb ="
_ASSIGNED = r"\.\s*{name}\b(?:\s*\.\s*\w+|\s*\[[^\]]*\])*\s*(?:[-+*/%&|^]|<<|>>)?=(?!=)"
# the whole data assigned or constructed, or a field passed where a function may write it
_WHOLE = re.compile(r"\.\s*data\s*=(?!=)|\bSurfaceData\s*\(")
_PASSED = r"[(,]\s*[\w.\[\]]*\.\s*{name}\s*[,)]"
_WRITING_PARAMETER = re.compile(r"\b(?:out|inout)\s+\w+\s+\w+")


def unwritten_data(source: Source, names: list[str]) -> list[str]:
    """Which of the G-buffer data ``names`` the GLSL of ``source`` never assigns (its own
    files: the generated ones declare, fetch and copy the data, they do not make it)."""
    text = _COMMENTS.sub(" ", "\n".join(
        line for line, (file, _) in zip(source.text.splitlines(), source.line_map, strict=False)
        if not file.startswith(("generated/", "<"))))
    if _WHOLE.search(text):
        return []
    writers = bool(_WRITING_PARAMETER.search(text))
    return [name for name in names
            if not re.search(_ASSIGNED.format(name=re.escape(name)), text)
            and not (writers and re.search(_PASSED.format(name=re.escape(name)), text))]


class ShadingTextures:
    """The samplers of a scene's shading models (ramps...) and light types (an environment's
    maps), offered to every program a frame binds (a binding source of the frame: wherever
    lights run)."""

    def __init__(self, textures: dict[str, moderngl.Texture]):
        self.textures = textures

    @classmethod
    def of(cls, models: Iterable[type[ShadingModel]], frame: Frame,
           light_types: Iterable[type[Light]] = ()) -> ShadingTextures | None:
        """The models' and the light types' samplers this frame; ``None`` where they have
        none (most scenes: the frame then has no source to ask at every draw)."""
        textures: dict[str, moderngl.Texture] = {}
        for kind, owner in [*(("shading model", model) for model in models),
                            *(("light", light_type) for light_type in light_types)]:
            try:
                textures.update(owner.textures(frame))
            except DeferredError:
                raise
            except Exception as exc:  # noqa: BLE001 - a plugin's model or light: say which
                raise RenderError(f"{kind} {owner.name}: textures: "
                                  f"{type(exc).__name__}: {exc}") from exc
        return cls(textures) if textures else None

    def bind(self, uniforms: ProgramUniforms, texture_unit: int) -> int:
        return uniforms.bind_samplers(self.textures, texture_unit)
