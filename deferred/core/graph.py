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
- a pass that breaks one of the ``rules`` the caller gives, each a function of the pass
  answering what is wrong with it or ``None``: the layers above the core know what their
  targets mean (the G-buffer's rule: :func:`deferred.gbuffer.layout.surfaces_need_depth`).

What it returns is every target of the frame with its format: the renderer creates exactly
those, and clears each when its creating pass runs.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from deferred.core.passes import RenderPass
from deferred.errors import RenderError
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


PassRule = Callable[[RenderPass], "str | None"]


def compile_graph(passes: Sequence[RenderPass], rules: Sequence[PassRule] = ()) -> PassGraph:
    """Check ``passes`` (in order, each against ``rules`` too) and collect the targets they
    create."""
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
        for rule in rules:
            problem = rule(render_pass)
            if problem:
                raise PassGraphError(f"pass {render_pass.name}: {problem}")
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
