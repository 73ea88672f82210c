"""The command line's conventions: progress on stderr (throttled lines off a terminal), results
on stdout, warnings as one line, choices, refusals with the fix, diff-like exit codes, `python -m
deferred`, help that names only files that ship, the optional extras and the Python floor."""

import ast
import io
import re
import subprocess
import sys
import warnings

import numpy as np
import pytest
from locations import ROOT
from rich.console import Console

import deferred.io.progress as progress_module
from deferred.cli import cli, main
from deferred.io.images import read_channels, write_image
from deferred.io.progress import Progress, duration

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

LIGHTS_SCENE = ROOT / "benchmarks" / "lights.toml"


def run(capsys, *args):
    code = main([str(a) for a in args])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def piped():
    return Console(file=io.StringIO(), force_terminal=False, width=200)


# -- progress -------------------------------------------------------------------------------------

def test_duration_reads_as_people_say_it():
    assert [duration(s) for s in (0.2, 7.4, 60, 125, 3600, 3725)] == \
        ["1 s", "7 s", "1 min", "2 min 5 s", "1 h", "1 h 2 min"]


def test_piped_progress_prints_at_most_a_line_an_interval():
    clock, console = FakeClock(), piped()
    with Progress("bench", console, interval=5.0, clock=clock, ticker=False) as progress:
        progress.count(24, "runs", "warm-up")
        assert not progress.tick()  # nothing before the first interval
        clock.now += 5.0
        progress.advance(3, "round 1 of 10", seconds_left=40.0)
        assert progress.tick()
        clock.now += 4.9
        assert not progress.tick()  # throttled
        clock.now += 0.1
        progress.advance(6, "round 2 of 10")  # no estimate given: the rate so far
        assert progress.tick()
    lines = console.file.getvalue().splitlines()
    assert lines == ["bench: 3/24 runs, ~40 s left: round 1 of 10",
                     "bench: 6/24 runs, ~30 s left: round 2 of 10"]  # 10 s for 6: 30 s for 18


def test_an_estimate_counts_down_and_says_nothing_once_past():
    """A step that takes long does not repeat the same time left: the estimate counts down,
    and once the time is past it is "estimating time", not "~1 s left"."""
    clock, console = FakeClock(), piped()
    with Progress("bench", console, interval=5.0, clock=clock, ticker=False) as progress:
        progress.count(10, "runs", "warm-up")
        progress.advance(0, "warm-up", seconds_left=40.0)
        clock.now += 10.0
        assert progress.describe() == "0/10 runs, ~30 s left: warm-up"
        clock.now += 35.0
        assert progress.describe() == "0/10 runs, estimating time: warm-up"


def test_piped_status_says_how_long_the_step_has_taken():
    clock, console = FakeClock(), piped()
    with Progress("render", console, interval=5.0, clock=clock, ticker=False) as progress:
        progress.count(10, "frames")
        assert progress.describe() == "0/10 frames, estimating time"
        progress.status("loading s.toml (meshes, UV unwraps)")
        clock.now += 12.0
        assert progress.tick()
    assert console.file.getvalue() == "render: loading s.toml (meshes, UV unwraps) (12 s)\n"


