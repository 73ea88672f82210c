"""Passes: the pipeline is an ordered list of these (Revie section 2.1, Figure 2.3).

Each pass has a unique name, the phase it belongs to, and the targets it creates (with their
format and clear value), reads and writes; :mod:`deferred.core.graph` checks these declarations
before any GL work, dumps capture a pass's ``writes`` after it runs and benchmarks time it. Passes
set all the GL state they need (``Frame.set_state``), so their order is the only coupling between
them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from enum import Enum
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar, Protocol

import moderngl

from deferred.gl.blend import PassBlend, blend_outputs, blended_outputs
from deferred.gl.target_spec import TargetSpec
from deferred.memo import overrides

if TYPE_CHECKING:
    from deferred.core.frame import Frame
    from deferred.core.protocols import SceneObjectLike


class Phase(str, Enum):
    """The phases of a frame, in the order they run; a pass belongs to one."""

    GEOMETRY = "geometry"  # opaque G-buffer passes
    SCREEN = "screen"  # effects needing a clean G-buffer (SSAO, edges), before stipple
    STIPPLE = "stipple"  # stippled G-buffer passes
    LIGHTING = "lighting"  # lights add into the light accumulation
    MATERIAL = "material"  # materials re-render meshes over the composition buffer
    FORWARD = "forward"  # the forward pipeline's lit passes and forward shells
    POST = "post"  # tone mapping etc.; knows no light and no object
    OUTPUT = "output"



class Order:
    """Where a pass runs within its phase (the pipeline sorts by it).

    In the material phase, materials first alter their own opaque pixels of the composition
    buffer, then the opaque scene is restored where stipple samples lie (obliteration copies
    from what the composition holds by then), then volumes (fur shells) and transparent surfaces
    are composited over it, far to near, so the image does not depend on the order of objects in
    the scene. The forward phase uses the same ranks: opaque lit passes, then blended ones. Post
    passes use them too: tone mapping first (``FIRST``), effects composited over the final image
    (``TRANSPARENT``), anti-aliasing last (``LAST``).
    """

    FIRST = -10  # passes that must precede every object's (clears, copies, tone mapping)
    OPAQUE = 0  # an object's own opaque pixels
    RESTORE = 5  # erasing stipple samples, which restores the opaque scene
    VOLUME = 10  # blended, depth-tested without depth writes: sorted far to near
    TRANSPARENT = 20  # blended surfaces over everything above: sorted far to near
    LAST = 30  # scene-wide passes over the finished phase (outlines, anti-aliasing)


class RenderPass(ABC):
    """One step of a frame."""

    name: str
    phase: Phase
    creates: Mapping[str, TargetSpec] = MappingProxyType({})
    reads: tuple[str, ...] = ()
    writes: tuple[str, ...] = ()
    samples: tuple[str, ...] = ()  # the reads bound as textures: never also written (GL feedback)
    order: int = Order.OPAQUE
    # a transparent surface: drawn over what lies behind it and hiding nothing, so Forward+'s
    # depth pre-pass leaves it out (a lit pass of it laid down there would hide what it shows)
    transparent: bool = False
    # the composition this pass is a member of, by name, and for one of a composition's own
    # passes (name, BEGIN or END): compose_runs
    composition: str | None = None
    brackets: tuple[str, str] | None = None

    def prepare(self, frame: Frame) -> None:  # noqa: B027 - optional hook
        """Upload per-frame data; called once per frame before any pass runs."""

    @abstractmethod
    def execute(self, frame: Frame) -> None:
        """Issue the GL work of this pass."""

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "phase": self.phase.value, "reads": list(self.reads),
                "writes": list(self.writes),
                "creates": {name: spec.format_name for name, spec in self.creates.items()}}

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name} ({self.phase.value})>"


BEGIN, END = "begin", "end"  # the roles of a composition's own passes (RenderPass.brackets)


def compose_runs(passes: list[RenderPass], brackets: list[RenderPass] | None = None,
                 split: bool = True) -> list[RenderPass]:
    """``passes`` with each composition's ``begin`` and ``end`` passes (those among
    ``passes``, or among ``brackets`` where given) taken from where they are and put around
    every run of its members (consecutive passes whose ``composition`` is its name): the same
    list where they already are so. Without ``split``, once around the span from its first
    member to its last (the list the pass graph checks: each pass in it once).

    A composition is a group of object passes composed together, order-independently
    (weighted blended or per-pixel sorted transparency). Each frame, every run of them that no
    other pass interrupts in the order the frame runs them (blended object passes far to near)
    is opened by the composition's begin passes (clearing what the members accumulate into)
    and closed by its end passes (resolving that over what lies behind): a fur volume between
    two glass panes splits them into two runs, so each pane is composed over what lies
    behind it, the fur included. A pass is one of those by its ``brackets``: (the
    composition's name, :data:`BEGIN` or :data:`END`); they keep their order among
    themselves."""
    roles: dict[str, dict[str, list[RenderPass]]] = {}
    for render_pass in passes if brackets is None else brackets:
        if render_pass.brackets is not None:
            name, role = render_pass.brackets
            listed = roles.setdefault(name, {BEGIN: [], END: []})[role]
            if not any(known is render_pass for known in listed):  # once though run twice
                listed.append(render_pass)
    if not roles:
        return passes
    out: list[RenderPass] = []
    current: str | None = None
    last = {p.composition: k for k, p in enumerate(passes) if p.composition in roles}
    for index, render_pass in enumerate(passes):
        if render_pass.brackets is not None:
            continue
        group = render_pass.composition
        if group not in roles:
            group = None  # none of its passes in this list: composed on its own
        if not split and group is None and current is not None and index < last[current]:
            group = current  # inside the span: no end yet
        if group != current:
            if current is not None:
                out += roles[current][END]
            if group is not None:
                out += roles[group][BEGIN]
            current = group
        out.append(render_pass)
    if current is not None:
        out += roles[current][END]
    return passes if same_passes(out, passes) else out


def without_brackets(passes: list[RenderPass]) -> list[RenderPass]:
    """``passes`` without the compositions' begin and end passes (the same list where it has
    none)."""
    if not any(p.brackets is not None for p in passes):
        return passes
    return [p for p in passes if p.brackets is None]


def same_passes(first: list[RenderPass], second: list[RenderPass]) -> bool:
    """Whether two pass lists hold the same passes in the same order."""
    return len(first) == len(second) and all(a is b for a, b in zip(first, second, strict=True))


def drawn_targets(samples: tuple[str, ...], colors: tuple[str, ...] | list[str],
                  blend: PassBlend, depth: str | None, depth_test: bool,
                  depth_write: bool) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(reads, writes) of a pass drawing into ``colors`` and ``depth`` with this state: it reads
    what it samples, the colours it blends over (``blend``: any form of
    :mod:`deferred.gl.blend`, an output whose state is ``None`` is written, not read), and the
    depth it tests against or has bound without writing it (the depth of earlier passes,
    kept); it writes its colours and, with depth writes, the depth."""
    reads = tuple(dict.fromkeys(
        [*samples, *(blended_outputs(blend, tuple(colors)) if blend is not None else ()),
         *((depth,) if depth and (depth_test or not depth_write) else ())]))
    writes = tuple(colors) + ((depth,) if depth and depth_write else ())
    return reads, writes


