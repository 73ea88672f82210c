"""glTF files in docs/figures/gltf/: the sample models of ../shared/assets in both pipelines
(side by side), the DamagedHelmet with shell fur on its crest (a scene file whose second object
picks the crest node of a copy of the helmet split in two and overrides its material), and a
frame of a skinned animation (a tentacle of four bones this script builds, and its loop as a
GIF). Run from the repository root: python examples/gltf/figures.py"""

from __future__ import annotations

import math
import shutil
import sys
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image

from deferred.debug.preview import labelled
from deferred.render.renderer import Renderer
from deferred.scene.gltf.asset import read_gltf
from deferred.scene.gltf.builder import UNSIGNED_SHORT, GltfBuilder
from deferred.scene.loader import load_scene, scene_from_toml

ROOT = Path(__file__).parents[2]
ASSETS = (ROOT.parent / "shared" / "assets").resolve()
FIGURES = ROOT / "docs" / "figures" / "gltf"
SAMPLES = ("BoxTextured.glb", "BoxInterleaved.glb", "DamagedHelmet/DamagedHelmet.gltf")


def render(scene, pipeline: str, size: tuple[int, int], time: float = 0.0) -> np.ndarray:
    with Renderer(scene, pipeline, size) as renderer:
        return renderer.render(time=time).image[..., :3]


def samples(size=(480, 360)) -> None:
    """Each sample model, deferred and forward side by side."""
    for name in SAMPLES:
        path = ASSETS / name
        if not path.is_file():
            print(f"skipped {name}: not in {ASSETS}", file=sys.stderr)
            continue
        tiles = [labelled(render(load_scene(path), pipeline, size), f"{pipeline}: {path.name}")
                 for pipeline in ("deferred", "forward")]
        out = FIGURES / f"{path.stem}.png"
        Image.fromarray(np.concatenate([np.asarray(t) for t in tiles], axis=1)).save(out)
        print(f"wrote {out}")


def split_helmet(folder: Path) -> Path:
    """A copy of the DamagedHelmet whose crest (the ridge over the top, from the brow back) is a
    node of its own, ``crest``, over the whole helmet, node ``helmet``. The visor's glass
    reaches the top at the front: the crest starts behind it."""
    source = ASSETS / "DamagedHelmet" / "DamagedHelmet.gltf"
    asset = read_gltf(source)
    mesh = asset.meshes[0][0].mesh
    rotation = asset.nodes[0].transform.matrix()[:3, :3]
    world = mesh.positions @ rotation.T
    centres = world[mesh.indices.astype(np.int64)].mean(axis=1)
    crest = (np.abs(centres[:, 0]) < 0.14) & (centres[:, 1] > 0.45) & (centres[:, 2] < -0.05)
    gltf = GltfBuilder()
    raw = asset.document.raw
    gltf.doc.update(images=raw["images"], textures=raw["textures"],
                    samplers=raw.get("samplers", []))
    gltf.doc["materials"] = [raw["materials"][0]]
    uvs = mesh.uvs.astype(np.float64).copy()
    uvs[:, 1] = 1.0 - uvs[:, 1]  # back to glTF's convention
    for name, faces in (("helmet", mesh.indices), ("crest", mesh.indices[crest])):
        used = np.unique(faces)
        remap = np.zeros(len(mesh.positions), np.int64)
        remap[used] = np.arange(len(used))
        primitive = gltf.primitive(mesh.positions[used], mesh.normals[used], remap[faces], 0,
                                   uvs=uvs[used])
        gltf.node(root=True, name=name, mesh=gltf.mesh(primitive, name=name),
                  rotation=list(asset.nodes[0].transform.quaternion))
    for image in raw["images"]:
        shutil.copy(source.parent / image["uri"], folder / image["uri"])
    return gltf.save_gltf(folder / "helmet_crest.gltf")


CREST_SCENE = """
size = [640, 480]
background = [0.05, 0.05, 0.06]
[camera]
position = [2.9, 1.6, 1.3]
target = [0.0, 0.3, -0.3]
fov = 42.0

[[light]]
type = "ambient"
color = [0.35, 0.37, 0.42]
ground = [0.12, 0.11, 0.10]
[[light]]
type = "directional"
direction = [-0.4, -0.8, -0.6]
intensity = 2.5

[[object]]
name = "helmet"
mesh = "helmet_crest.gltf"
node = "helmet"

[[object]]
name = "mohawk"
mesh = "helmet_crest.gltf"
node = "crest"
material = "shell_fur"
params = { fur_length = 0.22, shells = 48, color = [0.75, 0.12, 0.08], density = 30000.0 }
"""