def test_a_piped_render_that_takes_long_prints_progress_lines(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(progress_module, "LINE_INTERVAL_S", 0.01)
    code, out, err = run(capsys, "render", "--size", "64x36", "--frames", 3, "-o",
                         tmp_path / "f_#.png")
    assert code == 0, err
    assert out == ""
    lines = err.splitlines()
    assert re.search(r"^render: [0-3]/3 frames, (~.* left|estimating time): rendering f_#\.png",
                     err, re.M), err
    assert lines[-1].startswith("wrote ")
    assert all(line.startswith(("render: ", "wrote ")) for line in lines)


def test_a_quick_piped_render_prints_only_what_it_wrote(tmp_path, capsys, monkeypatch):
    # a render is "quick" by the progress interval, not by this machine's load
    monkeypatch.setattr(progress_module, "LINE_INTERVAL_S", 3600.0)
    code, _, err = run(capsys, "render", "--size", "64x36", "-o", tmp_path / "a.png")
    assert code == 0 and len(err.splitlines()) == 1 and err.startswith("wrote "), err


# -- bench ----------------------------------------------------------------------------------------

def test_bench_says_its_size_estimates_its_time_and_prints_results_on_stdout(capsys, monkeypatch):
    monkeypatch.setattr(progress_module, "LINE_INTERVAL_S", 0.01)
    code, out, err = run(capsys, "bench", LIGHTS_SCENE, "--size", "64x36", "--runs", 2,
                         "--warmup", 1, "--lights", "0,2", "--pipelines", "forward",
                         "--light-paths", "naive")
    assert code == 0, err
    lines = err.splitlines()
    assert re.fullmatch(r"bench: 2 configurations \(1 light path x 2 light counts x the "
                        r"scene's 0 shells\) x 2 runs, after 1 warm-up frame each; time: "
                        r"about \d+ s predicted", lines[0]), lines[0]
    assert any(re.fullmatch(r"bench: about .+ left, from the warm-ups and the first run "
                            r"measured", line) for line in lines), err
    assert any(re.match(r"bench: [0-4]/4 runs, ", line) for line in lines), err
    assert "median ms" in out and "median ms" not in err
    assert ", 2 runs (" in out  # --runs 2 is 2 runs in the title, not the frames timed
    assert re.search(r"^noise: a point's frames vary by", out, re.M), out
    assert "no object has a 'shells' parameter" not in err  # no --shells asked for


def test_bench_shells_default_to_the_scenes_own(gl):
    from deferred.bench.harness import Sweep, own_shells, run_bench, sweep_shells
    from deferred.scene.loader import load_scene

    demo = load_scene(None)
    own = {obj.material.params.shells for obj in demo.objects
           if "shells" in type(obj.material.params).model_fields}
    assert own and own_shells(demo) == max(own)
    assert sweep_shells(demo, None) == [max(own)]
    assert sweep_shells(demo, [0, 16]) == [0, 16]
    lights = load_scene(LIGHTS_SCENE)
    assert sweep_shells(lights, None) == [0]
    report = run_bench(demo, Sweep(lights=[0], runs=1, warmup=0, light_paths=["naive"],
                                   pipelines=["forward"], size=(32, 18), round_ms=0.0), gl=gl)
    assert [r.shells for r in report.results] == [max(own)]


def test_bench_refuses_a_bad_sweep_before_saying_its_size(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "bench", "--shells", "0,999", "--size", "16x9", "--runs", 1)
    assert code == 2 and out == ""
    assert err.splitlines() == [err.strip()] and "--shells:" in err and "bench:" not in err


# -- warnings -------------------------------------------------------------------------------------

def test_a_warning_is_one_line_without_a_source_path(tmp_path, capsys, monkeypatch):
    import deferred.cli.render as render_module

    load = render_module.load_scene

    def warning_load(path, **options):
        warnings.warn("something odd\nover two lines", UserWarning, stacklevel=1)
        return load(path, **options)

    monkeypatch.setattr(render_module, "load_scene", warning_load)
    code, _, err = run(capsys, "render", "--size", "32x18", "-o", tmp_path / "a.png")
    assert code == 0, err
    assert err.splitlines()[0] == "warning: something odd\\nover two lines"
    assert "UserWarning" not in err and ".py:" not in err


# -- choices, refusals, exit codes ----------------------------------------------------------------

@pytest.mark.parametrize("command", [["render"], ["dump", "-o", "d"]])
def test_light_path_is_a_choice(tmp_path, capsys, monkeypatch, command):
    monkeypatch.chdir(tmp_path)
    code, _, err = run(capsys, *command, "--light-path", "tild")
    assert code == 2 and list(tmp_path.iterdir()) == []
    assert err == ("error: Invalid value for '--light-path': 'tild' is not one of 'volumes', "
                   "'tiled', 'clustered', 'naive'.\n")
    code, out, _ = run(capsys, command[0], "--help")
    assert code == 0 and "[volumes|tiled|clustered|naive]" in out


def test_view_with_frames_is_refused(tmp_path, capsys):
    code, _, err = run(capsys, "render", "--view", "normal", "--frames", 2, "-o",
                       tmp_path / "n.png")
    assert code == 2 and err.startswith("error: --frames: --view writes one buffer of one frame")
    assert list(tmp_path.iterdir()) == []


@pytest.fixture(scope="module")
def two_dumps(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dumps")
    assert main(["dump", "-o", str(folder / "a"), "--size", "32x18", "--light-path",
                 "volumes"]) == 0
    return folder


@pytest.mark.slow
def test_dump_compare_exits_as_diff(two_dumps, capsys, tmp_path):
    import shutil

    a = two_dumps / "a"
    same, changed = tmp_path / "same", tmp_path / "changed"
    shutil.copytree(a, same)
    shutil.copytree(a, changed)
    pixels, names, _ = read_channels(changed / "final.exr")
    pixels[0, 0, 0] += 0.25
    write_image(changed / "final.exr", pixels, channels=names)
    assert run(capsys, "dump", "--compare", a, same)[0] == 0
    code, out, err = run(capsys, "dump", "--compare", a, changed)
    assert code == 1, err
    assert "1 of" in err and "final.exr" in out
    code, _, err = run(capsys, "dump", "--compare", a, tmp_path / "missing")
    assert code == 2 and err == f"error: {tmp_path / 'missing'}: not a folder\n"
    code, out, _ = run(capsys, "dump", "--help")
    assert "1 they differ" in " ".join(out.split())


@pytest.mark.slow
def test_python_m_deferred_is_the_command(tmp_path):
    done = subprocess.run([sys.executable, "-m", "deferred", "render", "--frames", "2", "-o",
                           str(tmp_path / "x.png")], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("error: --frames: 2 frames cannot go to one image")
    done = subprocess.run([sys.executable, "-m", "deferred", "--help"], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0 and "Usage: deferred" in done.stdout


def _help_texts():
    import click

    ctx = click.Context(cli, info_name="deferred")
    yield "deferred", cli.get_help(ctx)
    for name, command in cli.commands.items():
        yield name, command.get_help(click.Context(command, info_name=name, parent=ctx))


def test_help_names_only_files_that_ship():
    for name, text in _help_texts():
        text = " ".join(text.split())  # help wraps at any space
        for mentioned in re.findall(r"[\w./-]+\.md\b", text):
            assert (ROOT / mentioned).is_file(), f"{name} --help names {mentioned}"
        assert "DESIGN.md" not in text


# -- the extras -----------------------------------------------------------------------------------

def test_mp4_without_the_video_extra_names_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "imageio_ffmpeg", None)  # not installed
    code, _, err = run(capsys, "render", "--frames", 2, "-o", tmp_path / "a.mp4")
    assert code == 2 and list(tmp_path.iterdir()) == []
    assert err == ("error: -o: writing .mp4 needs the video extra: pip install "
                   "'deferred[video]'\n")


def test_plot_without_the_plot_extra_names_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    code, _, err = run(capsys, "bench", "--plot", tmp_path / "p.png", "--lights", "0",
                       "--runs", 1, "--size", "16x9")
    assert code == 2 and list(tmp_path.iterdir()) == []
    assert err == "error: --plot: a plot needs the plot extra: pip install 'deferred[plot]'\n"


def test_previews_need_no_plotting_library(monkeypatch):
    """Turbo and tab10 are the tables matplotlib gives; labels come from Pillow's font."""
    from matplotlib import colormaps

    turbo = colormaps["turbo"](np.linspace(0.0, 1.0, 256))[:, :3]
    tab10 = np.asarray(colormaps["tab10"].colors)
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    from deferred.debug.preview import heat_colors, id_colors, text_mask

    np.testing.assert_allclose(heat_colors(np.linspace(0.0, 1.0, 256)[1:]), turbo[1:],
                               atol=1e-6)
    np.testing.assert_allclose(id_colors(np.arange(1, 11, dtype=np.float32)), tab10, atol=1e-6)
    mask = text_mask("03 ball.gbuffer", 12)
    assert mask is not None and 8 <= mask.shape[0] <= 16 and mask.max() > 0.9


@pytest.mark.parametrize("pixels", [10, 12, 16])
def test_labels_keep_their_spaces(pixels):
    """The bundled font's space is 2 pixels at label sizes ("withoutself-shadowing" in the
    figures): words in a label stand at least a third of the text's height apart, and a
    labelled figure shows the text in its corner on its box."""
    from deferred.debug.preview import labelled, text_mask

    mask = text_mask("without self", pixels)
    columns = mask.max(axis=0) > 0.1
    gaps, run = [], 0
    for inked in columns:
        if inked:
            if run:
                gaps.append(run)
            run = 0
        else:
            run += 1
    assert max(gaps) >= pixels / 3.0
    assert mask.shape[1] > text_mask("withoutself", pixels).shape[1] + pixels / 3.0
    image = labelled(np.full((40, 200, 3), 128, np.uint8), "without self", pixels)
    assert image.dtype == np.uint8 and image.shape == (40, 200, 3)
    assert image[1, 1].tolist() == [0, 0, 0] and image[:, :mask.shape[1]].max() > 240
    assert (image[-5:] == 128).all()


def test_the_declared_dependencies_and_extras():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    core = {re.match(r"[\w.-]+", d).group(0).lower() for d in project["dependencies"]}
    extras = project["optional-dependencies"]
    assert not core & {"matplotlib", "imageio", "imageio-ffmpeg"} and "pillow" in core
    assert any(d.startswith("imageio-ffmpeg") for d in extras["video"])
    assert any(d.startswith("matplotlib") for d in extras["plot"])
    assert any(d.startswith("moderngl-window") for d in extras["viewer"])
    assert any(d.startswith("ray") for d in extras["ray"]) and "ray" not in core
    # the README's test command: them all, and the documentation site's tools
    assert "deferred[video,plot,viewer,docs,ray]" in extras["dev"]
    assert any(d.startswith("mkdocs>=") for d in extras["docs"])
    assert project["requires-python"] == ">=3.10"
    assert "tomli>=2.0; python_version < '3.11'" in project["dependencies"]


# -- the Python floor -----------------------------------------------------------------------------

NEW_IN_311 = {"tomllib", "importlib.resources.abc", "wsgiref.types"}
NAMES_NEW_IN_311 = {
    "typing": {"Self", "LiteralString", "Never", "assert_never", "assert_type", "reveal_type",
               "TypeVarTuple", "Unpack", "Required", "NotRequired", "dataclass_transform"},
    "enum": {"StrEnum", "ReprEnum", "verify", "member", "nonmember", "global_enum", "EnumCheck"},
    "datetime": {"UTC"}, "contextlib": {"chdir"}, "hashlib": {"file_digest"},
    "asyncio": {"TaskGroup", "timeout", "Runner"},
}


def _version_guarded(node, parents):
    """Whether an import sits under ``if sys.version_info ...`` (either branch)."""
    return any(isinstance(p, ast.If) and "version_info" in ast.unparse(p.test) for p in parents)


def _walk_with_parents(tree):
    stack = [(tree, [])]
    while stack:
        node, parents = stack.pop()
        yield node, parents
        for child in ast.iter_child_nodes(node):
            stack.append((child, [*parents, node]))


@pytest.mark.slow
def test_the_code_runs_on_python_3_10():
    """requires-python says 3.10: no syntax newer than 3.10 and no module or name 3.11 added
    unless under a version check (tomllib falls back on tomli)."""
    problems = []
    for folder in ("deferred", "materials", "lights"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            source = path.read_text(encoding="utf-8")
            where = path.relative_to(ROOT)
            try:
                tree = ast.parse(source, feature_version=(3, 10))
            except SyntaxError as exc:
                problems.append(f"{where}: {exc}")
                continue
            for node, parents in _walk_with_parents(tree):
                if _version_guarded(node, parents):
                    continue
                if isinstance(node, ast.Import):
                    problems += [f"{where}:{node.lineno}: import {a.name}" for a in node.names
                                 if a.name in NEW_IN_311]
                elif isinstance(node, ast.ImportFrom) and node.module:
                    if node.module in NEW_IN_311:
                        problems.append(f"{where}:{node.lineno}: from {node.module}")
                    new = NAMES_NEW_IN_311.get(node.module, set())
                    problems += [f"{where}:{node.lineno}: {node.module}.{a.name}"
                                 for a in node.names if a.name in new]
                elif isinstance(node, ast.ExceptHandler) and "ExceptionGroup" in \
                        ast.unparse(node.type or ast.Constant(None)):
                    problems.append(f"{where}:{node.lineno}: ExceptionGroup")
    assert problems == []
