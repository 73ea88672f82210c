"""Issue #40: a sequence's frames on local worker processes (``--workers N``) and on a local Ray
instance (``--ray``) are byte-identical to one process's (simulations, a temporal history);
``--resume`` renders only the missing frames; a killed worker's frames are rendered again and
no torn frame is ever visible; workers need only the scene's bytes."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from command_line import assert_one_line_error, leftovers, run
from farm_scenes import FUR, HAIR, TAA, frames, write_scene

from deferred.farm.manifest import manifest_path

FRAMES = 12


def render_frames(capsys, scene: Path, out: Path, count: int, *options) -> str:
    out.mkdir(exist_ok=True)
    code, _, err = run(capsys, "render", scene, "--frames", count, "-o", out / "f_##.png",
                       *options)
    assert code == 0, err
    return err


def distributed(request, kind: str) -> tuple[str, ...]:
    if kind == "ray":
        request.getfixturevalue("local_ray")
        return ("--ray", "--workers", "2")
    return ("--workers", "2")


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["workers", "ray"])
@pytest.mark.parametrize("text, count", [(FUR, FRAMES), (TAA, 6), (HAIR, 6)],
                         ids=["shell_fur", "taa", "cartoon_hair"])
def test_distributed_frames_are_the_single_process_frames(tmp_path, capsys, request, kind,
                                                          text, count):
    scene = write_scene(tmp_path, text)
    render_frames(capsys, scene, tmp_path / "one", count)
    err = render_frames(capsys, scene, tmp_path / "many", count, *distributed(request, kind))
    assert f"over {count} frames" in err
    single, many = frames(tmp_path / "one"), frames(tmp_path / "many")
    assert len(single) == count and many == single
    # the frames differ: the wind, the wetting, the head turning and the history show
    assert len(set(single.values())) == count
    assert manifest_path(tmp_path / "many" / "f_##.png").is_file()
    assert leftovers(tmp_path) == []


@pytest.mark.slow
def test_resume_renders_only_missing_frames_and_equals_an_uninterrupted_run(tmp_path, capsys):
    scene = write_scene(tmp_path, FUR)
    render_frames(capsys, scene, tmp_path / "one", FRAMES + 2)
    reference = frames(tmp_path / "one")
    out = tmp_path / "resumed"
    render_frames(capsys, scene, out, FRAMES, "--workers", "2", "--resume")
    # as a stopped run leaves it: frames missing, one not yet recorded in the manifest
    for name in ("f_03.png", "f_07.png", "f_08.png"):
        (out / name).unlink()
    (out / "f_10.png").write_bytes(b"not the frame")  # replaced since: rendered again
    kept = {path.name: (path.read_bytes(), path.stat().st_mtime_ns)
            for path in out.glob("f_*.png") if path.name != "f_10.png"}
    time.sleep(0.05)
    err = render_frames(capsys, scene, out, FRAMES, "--workers", "2", "--resume")
    assert f"resuming: {len(kept)} of {FRAMES} frames are done, 4 to render" in err
    assert "over 4 frames" in err
    for name, (data, mtime) in kept.items():
        assert (out / name).read_bytes() == data and (out / name).stat().st_mtime_ns == mtime
    assert frames(out) == {name: reference[name] for name in list(reference)[:FRAMES]}
    # nothing missing: nothing rendered
    err = render_frames(capsys, scene, out, FRAMES, "--resume")
    assert "every frame was done already" in err
    # more frames of the same run: the frames done are kept
    err = render_frames(capsys, scene, out, FRAMES + 2, "--resume")
    assert f"resuming: {FRAMES} of {FRAMES + 2} frames are done, 2 to render" in err
    assert frames(out) == reference


def test_resume_refuses_frames_of_other_options(tmp_path, capsys):
    scene = write_scene(tmp_path, TAA)
    render_frames(capsys, scene, tmp_path, 2, "--resume")
    code, _, err = run(capsys, "render", scene, "--frames", 2, "-o", tmp_path / "f_##.png",
                       "--resume", "--size", "40x30")
    assert_one_line_error(code, err, "--resume: f_##.manifest.jsonl: the frames were rendered "
                          "from something else (size was None, now [40, 30])")
    code, _, err = run(capsys, "render", scene, "--frames", 2, "-o", tmp_path / "f_##.png",
                       "--resume", "--fps", 30)
    assert_one_line_error(code, err, "fps was 24.0, now 30.0")
    scene.write_text(TAA.replace("scale = 0.6", "scale = 0.5"))
    code, _, err = run(capsys, "render", scene, "--frames", 2, "-o", tmp_path / "f_##.png",
                       "--resume")
    assert_one_line_error(code, err, "the scene or a file it reads changed")


def test_farm_options_need_a_sequence_and_the_ray_extra(tmp_path, capsys, monkeypatch):
    code, _, err = run(capsys, "render", "--workers", 2, "-o", tmp_path / "one.png")
    assert_one_line_error(code, err, "--workers: renders the frames of a sequence or a video")
    monkeypatch.setitem(sys.modules, "ray", None)  # not installed
    code, _, err = run(capsys, "render", "--ray", "--frames", 2, "-o", tmp_path / "f_#.png")
    assert_one_line_error(code, err, "--ray: --ray needs the ray extra: pip install "
                          "'deferred[ray]'")
    assert list(tmp_path.iterdir()) == []


def test_a_frame_failing_for_its_own_reason_stops_the_run_naming_it(tmp_path):
    from rich.console import Console

    from deferred.errors import InputError
    from deferred.farm.bundle import SceneBundle
    from deferred.farm.pools import Idle
    from deferred.farm.sequence import render_sequence
    from deferred.farm.worker import FrameDone, FrameFailed, FrameJob
    from deferred.io.progress import Progress

    class FailingAtTwo:
        names = ["w"]

        def __init__(self):
            self.chunks = []

        def assign(self, worker, chunk):
            self.chunks.append(list(chunk))

        def idle(self):
            return [] if self.chunks else ["w"]

        def events(self, timeout):
            for index in self.chunks.pop(0):
                if index == 2:
                    yield FrameFailed(2, "texture.png: cannot read", True, "w")
                    return
                yield FrameDone(index, b"frame", 1.0, "w")
            yield Idle("w")

        def close(self):
            pass

    job = FrameJob(SceneBundle(None), "deferred", None, [0.0, 0.5, 1.0, 1.5], 2.0, 0.0)
    with Progress("render", Console(file=open(os.devnull, "w"))) as progress:  # noqa: SIM115
        with pytest.raises(InputError, match=r"^frame 2 \(t = 1 s\): texture.png: cannot "
                                             r"read$"):
            render_sequence(job, tmp_path / "f_#.png", "sequence", FailingAtTwo, progress,
                            False, False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f_#.manifest.jsonl", "f_0.png",
                                                          "f_1.png"]


def test_chunks_are_runs_of_missing_frames():
    from deferred.farm.sequence import plan_chunks

    assert plan_chunks(list(range(8)), 1, False) == [[0, 1], [2, 3], [4, 5], [6, 7]]
    assert plan_chunks([0, 1, 2, 5, 6, 9], 2, False) == [[0], [1], [2], [5], [6], [9]]
    assert plan_chunks([0, 1, 2, 5, 6, 9], 1, False) == [[0, 1], [2], [5, 6], [9]]
    assert plan_chunks([3, 4, 8], 4, True) == [[3, 4, 8]]  # a history: one chunk


def _children(pid: int) -> list[int]:
    children = []
    for task in Path(f"/proc/{pid}/task").iterdir():
        text = (task / "children").read_text().split()
        children.extend(int(child) for child in text)
    return children


def _command_line(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux's /proc")
def test_a_worker_killed_mid_frame_is_replaced_and_no_torn_frame_shows(tmp_path, capsys):
    scene = write_scene(tmp_path, FUR)
    render_frames(capsys, scene, tmp_path / "one", FRAMES)
    reference = frames(tmp_path / "one")
    out = tmp_path / "killed"
    out.mkdir()
    driver = subprocess.Popen([sys.executable, "-m", "deferred", "render", str(scene),
                               "--frames", str(FRAMES), "-o", str(out / "f_##.png"),
                               "--workers", "2"], stderr=subprocess.PIPE, text=True)
    torn: list[str] = []
    stop = threading.Event()

    def watch() -> None:  # every frame visible is whole: the reference's bytes
        while not stop.is_set():
            for path in out.glob("f_*.png"):
                try:
                    data = path.read_bytes()
                except FileNotFoundError:
                    continue
                if data != reference[path.name]:
                    torn.append(path.name)

    watcher = threading.Thread(target=watch)
    watcher.start()
    try:
        killed = None
        deadline = time.monotonic() + 300
        while killed is None and time.monotonic() < deadline and driver.poll() is None:
            workers = [pid for pid in _children(driver.pid)
                       if "spawn_main" in _command_line(pid)]
            if len(workers) == 2 and any(out.glob("f_*.png")):
                os.kill(workers[0], signal.SIGKILL)  # busy: frames are pending
                killed = workers[0]
            time.sleep(0.02)
        _, err = driver.communicate(timeout=600)
    finally:
        stop.set()
        watcher.join()
    assert killed is not None and driver.returncode == 0, err
    assert "died (killed by SIGKILL) before frame" in err
    assert torn == [] and frames(out) == reference
    assert leftovers(tmp_path) == []


@pytest.mark.slow
def test_workers_need_only_the_scenes_bytes(tmp_path, capsys, monkeypatch):
    """A scene with a mesh and a texture beside it renders on workers after its folder is gone
    (each worker loads the files it was sent, in a folder of its own)."""
    from rich.console import Console

    from deferred.farm.bundle import bundle_scene
    from deferred.farm.pools import ProcessPool
    from deferred.farm.sequence import render_sequence
    from deferred.farm.worker import FrameJob
    from deferred.io.images import write_image
    from deferred.io.progress import Progress
    from deferred.scene.loader import load_scene

    source = tmp_path / "source"
    (source / "meshes").mkdir(parents=True)
    (source / "textures").mkdir()
    (source / "meshes" / "quad.obj").write_text(
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
        "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")
    checker = np.kron(np.indices((4, 4)).sum(axis=0) % 2, np.ones((8, 8)))
    write_image(source / "textures" / "checker.png",
                np.repeat((checker * 255).astype(np.uint8)[..., None], 4, axis=2))
    scene = write_scene(source, """
