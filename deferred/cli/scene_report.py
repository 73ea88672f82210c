"""What ``deferred info SCENE`` says of the scene itself, as lines: each object's mesh (vertices,
triangles, the materials its file names and which of them draw), the textures and other state
the materials hold (size, memory), the lights, the shadow maps and the memory budget used, all
from the loaded scene and its renderer's plan, before any GL object is made: where a frame's
time and memory go."""

from __future__ import annotations

import re
from pathlib import Path

from deferred.errors import InputError
from deferred.gl.target_spec import targets_bytes
from deferred.io.images import amount, check_image
from deferred.io.memory import BUDGET_VARIABLE, memory_budget
from deferred.lighting.shadows.coverage import fit_sizes
from deferred.lighting.shadows.plan import plan_atlas, tile_counts
from deferred.names import ShadowAllocation
from deferred.render.budget import renderer_holdings
from deferred.render.setup import SetupPlan
from deferred.scene.scene import Scene
from deferred.scene.state import FrameState
from deferred.scene.timeline import SceneEvaluator

_TEXTURE_KEY = re.compile(r"^texture (.+?\.(?:png|jpe?g|exr|hdr|tga|bmp|tiff?|webp))\b", re.I)
_USEMTL = re.compile(rb"^\s*usemtl\s+(\S+)", re.M)
SHOWN = 5  # the first few of a long list, then how many more


def _few(names: list[str]) -> str:
    more = len(names) - SHOWN
    return ", ".join(names[:SHOWN]) + (f" and {more} more" if more > 0 else "")


def _file_materials(source: Path) -> list[str]:
    """The materials an OBJ file assigns (``usemtl``), in order of first use; other formats
    that trimesh reads carry none the framework could take."""
    if source.suffix.lower() != ".obj" or not source.is_file():
        return []
    return list(dict.fromkeys(m.decode(errors="replace")
                              for m in _USEMTL.findall(source.read_bytes())))


def mesh_lines(state: FrameState) -> list[str]:
    """One line an object: its mesh, vertices and triangles, the material drawing it, and the
    materials its file names that do not draw (an OBJ's ``usemtl``: the object's material
    draws the whole mesh)."""
    lines = [f"objects: {len(state.objects)}, "
             f"{sum(o.mesh.vertex_count for o in state.objects):,} vertices, "
             f"{sum(len(o.mesh.indices) for o in state.objects):,} triangles"]
    for obj in state.objects:
        mesh = obj.mesh
        line = (f"  {obj.label:<16} {mesh.name}: {mesh.vertex_count:,} vertices, "
                f"{len(mesh.indices):,} triangles, material {obj.material.name}")
        if mesh.generated_uvs:
            line += ", UVs unwrapped"
        named = [m for source in mesh.sources[:1] for m in _file_materials(Path(source))]
        if named:
            line += (f"; the file's materials {_few(named)} dropped (the object's "
                     f"{obj.material.name} draws the whole mesh)")
        lines.append(line)
    return lines


def _texture_size(key: str) -> str:
    match = _TEXTURE_KEY.match(key)
    if match is None:
        return ""
    try:
        width, height, _ = check_image(match.group(1))
    except InputError:
        return ""
    return f"{width}x{height}, "


def held_lines(held: dict[str, int]) -> list[str]:
    """The textures and state the materials, shadows and effects hold, largest first."""
    if not held:
        return ["held: nothing besides the render targets (no textures, no shadow maps)"]
    lines = [f"held: {amount(sum(held.values()))} in {len(held)} part"
             f"{'s' if len(held) != 1 else ''} (textures, simulation state, shadow maps, "
             "effect histories)"]
    for key, size in sorted(held.items(), key=lambda item: -item[1]):
        lines.append(f"  {key}: {_texture_size(key)}{amount(size)}")
    return lines


def light_lines(state: FrameState) -> list[str]:
    """The lights, and the shadow atlas: which lights cast shadows, with how many tiles of
    what size, and which are left out (over the budget) and why."""
    lights = list(state.lights)
    lines = [f"scene lights: {len(lights)}"]
    for index, light in enumerate(lights[:20]):
        shadow = " (casts shadows)" if light.casts_shadows else ""
        lines.append(f"  light[{index}] {light.name}{shadow}")
    if len(lights) > 20:
        lines.append(f"  and {len(lights) - 20:,} more")
    shadowed = [light for light in lights if light.casts_shadows]
    if not shadowed:
        lines.append("shadow maps: none (no light has shadows = true)")
        return lines
    budget = state.shadow_budget
    sizes = None
    if budget.allocation == ShadowAllocation.COVERAGE:  # as if each light covered the view
        sizes = fit_sizes([(id(light), tile_counts(light), light.params.shadow_resolution, 1.0)
                           for light in shadowed[:budget.max_shadowed_lights]],
                          budget.atlas_size)
    placed, left_out = plan_atlas(lights, budget.atlas_size, budget.max_shadowed_lights, sizes)
    lines.append(f"shadow maps: {len(placed)} of {len(shadowed)} shadowed lights in an atlas of "
                 f"{budget.atlas_size}x{budget.atlas_size} (max_shadowed_lights = "
                 f"{budget.max_shadowed_lights})")
    if budget.allocation == ShadowAllocation.COVERAGE:
        lines.append("  allocation = coverage: each frame's spot and point maps at most these "
                     "(every light covering the view), by the screen each covers")
    index_of = {id(light): index for index, light in enumerate(lights)}
    for light in shadowed[:20]:
        if id(light) in placed:
            slot, tiles = placed[id(light)]
            sizes = sorted({size for _, _, size in tiles}, reverse=True)
            lines.append(f"  light[{index_of[id(light)]}] {light.name}: {len(tiles)} tile"
                         f"{'s' if len(tiles) != 1 else ''} of "
                         f"{', '.join(f'{s}x{s}' for s in sizes)}")
    if left_out:
        reasons = [f"light[{index}] ({why})" for index, why in left_out]
        lines.append(f"  unshadowed: {_few(reasons)}")
    return lines


def memory_lines(state: FrameState, pipeline: str, size: tuple[int, int]) -> list[str]:
    """The memory budget used by a renderer of the scene: its targets at ``size`` and what it
    holds besides, against the budget."""
    plan = SetupPlan(state, pipeline, state.light_path, size, "--size")
    targets = targets_bytes(plan.graph.targets.values(), *size)
    held = sum(renderer_holdings(state, pipeline, size).values())
    budget = memory_budget()
    used = targets + held
    return [f"memory ({pipeline}, {size[0]}x{size[1]}): {amount(used)} of the budget of "
            f"{amount(budget)} ({100.0 * used / budget:.1f}%, {BUDGET_VARIABLE}): "
            f"{len(plan.graph.targets)} render targets {amount(targets)}, held {amount(held)}"]


def scene_lines(scene: Scene, pipeline: str = "deferred") -> list[str]:
    """Everything above for ``scene`` at its first frame (t = 0) and its own size."""
    state = SceneEvaluator(scene).evaluate(0.0)
    return [f"scene: {scene.source}, {scene.size[0]}x{scene.size[1]}",
            *mesh_lines(state), *held_lines(renderer_holdings(state, pipeline, scene.size)),
            *light_lines(state), *memory_lines(state, pipeline, scene.size)]
