"""The ``deferred`` command group, its subcommands, and the entry point that runs it."""

from __future__ import annotations

import sys
import warnings

import click

from deferred.cli import exits
from deferred.cli.bench import bench
from deferred.cli.dump import dump
from deferred.cli.info import info
from deferred.cli.params import materials, params_command
from deferred.cli.render import render
from deferred.cli.schema import schema
from deferred.cli.view import view_command
from deferred.io.safety import raise_if_stop_requested, termination_as_interrupt


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks instead of one-line errors.")
@click.version_option(package_name="deferred")
def cli(debug: bool) -> None:
    """A deferred-shading renderer with pluggable materials."""
    exits.Settings.debug = debug


for command in (render, dump, bench, view_command, params_command, materials, schema, info):
    cli.add_command(command)


def main(argv: list[str] | None = None) -> int:
    """Run the command line ``argv`` (``sys.argv[1:]`` when ``None``): its exit status."""
    # SIGTERM unwinds like Ctrl-C, through the finally blocks that remove temporary files.
    with termination_as_interrupt(), warnings.catch_warnings():
        warnings.showwarning = exits.show_warning
        try:
            code = _run(argv)
            if code < 128:  # not ended by a signal already (said so once)
                raise_if_stop_requested()  # a signal whose exception was lost (a __del__ ate it)
            return code
        except KeyboardInterrupt as exc:
            return exits.interrupted(exc)


def _run(argv: list[str] | None) -> int:
    if not (sys.argv[1:] if argv is None else argv):  # no command: the help, not an error
        click.echo(cli.get_help(cli.make_context("deferred", [], resilient_parsing=True)))
        return 0
    return exits.run_group(cli, argv)


def entry() -> None:
    sys.exit(main())