class ClearPass(RenderPass):
    """Create targets and nothing else: the renderer clears each to its declared value when this
    pass runs (the G-buffer's ``gbuffer.clear``)."""

    order = Order.FIRST

    def __init__(self, name: str, phase: Phase, creates: dict[str, TargetSpec],
                 brackets: tuple[str, str] | None = None):
        self.brackets = brackets
        missing = [target for target, spec in creates.items() if spec.clear is None]
        if missing:
            raise ValueError(f"{name}: targets without a clear value: {', '.join(missing)}")
        self.name = name
        self.phase = phase
        self.creates = dict(creates)
        self.writes = tuple(creates)

    def execute(self, frame: Frame) -> None:
        pass  # the clears of ``creates`` are all there is


class FullscreenPass(RenderPass):
    """Run a fragment shader over every pixel (``post/fullscreen.vert``)."""

    def __init__(self, name: str, phase: Phase, fragment: str, inputs: dict[str, str],
                 outputs: tuple[str, ...], blend: PassBlend = None,
                 defines: dict[str, str] | None = None,
                 uniforms: Callable[[Frame], dict[str, Any]] | None = None,
                 depth: str | None = None, depth_test: bool = False, depth_func: str = "less",
                 depth_write: bool = False, instances: Callable[[Frame], int] | None = None,
                 vertex: str = "post/fullscreen.vert", creates: dict[str, TargetSpec] | None = None,
                 order: int = Order.OPAQUE, transparent: bool = False,
                 brackets: tuple[str, str] | None = None):
        self.name = name
        self.creates = dict(creates or {})
        self.transparent = transparent
        self.brackets = brackets
        self.order = order
        self.phase = phase
        self.fragment = fragment
        self.vertex = vertex
        self.inputs = inputs  # sampler uniform -> target name
        self.outputs = outputs
        blend_outputs(blend, len(outputs), f"pass {name}: blend")  # checked now, not drawing
        self.blend = tuple(blend) if isinstance(blend, list) else blend
        self.defines = defines or {}
        self.uniforms = uniforms
        self.depth = depth
        self.depth_test = depth_test
        self.depth_func = depth_func
        self.depth_write = depth_write
        self.instances = instances
        self.samples = tuple(dict.fromkeys(inputs.values()))
        self.reads, self.writes = drawn_targets(self.samples, outputs, blend, depth, depth_test,
                                                depth_write)

    def execute(self, frame: Frame) -> None:
        program = frame.shaders.program(self.vertex, self.fragment, defines=self.defines)
        frame.use_framebuffer(self.outputs, self.depth, depth_write=self.depth_write)
        frame.set_state(depth_test=self.depth_test, depth_func=self.depth_func, blend=self.blend)
        frame.bind(program, self.uniforms(frame) if self.uniforms else {},
                   {u: frame.target(t) for u, t in self.inputs.items()})
        count = self.instances(frame) if self.instances else 1
        if count > 0:
            frame.draw_fullscreen(program, instances=count)