size = [40, 30]
[camera]
position = [0.0, 0.0, 3.0]
target = [0.0, 0.0, 0.0]
[[object]]
name = "quad"
mesh = "meshes/quad.obj"
[object.params]
texture = "../source/textures/checker.png"
[[track]]
target = "object:quad"
keys = [{ time = 0.0, rotation = [0.0, 0.0, 0.0] }, { time = 1.0, rotation = [0.0, 0.0, 90.0] }]
[[light]]
type = "ambient"
""")
    render_frames(capsys, scene, tmp_path / "one", 3, "--fps", 4)
    loaded = load_scene(str(scene))
    bundle = bundle_scene(str(scene), loaded)
    assert sorted(bundle.files) == ["source/meshes/quad.obj", "source/scene.toml",
                                    "source/textures/checker.png"]
    shutil.move(source, tmp_path / "gone")  # no shared file system: the workers have the bytes
    out = tmp_path / "many"
    out.mkdir()
    job = FrameJob(bundle, "deferred", None, [0.0, 0.25, 0.5], 4.0, 0.0)
    with Progress("render", Console(file=open(os.devnull, "w"))) as progress:  # noqa: SIM115
        render_sequence(job, out / "f_##.png", "sequence", lambda: ProcessPool(job, 2),
                        progress, False, False)
    assert frames(out) == frames(tmp_path / "one")
    assert len(set(frames(out).values())) == 3


def _ray_actors() -> list[int]:
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit() and _command_line(int(entry.name)).startswith("ray::RenderActor"):
            found.append(int(entry.name))
    return found


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux's /proc")
def test_a_ray_actor_killed_mid_frame_is_restarted_and_its_frames_asked_again(
        tmp_path, capsys, local_ray):
    from deferred.cli import main

    scene = write_scene(tmp_path, FUR)
    render_frames(capsys, scene, tmp_path / "one", FRAMES)
    out = tmp_path / "killed"
    out.mkdir()
    codes = []
    driver = threading.Thread(target=lambda: codes.append(main(
        ["render", str(scene), "--frames", str(FRAMES), "-o", str(out / "f_##.png"), "--ray",
         "--workers", "2"])))
    driver.start()
    killed = None
    deadline = time.monotonic() + 300
    while killed is None and driver.is_alive() and time.monotonic() < deadline:
        actors = _ray_actors()
        if actors and any(out.glob("f_*.png")):
            os.kill(actors[0], signal.SIGKILL)
            killed = actors[0]
        time.sleep(0.02)
    driver.join(timeout=600)
    err = capsys.readouterr().err
    assert killed is not None and codes == [0], err
    assert frames(out) == frames(tmp_path / "one")
    assert leftovers(tmp_path) == []


@pytest.mark.slow
def test_a_video_is_made_from_the_finished_frames(tmp_path, capsys):
    scene = write_scene(tmp_path, TAA)
    code, _, err = run(capsys, "render", scene, "--frames", 3, "-o", tmp_path / "one.gif")
    assert code == 0, err
    code, _, err = run(capsys, "render", scene, "--frames", 3, "-o", tmp_path / "many.gif",
                       "--workers", "2", "--resume")
    assert code == 0, err
    assert (tmp_path / "many.gif").read_bytes() == (tmp_path / "one.gif").read_bytes()
    # the frames and their manifest were kept beside the video until it was written
    assert sorted(p.name for p in tmp_path.iterdir()) == ["many.gif", "one.gif", "scene.toml"]


@pytest.mark.slow
def test_ctrl_c_leaves_whole_frames_that_resume_keeps(tmp_path, capsys):
    scene = write_scene(tmp_path, FUR)
    render_frames(capsys, scene, tmp_path / "one", FRAMES)
    out = tmp_path / "stopped"
    out.mkdir()
    command = [sys.executable, "-m", "deferred", "render", str(scene), "--frames", str(FRAMES),
               "-o", str(out / "f_##.png"), "--workers", "2", "--resume"]
    driver = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while len(list(out.glob("f_*.png"))) < 3 and driver.poll() is None and \
            time.monotonic() < deadline:
        time.sleep(0.02)
    driver.send_signal(signal.SIGINT)
    _, err = driver.communicate(timeout=120)
    assert driver.returncode == 130 and err.strip().splitlines()[-1] == "interrupted", err
    done = {path.name: (path.read_bytes(), path.stat().st_mtime_ns)
            for path in out.glob("f_*.png")}
    assert 3 <= len(done) < FRAMES and leftovers(tmp_path) == []
    reference = frames(tmp_path / "one")
    assert all(data == reference[name] for name, (data, _) in done.items())
    err = render_frames(capsys, scene, out, FRAMES, "--workers", "2", "--resume")
    assert f"over {FRAMES - len(done)} frames" in err
    assert all((out / name).stat().st_mtime_ns == mtime for name, (_, mtime) in done.items())
    assert frames(out) == reference
