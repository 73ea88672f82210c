"""``deferred schema``: the JSON Schema of scene files."""

from __future__ import annotations

import click

from deferred.cli.options import stderr
from deferred.io.paths import check_output_path


@click.command()
@click.option("-o", "--output", metavar="FILE.json",
              help="Write the schema here (default: stdout).")
def schema(output: str | None) -> None:
    """Write the JSON Schema of scene files (draft-07), for an editor's completion and
    checks: each object's material selects its params, each light's and effect's type its
    parameters (registered plugins included)."""
    import json

    from deferred.io.images import write_text
    from deferred.scene.schema import scene_schema

    out = check_output_path(output, "-o", (".json",), patterns=False) if output else None
    text = json.dumps(scene_schema(), indent=2) + "\n"
    if out is None:
        click.echo(text, nl=False)
        return
    write_text(out, text)
    stderr.print(f"wrote {out}", markup=False, highlight=False)
