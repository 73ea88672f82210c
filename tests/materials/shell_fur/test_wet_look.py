"""Wet fur that looks wet (shell_fur, materials/shell_fur/wet.glsl): darker, with a stronger and
narrower highlight; and droplets of an event soak in over soak_time instead of in one frame."""

from pathlib import Path

import numpy as np
import pytest
from locations import ROOT

from deferred.io.images import write_image
from deferred.scene.loader import scene_from_dict

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

LIGHTS = [{"type": "ambient", "color": [0.05, 0.05, 0.06]},
          {"type": "directional", "direction": [-0.3, -0.2, -1.0], "intensity": 1.5}]


def wet_mask(path: Path, wetness: float) -> Path:
    """A mask wet all over: one clump of radius 1 (UV units) centred mid-square."""
    image = np.zeros((8, 8, 4), np.float32)
    image[...] = (0.5, 0.5, 1.0, wetness)
    write_image(path, image, channels=["R", "G", "B", "A"])
    return path


def ball(mask: Path, shading="kajiya_kay", specular=0.3, size=(160, 120)):
    return scene_from_dict({
        "size": list(size), "background": [0.0, 0.0, 0.0], "tonemap": "none",
        "camera": {"position": [0.0, 0.0, 3.6], "target": [0.0, 0.0, 0.0], "fov": 40.0},
        "object": [{"name": "ball", "mesh": "builtin:sphere", "material": "shell_fur",
                    "params": {"wetness_mask": str(mask), "clump_strength": 0.0,
                               "fur_length": 0.15, "shells": 12, "settle": 0.0,
                               "color": [0.6, 0.42, 0.25], "specular_intensity": specular,
                               "shading": shading}}],
        "light": LIGHTS})


def highlight(image: np.ndarray) -> tuple[float, float]:
    """(peak, area in pixels above half the peak) of a specular-only image's luminance."""
    luminance = image[..., :3] @ np.array([0.2126, 0.7152, 0.0722])
    peak = float(np.percentile(luminance, 99.9))
    return peak, float((luminance > 0.5 * peak).sum())


@pytest.mark.slow
@pytest.mark.parametrize("shading", ["kajiya_kay", "marschner"])
@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
def test_wet_fur_is_darker_with_a_sharper_stronger_highlight(render, tmp_path, pipeline,
                                                             shading):
    looks = {}
    for name, wetness in (("dry", 0.0), ("wet", 1.0)):
        mask = wet_mask(tmp_path / f"{name}.exr", wetness)
        lit, _ = render(ball(mask, shading), pipeline)
        matte, _ = render(ball(mask, shading, specular=0.0), pipeline)
        covered = matte.hdr[..., :3].max(-1) > 1e-4
        diffuse = float((matte.hdr[..., :3] @ np.array([0.2126, 0.7152, 0.0722]))[covered].mean())
        looks[name] = (diffuse, *highlight(np.maximum(lit.hdr - matte.hdr, 0.0)))
    (dry, dry_peak, dry_area), (wet, wet_peak, wet_area) = looks["dry"], looks["wet"]
    print(f"{pipeline} {shading}: mean {dry:.4f} -> {wet:.4f}, highlight peak "
          f"{dry_peak:.4f} -> {wet_peak:.4f}, area {dry_area:.0f} -> {wet_area:.0f} px")
    assert wet < 0.8 * dry  # darker
    assert wet_peak > 1.2 * dry_peak  # stronger
    assert wet_area < 0.8 * dry_area  # narrower


def frame_differences(render, scene, times):
    """Mean absolute differences of consecutive frames (8-bit levels), one renderer stepping
    its simulation forward."""
    result, renderer = render(scene, time=times[0])
    frames = [result.image[..., :3].astype(np.float64)]
    for time in times[1:]:
        frames.append(renderer.render(time=time).image[..., :3].astype(np.float64))
    return [float(np.abs(b - a).mean()) for a, b in zip(frames, frames[1:], strict=False)]


@pytest.mark.slow
def test_wetting_ramps_in_over_soak_time(render):
    """examples/shell_fur/wet_wind.toml at 12 frames a second: the droplets of t = 1 s change
    the image over soak_time (no frame holds more than half of the change), and the largest
    frame difference while they soak in is no more than twice the wind's (from t = 2 s)."""
    path = ROOT / "examples" / "shell_fur" / "wet_wind.toml"
    scene = scene_from_dict({**tomllib.loads(path.read_text()), "size": [160, 120]}, str(path),
                            base_dir=path.parent)
    wetting = frame_differences(render, scene, [k / 12.0 for k in range(11, 20)])
    wind = frame_differences(render, scene, [2.0 + k / 12.0 for k in range(1, 9)])
    print(f"wetting frame differences {np.round(wetting, 2)}, wind {np.round(wind, 2)}")
    assert max(wetting) <= 0.5 * sum(wetting)
    assert max(wetting) <= 2.0 * max(wind)

