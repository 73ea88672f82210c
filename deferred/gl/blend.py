"""Blend state: what a pass does with what its outputs already hold.

A pass's ``blend`` is one of

- ``None``: its outputs are written, not blended;
- a name (:data:`BLEND_MODES`: ``"add"``, ``"alpha"``, ``"premultiplied"``, ``"multiply"``,
  ``"min"``, ``"max"``): a shorthand for a :class:`Blend`, the same for every output;
- a :class:`Blend`: factors and equations, the colour's and (``*_alpha``; by default the
  colour's) the alpha's, the same for every output;
- a tuple with one entry per output, each ``None``, a name or a :class:`Blend`: the state of
  each output (weighted blended order-independent transparency adds into one target and
  multiplies another). Where the entries differ this needs per-output blending
  (``glBlendFuncSeparatei``, GL 4.0).

:func:`blend_outputs` turns any of them into one state an output; :func:`shared_blend` says
whether one state serves every output (set with the plain GL calls, as before per-output state
existed).
"""

from __future__ import annotations

import ctypes
from collections.abc import Sequence
from dataclasses import dataclass

import moderngl

FACTORS = {
    "zero": moderngl.ZERO,
    "one": moderngl.ONE,
    "src_color": moderngl.SRC_COLOR,
    "one_minus_src_color": moderngl.ONE_MINUS_SRC_COLOR,
    "dst_color": moderngl.DST_COLOR,
    "one_minus_dst_color": moderngl.ONE_MINUS_DST_COLOR,
    "src_alpha": moderngl.SRC_ALPHA,
    "one_minus_src_alpha": moderngl.ONE_MINUS_SRC_ALPHA,
    "dst_alpha": moderngl.DST_ALPHA,
    "one_minus_dst_alpha": moderngl.ONE_MINUS_DST_ALPHA,
    # dual-source blending: the fragment shader's second output of location 0 (index = 1)
    "src1_color": 0x88F9,
    "one_minus_src1_color": 0x88FA,
    "src1_alpha": 0x8589,
    "one_minus_src1_alpha": 0x88FB,
}
EQUATIONS = {
    "add": moderngl.FUNC_ADD,
    "subtract": moderngl.FUNC_SUBTRACT,
    "reverse_subtract": moderngl.FUNC_REVERSE_SUBTRACT,
    "min": moderngl.MIN,  # the factors play no part
    "max": moderngl.MAX,
}


@dataclass(frozen=True)
class Blend:
    """One output's blend state: ``colour = equation(source x src, destination x dst)``, and
    the alpha the same with the ``*_alpha`` fields (``None``: the colour's). Factors and
    equations by name (:data:`FACTORS`, :data:`EQUATIONS`)."""

    source: str = "one"
    destination: str = "zero"
    equation: str = "add"
    source_alpha: str | None = None
    destination_alpha: str | None = None
    equation_alpha: str | None = None

    def __post_init__(self) -> None:
        for field, value in (("source", self.source), ("destination", self.destination),
                             ("source_alpha", self.source_alpha),
                             ("destination_alpha", self.destination_alpha)):
            if value is not None and value not in FACTORS:
                raise ValueError(f"blend {field} '{value}' is not a factor (choose from "
                                 f"{', '.join(FACTORS)})")
        for field, value in (("equation", self.equation),
                             ("equation_alpha", self.equation_alpha)):
            if value is not None and value not in EQUATIONS:
                raise ValueError(f"blend {field} '{value}' is not an equation (choose from "
                                 f"{', '.join(EQUATIONS)})")

    @property
    def factors(self) -> tuple[int, int, int, int]:
        """GL's (src colour, dst colour, src alpha, dst alpha)."""
        return (FACTORS[self.source], FACTORS[self.destination],
                FACTORS[self.source_alpha or self.source],
                FACTORS[self.destination_alpha or self.destination])

    @property
    def equations(self) -> tuple[int, int]:
        """GL's (colour, alpha) equations."""
        return EQUATIONS[self.equation], EQUATIONS[self.equation_alpha or self.equation]