class CopyPass(FullscreenPass):
    """A pass creating ``target`` as a copy of ``source`` (a snapshot a later pass reads while it
    writes ``source``: GL forbids reading a texture while rendering into it). A pipeline may
    fold it into the pass that makes ``source`` (a second output of that pass)."""

    def __init__(self, name: str, phase: Phase, source: str, target: str, spec: TargetSpec,
                 order: int = Order.OPAQUE, brackets: tuple[str, str] | None = None):
        super().__init__(name, phase, "post/copy.frag", {"u_source": source}, (target,),
                         creates={target: spec}, order=order, brackets=brackets)
        self.source = source
        self.target = target


def copy_pass(name: str, phase: Phase, source: str, target: str, spec: TargetSpec,
              order: int = Order.OPAQUE,
              brackets: tuple[str, str] | None = None) -> CopyPass:
    """A :class:`CopyPass` of ``source`` into ``target``."""
    return CopyPass(name, phase, source, target, spec, order, brackets)


class PassInput:
    """Something an object pass reads besides the material's inputs, given to the pass as one
    of its ``inputs`` (composed, not mixed in: a pass type takes any of them). It may sample
    targets (``reads``: the pass graph orders the pass after their makers; the input binds them
    under its own sampler names with ``frame.target``), and gives uniforms and textures for the
    object as the frame has it (``obj``: its state at the frame's time). The same input serves
    every pass and object it is given to: it keeps nothing of one (what lasts is in
    ``frame.resources``, keyed by ``obj.node``)."""

    reads: tuple[str, ...] = ()

    def uniforms(self, frame: Frame, obj: SceneObjectLike) -> dict[str, Any]:
        return {}

    def textures(self, frame: Frame, obj: SceneObjectLike) -> dict[str, moderngl.Texture]:
        return {}


class Shape(Protocol):
    """What an object pass draws instead of its object's mesh (its ``shape``: the hair's tubes,
    say): one or more draw calls of ``program``, which the pass has bound."""

    def draw(self, frame: Frame, obj: SceneObjectLike, program: moderngl.Program) -> None: ...


