"""Where each shadowed light's maps go in the atlas: its slot (the row of the records
texture) and its squares, packed as a quadtree of power-of-two squares, largest maps first; the
lights over the budget, named for the warning."""

from __future__ import annotations

from deferred.interfaces.light import Light
from deferred.names import ShadowProjection

MAX_TILES = 6  # maps a light at most: a point light's cube faces


def scene_casts_shadows(lights: list[Light]) -> bool:
    return any(light.casts_shadows for light in lights)


class QuadtreeAllocator:
    """Power-of-two squares in a power-of-two atlas: each request takes the smallest free
    square that holds it, split down to its size (largest requests first)."""

    def __init__(self, size: int):
        self.free: list[tuple[int, int, int]] = [(0, 0, size)]

    def take(self, size: int) -> tuple[int, int] | None:
        fitting = [square for square in self.free if square[2] >= size]
        if not fitting:
            return None
        square = min(fitting, key=lambda sq: (sq[2], sq[1], sq[0]))
        self.free.remove(square)
        x, y, s = square
        while s > size:
            s //= 2
            self.free += [(x + s, y, s), (x, y + s, s), (x + s, y + s, s)]
        return x, y


def tile_counts(light: Light) -> int:
    kind = light.shadow_projection
    if kind == ShadowProjection.CASCADES:
        return int(light.params.cascades)
    return MAX_TILES if kind == ShadowProjection.CUBE else 1


def _place_tiles(lights: list[Light], atlas_size: int, sizes: dict[int, int]
                 ) -> tuple[dict[int, list[tuple[int, int, int]]], list[int]]:
    """The squares of each of ``lights`` whose maps all fit, largest maps first, and the
    lights whose maps did not (``id``), the first to run out of room first."""
    requests = sorted(((sizes.get(id(light), light.params.shadow_resolution), order, light)
                       for order, light in enumerate(lights) for _ in range(tile_counts(light))),
                      key=lambda item: (-item[0], item[1]))
    allocator = QuadtreeAllocator(atlas_size)
    tiles: dict[int, list[tuple[int, int, int]]] = {}
    failed: list[int] = []
    for size, _, light in requests:
        if id(light) in failed:
            continue
        place = allocator.take(size) if size <= atlas_size else None
        if place is None:
            failed.append(id(light))
            continue
        tiles.setdefault(id(light), []).append((*place, size))
    return {key: squares for key, squares in tiles.items() if key not in failed}, failed


def plan_atlas(lights: list[Light], atlas_size: int, max_lights: int,
               sizes: dict[int, int] | None = None
               ) -> tuple[dict[int, tuple[int, list[tuple[int, int, int]]]],
                          list[tuple[int, str]]]:
    """Slots and tiles for the shadowed ``lights`` (scene order): ``{id(light): (slot,
    [(x, y, size), ...])}``, and each light left out as (its index, why), for the warning.
    ``sizes`` (``id(light)`` -> side) replaces a light's ``shadow_resolution`` (0: the light
    gets no maps this frame, and is not left out); the squares are packed into the atlas's
    corner square of ``atlas_size``. A light's slot is its place among the first
    ``max_lights`` shadowed lights, whichever others are placed."""
    sizes = sizes or {}
    index_of = {id(light): index for index, light in enumerate(lights)}
    wanted = [light for light in lights if light.casts_shadows]
    left_out = [(index_of[id(light)], f"max_shadowed_lights = {max_lights}")
                for light in wanted[max_lights:]]
    wanted = wanted[:max_lights]
    slot_of = {id(light): slot for slot, light in enumerate(wanted, 1)}
    wanted = [light for light in wanted if sizes.get(id(light)) != 0]
    # Largest maps first packs best; the first light to run out of room is left out and the
    # rest planned again, so the squares it took are not lost to the lights after it.
    failed: set[int] = set()
    while True:
        tiles, missing = _place_tiles([light for light in wanted if id(light) not in failed],
                                      atlas_size, sizes)
        if not missing:
            break
        failed.add(missing[0])
    plan: dict[int, tuple[int, list[tuple[int, int, int]]]] = {}
    for light in wanted:
        if id(light) in failed:
            size = sizes.get(id(light), light.params.shadow_resolution)
            left_out.append((index_of[id(light)],
                             f"{tile_counts(light)} map(s) of {size}^2 "
                             f"each do not fit the {atlas_size}^2 atlas"))
        else:
            plan[id(light)] = (slot_of[id(light)], tiles[id(light)])
    return plan, left_out


SHOWN_LEFT_OUT = 5  # lights a budget warning names for each reason; the rest are counted


def left_out_warning(source: str, left_out: list[tuple[int, str]]) -> str:
    """One short line for the lights left unshadowed: their count, and for each reason the
    first :data:`SHOWN_LEFT_OUT` of them and how many more."""
    by_reason: dict[str, list[int]] = {}
    for index, reason in left_out:
        by_reason.setdefault(reason, []).append(index)
    parts = []
    for reason, indices in sorted(by_reason.items(), key=lambda item: item[1][0]):
        shown = ", ".join(map(str, indices[:SHOWN_LEFT_OUT]))
        more = f" and {len(indices) - SHOWN_LEFT_OUT:,} more" \
            if len(indices) > SHOWN_LEFT_OUT else ""
        parts.append(f"light{'s' * (len(indices) > 1)} {shown}{more} ({reason})")
    count = len(left_out)
    return (f"{source}: {count:,} light{'s' * (count != 1)} unshadowed, over the shadow "
            f"budget: {'; '.join(parts)}")

