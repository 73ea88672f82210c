"""The viewer's own GLSL (``shaders/viewer/``: the panels and the viewport), compiled on the
window's context."""

from __future__ import annotations

from importlib import resources

import moderngl

from deferred.errors import ShaderError


def viewer_program(ctx: moderngl.Context, vertex: str, fragment: str) -> moderngl.Program:
    folder = resources.files("deferred.shaders").joinpath("viewer")
    sources = {stage: folder.joinpath(name).read_text(encoding="utf-8")
               for stage, name in (("vertex_shader", vertex), ("fragment_shader", fragment))}
    try:
        return ctx.program(**sources)
    except moderngl.Error as exc:
        raise ShaderError(f"shaders/viewer/{vertex} + {fragment}: {exc}") from exc
