"""Silva et al., "Curling and Clumping Fur Represented by Texture Layers", figure by figure with the
shell_fur material: docs/figures/shell_fur_*.png and shell_fur_wet_wind.gif.

- Fig. 7 (curls: straight, wavy, few large, many small), deferred and forward;
- Fig. 9 (clump shape w = 0 and w = 1), deferred and forward;
- Fig. 11 (the Stanford bunny dry, and wet with its wetness mask);
- Fig. 12 (c) (a word written into the wetness mask of a furry square, the mask inset);
- Table 1's torus at 16 and 64 layers (a still, no timings: `deferred bench` times it);
- a GIF of fur getting wet, blown by gusting wind and drying (the scene's [[event]] timeline).

Run from the repository root: python examples/shell_fur/figures.py [--only fig7,fig9,...]
(each figure takes seconds on llvmpipe; the GIF about a minute).
"""

from __future__ import annotations

import argparse
import copy
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from deferred.debug.views import with_material_view  # noqa: E402
from deferred.io.images import read_image, write_image  # noqa: E402
from deferred.materials.techniques.uv_seams import UVSeams  # noqa: E402
from deferred.materials.techniques.wetness import (  # noqa: E402
    dry_mask,
    random_droplets,
    uv_wrap,
)
from deferred.render.renderer import Renderer  # noqa: E402
from deferred.scene.loader import scene_from_dict  # noqa: E402

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

HERE = Path(__file__).parent
ROOT = HERE.parents[1]
FIGURES = ROOT / "docs" / "figures"
sys.path.insert(0, str(HERE))
from word_mask import word_mask  # noqa: E402

# Fig. 7's variants: (label, curl_radius K, curl_frequency w)
CURLS = [("(a) straight: K = 0", 0.0, 0.0),
         ("(b) wavy: K = 0.03, w = 6", 0.03, 6.0),
         ("(c) few large curls: K = 0.05, w = 12.6", 0.05, 12.6),
         ("(d) many small curls: K = 0.015, w = 38", 0.015, 38.0)]


# -- scenes and rendering --------------------------------------------------------------------------

def scene_data(name: str) -> dict:
    return tomllib.loads((HERE / name).read_text(encoding="utf-8"))


def variant(data: dict, params: dict | None = None, **top) -> dict:
    """A copy of a scene's data with the first object's params and top-level keys replaced
    (``camera`` merges)."""
    data = copy.deepcopy(data)
    data["object"][0]["params"].update(params or {})
    for key, value in top.items():
        if key == "camera":
            data["camera"] = {**data["camera"], **value}
        else:
            data[key] = value
    return data


def render(data: dict, pipeline: str = "deferred", time: float = 0.0,
           view: str | None = None) -> tuple[np.ndarray, dict[str, int]]:
    scene = scene_from_dict(data, "shell_fur figure", HERE)
    if view is not None:
        scene = with_material_view(scene, view)
    with Renderer(scene, pipeline) as renderer:
        result = renderer.render(time=time)
        return result.image[..., :3], result.draws_by_pass


def panels(path: Path, images, titles, columns=None, scale=1.0, insets=None, suptitle=None,
           inset_box=(0.0, 0.64, 0.36, 0.36)):
    """Labelled panels in a grid (as examples/fur_figures.py); ``insets[i]``, if given, is an
    image drawn over panel i at ``inset_box`` (x, y, width, height in the panel's fractions;
    default the upper left corner), or a function drawing into the inset's axes."""
    columns = columns or len(images)
    rows = (len(images) + columns - 1) // columns
    height, width = images[0].shape[:2]
    top = 0.35 if suptitle else 0.0
    figure, axes = plt.subplots(rows, columns,
                                figsize=(columns * width / 100 * scale,
                                         (rows * (height / 100 + 0.3) + top) * scale),
                                squeeze=False)
    for axis in axes.ravel():
        axis.axis("off")
    for index, (axis, image, title) in enumerate(zip(axes.ravel(), images, titles,
                                                     strict=False)):
        axis.imshow(image, interpolation="nearest")
        axis.set_title(title, fontsize=9)
        inset = insets[index] if insets else None
        if inset is not None:
            box = axis.inset_axes(list(inset_box))
            if callable(inset):
                inset(box)
            else:
                box.imshow(inset, interpolation="nearest")
            box.set_xticks([])
            box.set_yticks([])
            for spine in box.spines.values():
                spine.set_edgecolor("white")
    if suptitle:
        figure.suptitle(suptitle, fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=100, facecolor="white")
    plt.close(figure)
    print(f"wrote {path.relative_to(ROOT)}")


