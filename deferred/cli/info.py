"""``deferred info``: the GL context, its optional features, the registered types and a scene's
G-buffer layout."""

from __future__ import annotations

from pathlib import Path

import click
from rich.console import Console

from deferred.cli.options import scene_argument
from deferred.cli.scene_report import scene_lines
from deferred.interfaces import registry
from deferred.scene.gltf import GLTF_SUFFIXES
from deferred.scene.gltf.summary import describe_file
from deferred.scene.loader import load_scene


@click.command()
@scene_argument
def info(scene: str | None) -> None:
    """GL vendor, renderer, version, the optional features in use, and the G-buffer layout of
    SCENE (the built-in demo when omitted); its meshes (vertices, triangles, the materials
    found and dropped), textures (size, memory), lights, shadow maps and the memory budget
    used; of a glTF file, its nodes, meshes, materials, textures, animations, cameras, lights
    and skins, and what the framework does not draw."""
    from deferred.gl.context import create_context

    gltf = None
    if scene is not None and Path(scene).suffix.lower() in GLTF_SUFFIXES:
        gltf = describe_file(Path(scene))  # the file's parts, what is not drawn
    loaded = load_scene(scene)
    layout = loaded.gbuffer_layout()  # bad input fails before GL start-up
    gl = create_context()
    try:
        console = Console(soft_wrap=True, markup=False)  # one line per entry; [..] is text
        for line in gltf or ():
            console.print(line)
        console.print(f"gbuffer: {layout.bytes_per_pixel} bytes per pixel")
        for name, entry in layout.describe().items():
            channels = f"  [{' '.join(entry['channels'])}]" if "channels" in entry else ""
            console.print(f"  {name:<20} {entry['format']:<8} {entry['bytes_per_pixel']:>2} B  "
                          f"{entry['description']}{channels}")
        for model in loaded.shading_models():
            if model.gbuffer_budget is not None:
                console.print(f"  shading model {model.name}: at most {model.gbuffer_budget} "
                              "bytes per pixel (its budget)")
        for line in scene_lines(loaded):
            console.print(line)
        for key, value in gl.info.items():
            console.print(f"{key:>16}: {value}")
        for key, value in gl.features.names().items():
            console.print(f"{key:>16}: {'on' if value else 'off'}")
        for what, reg in (("lights", registry.lights), ("materials", registry.materials),
                          ("shading models", registry.shading_models),
                          ("effects", registry.effects)):
            console.print(f"{what:>16}: {', '.join(reg)}")
    finally:
        gl.release()
