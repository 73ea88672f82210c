"""Built-in shading models (see :mod:`deferred.interfaces.shading`); importing this module
registers them.

- ``blinn_phong``: the standard model (albedo, specular intensity and exponent); area lights
  by the polygon's irradiance and, for the highlight, GGX's LTC of the same width
  (``blinn_phong_area.glsl``).
- ``kajiya_kay``: strands (Silva et al. Eq. 6; Kajiya and Kay 1989): diffuse |T x L|, specular
  ((T.L)(T.E) + |T x L||T x E|)^p along the strand tangent T, stored as G-buffer data.
- ``marschner``: hair (Marschner et al. 2003 in Karis's 2016 real-time form): R, TT and TRT
  lobes about the strand tangent (G-buffer data ``strand_tangent``, root to tip) and a
  multiple-scattering lobe, which also answers the ambient; ``specular_exponent`` carries the
  longitudinal roughness (radians), ``specular_intensity`` scales R.
- ``toon``: N.L through a ramp texture (a row per ramp, chosen per pixel by G-buffer data) and
  a hard-edged specular band (X-toon, Costigan's cartoon shading).
- ``toon_strands``: ``toon`` whose specular (the band and the ramp's specular metric) follows
  the strand tangent where a surface has one (G-buffer data ``strand_tangent``): Kajiya-Kay's
  sin(T, H) in place of N.H, a highlight band across the strands (cartoon_hair's tubes).
- ``pbr``: glTF 2.0's metallic-roughness as Filament lights it (``pbr.glsl``): GGX, Smith
  height-correlated visibility, Schlick Fresnel, multiple-scattering energy compensation from
  its DFG table (``dfg.py``), Lambert diffuse; its ambient and environment answers split the
  light between the lobes by the same table. The G-buffer carries the base colour as the
  albedo, metallic as the specular intensity, the perceptual roughness as the specular exponent
  and the material's ambient occlusion in the datum ``pbr_occlusion``: 21 bytes a pixel,
  within the model's budget of :data:`PBR_GBUFFER_BUDGET`. Area lights by linearly transformed
  cosines (``pbr_area.glsl``).

- ``subsurface``: a Lambertian diffuse part and Blinn-Phong's highlight, split (the lighting
  writes the diffuse part apart, which the subsurface material's screen-space blur scatters),
  and light through thin parts by the profile's transmittance at the shadow maps' thickness.
  The datum ``subsurface_profile`` (R8) holds the pixel's row of the scene's profile table
  (``u_subsurface_profiles``: :func:`subsurface_rows`).

``kajiya_kay``, ``marschner`` and ``toon`` have no area answer: an area light reaches them as a
point light along its vector irradiance bringing that irradiance (``area_as_point_light`` in
``lighting/area.glsl``): a strand's lobes are not cosine lobes an LTC fits, and a toon ramp
wants one light direction.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import moderngl
import numpy as np

from deferred.api import GBufferData, ShadingModel, shading_models

from ..techniques.subsurface_profile import TAPS as SUBSURFACE_TAPS
from ..techniques.subsurface_profile import kernel as subsurface_kernel
from ..techniques.xtoon import RAMP_HEIGHT, RAMP_WIDTH, XToonRamp, ramp_layer, scene_ramps
from .dfg import dfg_table

if TYPE_CHECKING:
    from deferred.api import Frame

STRAND_TANGENT = GBufferData(
    "strand_tangent", "RG16F", ("u", "v"),
    "strand tangent, view space, octahedral (kajiya_kay: materials/techniques/strand_tangent.glsl)")
TOON_RAMP = GBufferData("toon_ramp", "R8", ("row",), "row of the toon ramp texture / 255")
SUBSURFACE_PROFILE = GBufferData("subsurface_profile", "R8", ("row",),
                                 "row of the scene's subsurface profile table / 255")
PBR_OCCLUSION = GBufferData("pbr_occlusion", "R8", ("occlusion",),
                            "pbr: the material's ambient occlusion (its map, by strength)")
# bytes a pixel the pbr model's surfaces may take: the 20-byte core and 4 of its own
PBR_GBUFFER_BUDGET = 24


@shading_models.register
class BlinnPhong(ShadingModel):
    name = "blinn_phong"
    glsl_file = "materials/shading_models/blinn_phong.glsl"
    glsl_function = "blinn_phong"
    area_file = "materials/shading_models/blinn_phong_area.glsl"
    area_function = "blinn_phong_area"


@shading_models.register
class KajiyaKay(ShadingModel):
    name = "kajiya_kay"
    glsl_file = "materials/shading_models/kajiya_kay.glsl"
    glsl_function = "kajiya_kay"
    gbuffer_data = (STRAND_TANGENT,)


def _ramp(values: np.ndarray, dark, light) -> np.ndarray:
    return np.asarray(dark)[None, :] * (1.0 - values[:, None]) + \
        np.asarray(light)[None, :] * values[:, None]


def toon_ramps(width: int = 256) -> dict[str, np.ndarray]:
    """The built-in ramps, (width, 3) linear RGB over N.L from -1 (left) to 1 (right)."""
    n_dot_l = np.linspace(-1.0, 1.0, width)

    def steps(edges, tones, softness=0.02):
        out = np.full(width, tones[0])
        for edge, low, high in zip(edges, tones, tones[1:], strict=False):
            t = np.clip((n_dot_l - edge) / softness + 0.5, 0.0, 1.0)
            out = out + (high - low) * t
        return out

    soft = np.clip((n_dot_l + 0.2) / 0.8, 0.0, 1.0)
    grey = (1.0, 1.0, 1.0)
    return {
        "two_tone": _ramp(steps([0.1], [0.12, 1.0]), (0, 0, 0), grey),
        "three_tone": _ramp(steps([0.0, 0.5], [0.05, 0.4, 1.0]), (0, 0, 0), grey),
        "soft": _ramp(soft * soft * (3.0 - 2.0 * soft), (0, 0, 0), grey),
        "warm_cool": _ramp(steps([0.15], [0.0, 1.0], 0.1), (0.10, 0.14, 0.32), (1.0, 0.92, 0.78)),
    }


TOON_RAMP_NAMES = tuple(toon_ramps())


@shading_models.register
class Toon(ShadingModel):
    """N.L through a ramp: the built-in 1D ramps (layers 0 .. 3 of ``u_toon_ramps``, over N.L
    from -1 to 1, filtered) and the scene's X-toon ramps after them (2D, over max(N.L, 0) and a
    metric, fetched unfiltered: :mod:`deferred.materials.techniques.xtoon`). A material writes
    its ramp's layer into the G-buffer datum ``toon_ramp``; ``u_toon_ramp_constants`` holds a
    row per layer: metric, its two constants, and whether the layer is an X-toon ramp."""

    name = "toon"
    glsl_file = "materials/shading_models/toon.glsl"
    glsl_function = "toon"
    gbuffer_data = (TOON_RAMP,)

    @classmethod
    def textures(cls, frame: Frame) -> dict[str, moderngl.Texture]:
        ramps = scene_ramps(frame.scene)
        key = ("toon_ramps", tuple(ramps))

        def create(ctx: moderngl.Context) -> moderngl.Texture:
            layers = [np.repeat(row[None, :, :], RAMP_HEIGHT, axis=0)
                      for row in toon_ramps(RAMP_WIDTH).values()]
            layers += [ramp.texels() for ramp in ramps]
            data = np.stack(layers).astype(np.float32)  # (layers, height, width, 3)
            texture = ctx.texture_array((RAMP_WIDTH, RAMP_HEIGHT, len(layers)), 3,
                                        data.tobytes(), dtype="f4")
            texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
            texture.repeat_x = texture.repeat_y = False
            return texture

        def create_constants(ctx: moderngl.Context) -> moderngl.Texture:
            rows = [(0.0, 0.0, 0.0, 0.0)] * len(TOON_RAMP_NAMES)
            rows += [ramp.constants() for ramp in ramps]
            texture = ctx.texture((len(rows), 1), 4, np.asarray(rows, np.float32).tobytes(),
                                  dtype="f4")
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            return texture

        # one array at a time: a ramp edited between frames replaces it
        return {"u_toon_ramps": frame.resources.current("toon_ramps", key, create),
                "u_toon_ramp_constants": frame.resources.current(
                    "toon_ramp_constants", key, create_constants)}

    @staticmethod
    def ramp_row(name: str) -> float:
        """The ``toon_ramp`` value selecting built-in ramp ``name``."""
        return TOON_RAMP_NAMES.index(name) / 255.0

    @staticmethod
    def xtoon_row(scene, ramp: XToonRamp) -> float:
        """The ``toon_ramp`` value selecting X-toon ``ramp`` in ``scene``."""
        return ramp_layer(scene, ramp, len(TOON_RAMP_NAMES)) / 255.0


@shading_models.register
class ToonStrands(Toon):
    """:class:`Toon` with a specular along strands: where the surface writes a strand tangent
    (``strand_tangent``; a surface without one writes ``u = 4``, outside the octahedral
    square) the band and the X-toon specular metric take sin(T, H) for N.H
    (``toon_strands.glsl``). Its ramps are the toon model's (the same texture array)."""

    name = "toon_strands"
    glsl_file = "materials/shading_models/toon_strands.glsl"
    glsl_function = "toon_strands"
    gbuffer_data = (TOON_RAMP, STRAND_TANGENT)


