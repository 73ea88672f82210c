"""The ``pbr`` material's parameters: glTF 2.0's metallic-roughness material, by the names the
scene files and the glTF loader use (issue #35's interface)."""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import Field, field_validator

from deferred.api import Albedo, MaterialParams, Params, Radiance

UnitFloat = Annotated[float, Field(ge=0.0, le=1.0)]
Wrap = Literal["repeat", "clamp_to_edge", "mirrored_repeat"]
MinFilter = Literal["nearest", "linear", "nearest_mipmap_nearest", "linear_mipmap_nearest",
                    "nearest_mipmap_linear", "linear_mipmap_linear"]

# the textures, each a parameter <name>_texture (glTF's textureInfo)
TEXTURES = ("base_color", "metallic_roughness", "normal", "occlusion", "emissive")
SRGB_TEXTURES = ("base_color", "emissive")  # colour; the others hold data


class TextureParams(Params):
    """One texture of the material: the image, the UV set it reads, KHR_texture_transform's
    offset, rotation and scale (in glTF's texture space: v down from the image's top), and the
    glTF sampler's wrap and filter modes. A scene file gives a path alone or a table."""

    path: str = Field(description="image file, relative to the scene file")
    uv: Literal[0, 1] = Field(0, description="texture coordinate set (glTF texCoord)")
    offset: tuple[float, float] = Field((0.0, 0.0), description="KHR_texture_transform offset")
    rotation: float = Field(0.0, ge=-1e3, le=1e3,
                            description="KHR_texture_transform rotation, radians")
    scale: tuple[float, float] = Field((1.0, 1.0), description="KHR_texture_transform scale")
    wrap_s: Wrap = Field("repeat", description="wrap along u (glTF sampler wrapS)")
    wrap_t: Wrap = Field("repeat", description="wrap along v (glTF sampler wrapT)")
    mag_filter: Literal["nearest", "linear"] = Field("linear", description="magnification")
    min_filter: MinFilter = Field("linear_mipmap_linear", description="minification")

    def rows(self) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """The transform's two rows, T R S (KHR_texture_transform), applied to (u, v, 1)."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        (sx, sy), (ox, oy) = self.scale, self.offset
        return (c * sx, s * sy, ox), (-s * sx, c * sy, oy)


TextureField = str | TextureParams | None


def texture_params(value: TextureField) -> TextureParams | None:
    """A texture parameter as a table (a path alone: the defaults)."""
    if value is None or isinstance(value, TextureParams):
        return value
    return TextureParams(path=value)


class PbrParams(MaterialParams):
    # three numbers are taken as opaque (the validator below): the union says so to a schema
    base_color: tuple[UnitFloat, UnitFloat, UnitFloat, UnitFloat] | \
        tuple[UnitFloat, UnitFloat, UnitFloat] = Field(
        (1.0, 1.0, 1.0, 1.0), description="linear RGBA (glTF baseColorFactor; three numbers: "
                                          "opaque)")
    metallic: float = Field(1.0, ge=0.0, le=1.0, description="glTF metallicFactor")
    roughness: float = Field(1.0, ge=0.0, le=1.0, description="perceptual roughness (glTF "
                             "roughnessFactor; GGX alpha is its square)")
    emissive: Radiance = Field((0.0, 0.0, 0.0), description="linear RGB emission (glTF "
                               "emissiveFactor)")
    emissive_strength: float = Field(1.0, ge=0.0, description="KHR_materials_emissive_"
                                     "strength: a multiplier of the emission")
    normal_scale: float = Field(1.0, ge=-1e3, le=1e3, description="the normal map's X and Y "
                                "scale (glTF normalTexture.scale)")
    occlusion_strength: float = Field(1.0, ge=0.0, le=1.0, description="glTF "
                                      "occlusionTexture.strength")
    alpha_mode: Literal["opaque", "mask", "blend"] = Field(
        "opaque", description="glTF alphaMode: alpha ignored, a cut-out below alpha_cutoff, "
                              "or blended over what lies behind")
    alpha_cutoff: float = Field(0.5, ge=0.0, le=1.0, description="mask: alpha below it is cut")
    double_sided: bool = Field(False, description="both faces drawn, back faces lit with the "
                               "normal turned (glTF doubleSided)")
    base_color_texture: TextureField = Field(None, description="sRGB RGBA, multiplies "
                                             "base_color")
    metallic_roughness_texture: TextureField = Field(None, description="linear: B metallic, "
                                                     "G roughness, multiplying the factors")
    normal_texture: TextureField = Field(None, description="tangent-space normal map (+Y up)")
    occlusion_texture: TextureField = Field(None, description="linear: R ambient occlusion")
    emissive_texture: TextureField = Field(None, description="sRGB RGB, multiplies emissive")

    @field_validator("base_color", mode="before")
    @classmethod
    def _opaque_rgb(cls, value):
        # three numbers are an opaque colour: base_color = [0.8, 0.1, 0.1]
        if isinstance(value, list | tuple) and len(value) == 3:
            return (*value, 1.0)
        return value


__all__ = ["SRGB_TEXTURES", "TEXTURES", "Albedo", "PbrParams", "TextureParams",
           "texture_params"]
