"""deferred: a deferred-shading rendering framework on moderngl with pluggable materials."""

from __future__ import annotations

__version__ = "0.1.0"

from deferred.errors import DeferredError, InputError, RenderError, ShaderError  # noqa: E402
from deferred.gl.context import create_context  # noqa: E402
from deferred.render.renderer import Renderer, RenderResult, render_scene  # noqa: E402
from deferred.scene.loader import load_scene, scene_from_dict, scene_from_toml  # noqa: E402
from deferred.scene.model import Scene

__all__ = ["DeferredError", "InputError", "RenderError", "RenderResult", "Renderer", "Scene",
           "ShaderError", "create_context", "load_scene", "render_scene", "scene_from_dict",
           "scene_from_toml"]