def helmet_fur() -> None:
    with tempfile.TemporaryDirectory() as folder:
        split_helmet(Path(folder))
        scene = scene_from_toml(CREST_SCENE, "helmet_fur.toml", Path(folder))
        image = render(scene, "deferred", scene.size)
    out = FIGURES / "helmet_fur_crest.png"
    Image.fromarray(image).save(out)
    print(f"wrote {out}")


def tentacle(path: Path, bones: int = 4, length: float = 2.0) -> Path:
    """A tapering tube along +Y of ``bones`` joints in a chain, each waving about Z a quarter
    period behind the one below it (LINEAR rotation keys, a 2 s loop)."""
    gltf = GltfBuilder()
    rings, segments = 64, 32
    y = np.linspace(0.0, length, rings + 1)
    angle = np.linspace(0.0, 2 * math.pi, segments, endpoint=False)
    yy, aa = np.meshgrid(y, angle, indexing="ij")
    radius = 0.18 * (1.0 - 0.8 * yy / length)
    normals = np.stack([np.sin(aa), np.zeros_like(aa), np.cos(aa)], -1).reshape(-1, 3)
    positions = (np.stack([np.sin(aa) * radius, yy, np.cos(aa) * radius], -1)).reshape(-1, 3)
    faces = [(r * segments + s, r * segments + (s + 1) % segments,
              (r + 1) * segments + (s + 1) % segments) for r in range(rings)
             for s in range(segments)]
    faces += [(a, c, a + segments) for a, _, c in faces]
    step = length / bones
    # each vertex between the two joints nearest it, weighted by distance
    place = np.clip(positions[:, 1] / step - 0.5, 0.0, bones - 1)
    low = np.floor(place).astype(int)
    high = np.minimum(low + 1, bones - 1)
    upper = place - low
    joints = np.stack([low, high, np.zeros_like(low), np.zeros_like(low)], 1)
    weights = np.stack([1.0 - upper, upper, np.zeros_like(upper), np.zeros_like(upper)], 1)
    material = gltf.material((0.85, 0.35, 0.55, 1.0), pbr={"roughnessFactor": 0.45})
    primitive = gltf.primitive(positions, normals, np.array(faces), material)
    primitive["attributes"]["JOINTS_0"] = gltf.accessor(joints, UNSIGNED_SHORT)
    primitive["attributes"]["WEIGHTS_0"] = gltf.accessor(weights)
    chain: list[int] = []
    for k in reversed(range(bones)):
        chain.insert(0, gltf.node(name=f"bone{k}", translation=(0, step if k else 0, 0),
                                  children=chain[:1]))
    root = chain[0]
    gltf.doc["scenes"][0]["nodes"].append(root)
    binds = np.stack([np.linalg.inv(np.array([[1, 0, 0, 0], [0, 1, 0, k * step], [0, 0, 1, 0],
                                              [0, 0, 0, 1]], float)) for k in range(bones)])
    gltf.doc["skins"] = [{"joints": chain, "inverseBindMatrices": gltf.accessor(
        binds.transpose(0, 2, 1).reshape(bones, 16), kind="MAT4")}]
    gltf.node(root=True, name="tentacle", mesh=gltf.mesh(primitive), skin=0)
    times = np.linspace(0.0, 2.0, 17)
    channels = []
    for k, joint in enumerate(chain):
        angles = np.radians(28.0) * np.sin(2 * math.pi * (times / 2.0) - k * math.pi / 2)
        keys = np.stack([np.zeros_like(angles), np.zeros_like(angles), np.sin(angles / 2),
                         np.cos(angles / 2)], 1)
        channels.append((joint, "rotation", times, keys, "LINEAR"))
    gltf.animation(channels, name="wave")
    return gltf.save_glb(path)


def skinned(size=(480, 480)) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = tentacle(Path(folder) / "tentacle.glb")
        scene = load_scene(path)
        scene.camera = type(scene.camera)((0.0, 1.1, 4.2), (0.0, 1.0, 0.0), (0, 1, 0), 40.0,
                                          0.5, 20.0)
        frames = []
        with Renderer(scene, "deferred", size) as renderer:
            for index in range(24):
                frames.append(renderer.render(time=index / 12.0).image[..., :3])
    out = FIGURES / "skinned_tentacle.png"
    Image.fromarray(frames[5]).save(out)
    gif = FIGURES / "skinned_tentacle.gif"
    pictures = [Image.fromarray(frame).resize((240, 240)) for frame in frames]
    pictures[0].save(gif, save_all=True, append_images=pictures[1:], duration=83, loop=0)
    print(f"wrote {out}, {gif}")


def main() -> None:
    FIGURES.mkdir(parents=True, exist_ok=True)
    samples()
    if (ASSETS / "DamagedHelmet" / "DamagedHelmet.gltf").is_file():
        helmet_fur()
    skinned()


if __name__ == "__main__":
    main()