def mask_preview(image: np.ndarray) -> np.ndarray:
    """A wetness mask (R, G centre, B radius, A wetness) as the paper shows it: black dry, blue
    wet, as bright as it is wet, each clump centre a slightly different blue."""
    wet = image[..., 3:4] > 0.0
    centre = np.clip(image[..., 0:2], 0.0, 1.0)
    tint = np.stack([0.1 + 0.25 * centre[..., 0], 0.3 + 0.35 * centre[..., 1],
                     np.ones(image.shape[:2])], -1)
    return np.where(wet, tint * (0.35 + 0.65 * image[..., 3:4]), 0.0).clip(0.0, 1.0)


# -- figures ---------------------------------------------------------------------------------------

def fig7() -> None:
    data = scene_data("fig7_curls.toml")
    for pipeline, suffix in (("deferred", ""), ("forward", "_forward")):
        images, titles = [], []
        for title, radius, frequency in CURLS:
            image, _ = render(variant(data, {"curl_radius": radius,
                                             "curl_frequency": frequency}), pipeline)
            images.append(image)
            titles.append(title)
        panels(FIGURES / f"shell_fur_fig7_curls{suffix}.png", images, titles, columns=2,
               suptitle=f"Silva et al. Fig. 7: curls (Eq. 4), {pipeline}")


def fig9() -> None:
    data = scene_data("fig9_clump_shape.toml")
    images, titles = [], []
    for pipeline in ("deferred", "forward"):
        for shape, how in ((0.0, "straight, leaning in"), (1.0, "bending in along the strand")):
            image, _ = render(variant(data, {"clump_shape": shape}), pipeline)
            images.append(image)
            titles.append(f"w = {shape:g}: {how} ({pipeline})")
    panels(FIGURES / "shell_fur_fig9_clump_shape.png", images, titles, columns=2,
           suptitle="Silva et al. Fig. 9: clump shape w of Eq. 5")


def object_mask(data: dict, size: int = 256) -> tuple[np.ndarray, object]:
    """The wetness mask the first object's random droplets make at t = 0 (Algorithm 1, the
    material's own functions), rows from v = 0 up, and the object's mesh."""
    scene = scene_from_dict(data, "shell_fur figure", HERE)
    obj = scene.objects[0]
    params = obj.material.params
    mask = dry_mask(size)
    seams, wrap = UVSeams(obj.mesh), uv_wrap(obj.mesh)
    for droplet in random_droplets(obj.mesh, obj.model, params.droplets, params.droplet_radius,
                                   params.droplet_wetness, params.seed):
        seams.blend(mask, droplet, wrap)
    return mask, obj.mesh


def uv_inset(mask: np.ndarray, mesh) -> Callable:
    """Draws the mask over the UV square as Silva et al.'s Fig. 11 does (black dry, blue wet)
    with the parameterization's triangles over it."""
    def draw(axis) -> None:
        axis.imshow(mask_preview(mask), origin="lower", extent=(0.0, 1.0, 0.0, 1.0),
                    interpolation="nearest")
        uv = np.asarray(mesh.uvs, np.float64)
        axis.triplot(uv[:, 0], uv[:, 1], np.asarray(mesh.indices).reshape(-1, 3),
                     color=(0.55, 0.55, 0.55), linewidth=0.08)
        axis.set_xlim(0.0, 1.0)
        axis.set_ylim(0.0, 1.0)
    return draw


