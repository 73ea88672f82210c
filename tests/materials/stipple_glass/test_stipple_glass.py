"""Screen-door transparency: stippled into the G-buffer, deinterlaced in the material phase."""

import numpy as np
import pytest

from deferred.scene.loader import scene_from_dict


def glass_scene(pattern, opacity=0.4):
    return scene_from_dict({
        "size": [160, 120], "tonemap": "none",
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0]},
        "object": [
            {"name": "wall", "mesh": "builtin:cube", "position": [0.0, 0.0, -1.0],
             "scale": [3.0, 3.0, 0.1], "params": {"color": [0.9, 0.1, 0.1],
                                                 "specular_intensity": 0.0}},
            {"name": "glass", "mesh": "builtin:cube", "position": [0.0, 0.0, 0.5],
             "scale": [0.6, 0.6, 0.02], "material": "stipple_glass",
             "params": {"pattern": pattern, "opacity": opacity, "color": [0.2, 0.4, 0.9],
                        "specular_intensity": 0.0}}],
        "light": [{"type": "ambient", "color": [1.0, 1.0, 1.0], "ground": [1.0, 1.0, 1.0]}]})


@pytest.mark.parametrize("pattern", [2, 4])
def test_glass_is_stippled_then_blended_over_the_scene(render, pattern):
    shots = {}

    def grab(render_pass, frame):
        if render_pass.name in ("wall.gbuffer", "glass.stipple"):
            shots[render_pass.name] = frame.targets.read("normal_exponent_id")[..., 3]

    result, _ = render(glass_scene(pattern), on_pass=grab)
    written = shots["wall.gbuffer"] != shots["glass.stipple"]
    # one pixel (pattern 4) or one diagonal (pattern 2) of every 2x2 tile, which one varying
    # from tile to tile (materials/techniques/stipple.glsl)
    height, width = written.shape
    tiles = written[:height // 2 * 2, :width // 2 * 2].reshape(height // 2, 2, width // 2, 2)
    assert written.sum() > 200 and tiles.sum(axis=(1, 3)).max() == 4 // pattern
    assert not (tiles[:, :, :, 0] & tiles[:, :, :, 1]).any()  # never two side by side
    assert not (tiles[:, 0] & tiles[:, 1]).any()
    interior = written.copy()
    rows, cols = np.nonzero(written)
    interior[:] = False
    interior[rows.min() + 3:rows.max() - 3, cols.min() + 3:cols.max() - 3] = True
    interior = interior[::-1]  # to the top-down result
    # every interior pixel, stipple or not, is glass over wall: no screen-door pattern is left
    want = 0.6 * np.array([0.9, 0.1, 0.1]) + 0.4 * np.array([0.2, 0.4, 0.9])
    np.testing.assert_allclose(result.hdr[interior][:, :3], np.broadcast_to(want, (
        interior.sum(), 3)), atol=2e-3)


def test_forward_glass_matches_deferred(render):
    scene = glass_scene(4, opacity=0.7)
    deferred, _ = render(scene, "deferred")
    forward, _ = render(scene, "forward")
    difference = np.abs(deferred.hdr[..., :3] - forward.hdr[..., :3]).max(axis=-1)
    # identical inside; the stipple's half resolution only shows along the glass edges
    assert np.mean(difference < 1e-2) > 0.97


@pytest.mark.slow
def test_object_order_does_not_change_the_image(render):
    """Material-phase composition: obliterations first, then shells and glass far to near."""
    objects = [
        {"name": "far_fur", "mesh": "builtin:sphere", "material": "revie_fur",
         "position": [-0.3, 0.0, -0.6], "scale": 0.6, "params": {"shells": 8}},
        {"name": "near_fur", "mesh": "builtin:sphere", "material": "revie_fur",
         "position": [0.35, 0.0, 0.2], "scale": 0.5, "params": {"shells": 8, "seed": 3}},
        {"name": "glass", "mesh": "builtin:cube", "material": "stipple_glass",
         "position": [0.0, 0.0, 1.0], "scale": [0.6, 0.6, 0.02]},
    ]
    images = []
    for order in ([0, 1, 2], [2, 1, 0], [1, 2, 0]):
        scene = scene_from_dict({
            "size": [160, 120], "camera": {"position": [0.0, 0.0, 3.2]},
            "object": [objects[i] for i in order],
            "light": [{"type": "ambient"}, {"type": "directional"}]})
        result, _ = render(scene)
        images.append(result.image)
    assert np.array_equal(images[0], images[1]) and np.array_equal(images[0], images[2])


@pytest.mark.parametrize("pattern", [2, 4])
def test_glass_and_fur_samples_coexist(render, pattern):
    """Revie 2.3.4 interleaving: glass in front of fur takes another parity class, so the fur's
    outer-shell samples behind the glass are still in the G-buffer for its shells."""
    scene = scene_from_dict({
        "size": [160, 120], "tonemap": "none",
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0]},
        "object": [
            {"name": "fur", "mesh": "builtin:sphere", "material": "revie_fur", "scale": 0.8,
             "params": {"shells": 4}},
            {"name": "glass", "mesh": "builtin:cube", "position": [0.0, 0.0, 1.2],
             "scale": [0.5, 0.5, 0.02], "material": "stipple_glass",
             "params": {"pattern": pattern}}],
        "light": [{"type": "ambient"}]})
    shots = {}

    def grab(render_pass, frame):
        if render_pass.name in ("fur.gbuffer", "fur.stipple", "glass.stipple"):
            shots[render_pass.name] = frame.targets.read("normal_exponent_id")
            shots["ids"] = shots[render_pass.name][..., 3]

    render(scene, on_pass=grab)
    from deferred.interfaces import registry

    ids = shots["ids"] % 64
    # the fur's stipple samples: the pixels its stipple pass wrote
    fur_class = np.any(shots["fur.gbuffer"] != shots["fur.stipple"], axis=-1)
    glass = ids == registry.materials.get("stipple_glass").type_id
    fur = ids == registry.materials.get("revie_fur").type_id
    behind_glass = np.zeros_like(glass)
    rows, cols = np.nonzero(glass)
    behind_glass[rows.min() + 2:rows.max() - 2, cols.min() + 2:cols.max() - 2] = True
    assert glass[behind_glass].mean() > 0.2
    # every fur-class pixel behind the glass still holds the fur (its stipple sample)
    assert fur[behind_glass & fur_class].all()
    assert not (glass & fur_class).any()


