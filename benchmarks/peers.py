"""The peers' comparison: the deferred pipeline (tiled light lists) against a hand-written
moderngl forward renderer (``benchmarks/peers/forward.*``: one program, every point light
looped per fragment, no framework) on a torus over a floor lit by one directional light and N
point lights, at 640x360. Frames of the two are interleaved, each timed by the wall clock
around ``ctx.finish()``; the medians and their ratio.

    python benchmarks/peers.py [--lights 16,85] [--size 640x360] [--rounds 5]
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import moderngl
import numpy as np

from deferred import Renderer
from deferred.scene.loader import scene_from_dict
from deferred.scene.size import parse_size

HERE = Path(__file__).parent / "peers"
SUN = {"type": "directional", "direction": [-0.5, -1.0, -0.3], "intensity": 1.0,
       "color": [1.0, 0.95, 0.9]}
AMBIENT = {"type": "ambient", "color": [0.1, 0.1, 0.12], "ground": [0.1, 0.1, 0.12]}


def point_lights(count: int) -> list[dict]:
    rng = np.random.default_rng(7)
    return [{"type": "point", "position": [float(rng.uniform(-2, 2)), float(rng.uniform(0.1, 1.0)),
                                           float(rng.uniform(-2, 2))],
             "radius": float(rng.uniform(1.0, 2.0)), "intensity": 1.0,
             "color": [float(c) for c in rng.uniform(0.2, 1.0, 3)]} for _ in range(count)]


def scene(count: int, size: tuple[int, int]):
    return scene_from_dict({
        "size": list(size),
        "camera": {"position": [0.0, 1.6, 3.6], "target": [0.0, 0.3, 0.0], "fov": 45.0},
        "object": [{"mesh": "builtin:plane", "scale": 6.0, "params": {"color": [0.5, 0.5, 0.5]}},
                   {"mesh": "builtin:torus", "position": [0.0, 0.5, 0.0],
                    "params": {"color": [0.8, 0.4, 0.3]}}],
        "light": [AMBIENT, SUN, *point_lights(count)]})


class HandWrittenForward:
    """The scene's objects drawn by one program looping over every light."""

    def __init__(self, ctx: moderngl.Context, renderer: Renderer, lights: list[dict]):
        self.ctx = ctx
        self.program = ctx.program(vertex_shader=(HERE / "forward.vert").read_text(),
                                   fragment_shader=(HERE / "forward.frag").read_text())
        width, height = renderer.size
        self.fbo = ctx.framebuffer([ctx.renderbuffer((width, height), 4)],
                                   ctx.depth_renderbuffer((width, height)))
        state = renderer.state
        camera = state.camera
        view_projection = camera.projection(width / height) @ camera.view()
        self.objects = []
        for obj in state.objects:
            mesh = obj.mesh
            vertices = np.hstack([mesh.positions, mesh.normals]).astype("f4")
            vbo = ctx.buffer(vertices.tobytes())
            ibo = ctx.buffer(np.asarray(mesh.indices, "u4").tobytes())
            vao = ctx.vertex_array(self.program, [(vbo, "3f 3f", "in_position", "in_normal")],
                                   index_buffer=ibo, index_element_size=4)
            self.objects.append((vao, np.asarray(obj.model, "f4"),
                                 tuple(obj.material.params.color)))
        points = [light for light in lights if light["type"] == "point"]
        packed = np.zeros((128 * 2, 4), "f4")
        for index, light in enumerate(points):
            packed[2 * index] = (*light["position"], light["radius"])
            packed[2 * index + 1] = (*light["color"], 0.0)
        direction = -np.asarray(SUN["direction"], "f4")
        self.program["u_view_projection"].write(view_projection.T.astype("f4").tobytes())
        self.program["u_eye"].value = tuple(camera.position)
        self.program["u_sun_direction"].value = tuple(direction / np.linalg.norm(direction))
        self.program["u_sun_color"].value = tuple(SUN["color"])
        self.program["u_ambient"].value = tuple(AMBIENT["color"])
        self.program["u_count"].value = len(points)
        self.program["u_lights"].write(packed.tobytes())

    def render(self) -> None:
        ctx = self.ctx
        self.fbo.use()
        self.fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        # the framework's renderer on the same context leaves its own state: set this one's
        ctx.enable_only(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        ctx.scissor = None
        for vao, model, color in self.objects:
            self.program["u_model"].write(model.T.tobytes())
            self.program["u_color"].value = color
            vao.render()
        ctx.enable_only(moderngl.NOTHING)


def timed(render, ctx: moderngl.Context, frames: int = 5) -> float:
    times = []
    for _ in range(frames):
        start = time.perf_counter()
        render()
        ctx.finish()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--lights", default="16,85")
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    size = parse_size(args.size)
    for count in (int(v) for v in args.lights.split(",")):
        the_scene = scene(count, size)
        with Renderer(the_scene, "deferred", size, light_path="tiled") as renderer:
            renderer.render(readback=False)
            ctx = renderer.gl.ctx
            forward = HandWrittenForward(ctx, renderer, [AMBIENT, SUN, *point_lights(count)])
            forward.render()
            ctx.finish()
            results: dict[str, list[float]] = {"deferred": [], "forward": []}
            for _ in range(args.rounds):
                renderer.gl.make_current()
                results["deferred"].append(timed(lambda: renderer.render(readback=False), ctx))
                results["forward"].append(timed(forward.render, ctx))
        deferred_ms = statistics.median(results["deferred"]) * 1000
        forward_ms = statistics.median(results["forward"]) * 1000
        spread = {k: f"{min(v) * 1000:.1f}-{max(v) * 1000:.1f}" for k, v in results.items()}
        print(f"{count} point lights, {size[0]}x{size[1]}: deferred tiled {deferred_ms:.1f} ms "
              f"({spread['deferred']}), hand-written forward {forward_ms:.1f} ms "
              f"({spread['forward']}): deferred {forward_ms / deferred_ms:.2f}x ahead")


if __name__ == "__main__":
    main()