class ObjectPass(RenderPass):
    """Draw one scene object's mesh with a program; materials build their passes on this.

    The pass is made for an object (``node``: the user's object, which the frame's state is
    keyed by) and draws it as each frame has it: :meth:`object` is the object's state in the
    frame (its world matrix, its material with the parameters at the frame's time). Hooks
    read the object through it, never a state kept from another frame.

    Subclasses (or callers) give the shader files (a geometry shader too, if any), defines, the
    targets and state, and a ``uniforms`` hook. ``inputs`` (:class:`PassInput`) add what the
    pass reads besides the material's inputs (a comb field, a simulation's textures), each its
    uniforms and textures; ``shape`` (:class:`Shape`) draws something else than the mesh.
    ``draws`` > 1 renders the mesh that many times, each draw with its own ``draw_uniforms``
    (e.g. one shell per draw; ``None`` skips the draw). ``draw`` issues one draw call (override
    it to draw other primitives of the mesh).

    What a subclass overrides of those hooks is found when the class is made (a pass keeping
    them all draws without asking them), so change a hook by subclassing, not by patching the
    class later. Options (``extra_defines``, ``constants``...) are fixed at construction.
    """

    vertex: str = "common/mesh.vert"
    fragment: str = ""
    geometry: str | None = None
    colors: tuple[str, ...] = ()
    depth: str | None = "depth"
    depth_test: bool = True
    depth_func: str = "less"
    depth_write: bool = True
    cull: str | None = "back"
    blend: PassBlend = None  # a name, a Blend, or one of those per colour (deferred.gl.blend)
    transparent: bool = False  # RenderPass.transparent
    composition: str | None = None  # RenderPass.composition
    depth_offset: tuple[float, float] = (0.0, 0.0)  # glPolygonOffset (factor, units)
    extra_reads: tuple[str, ...] = ()
    constants: dict[str, Any] | None = None  # uniforms fixed at construction
    extra_defines: dict[str, str] | None = None
    inputs: tuple[PassInput, ...] = ()  # what the pass reads besides the material's inputs
    shape: Shape | None = None  # what the pass draws; None: the object's mesh
    # the last program lookup: (shaders, generation, material, params, mesh, defines, program)
    _program_memo: tuple | None = None
    # whether uniforms, textures, draws and draw_uniforms are ObjectPass's own, and whether
    # defines is the class's own (set for each subclass as it is made: deferred.memo.overrides)
    _hooks_unchanged: ClassVar[bool] = True
    _own_defines: ClassVar[bool] = False

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls._hooks_unchanged = not overrides(cls, ObjectPass, "uniforms", "textures", "draws",
                                             "draw_uniforms")
        cls._own_defines = overrides(cls, ObjectPass, "defines")

    def __init__(self, name: str, phase: Phase, obj: SceneObjectLike, **options: Any):
        self.name = name
        self.phase = phase
        self.node = obj.node  # what the frame's state is keyed by (the object's identity)
        self.mesh = obj.mesh  # another mesh is another pass graph
        for key, value in options.items():
            if key.startswith("_") or callable(getattr(type(self), key, None)) or \
                    not hasattr(type(self), key):
                raise TypeError(f"{type(self).__name__} has no option '{key}'")
            setattr(self, key, value)
        self.inputs = tuple(self.inputs)
        if isinstance(self.blend, list):
            self.blend = tuple(self.blend)  # a state compared from pass to pass
        blend_outputs(self.blend, len(self.colors), f"pass {name}: blend")
        self.samples = tuple(dict.fromkeys(
            [*self.extra_reads, *(target for given in self.inputs for target in given.reads)]))
        # one draw of the material's inputs alone: the pass's hooks are not asked (execute)
        self._plain = self._hooks_unchanged and not self.extra_reads and not self.inputs
        self.reads, self.writes = drawn_targets(self.samples, self.colors, self.blend,
                                                self.depth, self.depth_test, self.depth_write)

    def object(self, frame: Frame) -> SceneObjectLike:
        """The object this pass draws, as ``frame`` has it (its state at the frame's time)."""
        return frame.scene.object_state(self.node)

    def defines(self, frame: Frame) -> dict[str, str]:
        obj = self.object(frame)
        defines = obj.material.defines(obj)
        return {**defines, **self.extra_defines} if self.extra_defines else defines

    def uniforms(self, frame: Frame) -> dict[str, Any]:
        return {}

    def textures(self, frame: Frame) -> dict[str, moderngl.Texture]:
        """Samplers of the pass: each target in ``extra_reads`` as ``u_<target>``."""
        return frame.target_samplers(self.extra_reads)

    def draws(self, frame: Frame) -> int:
        return 1

    def draw_uniforms(self, frame: Frame, index: int, count: int) -> dict[str, Any] | None:
        """Uniforms that change from one draw of the pass to the next (e.g. a shell's depth);
        ``None`` skips draw ``index``."""
        return {}

    def draw(self, frame: Frame, program: moderngl.Program) -> None:
        if self.shape is None:
            frame.draw_mesh(self.mesh, program)
        else:
            self.shape.draw(frame, self.object(frame), program)

    def gather_uniforms(self, frame: Frame, obj: SceneObjectLike) -> dict[str, Any]:
        """The pass's uniforms (:meth:`uniforms`) and its inputs', an input's over the pass's
        of one name."""
        return self._with_inputs(self.uniforms(frame), "uniforms", frame, obj)

    def gather_textures(self, frame: Frame, obj: SceneObjectLike) -> dict[str, moderngl.Texture]:
        """The pass's samplers (:meth:`textures`) and its inputs'."""
        return self._with_inputs(self.textures(frame), "textures", frame, obj)

    def _with_inputs(self, own: dict[str, Any], hook: str, frame: Frame,
                     obj: SceneObjectLike) -> dict[str, Any]:
        for given in self.inputs:
            extra = getattr(given, hook)(frame, obj)
            if extra:
                own = {**own, **extra}
        return own

    def program(self, frame: Frame, obj: SceneObjectLike | None = None) -> moderngl.Program:
        shaders = frame.shaders
        memo = self._program_memo  # the last lookup: the same defines give the same program
        material = (obj or self.object(frame)).material
        fresh = memo is not None and memo[0] is shaders and memo[1] == shaders.generation
        # Where the pass keeps ObjectPass.defines, its defines are the material's, a function
        # of its params and the object's mesh (Material.defines), and its own fixed ones: while
        # those are the same objects, so is the program (building and comparing the defines
        # was a sixth of a draw's CPU time: benchmarks/README.md).
        if fresh and memo[2] is material and memo[3] is material.params and \
                memo[4] is self.mesh and not self._own_defines:
            return memo[6]
        defines = self.defines(frame)
        program = memo[6] if fresh and memo[5] == defines else \
            shaders.program(self.vertex, self.fragment, self.geometry, defines=defines)
        self._program_memo = (shaders, shaders.generation, material, material.params,
                              self.mesh, defines, program)
        return program

    def execute(self, frame: Frame) -> None:
        obj = self.object(frame)
        program = self.program(frame, obj)
        frame.use_framebuffer(self.colors, self.depth, depth_write=self.depth_write)
        frame.set_state(depth_test=self.depth_test, depth_func=self.depth_func, cull=self.cull,
                        blend=self.blend, depth_offset=self.depth_offset)
        material = frame.material_inputs(obj.material)
        if self._plain:
            # one draw and nothing of the pass's own but its constants (most objects'
            # G-buffer and forward passes): the hooks' empty answers are not asked for
            # (benchmarks/README.md has what asking cost)
            frame.bind(program, self.constants, None, offered=frame.object_uniforms(obj),
                       material=material)
            self.draw(frame, program)
            return
        uniforms = self.gather_uniforms(frame, obj)
        if self.constants:
            uniforms = {**self.constants, **uniforms}
        textures = self.gather_textures(frame, obj)
        offered = frame.object_uniforms(obj)
        count = self.draws(frame)
        bound = False
        for index in range(count):
            per_draw = self.draw_uniforms(frame, index, count)
            if per_draw is None:
                continue
            if bound:  # everything else is set already: only what changes per draw
                frame.set_uniforms(program, per_draw)
            else:
                frame.bind(program, {**uniforms, **per_draw} if per_draw else uniforms,
                           textures, offered=offered, material=material)
                bound = True
            self.draw(frame, program)
