"""Image-based light: an equirectangular ``.hdr`` or ``.exr`` map (or the built-in sky) lighting
every surface from all around: diffuse from 9 spherical harmonics of its irradiance, specular
from a GGX-prefiltered cube mip chain (the split-sum's first factor; the ``pbr`` shading model
brings the second, its DFG table). Its maps are made on the GPU once and cached on disk
(:mod:`.maps`). A material whose shading model has no environment function receives the
irradiance at its normal through its ambient answer, as it answers the ``ambient`` light. A
scene has at most one; ``background = "environment"`` shows it behind the scene.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import numpy as np
from pydantic import Field

from deferred.api import (
    InputError,
    Light,
    LightParams,
    LightVolume,
    RenderError,
    check_image,
    lights,
    require_regular_file,
)

from .maps import environment_maps, image_digest, level_sizes

if TYPE_CHECKING:
    import moderngl

    from deferred.api import Frame

MAP_SUFFIXES = (".hdr", ".exr")


class EnvironmentParams(LightParams):
    map: str | None = Field(None, description="equirectangular .hdr or .exr of linear "
                            "radiance (relative to the scene file); none: the built-in sky")
    rotation: float = Field(0.0, ge=-360.0, le=360.0,
                            description="degrees the map turns about the world's +Y")
    resolution: Literal[32, 64, 128, 256, 512] = Field(
        128, description="texels a side of the prefiltered cube's first level (a mirror's "
                         "sharpness)")


# an image file's hash by (path, size, modification time): read once while the file is the same
_DIGESTS: dict[tuple[str, int, int], str] = {}


def map_digest(path: Path | None) -> str:
    if path is None:
        return image_digest(None)
    status = os.stat(path)
    key = (str(path), status.st_size, status.st_mtime_ns)
    digest = _DIGESTS.get(key)
    if digest is None:
        digest = _DIGESTS[key] = image_digest(path)
    return digest


def to_map(view: np.ndarray, rotation_degrees: float) -> np.ndarray:
    """View-space directions to the map's: the camera's rotation undone, then the light's
    rotation about +Y undone (the map turned by ``rotation`` shows world direction d at its
    direction R_y(-rotation) d)."""
    angle = np.radians(-rotation_degrees)
    c, s = np.cos(angle), np.sin(angle)
    turn = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return turn @ np.asarray(view, np.float64)[:3, :3].T


@lights.register
class EnvironmentLight(Light):
    name = "environment"
    Params = EnvironmentParams
    glsl_file = "lights/environment/environment.glsl"
    glsl_function = "environment_light"
    volume = LightVolume.FULLSCREEN

    def check_files(self, where: str | None) -> None:
        if self.params.map is None:
            return
        key = f"{where}.map" if where else "map"
        if not str(self.params.map).strip():
            raise InputError("is empty; name an .hdr or .exr file", key)
        path = self.resolve_path(self.params.map)
        require_regular_file(path, "environment map", key)
        if path.suffix.lower() not in MAP_SUFFIXES:
            raise InputError(f"environment map {path.name} is not an equirectangular "
                             f"{' or '.join(MAP_SUFFIXES)} file", key)
        check_image(path, key)

    def map_path(self) -> Path | None:
        return None if self.params.map is None else self.resolve_path(self.params.map)

    def record(self, view: np.ndarray) -> np.ndarray:
        record = np.zeros((4, 4), dtype=np.float32)
        record[0, :3] = self.radiance()
        rows = to_map(view, self.params.rotation)
        record[1, :3], record[2, :3], record[3, :3] = rows
        record[1, 3] = len(level_sizes(self.params.resolution)) - 1  # roughness 1's level
        return record

    @classmethod
    def textures(cls, frame: Frame) -> dict[str, moderngl.Texture]:
        found = [light for light in frame.scene.lights if isinstance(light, cls)]
        if not found:
            return {}
        if len(found) > 1:
            raise InputError(f"{len(found)} environment lights: a scene has at most one",
                             f"{frame.scene.source}: light")
        if frame.shaders.glsl_version < 430:
            raise RenderError("the environment light makes its maps with compute shaders: it "
                              "needs GL 4.3, which this context lacks")
        light = found[0]
        path = light.map_path()
        resolution = light.params.resolution
        digest = map_digest(path)

        def create(ctx: moderngl.Context):
            return environment_maps(ctx, frame.shaders, path, digest, resolution,
                                    f"{frame.scene.source}: light.map")

        maps = frame.resources.current("environment", (digest, resolution), create)
        return {"u_environment_specular": maps.cube, "u_environment_sh": maps.sh}
