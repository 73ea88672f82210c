"""glTF 2.0 (.gltf, .glb) as a scene and as an object of one: pygltflib reads the document,
:mod:`~deferred.scene.gltf.document` checks the container and the buffers,
:mod:`~deferred.scene.gltf.accessors` reads the accessors, :mod:`~deferred.scene.gltf.asset`
the nodes, cameras, lights and skins, :mod:`~deferred.scene.gltf.materials` the materials as
``pbr`` parameters, :mod:`~deferred.scene.gltf.animation` the animations, and
:mod:`~deferred.scene.gltf.building` places them in a scene."""

from deferred.scene.gltf.asset import GltfAsset, read_gltf
from deferred.scene.gltf.building import add_gltf, fill_scene
from deferred.scene.gltf.document import GltfWarning

GLTF_SUFFIXES = (".gltf", ".glb")

__all__ = ["GLTF_SUFFIXES", "GltfAsset", "GltfWarning", "add_gltf", "read_gltf",
           "fill_scene"]
