"""The viewer's own GLSL (``shaders/viewer/``: the panels and the viewport), compiled on the
window's context."""

from __future__ import annotations

from importlib import resources

import moderngl

from deferred.errors import ShaderError


def viewer_program(ctx: moderngl.Context, vertex: str, fragment: str,
                   defines: dict[str, str] | None = None) -> moderngl.Program:
    """The program of these two files, the ``defines`` put after each one's ``#version``."""
    folder = resources.files("deferred.shaders").joinpath("viewer")
    lines = "".join(f"#define {name} {value}\n" for name, value in (defines or {}).items())
    sources = {}
    for stage, name in (("vertex_shader", vertex), ("fragment_shader", fragment)):
        text = folder.joinpath(name).read_text(encoding="utf-8")
        if lines:
            head, version, rest = text.partition("#version 330\n")
            text = head + version + lines + rest
        sources[stage] = text
    try:
        return ctx.program(**sources)
    except moderngl.Error as exc:
        raise ShaderError(f"shaders/viewer/{vertex} + {fragment}: {exc}") from exc