@pytest.mark.parametrize("pattern", [2, 4])
def test_glass_covers_the_frame_border(render, pattern):
    """Glass's parity class has no sample in the first row or column of the frame: the border
    pixels take the next sample of the class instead of losing the glass."""
    big = {"name": "glass", "mesh": "builtin:cube", "position": [0.0, 0.0, 0.5],
           "scale": [4.0, 4.0, 0.02], "material": "stipple_glass",
           "params": {"pattern": pattern, "opacity": 0.4, "color": [0.2, 0.4, 0.9],
                      "specular_intensity": 0.0}}
    scene = scene_from_dict({"size": [160, 120], "tonemap": "none",
                             "camera": {"position": [0.0, 0.0, 3.0], "target": [0, 0, 0]},
                             "object": [{
                                 "name": "wall", "mesh": "builtin:cube",
                                 "position": [0.0, 0.0, -1.0], "scale": [9.0, 9.0, 0.1],
                                 "params": {"color": [0.9, 0.1, 0.1],
                                            "specular_intensity": 0.0}}, big],
                             "light": [{"type": "ambient", "color": [1.0, 1.0, 1.0],
                                        "ground": [1.0, 1.0, 1.0]}]})
    result, _ = render(scene)
    want = 0.6 * np.array([0.9, 0.1, 0.1]) + 0.4 * np.array([0.2, 0.4, 0.9])
    border = np.concatenate([result.hdr[-1, :, :3], result.hdr[:, 0, :3]])  # bottom, left
    np.testing.assert_allclose(border, np.broadcast_to(want, border.shape), atol=2e-3)