@shading_models.register
class Marschner(ShadingModel):
    name = "marschner"
    glsl_file = "materials/shading_models/marschner.glsl"
    glsl_function = "marschner"
    ambient_function = "marschner_ambient"
    gbuffer_data = (STRAND_TANGENT,)


@shading_models.register
class Pbr(ShadingModel):
    name = "pbr"
    glsl_file = "materials/shading_models/pbr.glsl"
    glsl_function = "pbr"
    ambient_function = "pbr_ambient"
    environment_function = "pbr_environment"
    area_file = "materials/shading_models/pbr_area.glsl"
    area_function = "pbr_area"
    gbuffer_data = (PBR_OCCLUSION,)
    gbuffer_budget = PBR_GBUFFER_BUDGET

    @classmethod
    def textures(cls, frame: Frame) -> dict[str, moderngl.Texture]:
        def create(ctx: moderngl.Context) -> moderngl.Texture:
            table = dfg_table()
            size = table.shape[0]
            texture = ctx.texture((size, size), 2, np.ascontiguousarray(table).tobytes(),
                                  dtype="f4")
            texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
            texture.repeat_x = texture.repeat_y = False
            return texture

        return {"u_pbr_dfg": frame.resources.texture("pbr_dfg", create)}


def subsurface_rows(scene) -> list[tuple]:
    """The scene's distinct subsurface profiles, in scene order: each object's material's
    ``subsurface_profile()`` (shape d per channel, transmission), one row of the table each."""
    rows: list[tuple] = []
    for obj in scene.objects:
        answer = getattr(obj.material, "subsurface_profile", None)
        if answer is not None and answer() not in rows:
            rows.append(answer())
    return rows


