"""deferred: a deferred-shading rendering framework on moderngl with pluggable materials.

The names below are the Python API's entry points; each loads its layer when first used, so
importing one layer (``deferred.names``, ``deferred.api``) does not load every layer above it.
Plugins import ``deferred.api``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from deferred.errors import DeferredError, InputError, RenderError, ShaderError

__version__ = "0.1.0"

_LAZY = {
    "Camera": "deferred.scene.camera",
    "SceneObject": "deferred.scene.objects",
    "read_image": "deferred.io.images",
    "write_image": "deferred.io.images",
    "create_context": "deferred.gl.context",
    "Renderer": "deferred.render.renderer",
    "RenderResult": "deferred.render.renderer",
    "render_scene": "deferred.render.renderer",
    "Scene": "deferred.scene.scene",
    "load_scene": "deferred.scene.loader",
    "scene_from_dict": "deferred.scene.loader",
    "scene_from_toml": "deferred.scene.loader",
}

if TYPE_CHECKING:
    from deferred.gl.context import create_context
    from deferred.io.images import read_image, write_image
    from deferred.render.renderer import Renderer, RenderResult, render_scene
    from deferred.scene.camera import Camera
    from deferred.scene.loader import load_scene, scene_from_dict, scene_from_toml
    from deferred.scene.objects import SceneObject
    from deferred.scene.scene import Scene


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'deferred' has no attribute '{name}'")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # looked up once
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


__all__ = ["Camera", "DeferredError", "InputError", "RenderError", "RenderResult", "Renderer",
           "Scene", "SceneObject", "ShaderError", "create_context", "load_scene", "read_image",
           "render_scene", "scene_from_dict", "scene_from_toml", "write_image"]
