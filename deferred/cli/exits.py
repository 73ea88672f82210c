"""How a command ends: its exit status, and the lines it says on stderr when it fails, is
interrupted or warns (the conventions :mod:`deferred.cli` states)."""

from __future__ import annotations

import traceback

import click

from deferred.cli.options import stderr
from deferred.errors import DeferredError, InputError, RenderError, ShaderError, one_line
from deferred.io.safety import interrupt_exit_code

MAX_PROBLEM_LINES = 50  # a scene file's problems shown; the rest are counted

# The Python API names its arguments in errors; the command line's options carry them
PYTHON_ARGUMENTS = {"light_path": "--light-path", "pipeline": "--pipeline", "size": "--size",
                    "time": "--time", "samples": "--samples"}


class Settings:
    """What the group's own options set for every command."""

    debug = False  # --debug: a traceback instead of one-line errors


def run_group(group: click.Group, argv: list[str] | None) -> int:
    """Run ``group`` on ``argv``: the command's exit status, its failure said on stderr."""
    try:
        code = group.main(args=argv, prog_name="deferred", standalone_mode=False)
        return code if isinstance(code, int) else 0  # click returns an Exit's code
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.exceptions.Abort as exc:
        if isinstance(exc.__cause__, KeyboardInterrupt):  # click turns Ctrl-C into Abort
            return interrupted(exc.__cause__)
        stderr.print("aborted")
        return 1
    except click.ClickException as exc:
        fail(f"error: {exc.format_message()}")
        return 2
    except InputError as exc:
        fail(*problem_lines(exc))
        return 2
    except (RenderError, ShaderError, DeferredError) as exc:
        fail(f"render failed: {exc}")
        return 1
    except Exception as exc:  # noqa: BLE001 - the last line of defence of a CLI
        fail(f"render failed: {type(exc).__name__}: {exc}")
        return 1


def problem_lines(error: InputError) -> list[str]:
    """A line per problem (a scene file's are said at once), at most
    :data:`MAX_PROBLEM_LINES` of them and then their count."""
    problems = error.problems
    shown = [f"error: {as_option(problem)}" for problem in problems[:MAX_PROBLEM_LINES]]
    if len(problems) > MAX_PROBLEM_LINES:
        shown.append(f"error: ... and {len(problems) - MAX_PROBLEM_LINES} more problems")
    return shown


def as_option(problem: InputError) -> str:
    """A problem as the command line says it: a Python argument by the option that set it."""
    option = PYTHON_ARGUMENTS.get(problem.where or "")
    return f"{option}: {problem.message}" if option else str(problem)


def fail(*messages: str) -> None:
    if Settings.debug:
        traceback.print_exc()
    # one line each, whatever a file name holds: a newline in one is shown as \n
    for message in messages:
        click.echo(one_line(message), err=True)


def interrupted(exc: KeyboardInterrupt) -> int:
    """Ctrl-C or SIGTERM: said once, and 128 + the signal."""
    click.echo("interrupted" if interrupt_exit_code(exc) == 130 else "terminated", err=True)
    return interrupt_exit_code(exc)


def show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A Python warning as one line, ``warning: ...``, without the source file and line."""
    click.echo(f"warning: {one_line(str(message))}", err=True)
