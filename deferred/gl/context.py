"""Headless GL context creation and capability detection.

The framework needs GL 3.3 core. GL 4.3 features (shader storage buffers, compute shaders) are
detected and switched on only where the driver reports them; everything has a 3.3 path.
"""

from __future__ import annotations

import os
import threading
from dataclasses import dataclass, field

import moderngl

from deferred.errors import RenderError

MIN_GL_VERSION = 330


@dataclass(frozen=True)
class Features:
    """Optional GL features in use, decided once per context."""

    storage_buffers: bool = False  # GL 4.3 (GLSL 430): the light lists' storage buffer
    compute_shaders: bool = False  # GL 4.3
    depth_clamp: bool = True  # GL 3.2 core: light volumes are never cut by the far plane

    def glsl_version(self) -> int:
        return 430 if self.storage_buffers or self.compute_shaders else 330

    def names(self) -> dict[str, bool]:
        return {
            "storage_buffers": self.storage_buffers,
            "compute_shaders": self.compute_shaders,
            "depth_clamp": self.depth_clamp,
        }


@dataclass
class GLContext:
    """A moderngl context plus the features the framework decided to use on it."""

    ctx: moderngl.Context
    features: Features = field(default_factory=Features)

    @property
    def info(self) -> dict[str, str]:
        return {
            "vendor": self.ctx.info["GL_VENDOR"],
            "renderer": self.ctx.info["GL_RENDERER"],
            "version": self.ctx.info["GL_VERSION"],
            "glsl": str(self.features.glsl_version()),
        }

    @property
    def max_texture_size(self) -> int:
        """GL_MAX_TEXTURE_SIZE: the widest and tallest 2D texture (images, the GL 3.3 lights)."""
        return int(self.ctx.info["GL_MAX_TEXTURE_SIZE"])

    _parking: moderngl.Framebuffer | None = None
    pool_key: tuple | None = None  # set by acquire_context

    def make_current(self) -> None:
        """Make this context the thread's current one.

        Several standalone contexts can live in one thread (a session's plus one a CLI call
        made and released): GL calls go to whichever is current, so each user of a context
        makes it current before issuing work.
        """
        self.ctx.mglo.__enter__()

    def park(self) -> None:
        """Bind a framebuffer this context keeps for good.

        moderngl re-binds the last used framebuffer after creating another one; if that one was
        released, the next creation is a GL error. Renderers park before releasing theirs.
        """
        if self._parking is None:
            self._parking = self.ctx.framebuffer(self.ctx.renderbuffer((1, 1), 4))
        self._parking.use()

    def release(self) -> None:
        self.ctx.release()


def detect_features(ctx: moderngl.Context, allow_gl43: bool = True) -> Features:
    has_43 = allow_gl43 and ctx.version_code >= 430
    return Features(storage_buffers=has_43, compute_shaders=has_43, depth_clamp=True)


def create_context(backend: str | None = None, allow_gl43: bool | None = None) -> GLContext:
    """Create a headless context: EGL by default (Mesa llvmpipe on CI machines).

    ``DEFERRED_GL_BACKEND`` overrides the backend; ``DEFERRED_GL33=1`` forces the GL 3.3 paths;
    ``DEFERRED_EGL_DEVICE=N`` picks EGL's device N (a render worker given GPU N, ``--ray``).
    """
    backend = backend or os.environ.get("DEFERRED_GL_BACKEND", "egl")
    if allow_gl43 is None:
        allow_gl43 = os.environ.get("DEFERRED_GL33", "") not in ("1", "true", "yes")
    device = os.environ.get("DEFERRED_EGL_DEVICE", "")
    chosen = {"device_index": int(device)} if backend == "egl" and device.isdigit() else {}
    try:
        ctx = moderngl.create_standalone_context(backend=backend, require=MIN_GL_VERSION,
                                                 **chosen)
    except Exception as exc:  # noqa: BLE001 - moderngl raises plain Exception for missing drivers
        raise RenderError("cannot create a GL 3.3 core context "
                          f"(backend {backend}): {exc}") from exc
    return GLContext(ctx, detect_features(ctx, allow_gl43))


# Contexts given back by renderers that made their own, one per thread, backend and GL level:
# creating and destroying an EGL context per renderer grows the process by about 100 KB each
# time (Mesa keeps per-context allocations), so a program making a Renderer per frame reuses one.
_idle: dict[tuple, GLContext] = {}
_idle_lock = threading.Lock()


def _pool_key(backend: str | None, allow_gl43: bool | None) -> tuple:
    backend = backend or os.environ.get("DEFERRED_GL_BACKEND", "egl")
    if allow_gl43 is None:
        allow_gl43 = os.environ.get("DEFERRED_GL33", "") not in ("1", "true", "yes")
    return threading.get_ident(), backend, allow_gl43


def acquire_context(backend: str | None = None, allow_gl43: bool | None = None) -> GLContext:
    """A context for a renderer to own: one given back on this thread (:func:`give_back_context`),
    else a new one (:func:`create_context`)."""
    key = _pool_key(backend, allow_gl43)
    with _idle_lock:
        gl = _idle.pop(key, None)
    if gl is None:
        gl = create_context(backend, allow_gl43)
        gl.pool_key = key
    return gl


def give_back_context(gl: GLContext) -> None:
    """Keep ``gl`` (every object of its user released) for the next :func:`acquire_context` of
    this thread; a context already kept there, one not from the pool, or one left with a GL
    error (its user failed part way) is released. The fixed-function state a renderer may
    change is put back to GL's defaults, so the next renderer's image does not depend on it."""
    key = getattr(gl, "pool_key", None)
    clean = key is not None and _reset_state(gl.ctx)
    with _idle_lock:
        if not clean or key in _idle:
            gl.release()
        else:
            _idle[key] = gl


GL_DEPTH_CLAMP = 0x864F


def _reset_state(ctx: moderngl.Context) -> bool:
    """GL's default fixed-function state; False if the context holds a GL error."""
    if ctx.error != "GL_NO_ERROR":
        return False
    ctx.enable_only(moderngl.NOTHING)
    ctx.disable_direct(GL_DEPTH_CLAMP)
    ctx.polygon_offset = (0.0, 0.0)
    ctx.front_face = "ccw"
    ctx.cull_face = "back"
    ctx.wireframe = False
    ctx.depth_func = "<"
    ctx.blend_func = moderngl.DEFAULT_BLENDING
    ctx.blend_equation = moderngl.FUNC_ADD
    return ctx.error == "GL_NO_ERROR"
