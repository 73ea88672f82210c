"""Keyframe tracks: the camera, a light and an object's transform between keys against the
formulas, step and clamping, a seek against a sequence, the turntable's loop, bad tracks as one
line each, and the schema."""

from __future__ import annotations

import dataclasses
from itertools import pairwise

import jsonschema
import numpy as np
import pytest

from deferred.cli import main
from deferred.errors import InputError
from deferred.io.images import read_image
from deferred.render.renderer import Renderer
from deferred.scene.camera import model_matrix
from deferred.scene.loader import scene_from_toml
from deferred.scene.objects import SceneObject
from deferred.scene.schema import scene_schema

BASE = """
size = [64, 48]
[camera]
position = [0.0, 0.5, 3.0]
target = [0.0, 0.0, 0.0]
fov = 45.0

[[object]]
name = "ball"
mesh = "builtin:sphere?segments=24&rings=12"
rotation = [0.0, 20.0, 0.0]
scale = 0.5

[[object]]
name = "box"
mesh = "builtin:cube?size=0.5"
position = [1.0, 0.0, 0.0]

[[light]]
type = "ambient"
color = [0.1, 0.1, 0.1]

[[light]]
name = "key"
type = "point"
position = [1.0, 2.0, 2.0]
radius = 10.0
"""

TIMES = (0.0, 1.0, 3.0)
CAMERA = [(0.0, 0.5, 3.0), (1.0, 1.0, 2.5), (2.5, 0.2, 1.0)]
FOVS = [45.0, 30.0, 50.0]
LIGHT = [(1.0, 2.0, 2.0), (-1.0, 1.5, 2.0), (0.0, 3.0, 1.0)]
INTENSITY = [1.0, 4.0, 2.0]
OBJECT = [(0.0, 0.0, 0.0), (0.5, 0.3, -0.2), (-0.4, 0.1, 0.6)]
ROTATION = [(0.0, 0.0, 0.0), (10.0, 90.0, 0.0), (0.0, 200.0, 30.0)]
SCALE = [0.5, 0.8, 0.3]


def toml_list(values) -> str:
    return "[" + ", ".join(str(float(v)) for v in values) + "]"


def tracks(interpolation: str) -> str:
    def keys(**props) -> str:
        rows = []
        for index, time in enumerate(TIMES):
            fields = [f"time = {time}"]
            for name, values in props.items():
                value = values[index]
                fields.append(f"{name} = " + (toml_list(value) if isinstance(value, tuple)
                                              else str(value)))
            rows.append("{ " + ", ".join(fields) + " }")
        return "[" + ", ".join(rows) + "]"

    return (f'[[track]]\ntarget = "camera"\ninterpolation = "{interpolation}"\n'
            f"keys = {keys(position=CAMERA, fov=FOVS)}\n"
            f'[[track]]\ntarget = "light:key"\ninterpolation = "{interpolation}"\n'
            f"keys = {keys(position=LIGHT, intensity=INTENSITY)}\n"
            f'[[track]]\ntarget = "object:ball"\ninterpolation = "{interpolation}"\n'
            f"keys = {keys(position=OBJECT, rotation=ROTATION, scale=SCALE)}\n")


def scene_with(interpolation: str):
    return scene_from_toml(BASE + tracks(interpolation), "s.toml")


def segment(time: float) -> tuple[int, float]:
    k = int(np.searchsorted(TIMES, time, side="right")) - 1
    return k, (time - TIMES[k]) / (TIMES[k + 1] - TIMES[k])


def linear_reference(values, time: float) -> np.ndarray:
    values = np.asarray(values, dtype=float)
    k, s = segment(time)
    return (1.0 - s) * values[k] + s * values[k + 1]


