"""Animation: the scene timeline, frame time, numbered sequences and videos from the CLI."""

import numpy as np
import pytest

from deferred.cli import main
from deferred.errors import InputError
from deferred.io.images import read_image
from deferred.io.paths import expand_pattern, output_kind
from deferred.io.video import frame_times, gif_durations
from deferred.scene.loader import scene_from_toml
from deferred.scene.timeline import SceneEvaluator

SCENE = """
size = [64, 48]
[camera]
position = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]

[[object]]
name = "ball"
mesh = "builtin:sphere?segments=24&rings=12"
[object.params]
color = [0.8, 0.1, 0.1]

[[object]]
mesh = "builtin:cube?size=0.5"
position = [1.2, 0.0, 0.0]

[[light]]
type = "directional"
direction = [-0.3, -0.5, -1.0]
"""

TIMELINE = """
[[event]]
time = 0.2
object = "ball"
params = { color = [0.1, 0.1, 0.8] }

[[event]]
time = 0.1
object = "ball"
params = { color = [0.1, 0.8, 0.1], specular_exponent = 8.0 }
"""


def run(capsys, *args):
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def has_ffmpeg() -> bool:
    try:
        import imageio_ffmpeg

        return bool(imageio_ffmpeg.get_ffmpeg_exe())
    except (ImportError, RuntimeError):
        return False


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENE + TIMELINE)
    return path


# -- the timeline -------------------------------------------------------------------------------

def test_params_at_before_at_and_after_events():
    scene = scene_from_toml(SCENE + TIMELINE, "s.toml")
    ball, cube = scene.objects
    assert ball.event_times == (0.1, 0.2) and cube.event_times == ()
    assert ball.params_at(0.0) is ball.base_params
    assert ball.params_at(0.0).color == (0.8, 0.1, 0.1)
    assert ball.params_at(0.0999).color == (0.8, 0.1, 0.1)
    at = ball.params_at(0.1)  # an event applies from its own time on
    assert at.color == (0.1, 0.8, 0.1) and at.specular_exponent == 8.0
    later = ball.params_at(0.25)  # both, in time order: the later colour, the earlier exponent
    assert later.color == (0.1, 0.1, 0.8) and later.specular_exponent == 8.0
    assert ball.params_at(0.15) is at  # validated once per set of applied events
    assert ball.params_at(1e6) is later
    evaluator = SceneEvaluator(scene)  # what a renderer evaluates each frame
    assert evaluator.evaluate(0.15).object_state(ball).params is at
    cube_params = cube.material.params
    state = evaluator.evaluate(0.3)
    assert state.object_state(ball).params is later
    assert state.object_state(cube).material is cube.material  # no event: the object's own
    assert evaluator.evaluate(0.0).object_state(ball).params.color == (0.8, 0.1, 0.1)
    assert ball.material.params is ball.base_params and cube.material.params is cube_params


def test_events_at_the_same_time_apply_in_file_order():
    ties = """
[[event]]
time = 0.5
object = "ball"
params = { color = [1.0, 0.0, 0.0], specular_intensity = 0.25 }
[[event]]
time = 0.5
object = "ball"
params = { color = [0.0, 0.0, 1.0] }
"""
    ball = scene_from_toml(SCENE + ties, "s.toml").objects[0]
    assert ball.event_times == (0.5, 0.5)
    assert ball.params_at(0.5).color == (0.0, 0.0, 1.0)
    assert ball.params_at(0.5).specular_intensity == 0.25
    assert ball.params_at(0.49).color == (0.8, 0.1, 0.1)


def test_timeline_from_python():
    scene = scene_from_toml(SCENE, "s.toml")
    cube = scene.objects[1]
    assert cube.label == "cube0"
    scene.add_event("cube0", 1.0, {"color": (0.0, 1.0, 0.0)})
    assert cube.params_at(1.0).color == (0.0, 1.0, 0.0)
    with pytest.raises(InputError, match=r"^cube0: event\.params\.specular_intensity: Input "
                                         "should be less"):
        scene.add_event(cube, 2.0, {"specular_intensity": 2.0})
    assert cube.event_times == (1.0,)  # a rejected event is not kept
    with pytest.raises(InputError, match=r"^cube0: event\.time: must be a finite number"):
        scene.add_event(cube, float("nan"), {})


