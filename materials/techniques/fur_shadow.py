"""The fur's shadows (``techniques/fur.py``): its depth in the shadow maps, pushed a strand's
length away from the light, and its volume in the deep opacity maps, through which it shadows
itself and what lies behind it (``lighting/shadows.glsl``). :class:`FurShadow` is the shadow
caster of a fur material, drawing through the material's own fur vertex shader seen from the
light (:data:`SHADOW_CASTER_DEFINES`) with the inputs its shells read (a comb field, a
simulation's state).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from deferred.api import SHADOW_CASTER_DEFINES, PassInput, ShadowCaster

from .fins import FIN_GEOMETRY, draw_fins
from .fur import object_scale, self_shadowing, shell_count, shell_depth, vertex_constants
from .fur_volume import VOLUME_LAYERS

if TYPE_CHECKING:
    import moderngl

    from deferred.api import Frame, SceneObject, ShadowView

SHADOW_CASTER_FRAGMENT = "materials/techniques/fur_caster.frag"
SHADOW_SHELLS = 8  # most shells a fur object casts its shadow with (with its root shell)
OPACITY_FRAGMENT = "materials/techniques/fur_opacity.frag"
OPACITY_SHELLS = 12  # most shells the fur draws into the deep opacity maps (without the skin)
OPACITY_ENVELOPE = 1.0  # the shell depth of the fur's front in the opacity maps: the tips


class FurShadow(ShadowCaster):
    """The shadow caster of a fur material whose shells draw through ``vertex`` (its fur vertex
    shader) reading ``inputs`` (their textures are the caster's too)."""

    deferred_opacity = True  # the furs' deferred shells correct their light light by light

    def __init__(self, vertex: str, inputs: Sequence[PassInput] = ()):
        self.vertex = vertex
        self.inputs = tuple(inputs)

    def textures(self, frame: Frame, obj: SceneObject) -> dict[str, moderngl.Texture]:
        """The per-object textures the fur vertex shader reads."""
        textures: dict[str, moderngl.Texture] = {}
        for given in self.inputs:
            textures.update(given.textures(frame, obj))
        return textures

    def opacity_shadows(self, obj: SceneObject) -> bool:
        return self_shadowing(obj.material.params)

    def draw(self, frame: Frame, obj: SceneObject, view: ShadowView) -> None:
        """The fur's depth from a light, through the material's own fur vertex shader seen from
        it (:data:`SHADOW_CASTER_DEFINES`), which pushes it a strand's length away from the
        light (so its own skin, lit through the fur in front, does not shadow itself at the
        roots).

        Where the light has deep opacity maps (``view.opacity_maps``) and the fur is in them
        (``self_shadow_density`` above 0), only the root shell (the skin, opaque) casts depth:
        the body shadows its own far side and what lies behind it, and the fur's translucent
        shadow, on other surfaces as on itself, is the maps' alone (``lighting/shadows.glsl``:
        a surface beyond the fur's back keeps exp(-k x the fur's optical depth) there, the
        fur's own shells and skin the transmittance at their depth). Dithered shells in the
        depth map too would shadow the fur twice: toward the terminator a shell at height h
        reaches a flat skin under it where the light meets the skin at more than arccos(h)
        from its normal, however far it is pushed, and the deferred shells read their light
        from the skin's pixels.

        Otherwise (``self_shadow_density`` 0, or a pipeline that draws no maps) the root shell
        and up to ``SHADOW_SHELLS`` shells above it cast, each kept by a dither under its
        opacity (``materials/techniques/fur_caster.frag``), so the floor darkens with the fur's
        density; gamma(h) is the fur's own self-shadowing then."""
        material = obj.material
        params = material.params
        if params.shells == 0:
            super().draw(frame, obj, view)
            return
        program = frame.shaders.program(self.vertex, SHADOW_CASTER_FRAGMENT,
                                        defines={**material.defines(obj),
                                                 **SHADOW_CASTER_DEFINES})
        count = min(params.shells, SHADOW_SHELLS) + 1.0  # the root shell and the slabs above
        drawn = 1 if view.opacity_maps and self_shadowing(params) else int(count)
        # the light's matrices offered, not set: the shader declares them under the camera's
        # names (renamed by the defines), which is what strict mode reads
        frame.bind(program, {**vertex_constants(obj), "u_shell_depth": 0.0,
                             "u_root_shell": True,
                             "u_shell_weight": VOLUME_LAYERS / (count - 1.0)},
                   self.textures(frame, obj),
                   offered={**frame.object_uniforms(obj), **view.camera_uniforms},
                   material=frame.material_inputs(material))
        for k in range(drawn):
            if k:
                frame.set_uniforms(program, {"u_shell_depth": shell_depth(k, count),
                                             "u_root_shell": False})
            frame.draw_mesh(obj.mesh, program)
        if drawn > 1 and params.fins:
            self._draw_fins(frame, obj, view)

    def _draw_fins(self, frame: Frame, obj: SceneObject, view: ShadowView) -> None:
        """The fins at the fur's silhouette as the light sees it (``fins.geom`` from the
        light) into the depth map, each texel kept as the fins draw it: a fur edge-on to the
        light is all strands there, which the shells' slabs cast only as thin rims. Not into
        the deep opacity maps: there the shells' slabs crossing the light at grazing angles
        hold the fur's optical depth already, and the fins on top shadowed it twice."""
        material = obj.material
        program = frame.shaders.program(self.vertex, SHADOW_CASTER_FRAGMENT, FIN_GEOMETRY,
                                        defines={**material.defines(obj),
                                                 **SHADOW_CASTER_DEFINES, "FUR_FINS": "1"})
        frame.bind(program, {**vertex_constants(obj), "u_shell_depth": 0.0,
                             "u_fin_band": material.params.fin_band, "u_root_shell": False,
                             "u_shell_weight": 1.0},
                   self.textures(frame, obj),
                   offered={**frame.object_uniforms(obj), **view.camera_uniforms},
                   material=frame.material_inputs(material))
        draw_fins(frame, obj.mesh, program)

    def cache_key(self, frame: Frame, obj: SceneObject) -> int:
        """The shells the fur draws into the deep opacity maps: they follow the camera."""
        return self.opacity_shells(frame, obj) if self.opacity_shadows(obj) else 0

    def opacity_layer(self, obj: SceneObject) -> float:
        """The fur's world thickness: a strand's length."""
        return float(obj.material.params.fur_length * object_scale(obj).max())

    def opacity_shells(self, frame: Frame, obj: SceneObject) -> int:
        """How many outer shells the fur draws into the deep opacity maps this frame: as many
        as it draws in view (:func:`shell_count`, rounded up; the root shell is the skin's,
        the depth atlas's), at most ``OPACITY_SHELLS``. Far away the fur's self-shadowing
        takes few pixels and few shells; each shell then stands for more of the volume, so the
        optical depth summed through the fur stays the same."""
        params = obj.material.params
        wanted = math.ceil(shell_count(frame, obj, params) - 1e-9)
        return max(1, min(wanted, params.shells, OPACITY_SHELLS))

    def draw_opacity(self, frame: Frame, obj: SceneObject, view: ShadowView,
                     stage: str) -> None:
        """The fur in the deep opacity maps, where it is (not pushed away as the depth casters
        are). Stage "first": the fur's envelope, the shell through its strands' tips, which every
        shell drawn in view lies inside, so the front is where the fur begins along each texel
        (an inner shell would leave the tips beyond it out of the maps, with no fur in front).
        Stage "density": :meth:`opacity_shells` outer shells, each adding the optical depth of
        the opacity it draws (``materials/techniques/fur_opacity.frag``)."""
        material = obj.material
        if material.params.shells == 0:
            return
        defines = {**material.defines(obj), **SHADOW_CASTER_DEFINES, "OPACITY_CASTER": "1"}
        if stage == "first":
            defines["OPACITY_FIRST"] = "1"
        program = frame.shaders.program(self.vertex, OPACITY_FRAGMENT, defines=defines)
        count = self.opacity_shells(frame, obj) + 1.0  # as the shells: a root and slabs
        depths = [OPACITY_ENVELOPE] if stage == "first" else \
            [shell_depth(k, count) for k in range(1, int(count))]
        frame.bind(program, {**vertex_constants(obj, depths[0]),
                             "u_shell_weight": VOLUME_LAYERS / (count - 1.0)},
                   self.textures(frame, obj),
                   offered={**frame.object_uniforms(obj), **view.camera_uniforms},
                   material=frame.material_inputs(material))
        for k, depth in enumerate(depths):
            if k:
                frame.set_uniforms(program, {"u_shell_depth": depth})
            frame.draw_mesh(obj.mesh, program)