# The shorthands by name, as GL is given them (moderngl's blend_func: two factors set both the
# colour's and the alpha's)
BLEND_MODES: dict[str, Blend] = {
    "add": Blend("one", "one"),
    # alpha stays coverage: a over background (0) gives a, over a surface (1) stays 1
    "alpha": Blend("src_alpha", "one_minus_src_alpha", "add", "one", "one_minus_src_alpha"),
    "premultiplied": Blend("one", "one_minus_src_alpha"),
    # colour times the source (a tint over what is there); alpha kept
    "multiply": Blend("dst_color", "zero", "add", "zero", "one"),
    # the smaller (larger) of source and destination, channel by channel
    "min": Blend("one", "one", "min"),
    "max": Blend("one", "one", "max"),
}

OutputBlend = str | Blend | None
PassBlend = OutputBlend | Sequence[OutputBlend]


def resolve_blend(blend: OutputBlend, where: str = "blend") -> Blend | None:
    """One output's state: a name's :class:`Blend`, a :class:`Blend` as it is, ``None``."""
    if blend is None or isinstance(blend, Blend):
        return blend
    if isinstance(blend, str):
        if blend not in BLEND_MODES:
            raise ValueError(f"{where}: unknown blend mode '{blend}' (choose from "
                             f"{', '.join(BLEND_MODES)}, or give a Blend)")
        return BLEND_MODES[blend]
    raise TypeError(f"{where}: a blend is a name, a Blend or None, not {type(blend).__name__}")


def blend_outputs(blend: PassBlend, outputs: int, where: str = "blend") -> tuple[Blend | None, ...]:
    """The state of each of ``outputs`` outputs a pass's ``blend`` gives (module
    documentation); a tuple must have one entry an output."""
    if blend is None or isinstance(blend, (str, Blend)):
        return (resolve_blend(blend, where),) * outputs
    entries = tuple(blend)
    if len(entries) != outputs:
        raise ValueError(f"{where}: {len(entries)} blend states for {outputs} outputs")
    return tuple(resolve_blend(entry, f"{where}[{k}]") for k, entry in enumerate(entries))


def blended_outputs(blend: PassBlend, outputs: Sequence[str]) -> tuple[str, ...]:
    """The outputs that ``blend`` blends over (and so reads)."""
    states = blend_outputs(blend, len(outputs))
    return tuple(name for name, state in zip(outputs, states, strict=True) if state is not None)


def shared_blend(states: tuple[Blend | None, ...]) -> tuple[bool, Blend | None]:
    """(whether one state serves every output, that state): so with no outputs, or all
    alike."""
    if not states or all(state == states[0] for state in states):
        return True, states[0] if states else None
    return False, None


GL_BLEND = 0x0BE2


class IndexedBlend:
    """GL 4.0's per-draw-buffer blend calls, which moderngl does not wrap, loaded from the
    context's GL library (glcontext's ``load_opengl_function``)."""

    def __init__(self, ctx: moderngl.Context):
        loader = getattr(getattr(ctx.mglo, "_context", None), "load_opengl_function", None)
        if loader is None:
            raise RuntimeError("this moderngl context cannot load GL functions (per-output "
                               "blending needs glBlendFuncSeparatei)")
        uint = ctypes.c_uint

        def load(name: str, *args):
            address = loader(name)
            if not address:
                raise RuntimeError(f"the GL driver has no {name} (per-output blending needs "
                                   "GL 4.0)")
            return ctypes.CFUNCTYPE(None, *args)(address)

        self.enable = load("glEnablei", uint, uint)
        self.disable = load("glDisablei", uint, uint)
        self.func = load("glBlendFuncSeparatei", uint, uint, uint, uint, uint)
        self.equation = load("glBlendEquationSeparatei", uint, uint, uint)

    def apply(self, states: tuple[Blend | None, ...]) -> None:
        """Each draw buffer's state (buffer k is the pass's k-th output)."""
        for index, state in enumerate(states):
            if state is None:
                self.disable(GL_BLEND, index)
                continue
            self.enable(GL_BLEND, index)
            self.func(index, *state.factors)
            self.equation(index, *state.equations)