@pytest.mark.parametrize("event, expected", [
    ('time = 0.1\nobject = "bal"\nparams = { color = [1.0, 1.0, 1.0] }',
     "error: s.toml: event[0].object: no object named 'bal' (did you mean 'ball'? objects: "
     "ball, cube0)"),
    ('time = 0.1\nobject = "ball"\nparams = { color = [1.0, 1.0] }',
     "error: s.toml: event[0].params.color"),
    ('time = 0.1\nobject = "ball"\nparams = { wind = 2.0 }',
     "error: s.toml: event[0].params.wind: unknown parameter"),
    ('time = -0.5\nobject = "ball"\nparams = { color = [1.0, 1.0, 1.0] }',
     "error: s.toml: event[0].time: Input should be greater than or equal to 0"),
    ('time = inf\nobject = "ball"\nparams = {}', "error: s.toml: event[0].time: "),
    ('object = "ball"\nparams = {}', "error: s.toml: event[0].time: missing required key"),
])
def test_timeline_errors_exit_2_with_one_line(tmp_path, capsys, event, expected):
    scene = tmp_path / "s.toml"
    scene.write_text(SCENE + "[[event]]\n" + event + "\n")
    code, _, err = run(capsys, "render", scene, "-o", tmp_path / "out_##.png", "--frames", 2)
    assert code == 2
    assert err.startswith(expected), err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_same_time_same_image_and_frame_time(gl, scene_file):
    from deferred.render.renderer import Renderer
    from deferred.scene.loader import load_scene

    seen = []
    with Renderer(load_scene(scene_file), gl=gl) as renderer:
        first = renderer.render(time=0.2).image
        base = renderer.render(time=0.0).image
        again = renderer.render(time=0.2, on_pass=lambda p, frame: seen.append(frame.time)).image
    assert np.array_equal(first, again)
    assert not np.array_equal(first, base)
    assert seen and set(seen) == {0.2}


# -- outputs ------------------------------------------------------------------------------------

def test_frame_times_and_patterns():
    assert frame_times(3, 10.0, 0.5) == [0.5, 0.6, 0.7]
    assert expand_pattern("a/out_####.png", 7).as_posix() == "a/out_0007.png"
    assert expand_pattern("f#.exr", 12).name == "f12.exr"  # wider numbers keep every digit
    assert [output_kind(p) for p in ("a.png", "a_#.exr", "a.mp4", "a.GIF")] == \
        ["image", "sequence", "video", "video"]
    assert gif_durations(6, 24.0) == [40, 40, 40, 50, 40, 40]
    assert sum(gif_durations(48, 24.0)) == 2000


def test_sequence_writes_every_frame_and_the_timeline_shows(tmp_path, capsys, scene_file):
    code, out, err = run(capsys, "render", scene_file, "--frames", 3, "--fps", 10,
                         "-o", tmp_path / "out_##.png")
    assert code == 0, err
    assert out == "" and "t = 0..0.2 s at 10 fps" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out_00.png", "out_01.png",
                                                          "out_02.png", "s.toml"]
    frames = [read_image(tmp_path / f"out_0{i}.png") for i in range(3)]
    centre = [f[24, 32, :3] for f in frames]
    assert centre[0][0] > centre[0][1]  # red, then green from t = 0.1, then blue
    assert centre[1][1] > centre[1][0] and centre[2][2] > centre[2][1]
    assert np.array_equal(frames[0][:, 54:], frames[1][:, 54:])  # the cube has no events


