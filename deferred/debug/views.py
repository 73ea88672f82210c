"""Buffer views (``deferred render --view``): one buffer of a captured frame (a named view of the
decoded G-buffer, light or composite; a target at the end of the frame; a target after a pass)
as values for EXR and as a display image for PNG, and the catalogue of view names.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from deferred.core.passes import RenderPass
from deferred.debug.capture import (
    GBUFFER_CHANNELS,
    FrameCapture,
    PassCapture,
    channel_suffixes,
    fits_half,
    to_float,
)
from deferred.debug.preview import (
    depth_colors,
    grey,
    heat_colors,
    id_colors,
    normal_colors,
    target_views,
    to_uint8,
    tonemap,
)
from deferred.errors import InputError
from deferred.gbuffer.layout import GBUFFER_COLOR_TARGETS
from deferred.gl.targets import COMPOSITE, LIGHT_ACCUMULATION
from deferred.io.images import srgb_encode, write_image
from deferred.scene.scene import Scene

# Buffer views by name (``deferred render --view``): channels and what they show.
NAMED_VIEWS: dict[str, tuple[tuple[str, ...], str]] = {
    "albedo": (GBUFFER_CHANNELS[0:3], "linear albedo (G-buffer)"),
    "normal": (GBUFFER_CHANNELS[5:8], "view-space normal, decoded (G-buffer)"),
    "depth": (("Z",), "linear view depth, 0 = background (G-buffer)"),
    "specular": (GBUFFER_CHANNELS[3:5], "specular intensity and exponent (G-buffer)"),
    "material": (("material.id",), "material id, 0 = background (G-buffer)"),
    "shading": (("shading.model",), "shading model id, 0 = background (G-buffer)"),
    "light": (("R", "G", "B"), "light accumulation, linear HDR"),
    "composite": (("R", "G", "B", "A"), "composition buffer, linear HDR before tone mapping"),
    "light_lists": (("lights.listed",), "volume lights in the light list each pixel loops over "
                                        "(tiled, clustered, Forward+; a heat map in PNG)"),
    "shadow_atlas": (("shadow.depth",), "the shadow atlas: every shadowed light's maps, depth "
                                        "in [0, 1] (the atlas's size, not the frame's)"),
    "shadow.cascades": (("shadow.cascade",), "the cascade of the first shadowed directional "
                                             "light each pixel reads, 0 = none (PNG: the image "
                                             "tinted a colour per cascade)"),
}
SHADOW_PASS = "shadows"  # the pass drawing the shadow atlas (deferred.lighting.shadows)
LIST_CULLING_PASSES = (".cull_tiles", ".cull_clusters")  # the passes that fill the light lists


@dataclass
class View:
    """One buffer as values (for EXR) and as a display image (for PNG)."""

    name: str
    pixels: np.ndarray  # (H, W, C) float32, top row first
    channels: tuple[str, ...]
    half: bool  # whether half float holds the values exactly
    preview: np.ndarray  # (H, W, 3) float in [0, 1]


def material_views(scene: Scene) -> dict[str, str]:
    """``<material>.<view>`` -> what it shows, for the materials of ``scene``."""
    out = {}
    for obj in scene.objects:
        for name, (doc, _) in obj.material.debug_views.items():
            out[f"{obj.material.name}.{name}"] = f"{doc} (a debug view of the material)"
    return out


def with_material_view(scene: Scene, name: str) -> Scene | None:
    """A copy of ``scene`` whose objects of the material draw debug view ``name``
    (``<material>.<view>``); None when ``name`` is no material's view."""
    material_name, _, view_name = name.partition(".")
    objects = []
    found = False
    for obj in scene.objects:
        material = obj.material
        if material.name == material_name and view_name in material.debug_views:
            overrides = material.debug_views[view_name][1]
            params = type(material.params).model_validate(
                {**material.params.model_dump(), **overrides})
            obj = obj.with_material(type(material)(params, material.base_dir), overrides)
            found = True
        objects.append(obj)
    return replace(scene, objects=objects) if found else None


