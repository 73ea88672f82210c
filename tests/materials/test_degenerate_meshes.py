"""Every registered material over degenerate but valid meshes (one triangle, faces meeting only
at a vertex, zero-area faces beside a real one), in both pipelines: a finite image, or a
refusal naming the object. A mesh of zero-area faces alone is refused by name."""

from __future__ import annotations

import numpy as np
import pytest
from command_line import assert_one_line_error, run

from deferred.errors import InputError
from deferred.interfaces import registry
from deferred.scene.loader import load_scene

MESHES = {
    # one triangle: every edge a boundary, no interior edge (no fins, no silhouette pairs)
    "one_triangle": "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    # two triangles meeting at a vertex: no edge shared
    "bow_tie": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 0 0\nf 1 2 3\nf 2 5 4\n",
    # a real face and a zero-area one on its edge
    "zero_area_faces": "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 2 2 3\n",
}

SCENE = """\
[camera]
position = [0.4, 0.4, 2.5]
target = [0.4, 0.4, 0.0]

[[object]]
name = "thing"
mesh = "{mesh}.obj"
material = "{material}"

[[light]]
type = "point"
position = [0.4, 0.4, 2.0]
intensity = 10.0

[object.params]
{params}
"""

# options drawing from the mesh's edges or its surface on top of the defaults
OPTIONS = {"shell_fur": "fins = true\ndroplets = 20", "cartoon_hair": 'silhouettes = true\n'
           'hatching = "surface"'}
VARIANTS = [(material, "") for material in registry.materials] + \
    [(material, options) for material, options in OPTIONS.items()]


def scene_file(folder, mesh: str, material: str, params: str = ""):
    (folder / f"{mesh}.obj").write_text(MESHES[mesh])
    path = folder / "scene.toml"
    path.write_text(SCENE.format(mesh=mesh, material=material, params=params))
    return path


@pytest.mark.parametrize("pipeline", ["deferred", "forward"])
@pytest.mark.parametrize("mesh", sorted(MESHES))
@pytest.mark.parametrize("material, params", VARIANTS,
                         ids=[f"{m}{'+options' if p else ''}" for m, p in VARIANTS])
def test_degenerate_meshes_render_or_are_refused_by_name(render, tmp_path, material, params,
                                                         mesh, pipeline):
    scene = load_scene(scene_file(tmp_path, mesh, material, params))
    try:
        result, _ = render(scene, pipeline, size=(48, 32))
    except InputError as exc:  # a material may refuse a mesh it cannot draw, by name
        assert "thing" in str(exc) or "scene.toml" in str(exc), exc
        return
    assert np.isfinite(result.hdr).all()


def test_a_mesh_of_zero_area_faces_alone_is_refused_by_name(tmp_path, capfd):
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    scene = tmp_path / "scene.toml"
    scene.write_text('[[object]]\nmesh = "flat.obj"\nmaterial = "revie_fur"\n')
    code, _, err = run(capfd, "render", scene, "-o", tmp_path / "out.png", "--size", "32x24")
    assert_one_line_error(code, err, "flat.obj")
    assert not (tmp_path / "out.png").exists()
