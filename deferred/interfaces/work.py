"""What the cost model asks of materials, simulations and effects: the work they will do for a
render, counted from their parameters and their object's mesh before anything is made
(:mod:`deferred.io.cost` adds it up against the time budget; ``deferred.render.cost`` asks).

A material's :meth:`~deferred.interfaces.material.Material.work` (its simulation's and an
effect's likewise) is given a :class:`WorkObject`, the object as far as it is known (its
triangles, where its bounds fall in the frame once its mesh is loaded), and the
:class:`RenderWork` asked for (frame size, samples, frames, the latest time), and returns
:class:`~deferred.io.cost.Work` terms: a count of units times the seconds a unit takes on the
reference machine. The seconds below are the framework's, measured on llvmpipe with 2 cores
(``benchmarks/cost_model.py calibrate``; benchmarks/README.md, "The cost model").
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from deferred.io.cost import Per, Work

# seconds a triangle of a surface takes a sample: its G-buffer (or forward) pass and its
# shadow or depth pre-pass, vertex work and binning on llvmpipe
SURFACE_TRIANGLE_SECONDS = 100e-9
# seconds a pixel of a screen effect's passes (ssao and its blur, edges, fxaa) takes a sample
EFFECT_PIXEL_SECONDS = 400e-9

__all__ = ["EFFECT_PIXEL_SECONDS", "SURFACE_TRIANGLE_SECONDS", "Per", "RenderWork", "Screen",
           "Work", "WorkObject", "counted"]


def counted(number: float) -> str:
    """``20,000``, ``4.2M``, ``1.3G``: a count in a short line."""
    if number >= 1e9:
        return f"{number / 1e9:.1f}G"
    if number >= 1e6:
        return f"{number / 1e6:.1f}M"
    return f"{round(number):,}"


@dataclass(frozen=True)
class RenderWork:
    """What a render asks for, as the cost model counts it: the frame size, the samples a
    frame averages, the frames, the latest frame time (simulations step from 0 to it; a
    refusal of it names ``time_key``) and the pipeline."""

    size: tuple[int, int]
    samples: int = 1
    frames: int = 1
    latest_time: float = 0.0
    pipeline: str = "deferred"
    time_key: str = "time"

    @property
    def pixels(self) -> int:
        return self.size[0] * self.size[1]


@dataclass(frozen=True)
class Screen:
    """Where an object's bounding sphere falls in the frame: its centre's distance from the
    camera, its radius (world units), the frame's pixels per unit at distance 1 (the camera's
    focal length in pixels) and the object's scale (world units an object unit)."""

    distance: float
    radius: float
    focal_pixels: float
    scale: float = 1.0

    def pixels_across(self, length: float) -> float:
        """How many pixels ``length`` object units span where the object comes nearest the
        camera (as fur's level of detail counts its thickness)."""
        nearest = max(self.distance - self.radius, 1e-3 * self.radius, 1e-9)
        return length * self.scale * self.focal_pixels / nearest

    def share(self, size: tuple[int, int], reach: float = 0.0) -> float:
        """The share of the frame the sphere grown by ``reach`` covers (1 with the camera
        inside it), as its disc's area over the frame's."""
        radius = self.radius + max(reach, 0.0)
        if self.distance <= radius:
            return 1.0
        on_screen = self.focal_pixels * radius / math.sqrt(self.distance ** 2 - radius ** 2)
        return min(1.0, math.pi * on_screen ** 2 / (size[0] * size[1]))


@dataclass(frozen=True)
class WorkObject:
    """An object as the cost model sees it: its material (``material.params``), its mesh's
    triangles (before the mesh is loaded, the count its file or built-in spec gives, or 0 where
    neither says), its label, where the scene file sets it (``s.toml: object[1]``), its mesh's
    name and where its bounds fall in the frame (None before its mesh is loaded: the work over
    its pixels is not counted then)."""

    material: Any  # a Material
    triangles: int
    label: str
    where: str
    mesh: str = ""  # the mesh's name, or its spec before it loads (builtin:head?rings=24)
    screen: Screen | None = None

    def key(self, parameter: str) -> str:
        """Where the scene file sets ``parameter`` of the material."""
        return f"{self.where}.params.{parameter}"

    def covered_pixels(self, job: RenderWork, reach: float = 0.0) -> float | None:
        """The pixels the object covers, its bounds grown by ``reach`` (fur): None where not
        known yet."""
        if self.screen is None:
            return None
        return self.screen.share(job.size, reach) * job.pixels

    def surface_work(self, passes: float = 1.0, what: str = "") -> Work:
        """The mesh drawn ``passes`` times a sample."""
        label = what or f"{self.label}: {counted(self.triangles)} triangles"
        return Work(label, self.triangles * passes, SURFACE_TRIANGLE_SECONDS,
                    f"{self.where}.mesh", Per.SAMPLE)
