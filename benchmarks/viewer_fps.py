"""The viewer's frame rate under moderngl-window's headless window: while orbiting (a synthetic
mouse drag every frame, so every frame is a reduced render) and idle (nothing changes: the
panels alone are drawn), and the full frame drawn when input stops.

Each window frame is timed by the wall clock around ``ctx.finish()``: the viewer's tick (the
render, when one is due) and its draw (viewport and panels); and by the process's CPU time
(llvmpipe's threads included), which other users of a shared machine move less.

    python benchmarks/viewer_fps.py [SCENE ...] [--size 1280x720] [--reduce 2,3,4] [--frames N]
"""

from __future__ import annotations

import argparse
import statistics
import time

from deferred.scene.size import parse_size
from deferred.viewer.app import Viewer, ViewerOptions
from deferred.viewer.session import Session
from deferred.viewer.window import make_window, window_size


def window_frames(viewer: Viewer, frames: int, orbit: bool,
                  cpu: list[float] | None = None) -> list[float]:
    times = []
    x, y = viewer.viewport_rect().x + 100, 100
    if orbit:
        viewer.input.mouse_press(x, y, 1)
    for index in range(frames):
        start, cpu_start = time.perf_counter(), time.process_time()
        if orbit:
            viewer.input.mouse_drag(x + index, y, 4, 0)  # keeps the input recent: reduced frames
        viewer.tick()
        viewer.draw()
        viewer.ctx.finish()
        times.append(time.perf_counter() - start)
        if cpu is not None:
            cpu.append(time.process_time() - cpu_start)
    if orbit:
        viewer.input.mouse_release(x, y, 1)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenes", nargs="*", default=[None])
    parser.add_argument("--size", default="1280x720")
    parser.add_argument("--reduce", default="2,4,auto")
    parser.add_argument("--frames", type=int, default=20)
    args = parser.parse_args()
    size = parse_size(args.size)
    for scene in args.scenes:
        session = Session(scene or None)
        window = make_window(window_size(size), headless=True)
        viewer = Viewer(session, window, ViewerOptions(size=size))
        try:
            start = time.perf_counter()
            viewer.update(force_full=True)
            viewer.ctx.finish()
            first = time.perf_counter() - start
            full = []
            for _ in range(3):  # the full frame again (a changed time forces it)
                viewer.timeline.scrub(viewer.timeline.time + 1e-3)
                start = time.perf_counter()
                viewer.update(force_full=True)
                viewer.ctx.finish()
                full.append(time.perf_counter() - start)
            name = scene or "the demo"
            print(f"{name} at {size[0]}x{size[1]}: first frame {first * 1000:.0f} ms "
                  f"(compiling), full frame median {statistics.median(full) * 1000:.0f} ms")
            for reduce in args.reduce.split(","):
                viewer.adaptive = reduce == "auto"
                if not viewer.adaptive:
                    viewer.reduce = int(reduce)
                window_frames(viewer, 8, orbit=True)  # compiling; the adaptive one settles
                cpu: list[float] = []
                orbiting = window_frames(viewer, args.frames, orbit=True, cpu=cpu)
                what = f"adaptive, settled at 1/{viewer.reduce}" if viewer.adaptive \
                    else f"1/{reduce}"
                print(f"  orbiting, frames {what}: {1.0 / statistics.median(orbiting):.1f} "
                      f"fps (median {statistics.median(orbiting) * 1000:.0f} ms, CPU "
                      f"{statistics.median(cpu) * 1000:.0f} ms)")
            viewer.last_input = -1e9
            viewer.update()  # the refined frame, then nothing changes
            cpu = []
            idle = window_frames(viewer, args.frames, orbit=False, cpu=cpu)
            print(f"  idle (panels only): {1.0 / statistics.median(idle):.1f} fps "
                  f"(median {statistics.median(idle) * 1000:.1f} ms, CPU "
                  f"{statistics.median(cpu) * 1000:.1f} ms)")
        finally:
            viewer.close()
            window.destroy()


if __name__ == "__main__":
    main()
