"""The standard material: Blinn-Phong, colour or texture, specular intensity and exponent."""

from __future__ import annotations

from typing import TYPE_CHECKING

import moderngl
from pydantic import Field

from deferred.api import (
    Albedo,
    BlinnPhongParams,
    Material,
    check_image,
    image_texture_bytes,
    materials,
)

if TYPE_CHECKING:
    from deferred.api import Frame


class StandardParams(BlinnPhongParams):
    color: Albedo = Field((0.8, 0.8, 0.8), description="linear RGB albedo, each in [0, 1]")
    texture: str | None = Field(None, description="albedo image (sRGB), multiplied by color")


@materials.register
class StandardMaterial(Material):
    name = "standard"
    Params = StandardParams
    surface_shader = "materials/standard/surface.glsl"
    inputs_from_params = True  # uniforms from the params, textures from frame.resources

    def check_files(self, where: str | None) -> None:
        if self.params.texture is None:
            return
        key = f"{where}.texture" if where else "texture"
        self._texture_key = key
        path = self.file_parameter(self.params.texture, "texture file", key)
        # the texture is read when GL draws it: a bad file fails now, not after GL starts
        check_image(path, key)

    def held_memory(self, obj) -> dict[str, int]:
        if self.params.texture is None:
            return {}
        path = self.resolve_path(self.params.texture)
        width, height, _ = check_image(path, getattr(self, "_texture_key", None))
        return {f"texture {path}": image_texture_bytes(width, height)}

    def defines(self, obj) -> dict[str, str]:
        defines = super().defines(obj)
        if self.params.texture is not None:
            defines["HAS_ALBEDO_TEXTURE"] = "1"
        return defines

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        if self.params.texture is None:
            return {}
        return {"u_albedo_texture": frame.resources.image_texture(
            self.resolve_path(self.params.texture), where=getattr(self, "_texture_key", None))}