def check_material_view(scene: Scene, name: str, pipeline: str) -> None:
    """Refuse a material view the scene or pipeline cannot show: ``<fur>.opacity_shadow``
    needs a shadowed light and a pipeline whose shells read the deep opacity maps (forward;
    deferred where the material's caster's ``deferred_opacity`` says so, as both built-in
    furs' does: a plugin's fur whose deferred passes do not read them is refused there)."""
    if not name.endswith(".opacity_shadow"):
        return
    if not any(light.casts_shadows for light in scene.lights):
        raise InputError(f"view '{name}' shows the fur's deep opacity maps; no light of this "
                         "scene casts shadows (shadows = true)", "--view")
    material = name.partition(".")[0]
    if pipeline != "forward" and not any(obj.material.name == material and
                                         obj.material.shadow.deferred_opacity
                                         for obj in scene.objects):
        raise InputError(f"view '{name}' shows the deep opacity maps, which {material}'s "
                         "deferred passes do not read: use --pipeline forward", "--view")


def view_catalogue(passes: Sequence[RenderPass], scene: Scene | None = None
                   ) -> list[tuple[str, str]]:
    """Every ``--view`` name for a pass list (and the scene's material views), with what it
    shows."""
    rows = [(name, f"{doc} [{' '.join(channels)}]") for name, (channels, doc)
            in NAMED_VIEWS.items()]
    rows += list(material_views(scene).items()) if scene is not None else []
    targets = dict.fromkeys(t for p in passes for t in p.writes)
    rows += [(t, "target at the end of the frame") for t in targets if t not in NAMED_VIEWS]
    for p in passes:
        if len(p.writes) == 1:
            rows.append((p.name, f"{p.writes[0]} after this {p.phase.value} pass"))
        elif p.writes:
            rows.append((f"{p.name}:TARGET", f"TARGET after this {p.phase.value} pass: "
                                             f"{', '.join(p.writes)}"))
    return rows


def resolve_view(name: str, passes: Sequence[RenderPass]) -> tuple[str | None, str | None]:
    """``(pass, target)`` a view name needs: (None, None) for a named view, (None, target) for
    a target's end-of-frame contents, (pass, target) for a target after a pass."""
    written = {t for p in passes for t in p.writes}
    if name == "light_lists":
        if not any(p.name.endswith(LIST_CULLING_PASSES) for p in passes):
            raise InputError("view 'light_lists' shows the light lists, which only the tiled and "
                             "clustered light paths have", "--view")
        return None, None
    if name in ("shadow_atlas", "shadow.cascades"):
        if not any(p.name == SHADOW_PASS for p in passes):
            raise InputError(f"view '{name}' shows shadow maps; no light of this scene casts "
                             "shadows (shadows = true)", "--view")
        if name == "shadow.cascades" and "linear_depth" not in written:
            raise InputError("view 'shadow.cascades' reads the linear depth, which this "
                             "pipeline does not write (use the deferred pipeline or forward "
                             "tiled)", "--view")
        return None, None
    if name in NAMED_VIEWS:
        needs = {"light": (LIGHT_ACCUMULATION,), "composite": (COMPOSITE,)}.get(
            name, GBUFFER_COLOR_TARGETS)
        missing = [t for t in needs if t not in written]
        if missing:
            raise InputError(f"view '{name}' shows {', '.join(missing)}, which no pass of this "
                             "pipeline writes", "--view")
        return None, None
    by_name = {p.name: p for p in passes}
    if name in written:
        return None, name
    pass_name, _, target = name.partition(":")
    render_pass = by_name.get(pass_name)
    if render_pass is None:
        raise InputError(f"unknown view '{name}' (see --view help)", "--view")
    if not target:
        if len(render_pass.writes) != 1:
            choices = ", ".join(f"{pass_name}:{t}" for t in render_pass.writes)
            raise InputError(f"pass '{pass_name}' writes {len(render_pass.writes)} targets; "
                             f"choose one of {choices}", "--view")
        target = render_pass.writes[0]
    if target not in render_pass.writes:
        raise InputError(f"pass '{pass_name}' does not write '{target}' (it writes "
                         f"{', '.join(render_pass.writes)})", "--view")
    return pass_name, target


