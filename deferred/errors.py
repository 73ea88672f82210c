"""Error types the command line maps to exit codes (docs/guide/command-line.md)."""

from __future__ import annotations

from collections.abc import Sequence


def one_line(text: str) -> str:
    """``text`` with its line breaks written as ``\\n`` / ``\\r``: an error is one line."""
    return text.replace("\r", "\\r").replace("\n", "\\n")


class DeferredError(Exception):
    """Base class of the framework's own errors."""


class InputError(DeferredError):
    """Bad input: a scene, mesh, parameter or option. Exit code 2, one line on stderr (a line
    per problem where :class:`InputErrors` says several).

    ``where`` names the file and key (``scene.toml: object[0].params.shells``) so the message says
    exactly what to fix.
    """

    def __init__(self, message: str, where: str | None = None):
        # A file name may hold a line break; the message stays one line whatever it quotes.
        self.where = None if where is None else one_line(where)
        self.message = one_line(message)
        super().__init__(f"{self.where}: {self.message}" if where else self.message)

    @property
    def problems(self) -> tuple[InputError, ...]:
        """Each problem, one line each: this error alone, or an :class:`InputErrors`' list."""
        return (self,)


class InputErrors(InputError):
    """Several problems of one input (every problem of a scene file, found at once): its
    ``problems`` are one :class:`InputError` each, and ``str()`` is one line per problem."""

    def __init__(self, problems: Sequence[InputError]):
        self._problems = tuple(one for problem in problems for one in problem.problems)
        self.where = None
        self.message = "\n".join(map(str, self._problems))
        DeferredError.__init__(self, self.message)

    @property
    def problems(self) -> tuple[InputError, ...]:
        return self._problems


def input_error(problems: Sequence[InputError]) -> InputError:
    """The error saying ``problems`` (at least one): the one problem, or all of them."""
    if not problems:
        raise ValueError("no problems to say")
    return problems[0] if len(problems) == 1 else InputErrors(problems)


class ShaderError(DeferredError):
    """A GLSL compile or link error, mapped back to the shader file and line."""


class RenderError(DeferredError):
    """A failure while rendering (GL error, missing feature). Exit code 1."""


def gl_error(stage: str, error: str, size: tuple[int, int] | None = None) -> RenderError:
    """The error for GL error flag ``error`` raised during ``stage`` (a pass, an upload); out of
    memory says what to shrink."""
    message = f"{stage}: {error}"
    if error == "GL_OUT_OF_MEMORY":
        at = f" at {size[0]}x{size[1]}" if size else ""
        message += (f" (the frame's render targets, textures and buffers{at} do not fit in GL "
                    "memory: render smaller, or with fewer shells, lights or effects)")
    return RenderError(message)
