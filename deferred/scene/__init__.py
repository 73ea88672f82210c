"""The scene: the user's scene (objects, groups, lights, camera, timeline), the loader of scene
files, the scene graph, and the frame state a frame evaluates it into."""

from deferred.scene.camera import Camera
from deferred.scene.loader import load_scene, scene_from_dict, scene_from_toml
from deferred.scene.nodes import SceneNode
from deferred.scene.objects import SceneObject, TimelineEvent
from deferred.scene.scene import Scene
from deferred.scene.state import FrameState, ObjectState
from deferred.scene.transform import Transform

__all__ = ["Camera", "FrameState", "ObjectState", "Scene", "SceneNode", "SceneObject",
           "TimelineEvent", "Transform", "load_scene", "scene_from_dict", "scene_from_toml"]
