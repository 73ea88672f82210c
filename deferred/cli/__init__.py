"""The ``deferred`` command line (docs/guide/command-line.md): a module per command, the options
several share in :mod:`~deferred.cli.options`, ``--view BUFFER`` in
:mod:`~deferred.cli.view_option`, exit statuses and error lines in :mod:`~deferred.cli.exits`.

Exit codes: 0 success, 1 a failure while rendering (``dump --compare``: the dumps differ), 2 bad
input. Bad input is one line on stderr naming the file/key and the problem; ``--debug`` shows the
traceback instead. Progress goes to stderr (:mod:`deferred.io.progress`), so does a Python
warning, as one line (``warning: ...``); results (tables, ``--json -``) go to stdout.
"""

from deferred.cli.main import cli, entry, main

__all__ = ["cli", "entry", "main"]