def fig11() -> None:
    data = scene_data("fig11_bunny.toml")
    dry_data = variant(data, {"droplets": 0})
    dry, _ = render(dry_data)
    wet, _ = render(data)
    view, _ = render(data, view="shell_fur.wetness")
    wet_mask, mesh = object_mask(data)
    dry_uv, _ = object_mask(dry_data)
    droplets = data["object"][0]["params"]["droplets"]
    panels(FIGURES / "shell_fur_fig11_bunny.png", [dry, wet, view],
           ["(a) dry fur", f"(b) wet clumped fur: {droplets} droplets",
            "--view shell_fur.wetness (a colour per clump)"],
           insets=[uv_inset(dry_uv, mesh), uv_inset(wet_mask, mesh), None],
           inset_box=(0.64, 0.64, 0.36, 0.36),
           suptitle="Silva et al. Fig. 11: the Stanford bunny; insets: the wetness mask over "
                    "the unwrap (black dry, blue wet)")


def fig12() -> None:
    data = scene_data("fig12_word.toml")
    mask_path = HERE / data["object"][0]["params"]["wetness_mask"]
    image = word_mask("CGI10")
    # rewritten only when the texels change (the EXR header holds the time it was written)
    if not mask_path.is_file() or not np.array_equal(read_image(mask_path), image):
        write_image(mask_path, image, channels=("R", "G", "B", "A"))
        print(f"wrote {mask_path.relative_to(ROOT)}")
    deferred, _ = render(data)
    forward, _ = render(data, "forward")
    preview = mask_preview(image)
    panels(FIGURES / "shell_fur_fig12_word.png", [deferred, forward],
           ["(c) 'CGI10' in the wetness mask, deferred", "the same, forward"],
           insets=[preview, preview],
           suptitle="Silva et al. Fig. 12 (c): a word written with clumps (inset: the mask)")


def table1() -> None:
    data = scene_data("table1_torus.toml")
    images, titles = [], []
    for shells in (16, 64):
        image, draws = render(variant(data, {"shells": shells}))
        images.append(image[::2, ::2])
        titles.append(f"{shells} layers: {draws['torus.layers'] - 1} drawn (+ the skin)")
    panels(FIGURES / "shell_fur_table1_torus.png", images, titles,
           suptitle="Silva et al. Table 1's torus (9,360 triangles, rendered at 800 x 600)")


def wet_wind() -> None:
    """The GIF, through the command line as the README shows it."""
    command = [shutil.which("deferred") or str(Path(sys.executable).parent / "deferred"),
               "render", "examples/shell_fur/wet_wind.toml", "--frames", "60", "--fps", "12",
               "-o", "docs/figures/shell_fur_wet_wind.gif"]
    print("deferred " + " ".join(command[1:]))
    subprocess.run(command, check=True, cwd=ROOT)


FIGURE_FUNCTIONS = {"fig7": fig7, "fig9": fig9, "fig11": fig11, "fig12": fig12,
                    "table1": table1, "wet_wind": wet_wind}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", default=",".join(FIGURE_FUNCTIONS),
                        help=f"comma-separated figures ({', '.join(FIGURE_FUNCTIONS)})")
    args = parser.parse_args()
    names = [name.strip() for name in args.only.split(",") if name.strip()]
    unknown = [name for name in names if name not in FIGURE_FUNCTIONS]
    if unknown:
        parser.error(f"unknown figure(s) {', '.join(unknown)}")
    FIGURES.mkdir(parents=True, exist_ok=True)
    for name in names:
        FIGURE_FUNCTIONS[name]()


if __name__ == "__main__":
    main()