def smooth_reference(values, time: float) -> np.ndarray:
    """The Catmull-Rom Hermite segment as a cubic Bezier (control points a third of a
    tangent from the keys), evaluated by de Casteljau: another form of the same curve."""
    p = np.asarray(values, dtype=float)
    t = np.asarray(TIMES)
    k, s = segment(time)
    tangents = [np.zeros_like(p[0])] + [(p[i + 1] - p[i - 1]) / (t[i + 1] - t[i - 1])
                                        for i in range(1, len(t) - 1)] + [np.zeros_like(p[0])]
    h = t[k + 1] - t[k]
    points = [p[k], p[k] + h * tangents[k] / 3.0, p[k + 1] - h * tangents[k + 1] / 3.0, p[k + 1]]
    while len(points) > 1:
        points = [(1.0 - s) * a + s * b for a, b in pairwise(points)]
    return points[0]


@pytest.mark.parametrize("interpolation, reference", [("linear", linear_reference),
                                                      ("smooth", smooth_reference)])
@pytest.mark.parametrize("time", [0.25, 0.7, 1.5, 2.9])
def test_between_keys_the_camera_a_light_and_an_object_follow_the_formula(
        interpolation, reference, time):
    scene = scene_with(interpolation)
    camera = scene.camera_at(time)
    assert np.allclose(camera.position, reference(CAMERA, time), atol=1e-12)
    assert np.isclose(camera.fov, reference(FOVS, time), atol=1e-12)
    assert camera.target == (0.0, 0.0, 0.0)  # not on the track: the scene's
    key = scene.light_names["key"]
    params = scene.light_params_at(key, time)
    assert np.allclose(params.position, reference(LIGHT, time), atol=1e-12)
    assert np.isclose(params.intensity, reference(INTENSITY, time), atol=1e-12)
    assert params.radius == 10.0
    ball = scene.objects[0]
    expected = model_matrix(reference(OBJECT, time), reference(ROTATION, time),
                            reference(SCALE, time))
    assert np.allclose(ball.local_at(time), expected, atol=1e-12)
    # the object between keys is neither key (the test would pass a track that holds)
    assert not np.allclose(ball.local_at(time), ball.local_at(TIMES[segment(time)[0]]))


def test_smooth_differs_from_linear_and_eases_at_the_ends():
    linear, smooth = scene_with("linear"), scene_with("smooth")
    assert not np.allclose(linear.camera_at(0.5).position, smooth.camera_at(0.5).position)
    # zero tangent at the first key: a small step moves it second-order
    near = np.subtract(smooth.camera_at(1e-3).position, CAMERA[0])
    assert np.linalg.norm(near) < 1e-4


def test_step_holds_and_times_out_of_range_clamp():
    scene = scene_with("step")
    key = scene.light_names["key"]
    ball = scene.objects[0]
    for time, index in [(0.0, 0), (0.99, 0), (1.0, 1), (2.99, 1), (3.0, 2), (50.0, 2)]:
        assert scene.camera_at(time).position == CAMERA[index]
        assert scene.light_params_at(key, time).intensity == INTENSITY[index]
        assert np.allclose(ball.local_at(time),
                           model_matrix(OBJECT[index], ROTATION[index], SCALE[index]))
    for interpolation in ("linear", "smooth"):
        scene = scene_with(interpolation)
        assert scene.camera_at(1e6).position == CAMERA[-1]
        assert scene.camera_at(3.0).fov == FOVS[-1]
        later = scene_from_toml(BASE + tracks(interpolation).replace(
            "keys = [{ time = 0.0", "keys = [{ time = 0.5"), "s.toml")
        assert later.camera_at(0.0).position == later.camera_at(0.5).position == CAMERA[0]


def test_a_seek_gives_the_frame_of_a_sequence_bit_for_bit(gl):
    scene = scene_with("smooth")
    times = [0.0, 0.4, 1.2, 2.5]
    with Renderer(scene, gl=gl) as renderer:
        graph = renderer.graph
        sequence = [renderer.render(time=t).image for t in times]
        assert renderer.graph is graph  # moving the camera, a light, an object: no rebuild
    assert all(not np.array_equal(a, b) for a, b in pairwise(sequence))
    seeking = scene_with("smooth")
    with Renderer(seeking, gl=gl) as renderer:
        for index in (3, 1, 2, 0, 2):
            assert np.array_equal(renderer.render(time=times[index]).image, sequence[index])


