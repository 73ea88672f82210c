"""What ``deferred info model.glb`` says of a glTF file: its nodes, meshes, materials,
textures, animations, cameras, lights and skins, and what of it the framework does not draw."""

from __future__ import annotations

from pathlib import Path

from deferred.scene.gltf.asset import GltfAsset

MAX_LISTED = 20  # entries listed of each kind; the rest counted


def _listed(title: str, items: list[str]) -> list[str]:
    lines = [f"{title}: {len(items)}"]
    lines += [f"  {item}" for item in items[:MAX_LISTED]]
    if len(items) > MAX_LISTED:
        lines.append(f"  ... ({len(items) - MAX_LISTED} more)")
    return lines


def describe(asset: GltfAsset) -> list[str]:
    """One line an entry (see the module documentation)."""
    lines = [f"glTF: {asset.name} (glTF {asset.document.raw['asset'].get('version')}, "
             f"generator {str(asset.document.raw['asset'].get('generator', '?'))[:60]})"]
    lines += _listed("nodes", _nodes(asset))
    lines += _listed("meshes", [
        f"meshes[{index}]: {len(primitives)} primitive(s), "
        f"{sum(p.mesh.vertex_count for p in primitives):,} vertices, "
        f"{sum(len(p.mesh.indices) for p in primitives):,} triangles"
        + (", skinned" if any(p.mesh.joints is not None for p in primitives) else "")
        for index, primitives in sorted(asset.meshes.items())])
    lines += _listed("materials", [_material(asset, index)
                                   for index in range(len(asset.materials))])
    lines += _listed("textures", [f"images[{index}]: {image.name or image.uri or '(embedded)'}"
                                  [:100] for index, image in
                                  enumerate(asset.document.gltf.images or [])])
    lines += _listed("animations", [
        f"[{a.index}] {a.name}: {sum(len(c) for c in a.curves.values())} channel(s) on "
        f"{len(a.curves)} node(s), {a.duration:g} s, "
        f"{'/'.join(sorted({c.interpolation for n in a.curves.values() for c in n.values()}))}"
        for a in asset.animations])
    lines += _listed("cameras", [f"{c.name}: {c.kind}, fov {c.fov:.1f} deg, near {c.near:g}, "
                                 f"far {'infinite' if c.far is None else f'{c.far:g}'}"
                                 for c in asset.cameras])
    lines += _listed("lights", [f"{light.name}: {light.kind}, intensity {light.intensity:g}, "
                                f"colour {tuple(round(c, 3) for c in light.color)}"
                                for light in asset.lights])
    lines += _listed("skins", [f"{skin.name}: {len(skin.joints)} joints"
                               for skin in asset.skins])
    lines += _listed("not supported", unsupported(asset))
    return lines


def _nodes(asset: GltfAsset) -> list[str]:
    depth: dict[int, int] = {}
    out = []
    for index in asset.subtree():
        parent = asset.parents.get(index)
        depth[index] = 0 if parent is None else depth[parent] + 1
        node = asset.nodes[index]
        carries = [f"{key} {value}" for key, value in (("mesh", node.mesh),
                                                       ("camera", node.camera),
                                                       ("light", node.light),
                                                       ("skin", node.skin)) if value is not None]
        named = f" {node.name[:60]}" if node.name else ""
        out.append(f"{'  ' * min(depth[index], 8)}nodes[{index}]{named}"
                   f"{' (' + ', '.join(carries) + ')' if carries else ''}")
    return out


def _material(asset: GltfAsset, index: int) -> str:
    material = asset.materials[index]
    values = material.values
    textures = [key.removesuffix("_texture") for key in values if key.endswith("_texture")]
    return (f"materials[{index}] {material.name}: base colour "
            f"{tuple(round(c, 3) for c in values['base_color'])}, metallic "
            f"{values['metallic']:g}, roughness {values['roughness']:g}, "
            f"{values['alpha_mode']}"
            + (", double-sided" if values["double_sided"] else "")
            + (f", textures: {', '.join(textures)}" if textures else ""))


def unsupported(asset: GltfAsset) -> list[str]:
    """What the file has that the framework does not draw."""
    out = [f"extension {name} (used, not implemented)" for name in asset.document.unsupported]
    morphs = [f"meshes[{index}]" for index, primitives in sorted(asset.meshes.items())
              if any(p.targets for p in primitives)]
    if morphs:
        out.append(f"morph targets of {', '.join(morphs[:10])} (drawn in their base shape)")
    out += [f"cameras[{i}] {c.name} is orthographic (drawn as perspective)"
            for i, c in enumerate(asset.cameras) if c.kind == "orthographic"]
    weights = [a.name for a in asset.animations if a.morph_nodes]
    if weights:
        out.append(f"morph weight channels of {', '.join(weights[:10])}")
    return out


def describe_file(path: Path) -> list[str]:
    from deferred.scene.gltf.asset import read_gltf

    return describe(read_gltf(path))