def test_pattern_single_frame_and_start_time(tmp_path, capsys, scene_file):
    code, _, err = run(capsys, "render", scene_file, "--time", 0.15, "-o",
                       tmp_path / "out_####.png")
    assert code == 0, err
    assert (tmp_path / "out_0000.png").is_file()
    assert read_image(tmp_path / "out_0000.png")[24, 32, 1] > 0.5  # green: t = 0.15


def test_frames_to_a_plain_image_are_refused_with_the_fix(tmp_path, capsys, scene_file):
    code, _, err = run(capsys, "render", scene_file, "--frames", 3, "--fps", 10, "-o",
                       tmp_path / "last.png")
    assert code == 2
    assert err == ("error: --frames: 3 frames cannot go to one image, last.png: use a # "
                   "pattern such as last_####.png, or .mp4/.gif\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]
    # time advances frame by frame: the third frame of a pattern, t = 0.2, is blue
    code, _, err = run(capsys, "render", scene_file, "--frames", 3, "--fps", 10, "-o",
                       tmp_path / "frame_#.png")
    assert code == 0, err
    pixel = read_image(tmp_path / "frame_2.png")[24, 32]
    assert pixel[2] > pixel[1]


def test_gif(tmp_path, capsys, scene_file):
    import imageio.v3 as iio

    out = tmp_path / "anim.gif"
    code, _, err = run(capsys, "render", scene_file, "--frames", 3, "--fps", 10, "-o", out)
    assert code == 0, err
    frames = iio.imread(out, index=None)
    assert frames.shape[:3] == (3, 48, 64)
    assert iio.immeta(out)["loop"] == 0 and iio.immeta(out)["duration"] == 100
    assert sorted(p.name for p in tmp_path.iterdir()) == ["anim.gif", "s.toml"]


@pytest.mark.skipif(not has_ffmpeg(), reason="no ffmpeg (imageio-ffmpeg)")
def test_mp4(tmp_path, capsys, scene_file):
    import imageio.v2 as iio

    out = tmp_path / "anim.mp4"
    code, _, err = run(capsys, "render", scene_file, "--frames", 3, "--fps", 10, "-o", out)
    assert code == 0, err
    reader = iio.get_reader(out)
    try:
        meta = reader.get_meta_data()
        frames = list(reader.iter_data())
    finally:
        reader.close()
    assert meta["codec"] == "h264" and meta["fps"] == 10.0 and len(frames) == 3
    assert frames[1][24, 32, 1] > frames[1][24, 32, 0]  # green at t = 0.1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["anim.mp4", "s.toml"]


@pytest.mark.parametrize("suffix", [".gif", pytest.param(".mp4", marks=pytest.mark.skipif(
    not has_ffmpeg(), reason="no ffmpeg"))])
def test_ctrl_c_mid_video_leaves_no_file(tmp_path, capsys, scene_file, monkeypatch, suffix):
    from deferred.render.renderer import Renderer

    original = Renderer.render

    def failing(self, *args, time=0.0, **kwargs):
        if time > 0.15:
            raise KeyboardInterrupt
        return original(self, *args, time=time, **kwargs)

    monkeypatch.setattr(Renderer, "render", failing)
    code, _, err = run(capsys, "render", scene_file, "--frames", 3, "--fps", 10,
                       "-o", tmp_path / f"anim{suffix}")
    assert code == 130 and err.strip().endswith("interrupted")  # Ctrl-C: 128 + SIGINT
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


@pytest.mark.parametrize("args, expected", [
    (["-o", "x.avi"], "error: -o: output must end in .png, .exr, .mp4 or .gif: x.avi"),
    (["-o", "x_##.mp4"], "error: -o: a frame pattern must end in .png or .exr"),
    (["-o", "x_#_#.png"], "error: -o: a frame pattern has one run of '#'"),
    (["-o", "x.mp4", "--size", "65x48"], "error: -o: an .mp4 (H.264, yuv420p) needs an even "
                                          "width and height, got 65x48; render at --size 66x48"),
    (["-o", "x_#.png", "--view", "albedo"], "error: --view: writes one buffer"),
    (["--fps", "0"], "error: Invalid value for '--fps'"),
    (["--fps", "nan"], "error: Invalid value for '--fps': 'nan' is not a finite number"),
    (["--fps", "inf"], "error: Invalid value for '--fps': inf is not in the range"),
    (["--time", "nan"], "error: Invalid value for '--time': 'nan' is not a finite number"),
    (["--time", "-1"], "error: Invalid value for '--time'"),
])
def test_bad_animation_options_exit_2(tmp_path, capsys, monkeypatch, scene_file, args,
                                      expected):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, "render", scene_file, "--frames", 2, *args)
    assert code == 2
    assert err.startswith(expected), err
    assert len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_bench_shell_sweep_holds_over_a_timeline():
    from deferred.bench.scenes import with_shells

    text = SCENE.replace('name = "ball"', 'name = "ball"\nmaterial = "revie_fur"').replace(
        "color = [0.8, 0.1, 0.1]", "shells = 8") + """
[[event]]
time = 1.0
object = "ball"
params = { shells = 32, fur_length = 0.3 }
"""
    scene = scene_from_toml(text, "s.toml")
    assert scene.objects[0].params_at(1.0).shells == 32
    swept = with_shells(scene, 4).objects[0]
    assert swept.params_at(0.0).shells == 4
    assert swept.params_at(1.0).shells == 4 and swept.params_at(1.0).fur_length == 0.3
    assert scene.objects[0].params_at(1.0).shells == 32  # the original keeps its timeline


