"""The scene: its model (objects, lights, camera, timeline), the loader of scene files, the
camera and the meshes' loaders."""

from deferred.scene.camera import Camera
from deferred.scene.loader import load_scene, scene_from_dict, scene_from_toml
from deferred.scene.model import Scene, SceneObject, TimelineEvent

__all__ = ["Camera", "Scene", "SceneObject", "TimelineEvent", "load_scene", "scene_from_dict",
           "scene_from_toml"]
