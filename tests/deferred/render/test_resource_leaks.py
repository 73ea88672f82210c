"""Issue #11, soak: 1,000 frames at 64x64 through the Python API, half of them each from a new
``Renderer`` (which takes its context from the pool), leave the live GL object count flat and
the process's resident memory within 5% of where it settled."""

from __future__ import annotations

import gc

import moderngl
import numpy as np
import pytest

from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

FRAMES = 1000
GL_CLASSES = tuple(getattr(moderngl, name) for name in (
    "Buffer", "Texture", "TextureArray", "Texture3D", "TextureCube", "Renderbuffer",
    "Framebuffer", "Program", "ComputeShader", "VertexArray", "Sampler", "Query", "Scope")
    if hasattr(moderngl, name))


def live_gl_objects() -> int:
    """moderngl objects alive and not released (textures, buffers, programs, framebuffers,
    vertex arrays, ...)."""
    gc.collect()
    return sum(1 for obj in gc.get_objects()
               if isinstance(obj, GL_CLASSES) and
               not isinstance(getattr(obj, "mglo", None), moderngl.InvalidObject))


def resident_bytes() -> int:
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * 4096


@pytest.mark.slow
def test_a_thousand_frames_keep_gl_objects_and_memory_flat():
    scene = scene_from_dict({
        "size": [64, 64],
        "camera": {"position": [0.0, 1.0, 3.0], "target": [0.0, 0.0, 0.0]},
        "object": [{"mesh": "builtin:sphere", "params": {"color": [0.8, 0.4, 0.2]}},
                   {"mesh": "builtin:plane", "position": [0.0, -1.0, 0.0], "scale": 3.0}],
        "light": [{"type": "ambient"}, {"type": "directional"},
                  {"type": "point", "position": [1.0, 1.5, 1.0], "radius": 5.0}]})
    first = None
    counts, memory = [], []
    with Renderer(scene) as kept:
        for frame in range(FRAMES):
            if frame % 2:
                with Renderer(scene) as renderer:  # a new renderer per frame
                    image = renderer.render().image
            else:
                image = kept.render(time=frame / 60.0).image
            if first is None:
                first = image
            elif frame % 97 == 0:
                np.testing.assert_array_equal(image, first)  # the same frame every time
            if frame % 100 == 99:
                counts.append(live_gl_objects())
                memory.append(resident_bytes())
    assert len(set(counts)) == 1, counts
    settled = memory[1]  # after the first 200 frames: caches and allocator pools filled
    assert max(memory[1:]) <= settled * 1.05, [m >> 20 for m in memory]


def test_a_pooled_context_carries_no_state_or_error_into_the_next_renderer():
    scene = scene_from_dict({
        "size": [48, 32],
        "object": [{"mesh": "builtin:torus"}],
        "light": [{"type": "directional"}, {"type": "point", "position": [1.0, 1.0, 2.0]}]})
    with Renderer(scene) as renderer:
        reference = renderer.render().image
    renderer = Renderer(scene)
    renderer.render()
    ctx = renderer.gl.ctx
    ctx.front_face = "cw"  # what a caller's own GL code, or a pass that raised, may leave
    ctx.wireframe = True
    ctx.enable_direct(0x864F)  # GL_DEPTH_CLAMP
    ctx.enable_direct(0x7FFF)  # no such capability: a pending GL_INVALID_ENUM
    renderer.release()
    with Renderer(scene) as again:
        np.testing.assert_array_equal(again.render().image, reference)
    renderer = Renderer(scene)
    renderer.gl.ctx.front_face = "cw"
    renderer.release()  # state only, no error: the context is kept, and reset
    with Renderer(scene) as again:
        np.testing.assert_array_equal(again.render().image, reference)