def subsurface_table(rows: list[tuple]) -> np.ndarray:
    """``(rows, 1 + SUBSURFACE_TAPS, 4)`` float32: a row per profile, texel 0 its shape and
    transmission, then its blur taps (offset, weights per channel)."""
    table = np.zeros((max(len(rows), 1), 1 + SUBSURFACE_TAPS, 4), np.float32)
    for index, (shape, transmission) in enumerate(rows):
        offsets, weights = subsurface_kernel(tuple(float(d) for d in shape))
        table[index, 0] = (*shape, transmission)
        table[index, 1:, 0] = offsets
        table[index, 1:, 1:] = weights
    return table


@shading_models.register
class Subsurface(ShadingModel):
    name = "subsurface"
    glsl_file = "materials/shading_models/subsurface.glsl"
    glsl_function = "subsurface"
    diffuse_function = "subsurface_diffuse"
    specular_function = "subsurface_specular"
    transmission_function = "subsurface_transmission"
    area_file = "materials/shading_models/subsurface_area.glsl"
    area_function = "subsurface_area"
    gbuffer_data = (SUBSURFACE_PROFILE,)

    @classmethod
    def textures(cls, frame: Frame) -> dict[str, moderngl.Texture]:
        rows = subsurface_rows(frame.scene)
        key = tuple(rows)

        def create(ctx: moderngl.Context) -> moderngl.Texture:
            table = subsurface_table(rows)
            texture = ctx.texture((table.shape[1], table.shape[0]), 4, table.tobytes(),
                                  dtype="f4")
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            return texture

        return {"u_subsurface_profiles": frame.resources.current("subsurface_profiles", key,
                                                                 create)}
