"""mkdocs hooks: the generated pages (docs/site_pages.py) added to the build, so the site's
scene file reference, materials gallery, command reference and benchmarks page are made from
the code and benchmarks/README.md at every build, never copied by hand."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

from mkdocs.structure.files import File, Files

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def _site_pages():
    spec = importlib.util.spec_from_file_location("site_pages", HERE / "site_pages.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def on_files(files: Files, config) -> Files:
    from deferred.interfaces.catalogue import catalogue
    from deferred.scene.schema import scene_schema

    pages = _site_pages()
    generated = {"reference/scene-file.md": pages.scene_reference(scene_schema()),
                 "reference/materials.md": pages.materials_gallery(catalogue("material")),
                 "reference/commands.md": pages.command_reference()}
    results = sorted((ROOT / "benchmarks" / "results").glob("*.png"))
    for image in results:
        files.append(File.generated(config, f"benchmarks/results/{image.name}",
                                    abs_src_path=str(image)))
    site_files = {file.src_uri for file in files} | set(generated) | {"benchmarks/index.md"}
    readme = (ROOT / "benchmarks" / "README.md").read_text(encoding="utf-8")
    generated["benchmarks/index.md"] = pages.site_links(readme, ROOT / "benchmarks", site_files,
                                                        "benchmarks")
    for uri, content in generated.items():
        files.append(File.generated(config, uri, content=content))
    return files


ROLE = re.compile(r":(?:class|func|meth|mod|attr|data|exc|obj):(?=<code)")


def on_page_content(html: str, page, config, files) -> str:
    """Docstrings are reStructuredText-flavoured: their roles (``:class:`X```) show as the code
    alone, as pdoc renders them."""
    return ROLE.sub("", html)
