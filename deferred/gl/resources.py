"""GPU objects that outlive a frame: meshes' buffers, textures loaded from files, helper
geometry; a renderer holds one and releases it with itself."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import moderngl
import numpy as np

from deferred.gl.meshes import GpuMesh, MeshData
from deferred.io.images import read_image

UPLOAD_BAND_PIXELS = 1 << 20  # texels written to a texture at once


def image_texture_bytes(width: int, height: int) -> int:
    """GPU bytes of :meth:`Resources.image_texture` for an image of ``width`` x ``height``:
    float16 RGBA and its mipmaps (a third more)."""
    return width * height * 8 * 4 // 3


class _Slot(tuple):
    """(key, object) of :meth:`Resources.current`: released with the resources."""

    def __new__(cls, key: Any, made: Any) -> _Slot:
        return super().__new__(cls, (key, made))

    def release(self) -> None:
        self[1].release()


class Resources:
    """GPU objects that outlive one frame: meshes, textures loaded from files, helper geometry."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._meshes: dict[int, GpuMesh] = {}
        self._mesh_refs: list[MeshData] = []  # keep ids stable while cached
        self._cached: dict[Any, Any] = {}
        self._fullscreen_vaos: dict[int, moderngl.VertexArray] = {}

    def gpu_mesh(self, mesh: MeshData) -> GpuMesh:
        gpu = self._meshes.get(id(mesh))
        if gpu is None:
            gpu = GpuMesh(self.ctx, mesh, skinned=mesh.joints is not None)
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

    def current(self, slot: Any, key: Any, create: Callable[[moderngl.Context], Any]) -> Any:
        """A GPU object in ``slot`` made for ``key`` (anything with ``release()``): asked for
        with another key, the slot's object is released and ``create(ctx)`` makes the new
        one (what follows a value that changes between frames: a cached object a value would
        outlive its use)."""
        held = self._cached.get(("slot", slot))
        if held is not None and held[0] == key:
            return held[1]
        made = create(self.ctx)
        if held is not None:
            held[1].release()
        self._cached[("slot", slot)] = _Slot(key, made)
        return made

    def texture(self, key: Any, create: Callable[[moderngl.Context], moderngl.Texture]
                ) -> moderngl.Texture:
        """A cached texture (see :meth:`cached`)."""
        return self.cached(key, create)

    def image_texture(self, path: Path, srgb: bool = True, where: str | None = None,
                      sampler: tuple[tuple[int, int], tuple[bool, bool]] | None = None
                      ) -> moderngl.Texture:
        """The image at ``path`` as a mipmapped texture (cached); ``where`` (the scene key)
        names it in a read error. ``sampler``: its (minification, magnification) filters
        and whether it repeats along x and y (else clamped to its edge), where not
        trilinear and repeating; each sampler of one image is a texture of its own."""
        def create(ctx: moderngl.Context) -> moderngl.Texture:
            pixels = read_image(path, srgb_to_linear=srgb, where=where,
                                max_size=ctx.info["GL_MAX_TEXTURE_SIZE"], dtype=np.float16)
            height, width, _ = pixels.shape
            texture = ctx.texture((width, height), 4, dtype="f2")
            # bottom row first, a band at a time (no flipped copy of a large image)
            rows = max(1, UPLOAD_BAND_PIXELS // width)
            for first in range(0, height, rows):
                band = pixels[first:first + rows]
                texture.write(np.ascontiguousarray(band[::-1]),
                              viewport=(0, height - first - len(band), width, len(band)))
            texture.build_mipmaps()
            texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            if sampler is not None:
                texture.filter, (texture.repeat_x, texture.repeat_y) = sampler
            return texture

        key = ("image", str(path), srgb)
        return self.texture(key if sampler is None else (*key, sampler), create)

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