def test_a_gif_past_the_memory_budget_is_refused_before_a_frame(tmp_path, capsys, scene_file,
                                                                 monkeypatch):
    """A GIF's frames are held until it is written (Pillow merges and crops them): their bytes
    are counted before the first frame, naming --frames and the budget, and nothing is
    written; a sequence and an .mp4 hold none. (4096x4096 x 100,000 frames was accepted.)"""
    out = tmp_path / "anim.gif"
    code, _, err = run(capsys, "render", "--size", "4096x4096", "--frames", 100000, "-o", out)
    assert code == 2 and err.strip().splitlines() == [
        "error: --frames: 100,000 frames of 4096x4096 held for a GIF take 3.1 TiB; the budget "
        "is 4.0 GiB (DEFERRED_TARGET_MEMORY): fewer frames, a smaller size, an .mp4 or a frame "
        "pattern"], err
    # 64x48 x 3 frames hold 18 KiB: refused under a 16 KiB budget, written under 64 KiB
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(16 << 10))
    code, _, err = run(capsys, "render", scene_file, "--frames", 3, "--fps", 10, "-o", out)
    assert code == 2 and "3 frames of 64x48 held for a GIF take 18.0 KiB" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]
    monkeypatch.setenv("DEFERRED_TARGET_MEMORY", str(1 << 30))
    code, _, err = run(capsys, "render", scene_file, "--frames", 3, "--fps", 10, "-o", out)
    assert code == 0, err


def test_gif_frames_held_as_palettes_write_the_file_rgb_frames_give(tmp_path):
    """The writer keeps each frame as Pillow's adaptive palette image (a byte a pixel, not
    three): the file is byte for byte the one Pillow writes from the RGB frames."""
    from PIL import Image

    from deferred.io.video import AnimationWriter

    rng = np.random.default_rng(5)
    frames = [(rng.random((30, 40, 4)) * 255).astype(np.uint8) for _ in range(3)]
    frames.append(frames[-1].copy())  # merged into the one before
    with AnimationWriter(tmp_path / "held.gif", 10.0) as writer:
        for frame in frames:
            writer.write(frame)
    rgb = [Image.fromarray(np.ascontiguousarray(f[..., :3])) for f in frames]
    rgb[0].save(tmp_path / "direct.gif", format="GIF", save_all=True, append_images=rgb[1:],
                duration=gif_durations(4, 10.0), loop=0)
    assert (tmp_path / "held.gif").read_bytes() == (tmp_path / "direct.gif").read_bytes()
