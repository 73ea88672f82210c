"""The pass graph: a pipeline's ordered passes, checked before any GL work.

Every pass declares the targets it creates (format, size, clear value), reads and writes
(Falcor's render-pass reflection is the model). :func:`compile_graph` walks the passes in order
and refuses, naming the pass and the target:

- two passes with one name;
- a target created twice;
- a read or write of a target no pass creates (an unknown target);
- a read or write before the pass that creates the target (no earlier producer);
- a target sampled by the pass that draws into it (a GL feedback loop: snapshot it first with
  :func:`deferred.core.passes.copy_pass`);
- a pass writing G-buffer surfaces (the surface id's target) with no depth target: the
  deferred lighting runs where the depth is nearer than the far plane
  (:func:`deferred.interfaces.light.surface_pass`), so such a surface would go unlit. (One
  that tests against the depth without writing it draws over surfaces already there.)

What it returns is every target of the frame with its format: the renderer creates exactly
those, and clears each when its creating pass runs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from deferred.core.passes import RenderPass
from deferred.errors import RenderError
from deferred.gbuffer.layout import DEPTH, NORMAL_EXPONENT_ID
from deferred.gl.target_spec import TargetSpec


class PassGraphError(RenderError):
    """A pass list whose declarations do not hold together."""


@dataclass
class PassGraph:
    passes: list[RenderPass]
    targets: dict[str, TargetSpec]  # every target, in creation order
    creators: dict[str, str]  # target -> the pass that creates it

    def index(self, name: str) -> int:
        for index, render_pass in enumerate(self.passes):
            if render_pass.name == name:
                return index
        raise PassGraphError(f"no pass is named '{name}' (passes: "
                             f"{', '.join(p.name for p in self.passes)})")


def compile_graph(passes: Sequence[RenderPass]) -> PassGraph:
    """Check ``passes`` (in order) and collect the targets they create."""
    names: set[str] = set()
    creators: dict[str, str] = {}
    targets: dict[str, TargetSpec] = {}
    for render_pass in passes:
        if render_pass.name in names:
            raise PassGraphError(f"two passes are named '{render_pass.name}'")
        names.add(render_pass.name)
        for target, spec in render_pass.creates.items():
            if target in creators:
                raise PassGraphError(f"pass {render_pass.name}: creates target '{target}', "
                                     f"which pass {creators[target]} already creates")
            creators[target] = render_pass.name
            targets[target] = spec
    created: set[str] = set()
    for render_pass in passes:
        created.update(render_pass.creates)
        for target in render_pass.samples:
            if target in render_pass.writes:
                raise PassGraphError(f"pass {render_pass.name}: samples target '{target}' while "
                                     "writing it (snapshot it first with copy_pass)")
        if NORMAL_EXPONENT_ID in render_pass.writes and DEPTH not in render_pass.writes \
                and DEPTH not in render_pass.reads:
            raise PassGraphError(f"pass {render_pass.name}: writes G-buffer surfaces "
                                 f"('{NORMAL_EXPONENT_ID}') with no '{DEPTH}': the lighting "
                                 "runs only where a surface's depth was written")
        for kind, used in (("reads", render_pass.reads), ("writes", render_pass.writes)):
            for target in used:
                if target in created:
                    continue
                if target not in creators:
                    raise PassGraphError(f"pass {render_pass.name}: {kind} unknown target "
                                         f"'{target}' (no pass creates it)")
                raise PassGraphError(f"pass {render_pass.name}: {kind} target '{target}' "
                                     f"before any pass produces it (pass "
                                     f"{creators[target]} creates it later)")
    return PassGraph(list(passes), targets, creators)
