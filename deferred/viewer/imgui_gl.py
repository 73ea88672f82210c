"""imgui's draw data on a moderngl context (the viewer's panels).

imgui 1.92 hands its textures (the font atlas, grown as glyphs are needed) to the renderer
(``RendererHasTextures``); moderngl-window 3.1's imgui integration predates that protocol, so
the viewer draws imgui itself: one program, one vertex and one index buffer, a texture per
imgui texture.
"""

from __future__ import annotations

import struct

import moderngl
import numpy as np
from imgui_bundle import imgui

from deferred.viewer.shaders import viewer_program


class ImguiRenderer:
    """Draws imgui's frames into whatever framebuffer is bound on ``ctx``."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.io = imgui.get_io()
        self.program = viewer_program(ctx, "imgui.vert", "imgui.frag")
        self.program["u_texture"].value = 0
        self.vertices = ctx.buffer(reserve=1 << 16, dynamic=True)
        self.indices = ctx.buffer(reserve=1 << 15, dynamic=True)
        self.vao = ctx.vertex_array(
            self.program, [(self.vertices, "2f 2f 4f1", "in_position", "in_uv", "in_color")],
            index_buffer=self.indices, index_element_size=imgui.INDEX_SIZE)
        self.textures: dict[int, moderngl.Texture] = {}
        self.io.backend_flags |= imgui.BackendFlags_.renderer_has_textures
        platform = imgui.get_platform_io()
        platform.renderer_texture_max_width = platform.renderer_texture_max_height = \
            int(ctx.info["GL_MAX_TEXTURE_SIZE"])

    # -- textures --------------------------------------------------------------------------------
    def update_textures(self) -> bool:
        """imgui's texture requests carried out; whether any texture changed."""
        changed = False
        for tex in imgui.get_platform_io().textures:
            if tex.status in (imgui.ImTextureStatus.want_create,
                              imgui.ImTextureStatus.want_updates,
                              imgui.ImTextureStatus.want_destroy):
                changed = True
            status = tex.status
            if status == imgui.ImTextureStatus.want_create:
                texture = self.ctx.texture((tex.width, tex.height), 4,
                                           tex.get_pixels_array().tobytes())
                texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
                texture.repeat_x = texture.repeat_y = False
                self.textures[texture.glo] = texture
                tex.set_tex_id(texture.glo)
                tex.status = imgui.ImTextureStatus.ok
            elif status == imgui.ImTextureStatus.want_updates:
                texture = self.textures[tex.tex_id]
                pixels = np.asarray(tex.get_pixels_array()).reshape(tex.height, tex.width, 4)
                for rect in tex.updates:
                    block = np.ascontiguousarray(pixels[rect.y:rect.y + rect.h,
                                                        rect.x:rect.x + rect.w])
                    texture.write(block.tobytes(), viewport=(rect.x, rect.y, rect.w, rect.h))
                tex.status = imgui.ImTextureStatus.ok
            elif status == imgui.ImTextureStatus.want_destroy:
                texture = self.textures.pop(tex.tex_id, None)
                if texture is not None:
                    texture.release()
                tex.set_tex_id(0)
                tex.status = imgui.ImTextureStatus.destroyed
        return changed

    # -- drawing ---------------------------------------------------------------------------------
    def render(self, draw_data: imgui.ImDrawData, framebuffer: moderngl.Framebuffer) -> None:
        self.update_textures()
        width, height = self.io.display_size
        if width <= 0 or height <= 0:
            return
        ctx = self.ctx
        framebuffer.use()
        ctx.viewport = (0, 0, int(width), int(height))
        ctx.enable_only(moderngl.BLEND)
        ctx.blend_func = (moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA, moderngl.ONE,
                          moderngl.ONE_MINUS_SRC_ALPHA)
        ctx.blend_equation = moderngl.FUNC_ADD
        self.program["u_projection"].write(np.array([
            [2.0 / width, 0.0, 0.0, 0.0],
            [0.0, -2.0 / height, 0.0, 0.0],
            [0.0, 0.0, -1.0, 0.0],
            [-1.0, 1.0, 0.0, 1.0]], dtype="f4").tobytes())
        try:
            for commands in draw_data.cmd_lists:
                vertex_bytes = commands.vtx_buffer.size() * imgui.VERTEX_SIZE
                index_bytes = commands.idx_buffer.size() * imgui.INDEX_SIZE
                self._fit(vertex_bytes, index_bytes)
                self.vertices.write(_bytes_at(commands.vtx_buffer.data_address(), vertex_bytes))
                self.indices.write(_bytes_at(commands.idx_buffer.data_address(), index_bytes))
                for command in commands.cmd_buffer:
                    texture = self.textures.get(command.tex_ref.get_tex_id())
                    if texture is None:
                        continue
                    texture.use(0)
                    x0, y0, x1, y1 = command.clip_rect
                    ctx.scissor = (int(x0), int(height - y1), int(x1 - x0), int(y1 - y0))
                    self.vao.render(moderngl.TRIANGLES, vertices=command.elem_count,
                                    first=command.idx_offset)
        finally:
            ctx.scissor = None
            ctx.enable_only(moderngl.NOTHING)

    def _fit(self, vertex_bytes: int, index_bytes: int) -> None:
        if vertex_bytes > self.vertices.size:
            self.vertices.orphan(max(vertex_bytes, 2 * self.vertices.size))
        if index_bytes > self.indices.size:
            self.indices.orphan(max(index_bytes, 2 * self.indices.size))

    def release(self) -> None:
        for texture in self.textures.values():
            texture.release()
        self.textures.clear()
        for item in (self.vao, self.vertices, self.indices, self.program):
            item.release()