def test_rendering_leaves_the_scene_as_it_was_given(gl):
    """The timeline (tracks and events) is evaluated, never written back: after frames at
    several times, every object's placement and parameters, every light's and the camera are
    the very values the scene was made with (the same objects, not copies)."""
    scene = scene_from_toml(BASE + tracks("smooth") + """
[[event]]
time = 1.5
object = "box"
params = { color = [0.1, 0.9, 0.1], specular_intensity = 0.9 }
""", "s.toml")
    models = [obj.model for obj in scene.objects]
    transforms = [obj.transform for obj in scene.objects]
    materials = [(obj.material, obj.material.params) for obj in scene.objects]
    lights = [light.params for light in scene.lights]
    camera = scene.camera
    revisions = [obj.revision for obj in scene.objects] + [scene.revision]
    with Renderer(scene, gl=gl, size=(32, 24)) as renderer:
        for time in (2.0, 0.5, 2.9):
            renderer.render(time=time)
            assert renderer.state.time == time
    assert all(obj.model is model for obj, model in zip(scene.objects, models, strict=True))
    assert all(obj.transform is t for obj, t in zip(scene.objects, transforms, strict=True))
    assert all(obj.material is m and obj.material.params is p
               for obj, (m, p) in zip(scene.objects, materials, strict=True))
    assert all(light.params is p for light, p in zip(scene.lights, lights, strict=True))
    assert scene.camera is camera
    assert [obj.revision for obj in scene.objects] + [scene.revision] == revisions
    box = scene.objects[1]  # the event holds in the frames' states, not in the object
    assert box.params_at(2.9).color == (0.1, 0.9, 0.1) and box.params.color != (0.1, 0.9, 0.1)


def test_what_is_set_by_hand_is_the_base_of_the_tracks():
    scene = scene_with("linear")
    scene.camera = dataclasses.replace(scene.camera, target=(0.0, 0.3, 0.0), near=0.1)
    moved = scene.camera_at(0.5)
    assert moved.near == 0.1 and moved.target == (0.0, 0.3, 0.0)
    assert np.allclose(moved.position, linear_reference(CAMERA, 0.5))
    box = scene.objects[1]  # no placement known: the matrix's is found
    bare = SceneObject("bare", box.mesh, box.material, model_matrix((1, 2, 3), (30, 60, 10), 2))
    scene.objects.append(bare)
    scene.add_track(bare, [{"time": 0.0, "position": [0.0, 0.0, 0.0]},
                           {"time": 1.0, "position": [2.0, 0.0, 0.0]}])
    assert np.allclose(bare.local_at(0.5), model_matrix((1, 0, 0), (30, 60, 10), 2))
    assert np.allclose(scene.world_at(bare, 0.5), bare.local_at(0.5))  # no parent


def test_the_model_at_a_time_does_not_depend_on_the_frames_before(gl):
    scene = scene_with("smooth")
    ball = scene.objects[0]
    direct = ball.local_at(1.7)
    with Renderer(scene, gl=gl, size=(32, 24)) as renderer:
        for time in (0.0, 2.9, 0.3, 1.7):
            renderer.render(time=time)
        assert np.array_equal(renderer.state.object_state(ball).model, direct)
    assert np.array_equal(ball.local_at(1.7), direct)


# -- the turntable -------------------------------------------------------------------------------

def test_the_turntable_orbits_once_and_its_frame_n_is_frame_0(gl):
    frames, fps = 8, 4.0
    scene = scene_from_toml(BASE, "s.toml")
    scene.set_turntable(frames / fps)
    start = scene.camera_at(0.0)
    assert scene.camera_at(frames / fps) == start  # bit for bit, not nearly
    for index in range(1, frames):
        camera = scene.camera_at(index / fps)
        offset = np.subtract(camera.position, camera.target)
        assert np.isclose(camera.position[1], 0.5)  # height kept
        assert np.isclose(np.hypot(offset[0], offset[2]), 3.0)  # distance kept
        angle = np.arctan2(offset[0], offset[2]) % (2 * np.pi)
        assert np.isclose(angle, 2 * np.pi * index / frames)
    with Renderer(scene, gl=gl) as renderer:
        first = renderer.render(time=0.0).image
        half = renderer.render(time=frames / 2 / fps).image
        after_last = renderer.render(time=frames / fps).image
    assert not np.array_equal(first, half)
    assert np.array_equal(first, after_last)


