"""A frame averaged over sub-pixel samples (``deferred render --samples N``): each sample moved
by an offset of the Halton (2, 3) sequence, the images averaged in linear light; and the check
of a frame's jitter (:func:`check_jitter`)."""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from typing import Any, Protocol

import numpy as np

from deferred.errors import InputError
from deferred.interfaces.effect import halton
from deferred.io.images import srgb_decode, srgb_encode
from deferred.io.memory import check_memory
from deferred.render.result import RenderResult


class SampledRenderer(Protocol):
    """What :func:`render_samples` asks of a renderer (:class:`deferred.render.renderer.
    Renderer`)."""

    temporal: Any
    size: tuple[int, int]

    def render(self, **options: Any) -> RenderResult: ...

    def memory_bytes(self) -> int: ...


MAX_SAMPLES = 1024  # sub-pixel samples a frame
# Bytes a pixel the average holds besides the renderer: the image decoded to linear light and
# the composite, summed in float64, each sample's own read back and decoded (213 measured: the
# peak RSS of --samples 4 against one sample at 1024x1024)
SAMPLES_BYTES_PER_PIXEL = 224

__all__ = ["MAX_JITTER", "MAX_SAMPLES", "check_jitter", "check_samples_memory", "halton",
           "halton_offsets", "render_samples"]


MAX_JITTER = 1.0  # pixels: a jitter moves the image by a sub-pixel offset (ours: +-0.5)


def check_jitter(jitter: object) -> tuple[float, float] | None:
    """``render(jitter=...)`` checked: None, or (x, y) finite and within +-MAX_JITTER."""
    if jitter is None:
        return None
    shaped = isinstance(jitter, Sequence | np.ndarray) and not isinstance(jitter, str | bytes) \
        and len(jitter) == 2
    values = list(jitter) if shaped else []
    if not shaped or not all(isinstance(v, numbers.Real) and not isinstance(v, bool | np.bool_)
                             and math.isfinite(v) and abs(v) <= MAX_JITTER for v in values):
        shown = repr(jitter)
        shown = shown if len(shown) <= 60 else f"{shown[:57]}..."
        raise InputError(f"a jitter is a sub-pixel offset (x, y) of finite numbers within "
                         f"+-{MAX_JITTER:g} pixel, got {shown}", "jitter")
    return float(values[0]), float(values[1])


def check_samples_memory(size: tuple[int, int], samples: int, renderer_bytes: int = 0) -> None:
    """Refuse (naming ``samples``) an average of ``samples`` frames of ``size`` whose arrays,
    with the renderer's ``renderer_bytes``, pass the memory budget (one sample holds none)."""
    if samples > 1:
        width, height = size
        check_memory(renderer_bytes + width * height * SAMPLES_BYTES_PER_PIXEL,
                     f"averaging {samples} samples of {width}x{height}"
                     f"{' with the renderer' if renderer_bytes else ''} needs {{}}", "samples",
                     "fewer pixels")


def halton_offsets(count: int) -> list[tuple[float, float]]:
    """``count`` sub-pixel offsets in [-0.5, 0.5)^2: Halton (2, 3) from index 1, centred."""
    return [(halton(k, 2) - 0.5, halton(k, 3) - 0.5) for k in range(1, count + 1)]


def render_samples(renderer: SampledRenderer, samples: int, time: float = 0.0,
                   on_sample: Callable[[int], None] | None = None) -> RenderResult:
    """:meth:`Renderer.render_samples`: the frame at ``time`` averaged over ``samples``
    renders; the image averaged in linear light (its sRGB decoded, then encoded again) and the
    float composite averaged, converging to a supersampled frame (a box filter over the
    pixel). One sample is a plain render. ``on_sample(done)`` is called after each sample
    (progress)."""
    if isinstance(samples, bool) or not isinstance(samples, numbers.Integral) or \
            not 1 <= samples <= MAX_SAMPLES:
        raise InputError(f"must be a whole number 1..{MAX_SAMPLES}, got {samples!r}",
                         "samples")
    check_samples_memory(renderer.size, samples, renderer.memory_bytes())
    if samples == 1:
        result = renderer.render(time=time, hdr=True)
        if on_sample is not None:
            on_sample(1)
        return result
    light = composite = None
    for index, jitter in enumerate(halton_offsets(samples)):
        # each sample its own parity of the stipple pattern (sample_index), which the
        # average integrates (Revie's 1-in-4 pattern covers every pixel over four)
        # each sample alone: a temporal effect's history would average the samples twice
        renderer.temporal.reset()
        result = renderer.render(time=time, hdr=True, jitter=jitter, sample_index=index)
        decoded = srgb_decode(result.image.astype(np.float64) / 255.0)
        light = decoded if light is None else light + decoded
        composite = result.hdr.astype(np.float64) if composite is None \
            else composite + result.hdr
        if on_sample is not None:
            on_sample(index + 1)
    image = np.clip(np.rint(srgb_encode(light / samples) * 255.0), 0, 255).astype(np.uint8)
    return RenderResult(image, result.draw_calls * samples,
                        {name: count * samples for name, count in result.draws_by_pass.items()},
                        _hdr=(composite / samples).astype(np.float32))