class PanelLayer:
    """The panels drawn into a texture of their own and copied onto the window, their
    triangles drawn again only when imgui's draw data (vertices, indices, commands) or its
    textures differ from those last drawn: a window frame whose panels did not change (the
    camera orbiting, say) costs a copy of their pixels, not their triangles."""

    def __init__(self, ctx: moderngl.Context, renderer: ImguiRenderer):
        self.ctx = ctx
        self.renderer = renderer
        self.texture: moderngl.Texture | None = None
        self.framebuffer: moderngl.Framebuffer | None = None
        self.signature: bytes | None = None
        self.drawn = 0  # times the triangles were drawn (tests, benchmarks)

    def draw(self, draw_data: imgui.ImDrawData, window: moderngl.Framebuffer, width: int,
             height: int, background: tuple[float, float, float]) -> bool:
        """The panels, all within the window's first ``width`` columns, onto ``window``
        (the same pixels as :meth:`ImguiRenderer.render` over the ``background``); False,
        drawing nothing, where imgui draws beyond those columns (a popup over the viewport)."""
        signature = draw_signature(draw_data, width)
        if signature is None:
            return False
        changed = self.renderer.update_textures()
        if self.texture is None or self.texture.size != (width, height):
            self.release()
            self.texture = self.ctx.texture((width, height), 4)
            self.framebuffer = self.ctx.framebuffer(color_attachments=[self.texture])
        if changed or signature != self.signature:
            self.framebuffer.use()
            self.framebuffer.clear(*background, 1.0)
            self.renderer.render(draw_data, self.framebuffer)
            self.signature = signature
            self.drawn += 1
        self.ctx.copy_framebuffer(window, self.framebuffer)
        return True

    def release(self) -> None:
        for item in (self.framebuffer, self.texture):
            if item is not None:
                item.release()
        self.texture = self.framebuffer = self.signature = None


def draw_signature(draw_data: imgui.ImDrawData, width: int) -> bytes | None:
    """What imgui draws, as bytes (equal bytes: the same pixels); None where it draws beyond
    the first ``width`` columns (a vertex there, unclipped)."""
    parts = []
    for commands in draw_data.cmd_lists:
        vertices = _bytes_at(commands.vtx_buffer.data_address(),
                             commands.vtx_buffer.size() * imgui.VERTEX_SIZE)
        # the vertices' x: the first float of each (position, uv, colour)
        right = float(np.frombuffer(vertices, np.float32)[::imgui.VERTEX_SIZE // 4].max()) \
            if vertices else 0.0
        parts.append(vertices)
        parts.append(_bytes_at(commands.idx_buffer.data_address(),
                               commands.idx_buffer.size() * imgui.INDEX_SIZE))
        for command in commands.cmd_buffer:
            if command.elem_count == 0:
                continue
            x0, y0, x1, y1 = command.clip_rect
            if min(x1, right) > width:
                return None
            parts.append(struct.pack("4f3Q", x0, y0, x1, y1, command.tex_ref.get_tex_id(),
                                     command.elem_count, command.idx_offset))
    return b"".join(parts)


def _bytes_at(address: int, size: int) -> bytes:
    import ctypes

    return ctypes.string_at(address, size)
