"""Another renderer's image of a glTF file, for comparison with docs/figures/gltf: pyrender
(not a dependency of the project: pip install pyrender DracoPy in an environment of its own) from
the camera `deferred render` frames the file with, lit by a directional light along the default
light's direction and pyrender's constant ambient. Run:
python examples/gltf/pyrender_reference.py MODEL.glb OUT.png '{"position": [...], "target":
[...], "fov": 40}' (the camera: deferred.scene.gltf.building.framing_camera's)."""

from __future__ import annotations

import json
import os
import sys

import numpy as np

os.environ.setdefault("PYOPENGL_PLATFORM", "egl")


def look_at_pose(position, target) -> np.ndarray:
    """A camera's pose (OpenGL axes: -Z forward, +Y up) at ``position`` facing ``target``."""
    forward = np.subtract(target, position, dtype=float)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    pose = np.identity(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2] = right, np.cross(right, forward), -forward
    pose[:3, 3] = position
    return pose


def main(path: str, out: str, camera: dict, size=(480, 360)) -> None:
    import pyrender
    import trimesh
    from PIL import Image

    scene = pyrender.Scene.from_trimesh_scene(trimesh.load(path),
                                              bg_color=[0.02, 0.02, 0.025, 1.0],
                                              ambient_light=[0.3, 0.3, 0.3])
    scene.add(pyrender.PerspectiveCamera(yfov=np.radians(camera["fov"]),
                                         aspectRatio=size[0] / size[1]),
              pose=look_at_pose(camera["position"], camera["target"]))
    toward_light = -np.array([-0.4, -0.8, -0.6])
    scene.add(pyrender.DirectionalLight(intensity=3.0),
              pose=look_at_pose(toward_light, [0.0, 0.0, 0.0]))
    color, _ = pyrender.OffscreenRenderer(*size).render(scene)
    Image.fromarray(color).save(out)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], json.loads(sys.argv[3]))