def test_render_turntable_writes_the_loop_and_refuses_one_image(tmp_path, capsys):
    scene = tmp_path / "s.toml"
    scene.write_text(BASE)
    assert main(["render", str(scene), "--turntable", "4", "--fps", "2",
                 "-o", str(tmp_path / "spin_##.png")]) == 0
    frames = [read_image(tmp_path / f"spin_{i:02d}.png") for i in range(4)]
    assert not (tmp_path / "spin_04.png").exists()
    assert all(not np.array_equal(a, b) for a, b in pairwise(frames))
    capsys.readouterr()
    assert main(["render", str(scene), "--turntable", "4", "-o", str(tmp_path / "one.png")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --turntable: a turntable is 4 frames and one.png holds one "
                          "image") and len(err.splitlines()) == 1
    assert main(["render", str(scene), "--turntable", "4", "--frames", "3",
                 "-o", str(tmp_path / "x_##.png")]) == 2
    assert "error: --frames: --turntable 4 renders 4 frames" in capsys.readouterr().err
    assert not (tmp_path / "one.png").exists() and not (tmp_path / "x_00.png").exists()


# -- bad tracks ----------------------------------------------------------------------------------

BAD = [
    ('target = "camra"\nkeys = [{ time = 0.0, fov = 30.0 }]',
     "s.toml: track[0].target: expected 'camera', 'object:NAME', 'light:INDEX' or "
     "'light:NAME', got 'camra' (did you mean 'camera'?)"),
    ('target = "object:bal"\nkeys = [{ time = 0.0, position = [0.0, 0.0, 0.0] }]',
     "s.toml: track[0].target: no object named 'bal' (did you mean 'ball'? objects: ball, box)"),
    ('target = "light:5"\nkeys = [{ time = 0.0, intensity = 1.0 }]',
     "s.toml: track[0].target: no light '5' (lights: light:0 to light:1, or by name: key)"),
    ('target = "camera"\nkeys = [{ time = 1.0, fov = 30.0 }, { time = 0.5, fov = 40.0 }]',
     "s.toml: track[0].keys[1].time: 0.5 s is not after the key before it (1 s): keys go in "
     "rising time, one key a time"),
    ('target = "object:ball"\nkeys = [{ time = 0.0, position = [0.0, nan, 0.0] }]',
     "s.toml: track[0].keys[0].position[1]: must be a finite number (got nan)"),
    ('target = "light:key"\nkeys = [{ time = 0.0, rotation = [0.0, 90.0, 0.0] }]',
     "s.toml: track[0].keys[0].rotation: a light's keys set time and position, direction, "
     "color, intensity, not 'rotation' (did you mean 'position'?)"),
    ('target = "light:key"\nkeys = [{ time = 0.0, direction = [0.0, -1.0, 0.0] }]',
     "s.toml: track[0].keys[0].direction: a point light has no direction (its keys may set "
     "position, color, intensity)"),
    ('target = "light:0"\nkeys = [{ time = 0.0, intensity = -1.0 }]',
     "s.toml: track[0].keys[0].intensity: Input should be greater than or equal to 0 "
     "(got -1.0)"),
    ('target = "camera"\ninterpolation = "smooth"\nkeys = [{ time = 0.0, fov = 170.0 }, '
     '{ time = 1.0, fov = 178.0 }, { time = 2.0, fov = 60.0 }]',
     "s.toml: track[0].keys[1].fov: the smooth curve between keys 0 and 1 reaches 184.5 (fov "
     "must be in (1, 179)): use linear or add a key"),
    ('target = "object:ball"\nkeys = [{ time = 0.0, scale = 1.0 }, { time = 1.0, scale = -1.0 }]',
     "s.toml: track[0].keys[1].scale: between keys 0 and 1 the scale passes through 0"),
    ('target = "object:ball"\nkeys = [{ time = 0.0, position = "up" }]',
     "s.toml: track[0].keys[0].position: expected 3 numbers, not a string (got 'up')"),
    ('target = "object:ball"\nkeys = [{ time = 0.0, colour = [1.0, 1.0, 1.0] }]',
     "s.toml: track[0].keys[0].colour: an object's keys set time and position, rotation, "
     "scale, not 'colour'"),
    ('target = "camera"\nkeys = [{ time = 0.0 }]',
     "s.toml: track[0].keys[0]: sets nothing: give one of position, target, fov"),
    ('target = "camera"\nkeys = [{ time = 0.0, target = [0.0, 0.5, 3.0] }]',
     "s.toml: track[0]: the camera at t = 0 s: position and target are the same point"),
    ('target = "camera"\ninterpolation = "smoth"\nkeys = [{ time = 0.0, fov = 30.0 }]',
     "s.toml: track[0].interpolation: expected one of 'step', 'linear', 'smooth' (got "
     "'smoth')"),
    ('target = "camera"\nkeys = []',
     "s.toml: track[0].keys: "),
]


@pytest.mark.parametrize("table, expected", BAD, ids=[e.split(": ")[1] + e[-12:] for _, e in BAD])
def test_a_bad_track_is_one_line_naming_the_key(table, expected):
    with pytest.raises(InputError) as info:
        scene_from_toml(BASE + "[[track]]\n" + table + "\n", "s.toml")
    assert type(info.value) is InputError, str(info.value)
    assert str(info.value).startswith(expected), str(info.value)
    assert len(str(info.value).splitlines()) == 1


def test_one_property_has_one_track_and_light_names_are_checked():
    twice = ('[[track]]\ntarget = "object:ball"\nkeys = [{ time = 0.0, scale = 2.0 }]\n'
             '[[track]]\ntarget = "object:ball"\nkeys = [{ time = 1.0, scale = 1.0 }]\n')
    with pytest.raises(InputError) as info:
        scene_from_toml(BASE + twice, "s.toml")
    assert str(info.value) == ("s.toml: track[1].keys[0].scale: object:ball's scale is moved "
                               "by s.toml: track[0] already (one track a property)")
    for name, message in [('"key"', "a light is named 'key' already"),
                          ('"3"', "a light's name is printable text and not a number")]:
        with pytest.raises(InputError) as info:
            scene_from_toml(BASE + f'[[light]]\ntype = "ambient"\nname = {name}\n', "s.toml")
        assert str(info.value).startswith(f"s.toml: light[2].name: {message}")


def test_a_bad_track_from_python_names_the_key():
    scene = scene_from_toml(BASE, "s.toml")
    with pytest.raises(InputError) as info:
        scene.add_track("object:ball", [{"time": 0.0, "position": [0.0, 0.0, 0.0]},
                                        {"time": 0.0, "position": [1.0, 0.0, 0.0]}], "smooth")
    assert str(info.value).startswith("s.toml: track[0].keys[1].time: 0 s is not after")
    assert scene.objects[0].tracks == ()
    with pytest.raises(InputError) as info:
        scene.add_track("light:key", [{"time": 0.0, "color": [1.0, float("nan"), 0.0]}])
    assert str(info.value) == "s.toml: track[0].keys[0].color[1]: must be a finite number " \
                              "(got nan)"
    assert scene.tracks == []


# -- the schema ----------------------------------------------------------------------------------

def test_the_schema_accepts_tracks_and_refuses_a_typo():
    import tomllib

    validator = jsonschema.Draft7Validator(scene_schema())
    scene = tomllib.loads(BASE + tracks("smooth"))
    assert list(validator.iter_errors(scene)) == []
    for edit, at in [(lambda s: s["track"][2]["keys"][0].update(rotaton=[0.0, 0.0, 0.0]),
                      "track/2/keys/0"),
                     (lambda s: s["track"][1]["keys"][0].update(rotation=[0.0, 0.0, 0.0]),
                      "track/1/keys/0"),
                     (lambda s: s["track"][0].update(target="camra"), "track/0/target"),
                     (lambda s: s["track"][0].update(interpolation="cubic"),
                      "track/0/interpolation")]:
        bad = tomllib.loads(BASE + tracks("smooth"))
        edit(bad)
        found = ["/".join(map(str, e.absolute_path)) for e in validator.iter_errors(bad)]
        assert at in found, found
        with pytest.raises(InputError):  # the loader refuses it too
            from deferred.scene.loader import scene_from_dict
            scene_from_dict(bad, "s.toml")


def test_scales_are_checked_key_by_key():
    """A single key's scale of 0 is refused (it rendered a singular matrix); a step track may
    flip the sign at a key, which a linear one may not pass through."""
    from deferred import InputError, Scene

    scene = Scene()
    ball = scene.add_object("builtin:sphere", label="ball")
    with pytest.raises(InputError, match="scale: must be at least 1e-06"):
        scene.add_track(ball, [{"time": 0.0, "scale": 0.0}])
    scene.add_track(ball, [{"time": 0.0, "scale": 1.0}, {"time": 1.0, "scale": -1.0}],
                    interpolation="step")
    other = scene.add_object("builtin:sphere", label="other")
    with pytest.raises(InputError, match="passes through 0"):
        scene.add_track(other, [{"time": 0.0, "scale": 1.0}, {"time": 1.0, "scale": -1.0}])


def test_a_track_bad_between_keys_is_refused_before_the_first_frame(tmp_path, capsys):
    """A light direction turning through zero between its keys is refused before any frame of
    the animation is written (frames 0 and 1 were written, then exit 2 at t = 0.5)."""
    from deferred.cli import main

    (tmp_path / "s.toml").write_text("""size = [32, 18]
[[object]]
mesh = "builtin:sphere"
[[light]]
type = "directional"
direction = [1.0, 0.0, 0.0]
[[track]]
target = "light:0"
keys = [{ time = 0.0, direction = [1.0, 0.0, 0.0] }, { time = 1.0, direction = [-1.0, 0.0, 0.0] }]
""")
    code = main(["render", str(tmp_path / "s.toml"), "--frames", "5", "--fps", "4",
                 "-o", str(tmp_path / "f_##.png")])
    err = capsys.readouterr().err
    assert code == 2 and "the light at t = 0.5 s" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_the_camera_returns_to_its_base_when_what_moved_it_goes():
    """A turntable turned off (or the last camera track removed) leaves the camera where the
    scene has it, not at the last orbited pose; an object not in the scene takes no track."""
    from deferred import Camera, InputError, Scene

    scene = Scene(camera=Camera(position=(0.0, 1.0, 4.0), target=(0.0, 0.0, 0.0)))
    base = scene.camera
    scene.set_turntable(8)
    assert scene.camera_at(0.25) != base and scene.camera is base
    scene.set_turntable(None)
    assert scene.camera_at(0.25) is base
    stranger = Scene().add_object("builtin:sphere", label="elsewhere")
    with pytest.raises(InputError, match="^target: the object 'elsewhere' is not in the scene"):
        scene.add_track(stranger, [{"time": 0.0, "position": [0.0, 0.0, 0.0]}])


def test_a_placement_set_by_hand_is_the_base_the_tracks_animate():
    """A new position (or a matrix) set on an object moves the base a rotation track
    animates; a model matrix is a value: writing into it in place is refused, not missed."""
    from deferred import Scene

    scene = Scene()
    ball = scene.add_object("builtin:sphere", label="ball")
    scene.add_track(ball, [{"time": 0.0, "rotation": [0.0, 0.0, 0.0]},
                           {"time": 1.0, "rotation": [0.0, 90.0, 0.0]}])
    with pytest.raises(ValueError, match="read-only"):
        ball.model[:3, 3] = (1.0, 2.0, 3.0)
    ball.position = (1.0, 2.0, 3.0)
    np.testing.assert_allclose(ball.local_at(1.0)[:3, 3], (1.0, 2.0, 3.0), atol=1e-12)
    moved = ball.model.copy()
    moved[:3, 3] = (-1.0, 0.0, 0.5)
    ball.model = moved
    np.testing.assert_allclose(ball.local_at(0.25)[:3, 3], (-1.0, 0.0, 0.5), atol=1e-12)
