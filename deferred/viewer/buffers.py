"""The buffer view: any ``--view`` buffer of the frame shown (G-buffer channels, declared data,
light accumulation, light lists, a target after a pass, a material's debug view), with an
exposure (stops) and one channel or all. With no exposure and all channels it is the image
``deferred render --view`` writes."""

from __future__ import annotations

import numpy as np

from deferred.debug.capture import capture_frame
from deferred.debug.preview import to_uint8
from deferred.debug.views import View, resolve_view, view, view_catalogue, with_material_view
from deferred.render.renderer import Renderer
from deferred.scene.scene import Scene

ALL_CHANNELS = -1


def buffer_names(renderer: Renderer, scene: Scene) -> list[str]:
    """Every buffer the view can show for this renderer's passes; a pass writing several
    targets is listed once a target (``PASS:TARGET``)."""
    names = []
    for name, _ in view_catalogue(renderer.passes, scene):
        if name.endswith(":TARGET"):
            pass_name = name.removesuffix(":TARGET")
            writes = next(p.writes for p in renderer.passes if p.name == pass_name)
            names += [f"{pass_name}:{target}" for target in dict.fromkeys(writes)]
        else:
            names.append(name)
    return names


def material_view_scene(scene: Scene, name: str) -> Scene | None:
    """A copy of ``scene`` drawing material debug view ``name``; None for other buffers."""
    return with_material_view(scene, name)


def capture_view(renderer: Renderer, name: str, time: float) -> View:
    """Render the frame at ``time`` and keep buffer ``name`` (not a material's debug view)."""
    pass_name, _ = resolve_view(name, renderer.passes)
    capture = capture_frame(renderer, [pass_name] if pass_name else [], warmup=False, time=time)
    return view(capture, name)


def display_image(shown: View, exposure: float = 0.0, channel: int = ALL_CHANNELS
                  ) -> np.ndarray:
    """(H, W, 3) uint8: the view's display image scaled by 2^exposure, or one of its channels
    as grey (its values times 2^exposure, clipped to [0, 1])."""
    scale = 2.0 ** exposure
    if channel == ALL_CHANNELS:
        preview = shown.preview if exposure == 0.0 else shown.preview * scale
        return to_uint8(preview)
    values = shown.pixels[..., min(channel, shown.pixels.shape[-1] - 1)] * scale
    return to_uint8(np.repeat(np.clip(values, 0.0, 1.0)[..., None], 3, axis=2))
