"""What a renderer will hold, counted against the memory budget before anything is made: the
pass graph's render targets, the materials' textures and state, the shadow atlas and deep
opacity maps, the effects' histories."""

from __future__ import annotations

from deferred.core.graph import PassGraph
from deferred.gl.target_spec import targets_bytes
from deferred.io.images import amount
from deferred.io.memory import check_memory
from deferred.lighting.shadows.atlas import atlas_memory
from deferred.lighting.shadows.opacity import opacity_extent, opacity_size
from deferred.lighting.shadows.plan import scene_casts_shadows
from deferred.lighting.shadows.transmittance import scene_has_transparent_casters
from deferred.scene.state import FrameState


def check_target_memory(graph: PassGraph, size: tuple[int, int], where: str = "size",
                        held: dict[str, int] | None = None, held_where: str = "scene") -> None:
    """Refuse a frame size whose render targets need more than the memory budget (naming
    ``where``), then a scene whose materials will hold more (``held``:
    :meth:`~deferred.interfaces.material.Material.held_memory`) than what the targets leave
    (naming ``held_where`` and the largest of what they hold)."""
    targets = targets_bytes(graph.targets.values(), *size)
    check_memory(targets, f"{size[0]}x{size[1]} needs {{}} of render targets "
                          f"({len(graph.targets)} targets)", where)
    if held:
        largest = max(held, key=held.__getitem__)
        check_memory(targets + sum(held.values()),
                     f"the materials' textures and state ({len(held)}, the largest "
                     f"{largest}: {amount(held[largest])}) and the render targets at "
                     f"{size[0]}x{size[1]} need {{}}", held_where)


# What a renderer holds that neither its targets nor its materials count: its compiled programs
# and the driver's state for them, its buffers of lights and lists. Measured as the growth of
# RSS for each renderer kept alive at 64x64 (benchmarks/README.md, "The cost model"): 6-45 MB
# on lights.toml (standard surfaces), 38-85 MB on the demo (fur and ssao).
RENDERER_BYTES = 24 << 20
MATERIAL_TYPE_BYTES = 16 << 20  # each material type's programs


def renderer_overhead(scene: FrameState) -> int:
    """Bytes a renderer of ``scene`` holds besides its targets and what its materials,
    shadows and effects say they hold: :data:`RENDERER_BYTES` and
    :data:`MATERIAL_TYPE_BYTES` for each material type."""
    kinds = {type(obj.material) for obj in scene.objects}
    return RENDERER_BYTES + MATERIAL_TYPE_BYTES * len(kinds)


def held_memory(scene: FrameState) -> dict[str, int]:
    """What every object's material will hold, by what it is (a shared texture once): the
    textures it loads and its simulation's state."""
    held: dict[str, int] = {}
    for obj in scene.objects:
        held.update(obj.material.held_memory(obj))
        if obj.material.simulation is not None:
            held.update(obj.material.simulation.held_memory(obj))
    return held


def renderer_holdings(scene: FrameState, pipeline: str, size: tuple[int, int]) -> dict[str, int]:
    """What a renderer of ``scene`` holds besides its pass graph's targets: the materials'
    textures and state, what their scene-wide passes hold for a frame of ``size``
    (``Material.frame_memory``), the shadow atlas and opacity maps, the effects' histories."""
    held = held_memory(scene)
    by_class: dict[type, list] = {}
    for obj in scene.objects:
        by_class.setdefault(type(obj.material), []).append(obj)
    for cls, objects in by_class.items():
        held.update(cls.frame_memory(objects, size))
    if scene_casts_shadows(scene.lights):
        transparent = opacity_extent(scene) if scene_has_transparent_casters(scene) else 0
        held.update(atlas_memory(scene.shadow_budget, opacity_size(scene, pipeline),
                                 transparent))
    for effect in scene.effects:
        held.update(effect.held_memory(size))
    return held