def view(capture: FrameCapture, name: str) -> View:
    """The buffer ``--view name`` shows, from a capture that kept the pass it needs."""
    pass_name, target = resolve_view(name, [_Described(p) for p in capture.passes])
    if target is None:
        return _named_view(capture, name)
    if pass_name is None:
        raw = capture.targets[target]
    else:
        if target not in capture[pass_name].raw:
            raise KeyError(f"pass {pass_name} was not captured")
        raw = capture[pass_name].raw[target]
    spec = capture.specs[target]
    pixels = to_float(raw)
    _, preview = target_views(target, pixels, spec, capture.tonemap, capture.exposure)[0]
    suffixes = channel_suffixes(spec)
    return View(name, pixels, tuple(f"{target}.{s}" for s in suffixes),
                fits_half([spec]), preview)


def _named_view(capture: FrameCapture, name: str) -> View:
    channels, _ = NAMED_VIEWS[name]
    if name == "light_lists":
        if capture.light_lists is None:
            raise KeyError("the frame was captured without light lists")
        counts = capture.light_lists
        return View(name, counts[..., None], channels, bool(counts.max(initial=0.0) <= 2048.0),
                    heat_colors(counts))
    if name == "shadow_atlas":
        if capture.shadow_atlas is None:
            raise KeyError("the frame was captured without a shadow atlas")
        depth = capture.shadow_atlas
        # stretched over the depths drawn (what is cleared, 1, stays white)
        drawn = depth[depth < 1.0]
        low, high = (float(drawn.min()), float(drawn.max())) if drawn.size else (0.0, 1.0)
        stretched = np.where(depth < 1.0, (depth - low) / max(high - low, 1e-6) * 0.9, 1.0)
        return View(name, depth[..., None], channels, False, grey(stretched))
    if name == "shadow.cascades":
        if capture.shadow_cascades is None:
            raise InputError("view 'shadow.cascades' shows a directional light's cascades; no "
                             "directional light of this scene casts shadows", "--view")
        cascades = capture.shadow_cascades
        shade = capture.image[..., :3].astype(np.float32).mean(-1, keepdims=True) / 255.0
        tint = np.where((cascades > 0)[..., None], id_colors(cascades), 1.0)
        return View(name, cascades[..., None], channels, True,
                    (tint * (0.35 + 0.65 * shade)).astype(np.float32))
    if name in ("light", "composite"):
        source = LIGHT_ACCUMULATION if name == "light" else COMPOSITE
        pixels = capture.target(source)[..., : len(channels)]
        return View(name, pixels, channels, True,
                    tonemap(pixels, capture.tonemap, capture.exposure))
    g = capture.gbuffer()
    pixels = np.stack([g[c] for c in channels], axis=-1)
    covered = g["material.id"] > 0.0
    if name == "albedo":
        preview = srgb_encode(pixels).astype(np.float32)
    elif name == "normal":
        preview = normal_colors(pixels, covered)
    elif name == "depth":
        preview = depth_colors(pixels[..., 0], covered)
    elif name == "specular":
        preview = grey(pixels[..., 0])
    else:  # material, shading: categorical ids
        preview = id_colors(pixels[..., 0])
    return View(name, pixels, channels, name in ("albedo", "material", "shading"), preview)


class _Described:
    """A captured pass seen through the RenderPass fields :func:`resolve_view` reads."""

    def __init__(self, capture: PassCapture):
        self.name = capture.name
        self.writes = capture.writes


def write_view(path: Path, result: View) -> None:
    """EXR: the values with named channels; PNG: the display image."""
    if path.suffix.lower() == ".exr":
        write_image(path, result.pixels, channels=result.channels, half=result.half)
    else:
        write_image(path, to_uint8(result.preview))
