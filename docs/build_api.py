"""Build the API reference from the docstrings with pdoc: ``python docs/build_api.py [OUT_DIR]``.

It documents what users and plugins import: the ``deferred`` package root (``Renderer``,
``load_scene``, ``Scene``, ``RenderResult``, the errors) and ``deferred.api`` (everything a
material, light, shading model or effect imports). The other modules are internal and left
out. The output (default ``docs/api/``, not committed) is plain HTML: open ``index.html``.
Docstrings are reStructuredText-flavoured (``:class:`Material```), which pdoc renders.
``tests/docs/test_api_docs.py`` builds it and fails on any warning pdoc gives.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

# The package root and the plugin API; "!deferred\..*" drops the submodules that walking the
# package root adds, and deferred.api is named again after it.
MODULES = ("deferred", r"!deferred\..*", "deferred.api")
DEFAULT_OUT = Path(__file__).resolve().parent / "api"


def build(out_dir: Path) -> list[str]:
    """Write the reference into ``out_dir``; return the warnings pdoc gave (empty when clean)."""
    import pdoc
    import pdoc.render

    pdoc.render.configure(docformat="restructuredtext", show_source=False)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        pdoc.pdoc(*MODULES, output_directory=Path(out_dir))
    return [f"{w.category.__name__}: {w.message}" for w in caught]


def main(argv: list[str]) -> int:
    out_dir = Path(argv[0]) if argv else DEFAULT_OUT
    problems = build(out_dir)
    for line in problems:
        print(f"warning: {line}", file=sys.stderr)
    print(f"API reference: {out_dir / 'index.html'}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
