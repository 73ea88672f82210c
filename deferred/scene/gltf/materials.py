"""glTF materials as the framework's: each glTF material's metallic-roughness values and
textures as the ``pbr`` material's parameters (:func:`read_material`), and the material made from
them (:func:`make_material`).

The keys are ``pbr``'s: ``base_color`` (RGBA), ``metallic``, ``roughness``, ``emissive``,
``emissive_strength``, ``alpha_mode``, ``alpha_cutoff``, ``double_sided``, ``normal_scale``,
``occlusion_strength`` and, for each texture slot (``base_color``, ``metallic_roughness``,
``normal``, ``occlusion``, ``emissive``), ``<slot>_texture``: a table of the image file
(``path``), its UV set (``uv``), its ``KHR_texture_transform`` (``offset``, ``rotation``,
``scale``, in glTF's texture space) and its sampler (``wrap_s``, ``wrap_t``, ``mag_filter``,
``min_filter``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from deferred.interfaces import registry
from deferred.interfaces.material import Material
from deferred.scene.gltf.document import GltfDocument
from deferred.scene.gltf.images import ImageFiles

SLOTS = ("base_color", "metallic_roughness", "normal", "occlusion", "emissive")
WRAPS = {33071: "clamp_to_edge", 33648: "mirrored_repeat", 10497: "repeat"}
FILTERS = {9728: "nearest", 9729: "linear", 9984: "nearest_mipmap_nearest",
           9985: "linear_mipmap_nearest", 9986: "nearest_mipmap_linear",
           9987: "linear_mipmap_linear"}
ALPHA_MODES = {"OPAQUE": "opaque", "MASK": "mask", "BLEND": "blend"}
DEFAULT_VALUES: dict[str, Any] = {
    "base_color": (1.0, 1.0, 1.0, 1.0), "metallic": 1.0, "roughness": 1.0,
    "emissive": (0.0, 0.0, 0.0), "emissive_strength": 1.0, "alpha_mode": "opaque",
    "alpha_cutoff": 0.5, "double_sided": False, "normal_scale": 1.0, "occlusion_strength": 1.0}


@dataclass
class GltfMaterial:
    """A glTF material as ``pbr`` parameter values (``values``), its name and JSON path."""

    name: str
    where: str
    values: dict[str, Any] = field(default_factory=dict)


def _floats(value: Any, count: int, default: tuple, document: GltfDocument,
            where: str) -> tuple[float, ...]:
    if value is None:
        return default
    if not isinstance(value, list | tuple) or len(value) != count or \
            not all(isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
                    for v in value):
        raise document.error(f"expected {count} finite numbers", where)
    return tuple(float(v) for v in value)


def _number(value: Any, default: float, document: GltfDocument, where: str,
            low: float = 0.0, high: float = math.inf) -> float:
    if value is None:
        return default
    if not isinstance(value, int | float) or isinstance(value, bool) or \
            not (math.isfinite(value) and low <= value <= high):
        raise document.error(f"expected a number in [{low:g}, {high:g}], got {value!r:.40}",
                             where)
    return float(value)


def read_material(document: GltfDocument, images: ImageFiles, index: int) -> GltfMaterial:
    """Material ``index`` of the file as ``pbr`` values (textures made files)."""
    raw = document.raw["materials"][index]
    where = f"materials[{index}]"
    if not isinstance(raw, dict):
        raise document.error("expected an object", where)
    pbr = raw.get("pbrMetallicRoughness") or {}
    extensions = raw.get("extensions") or {}
    values: dict[str, Any] = {
        "base_color": _floats(pbr.get("baseColorFactor"), 4, DEFAULT_VALUES["base_color"],
                              document, f"{where}.pbrMetallicRoughness.baseColorFactor"),
        "metallic": _number(pbr.get("metallicFactor"), 1.0, document,
                            f"{where}.pbrMetallicRoughness.metallicFactor", high=1.0),
        "roughness": _number(pbr.get("roughnessFactor"), 1.0, document,
                             f"{where}.pbrMetallicRoughness.roughnessFactor", high=1.0),
        "emissive": _floats(raw.get("emissiveFactor"), 3, (0.0, 0.0, 0.0), document,
                            f"{where}.emissiveFactor"),
        "emissive_strength": _number(
            (extensions.get("KHR_materials_emissive_strength") or {}).get("emissiveStrength"),
            1.0, document, f"{where}.extensions.KHR_materials_emissive_strength"),
        "alpha_cutoff": _number(raw.get("alphaCutoff"), 0.5, document,
                                f"{where}.alphaCutoff"),
        "double_sided": bool(raw.get("doubleSided", False)),
    }
    mode = raw.get("alphaMode", "OPAQUE")
    if mode not in ALPHA_MODES:
        raise document.error(f"unknown alphaMode {mode!r:.40} (OPAQUE, MASK or BLEND)",
                             f"{where}.alphaMode")
    values["alpha_mode"] = ALPHA_MODES[mode]
    textures = {"base_color": (pbr.get("baseColorTexture"),
                               f"{where}.pbrMetallicRoughness.baseColorTexture"),
                "metallic_roughness": (pbr.get("metallicRoughnessTexture"),
                                       f"{where}.pbrMetallicRoughness.metallicRoughnessTexture"),
                "normal": (raw.get("normalTexture"), f"{where}.normalTexture"),
                "occlusion": (raw.get("occlusionTexture"), f"{where}.occlusionTexture"),
                "emissive": (raw.get("emissiveTexture"), f"{where}.emissiveTexture")}
    for slot, (info, at) in textures.items():
        if info is not None:
            values.update(_texture(document, images, slot, info, at))
    if "normalTexture" in raw:
        values["normal_scale"] = _number(raw["normalTexture"].get("scale"), 1.0, document,
                                         f"{where}.normalTexture.scale", low=-math.inf)
    if "occlusionTexture" in raw:
        values["occlusion_strength"] = _number(raw["occlusionTexture"].get("strength"), 1.0,
                                               document, f"{where}.occlusionTexture.strength",
                                               high=1.0)
    name = raw.get("name") if isinstance(raw.get("name"), str) else f"material{index}"
    return GltfMaterial(name, where, values)


def _texture(document: GltfDocument, images: ImageFiles, slot: str, info: Any,
             where: str) -> dict[str, Any]:
    """A texture reference as ``pbr``'s texture table: the image file, its UV set, its
    ``KHR_texture_transform`` (in glTF's texture space, as the extension gives it) and its
    sampler's wrap and filter modes."""
    if not isinstance(info, dict):
        raise document.error("expected an object", where)
    texture = document.entry("textures", info.get("index"), f"{where}.index")
    texture_at = f"textures[{info['index']}]"
    source = texture.source
    if source is None:
        raise document.error("has no source image (or only an extension's, which the "
                             "framework does not read)", texture_at)
    table: dict[str, Any] = {"path": str(images.path(source, f"{texture_at}.source")),
                             "uv": _texcoord(document, info.get("texCoord"),
                                             f"{where}.texCoord")}
    transform = (info.get("extensions") or {}).get("KHR_texture_transform")
    if transform is not None:
        at = f"{where}.extensions.KHR_texture_transform"
        table["offset"] = _floats(transform.get("offset"), 2, (0.0, 0.0), document,
                                  f"{at}.offset")
        table["rotation"] = _number(transform.get("rotation"), 0.0, document, f"{at}.rotation",
                                    low=-math.inf)
        table["scale"] = _floats(transform.get("scale"), 2, (1.0, 1.0), document, f"{at}.scale")
        if "texCoord" in transform:
            table["uv"] = _texcoord(document, transform["texCoord"], f"{at}.texCoord")
    if texture.sampler is not None:
        sampler = document.entry("samplers", texture.sampler, f"{texture_at}.sampler")
        table.update(wrap_s=WRAPS.get(sampler.wrapS, "repeat"),
                     wrap_t=WRAPS.get(sampler.wrapT, "repeat"),
                     mag_filter=FILTERS.get(sampler.magFilter, "linear"),
                     min_filter=FILTERS.get(sampler.minFilter, "linear_mipmap_linear"))
        if table["mag_filter"] not in ("nearest", "linear"):
            raise document.error(f"magFilter {sampler.magFilter!r:.20} is a minification "
                                 "filter", f"samplers[{texture.sampler}].magFilter")
    return {f"{slot}_texture": table}


def _texcoord(document: GltfDocument, value: Any, where: str) -> int:
    if value is None:
        return 0
    if value not in (0, 1) or isinstance(value, bool):
        raise document.error(f"the framework reads TEXCOORD_0 and TEXCOORD_1, not "
                             f"{value!r:.40}", where)
    return int(value)


DEFAULT_MATERIAL = GltfMaterial("default", "the default material", dict(DEFAULT_VALUES))


def make_material(material: GltfMaterial, document: GltfDocument) -> Material:
    """The framework's material of ``material``: ``pbr`` with its values (errors name the
    file and the material)."""
    return registry.materials.get("pbr").from_dict(dict(material.values), None,
                                                   f"{document.name}: {material.where}")
