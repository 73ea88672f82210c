"""The cost model of a render: the work it will do, predicted before anything heavy is loaded
or made, as :class:`~deferred.io.cost.Work` terms (a count of units times the seconds a unit
takes on the reference machine) added up by :mod:`deferred.io.cost`.

What it counts (benchmarks/README.md, "The cost model", has the constants' measurements and
the predictions against measured times):

- once a render: making the context and targets, and compiling the programs of each material
  type and effect;
- once a sample (a frame averaged over ``--samples N`` renders each N times): the frame's own
  passes over every pixel, each light over every pixel (the lights without a volume) or a
  share of them (spheres), each shadowed light's maps drawing every object's triangles, each
  effect's passes, each object's material (:meth:`Material.work`: its mesh drawn; fur shells
  over its triangles and the pixels its bounds cover; hair tubes, strokes and hatching), and
  where a frame averages samples, reading each back and adding it up;
- once a frame: writing it;
- once a render again: each simulation stepped from t = 0 to the latest frame
  (:meth:`Simulation.work`).

Before the meshes load (:func:`objects_before_loading`) an object's triangles are what its
file or built-in spec says and its place in the frame is not known, so the terms over its
pixels are left out: that prediction is a lower bound, and a refusal from it is sound. Once
they load (:func:`loaded_objects`) every term is counted.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from deferred.interfaces.work import (
    SURFACE_TRIANGLE_SECONDS,
    Per,
    RenderWork,
    Screen,
    Work,
    WorkObject,
    counted,
)
from deferred.io.cost import Prediction
from deferred.names import LightVolume, ShadowProjection
from deferred.scene.state import FrameState

# seconds of the calibration (benchmarks/cost_model.py calibrate)
SETUP_SECONDS = 0.3  # the context, the targets, the light buffer
# compiling the programs of a material type or an effect (Mesa's shader cache on disk holding
# most of them)
PROGRAM_SECONDS = 0.15
FRAME_PIXEL_SECONDS = 105e-9  # the frame's own passes, a pixel a sample
FULLSCREEN_LIGHT_PIXEL_SECONDS = 7e-9  # an ambient or directional light, a pixel
SPHERE_LIGHT_PIXEL_SECONDS = 1e-9  # a point or spot light, a pixel (its share of the frame)
SHADOW_TEXEL_SECONDS = 2e-9  # clearing and filtering a shadow map, a texel
SAMPLE_PIXEL_SECONDS = 130e-9  # a sample read back, decoded to linear light and added
WRITE_PIXEL_SECONDS = 300e-9  # a frame encoded and written

RENDER_OPTIONS = {Per.SAMPLE: "--samples", Per.FRAME: "--frames"}


def screen_of(obj, camera, size: tuple[int, int]) -> Screen:
    """Where ``obj``'s (an object's frame state) bounding sphere falls in the frame seen by
    ``camera``: the sphere about its mesh's bounds, placed by its world matrix."""
    low, high = (np.asarray(bound, np.float64) for bound in obj.mesh.bounds())
    model = np.asarray(obj.model, np.float64)
    centre = model @ np.append((low + high) / 2.0, 1.0)
    scale = float(np.max(np.linalg.norm(model[:3, :3], axis=0)))
    radius = float(np.linalg.norm(high - low)) / 2.0 * scale
    eye = np.asarray(camera.position, np.float64)
    distance = float(np.linalg.norm(centre[:3] - eye))
    focal = size[1] / 2.0 / math.tan(math.radians(camera.fov) / 2.0)
    return Screen(distance, radius, focal, scale)


def loaded_objects(state: FrameState, size: tuple[int, int]) -> list[WorkObject]:
    """The objects of a loaded scene (its state at the first frame's time) as the cost model
    counts them: their meshes' triangles and where their bounds fall in the frame."""
    objects = []
    for obj in state.objects:
        where = getattr(obj.node, "where", None) or obj.label
        objects.append(WorkObject(obj.material, len(obj.mesh.indices), obj.label, where,
                                  obj.mesh.name, screen_of(obj, state.camera, size)))
    return objects


def _shadow_views(light) -> int:
    projection = light.shadow_projection
    if projection == ShadowProjection.CASCADES:
        return int(getattr(light.params, "cascades", 3))
    return 6 if projection == ShadowProjection.CUBE else 1


def frame_works(job: RenderWork, lights: Sequence, effects: Sequence,
                objects: Sequence[WorkObject], where_size: str) -> list[Work]:
    """The framework's own terms: setup, compiling, the frame's passes, the lights and their
    shadows, the effects, reading samples back and writing frames."""
    pixels = job.pixels
    size = f"{job.size[0]}x{job.size[1]}"
    kinds = {type(obj.material) for obj in objects}
    works = [Work("context and targets", 1, SETUP_SECONDS, where_size, Per.RENDER),
             Work(f"compiling {len(kinds)} material types and {len(effects)} effects",
                  len(kinds) + len(effects) + 1, PROGRAM_SECONDS, where_size, Per.RENDER),
             Work(f"{size}: the frame's passes", pixels, FRAME_PIXEL_SECONDS, where_size)]
    fullscreen = sum(1 for light in lights if light.volume == LightVolume.FULLSCREEN)
    spheres = len(lights) - fullscreen
    if fullscreen:
        works.append(Work(f"{fullscreen} full-screen lights x {size}", fullscreen * pixels,
                          FULLSCREEN_LIGHT_PIXEL_SECONDS, "light", Per.SAMPLE))
    if spheres:
        works.append(Work(f"{spheres:,} point and spot lights x {size}", spheres * pixels,
                          SPHERE_LIGHT_PIXEL_SECONDS, "light", Per.SAMPLE))
    triangles = sum(obj.triangles for obj in objects)
    for index, light in enumerate(light for light in lights if light.casts_shadows):
        views = _shadow_views(light)
        resolution = int(getattr(light.params, "shadow_resolution", 1024))
        works.append(Work(f"shadowed light {index}: {views} maps of {resolution}^2 over "
                          f"{counted(triangles)} triangles", views * triangles,
                          SURFACE_TRIANGLE_SECONDS, "light.shadow_resolution"))
        works.append(Work(f"shadowed light {index}: {views} maps of {resolution}^2",
                          views * resolution ** 2, SHADOW_TEXEL_SECONDS,
                          "light.shadow_resolution"))
    for effect in effects:
        works += effect.work(job)
    if job.samples > 1:
        works.append(Work(f"{size}: each sample read back and added", pixels,
                          SAMPLE_PIXEL_SECONDS, "--samples"))
    works.append(Work(f"{size}: writing each frame", pixels, WRITE_PIXEL_SECONDS, where_size,
                      Per.FRAME))
    return works


def predict_render(job: RenderWork, lights: Sequence, effects: Sequence,
                   objects: Sequence[WorkObject], where_size: str = "--size") -> Prediction:
    """The work of rendering ``job``: the framework's terms (:func:`frame_works`), each
    object's material's (:meth:`Material.work`) and its simulation's
    (:meth:`Simulation.work`)."""
    works = frame_works(job, lights, effects, objects, where_size)
    for obj in objects:
        material = obj.material
        works += material.work(obj, job)
        if material.simulation is not None:
            works += material.simulation.work(obj, job)
    unplaced = any(obj.screen is None for obj in objects)  # before the meshes load
    return Prediction(tuple(works), job.frames, job.samples, lower_bound=unplaced)
