"""Small glTF files written from numpy arrays (pygltflib saves them): the tests' and the
examples' files, and any generated asset. A :class:`GltfBuilder` adds accessors, meshes,
materials, nodes, cameras, ``KHR_lights_punctual`` lights, skins' matrices and animations a
part at a time; :meth:`GltfBuilder.save_glb` and :meth:`GltfBuilder.save_gltf` write it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

FLOAT, UNSIGNED_SHORT, UNSIGNED_INT = 5126, 5123, 5125
TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}


class GltfBuilder:
    """A glTF document and its one binary buffer, built a part at a time."""

    def __init__(self):
        self.doc: dict[str, Any] = {"asset": {"version": "2.0", "generator": "deferred"},
                                    "scene": 0, "scenes": [{"nodes": []}], "nodes": [],
                                    "meshes": [], "materials": [], "accessors": [],
                                    "bufferViews": [], "buffers": []}
        self.blob = bytearray()

    def _list(self, key: str, item: dict) -> int:
        self.doc.setdefault(key, []).append(item)
        return len(self.doc[key]) - 1

    def view(self, data: bytes) -> int:
        while len(self.blob) % 4:
            self.blob.append(0)
        index = self._list("bufferViews", {"buffer": 0, "byteOffset": len(self.blob),
                                           "byteLength": len(data)})
        self.blob.extend(data)
        return index

    def accessor(self, values: np.ndarray, component: int = FLOAT, kind: str | None = None,
                 **extra: Any) -> int:
        values = np.asarray(values)
        if values.ndim == 1:
            values = values[:, None]
        dtype = {FLOAT: np.float32, UNSIGNED_SHORT: np.uint16, UNSIGNED_INT: np.uint32,
                 5121: np.uint8}[component]
        data = np.ascontiguousarray(values.astype(dtype))
        accessor = {"bufferView": self.view(data.tobytes()), "componentType": component,
                    "count": len(values), "type": kind or TYPES[values.shape[1]], **extra}
        if component == FLOAT and values.shape[1] <= 4 and np.isfinite(values).all():
            accessor["min"] = [float(v) for v in values.min(axis=0)]
            accessor["max"] = [float(v) for v in values.max(axis=0)]
        return self._list("accessors", accessor)

    def material(self, color=(1.0, 1.0, 1.0, 1.0), **extra: Any) -> int:
        pbr = {"baseColorFactor": list(color), "metallicFactor": 0.0, "roughnessFactor": 1.0}
        pbr.update(extra.pop("pbr", {}))
        return self._list("materials", {"pbrMetallicRoughness": pbr, **extra})

    def primitive(self, positions, normals, indices, material: int | None = None,
                  uvs=None, **attributes: np.ndarray) -> dict:
        made = {"attributes": {"POSITION": self.accessor(positions),
                               "NORMAL": self.accessor(normals)},
                "indices": self.accessor(np.asarray(indices).reshape(-1), UNSIGNED_INT)}
        if uvs is not None:
            made["attributes"]["TEXCOORD_0"] = self.accessor(uvs)
        for key, values in attributes.items():
            component = UNSIGNED_SHORT if key.startswith("JOINTS") else FLOAT
            made["attributes"][key] = self.accessor(values, component)
        if material is not None:
            made["material"] = material
        return made

    def mesh(self, *primitives: dict, name: str | None = None) -> int:
        mesh: dict[str, Any] = {"primitives": list(primitives)}
        if name:
            mesh["name"] = name
        return self._list("meshes", mesh)

    def node(self, root: bool = False, **fields: Any) -> int:
        index = self._list("nodes", {key: value for key, value in fields.items()
                                     if value is not None})
        if root:
            self.doc["scenes"][0]["nodes"].append(index)
        return index

    def light(self, **fields: Any) -> int:
        self.doc.setdefault("extensionsUsed", []).append("KHR_lights_punctual")
        self.doc["extensionsUsed"] = sorted(set(self.doc["extensionsUsed"]))
        lights = self.doc.setdefault("extensions", {}).setdefault(
            "KHR_lights_punctual", {"lights": []})["lights"]
        lights.append(fields)
        return len(lights) - 1

    def camera(self, yfov: float, znear: float = 0.1, zfar: float | None = 100.0,
               aspect: float | None = None, name: str | None = None) -> int:
        perspective: dict[str, Any] = {"yfov": yfov, "znear": znear}
        if zfar is not None:
            perspective["zfar"] = zfar
        if aspect is not None:
            perspective["aspectRatio"] = aspect
        camera: dict[str, Any] = {"type": "perspective", "perspective": perspective}
        if name:
            camera["name"] = name
        return self._list("cameras", camera)

    def animation(self, channels: list[tuple[int, str, np.ndarray, np.ndarray, str]],
                  name: str = "move") -> int:
        """``channels``: (node, path, key times, values (K x D, or 3K x D for CUBICSPLINE),
        interpolation)."""
        samplers, made = [], []
        for node, path, times, values, interpolation in channels:
            samplers.append({"input": self.accessor(np.asarray(times, np.float64)),
                             "output": self.accessor(np.asarray(values, np.float64)),
                             "interpolation": interpolation})
            made.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})
        return self._list("animations", {"name": name, "samplers": samplers,
                                         "channels": made})

    def document(self) -> dict[str, Any]:
        doc = {key: value for key, value in self.doc.items() if value != []}
        doc["buffers"] = [{"byteLength": len(self.blob)}]
        return doc

    def save_glb(self, path: Path) -> Path:
        import warnings

        import pygltflib

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pygltflib's notes on fields it fills in
            gltf = pygltflib.GLTF2.from_dict(self.document())
        gltf.set_binary_blob(bytes(self.blob))
        gltf.save_binary(str(path))
        return path

    def save_gltf(self, path: Path) -> Path:
        """A .gltf beside a .bin of the same stem."""
        import json

        doc = self.document()
        binary = path.with_suffix(".bin")
        binary.write_bytes(bytes(self.blob))
        doc["buffers"][0]["uri"] = binary.name
        path.write_text(json.dumps(doc))
        return path
