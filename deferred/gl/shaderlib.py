"""The shader library: GLSL files with ``#include``, injected defines, cached programs.

GLSL lives in ``.glsl`` files (found with ``importlib.resources``): the framework's shared files in
the ``deferred.shaders`` package (``common/``, ``gbuffer/``, ``lighting/``, ``post/``...), each
built-in material's, light's and effect's beside its Python in its own package, named from the
feature package (``materials/revie_fur/shell.frag`` is ``shell.frag`` of
``deferred.materials.revie_fur``), and a plugin's under the roots it adds. A file may
``#include "path/from/a/root.glsl"``; the argument may also be the name of an injected define
whose value is a quoted path (``#include SURFACE_FILE``), which is how a generic pass pulls in a
material's surface function. Each file is included once per
program (include-once), nesting is limited to ``MAX_INCLUDE_DEPTH``, and a cycle is an error.

The assembled source keeps a line map, so a compile error reported by the driver as ``0:57(3)``
(Mesa) or ``0(57)`` (NVIDIA) is reported as ``materials/standard/surface.glsl:12``; a file a
plugin's root holds is also named by the plugin's package (``... (plugin my_plugin)``).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from dataclasses import dataclass
from functools import cache
from importlib import metadata, resources
from pathlib import Path

import moderngl

if sys.version_info >= (3, 11):
    from importlib.resources.abc import Traversable
else:  # Python 3.10
    from importlib.abc import Traversable

from deferred.errors import ShaderError
from deferred.gl.uniforms import ProgramUniforms

MAX_INCLUDE_DEPTH = 16

# Uniform declarations of assembled GLSL (strict mode checks names against them; blocks excluded).
_QUALIFIERS = r"(?:(?:lowp|mediump|highp|coherent|volatile|restrict|readonly|writeonly)\s+)*"
# Groups: the layout qualifier's arguments (a ``binding`` gives a sampler or image its unit), the
# names (with any array sizes and initializers).
_UNIFORM = re.compile(r"^\s*(?:layout\s*\(([^)]*)\)\s*)?" + _QUALIFIERS + r"uniform\s+" +
                      _QUALIFIERS + r"\w+\s+([^;{]+);", re.MULTILINE)
_INCLUDE = re.compile(r'^\s*#\s*include\s+(?:"([^"]+)"|<([^>]+)>|([A-Za-z_]\w*))\s*$')
# Mesa "0:57(3):", NVIDIA "0(57) :" - the location and the colon after it.
_ERROR_LOCATION = re.compile(r"\b(\d+)(?::(\d+)\((\d+)\)|\((\d+)\))\s*:?")


@dataclass
class Source:
    """Assembled GLSL text and, per output line, the (file, line) it came from."""

    text: str
    line_map: list[tuple[str, int]]

    def locate(self, line: int) -> tuple[str, int]:
        """File and line (1-based) of assembled line ``line`` (1-based)."""
        if 1 <= line <= len(self.line_map):
            return self.line_map[line - 1]
        return ("<generated>", line)


# The first folder of a built-in feature's shader name -> the package holding the feature's
# folders (a material's GLSL sits beside its Python, as a plugin's does).
FEATURE_PACKAGES = {"materials": "deferred.materials", "lights": "deferred.lights",
                    "effects": "deferred.effects"}
GLSL_SUFFIXES = (".glsl", ".vert", ".frag", ".geom", ".comp")


class FrameworkShaders:
    """The framework's GLSL as one root: a name's first folder picks a feature package
    (``FEATURE_PACKAGES``), any other name is a file of ``deferred.shaders``."""

    def __init__(self) -> None:
        self.shared: Traversable = resources.files("deferred.shaders")
        self.features: dict[str, Traversable] = {
            folder: resources.files(package) for folder, package in FEATURE_PACKAGES.items()}

    def joinpath(self, *parts: str) -> Traversable:
        feature = self.features.get(parts[0]) if len(parts) > 1 else None
        if feature is not None:
            return feature.joinpath(*parts[1:])
        return self.shared.joinpath(*parts)

    def is_dir(self) -> bool:
        return True

    def folders(self) -> list[Traversable]:
        """The folders holding its files: the shared one and each feature package's."""
        return [self.shared, *self.features.values()]

    def __str__(self) -> str:
        return ", ".join(str(folder) for folder in self.folders())


# Include names of the framework's public GLSL (deferred.api's GLSL_INCLUDES) as a plugin may
# still spell them -> the name to write: the error says so.
RENAMED_INCLUDES = {"lights/shadows.glsl": "lighting/shadows.glsl",
                    "techniques/": "materials/techniques/"}


def renamed_include(name: str) -> str | None:
    """The framework's name for an include spelled by its former name, else None."""
    for old, new in RENAMED_INCLUDES.items():
        if name == old or (old.endswith("/") and name.startswith(old)):
            return new + name[len(old):]
    return None


_registered_roots: list[Traversable | Path] = []


def register_shader_root(root: Traversable | Path | str) -> None:
    """Search ``root`` for GLSL in every shader library from now on: the public way for a
    plugin to ship shader files (a package's ``importlib.resources.files(...)`` or a folder).
    Roots are searched in order, the framework's own first; a class's ``shader_root``
    (materials, lights, shading models, effects) is added for the scenes that use it."""
    root = Path(root) if isinstance(root, str) else root
    if not root.is_dir():
        raise ValueError(f"shader root is not a folder: {root}")
    if root not in _registered_roots:
        _registered_roots.append(root)


class ShaderLibrary:
    """Resolves, assembles, compiles and caches GLSL programs for one context."""

    def __init__(self, ctx: moderngl.Context, glsl_version: int = 330,
                 defines: dict[str, str] | None = None):
        self.ctx = ctx
        self.glsl_version = glsl_version
        self.global_defines = dict(defines or {})
        self.roots: list[Traversable | Path | FrameworkShaders] = [FrameworkShaders(),
                                                                   *_registered_roots]
        self.virtual_files: dict[str, str] = {}
        self._programs: dict[tuple, moderngl.Program] = {}
        self._declared: dict[int, frozenset[str]] = {}  # program glo -> declared uniform names
        # program glo -> its uniforms' declarations, and its assembled stages (strict checks)
        self._declarations: dict[int, dict[str, Declaration]] = {}
        self._sources: dict[int, dict[str, Source]] = {}
        self._required: dict[int, tuple[str, ...]] = {}  # glo -> what a pass must set (strict)
        self._origins: dict[str, Traversable | Path] = {}  # file -> the added root holding it
        self._labels: dict[int, str] = {}  # program glo -> its files, for messages
        # program glo -> its active uniforms and the values last written to them
        self._uniforms: dict[int, ProgramUniforms] = {}
        # between start_frame and end_frame; whether a program was looked up outside them
        self._in_frame = False
        self._looked_up_outside = True
        self._virtual_key: tuple[str, ...] = ()  # the virtual files' names, in program keys
        # counts the times programs were released: a program looked up before is still valid
        # while it is unchanged
        self.generation = 0

    # -- files -------------------------------------------------------------------------------
    def add_root(self, root: Traversable | Path, first: bool = False) -> None:
        """Search ``root`` for shader files too (plugins ship their GLSL this way); ``first``:
        before every other root, so that its files replace theirs (benchmarks/shader_ab.py)."""
        if root in self.roots:
            return
        if first:
            if self._programs:  # they (and what is cached by them) hold the files replaced
                raise RuntimeError("a root replacing shader files is added before any "
                                   "program is compiled")
            self.roots.insert(0, root)
        else:
            self.roots.append(root)

    def set_virtual_file(self, name: str, text: str) -> None:
        """Provide generated GLSL under ``name`` (e.g. the light dispatch of the registry)."""
        if self.virtual_files.get(name) != text:
            self.virtual_files[name] = text
            self._virtual_key = tuple(sorted(self.virtual_files))
            self.generation += 1
            for key in [k for k in self._programs if name in k[-1]]:
                program = self._programs.pop(key)
                self._uniforms.pop(program.glo, None)
                program.release()

    def read(self, name: str) -> str:
        if name in self.virtual_files:
            return self.virtual_files[name]
        for index, root in enumerate(self.roots):
            candidate = root.joinpath(*name.split("/"))
            if candidate.is_file():
                if index:  # not the framework's own: errors name the plugin
                    self._origins[name] = root
                return candidate.read_text(encoding="utf-8")
        renamed = renamed_include(name)
        if renamed is not None and renamed != name and self._exists(renamed):
            raise ShaderError(f'shader file not found: {name}: the framework names it '
                              f'{renamed}; write #include "{renamed}"')
        searched = ", ".join(str(root) for root in self.roots)
        raise ShaderError(f"shader file not found: {name} (searched: {searched})")

    def _exists(self, name: str) -> bool:
        return any(root.joinpath(*name.split("/")).is_file() for root in self.roots)

    def assemble(self, name: str, defines: dict[str, str] | None = None) -> Source:
        """Resolve includes of ``name`` and inject ``#version`` and defines."""
        defines = {**self.global_defines, **(defines or {})}
        lines: list[str] = [f"#version {self.glsl_version} core"]
        line_map: list[tuple[str, int]] = [("<version>", 0)]
        for key, value in defines.items():
            lines.append(f"#define {key} {value}".rstrip())
            line_map.append(("<defines>", 0))
        included: set[str] = set()
        self._expand(name, defines, lines, line_map, included, stack=[])
        return Source("\n".join(lines) + "\n", line_map)

    def _expand(self, name: str, defines: dict[str, str], lines: list[str],
                line_map: list[tuple[str, int]], included: set[str], stack: list[str]) -> None:
        # Include-once (below) makes cycles harmless; the depth limit bounds what is left.
        if len(stack) >= MAX_INCLUDE_DEPTH:
            raise ShaderError(f"{stack[-1]}: includes nested deeper than {MAX_INCLUDE_DEPTH}")
        included.add(name)
        text = self.read(name)
        for number, line in enumerate(text.splitlines(), start=1):
            match = _INCLUDE.match(line)
            if not match:
                if line.lstrip().startswith("#version"):
                    continue  # the library owns the version line
                lines.append(line)
                line_map.append((name, number))
                continue
            target = match.group(1) or match.group(2)
            if match.group(3):
                value = defines.get(match.group(3))
                if value is None:
                    raise ShaderError(f"{name}:{number}: #include {match.group(3)}: "
                                      "no such define was injected")
                target = value.strip().strip('"')
            if target in included:
                continue
            self._expand(target, defines, lines, line_map, included, stack + [name])

    # -- programs ----------------------------------------------------------------------------
    def program(self, vertex: str, fragment: str | None = None, geometry: str | None = None,
                defines: dict[str, str] | None = None) -> moderngl.Program:
        """Compile (or return the cached) program of these files with these defines."""
        if not self._in_frame:
            self._looked_up_outside = True  # its uniforms may be written directly
        defines = defines or {}
        # a frozenset of the defines: hashing it is cheaper than sorting them on every lookup
        key = (vertex, fragment, geometry, frozenset(defines.items()), self._virtual_key)
        cached = self._programs.get(key)
        if cached is not None:
            return cached
        stages = {"vertex_shader": vertex, "fragment_shader": fragment,
                  "geometry_shader": geometry}
        sources = {stage: self.assemble(name, defines)
                   for stage, name in stages.items() if name is not None}
        try:
            program = self.ctx.program(**{stage: src.text for stage, src in sources.items()})
        except moderngl.Error as exc:
            raise ShaderError(self._map_error(str(exc), sources, stages,
                                              self._plugins_of)) from None
        self._programs[key] = program
        self._remember(program, sources, " + ".join(n for n in stages.values() if n is not None))
        self._uniforms[program.glo] = ProgramUniforms(program)
        return program

    def _remember(self, program: moderngl.Program | moderngl.ComputeShader,
                  sources: dict[str, Source], label: str) -> None:
        declarations = uniform_declarations(list(sources.values()))
        self._declarations[program.glo] = declarations
        self._declared[program.glo] = frozenset(declarations)
        self._sources[program.glo] = sources
        self._labels[program.glo] = label
        self._required.pop(program.glo, None)

    def declared_uniforms(self, program: moderngl.Program) -> frozenset[str]:
        """Names of the uniforms (and samplers) the program's sources declare, used or not."""
        return self._declared.get(program.glo, frozenset())

    def declaration(self, program: moderngl.Program, name: str) -> str:
        """``file:line`` declaring uniform ``name`` of ``program`` (its files where unknown)."""
        found = self._declarations.get(program.glo, {}).get(name)
        return found.where if found else self.describe(program)

    def sources(self, program: moderngl.Program) -> dict[str, Source]:
        """The assembled GLSL of each stage of ``program`` (``fragment_shader``...)."""
        return self._sources.get(program.glo, {})

    def unset_uniforms(self, program: moderngl.Program | moderngl.ComputeShader) -> list[str]:
        """Strict mode: the active uniforms of ``program`` (those the linked program uses) that
        no write gave a value since its values were last forgotten (a frame starts) and whose
        declaration gives none (an initializer or a layout binding): they read 0."""
        required = self._required.get(program.glo)
        if required is None:
            declarations = self._declarations.get(program.glo, {})
            required = self._required[program.glo] = tuple(
                name for name in program
                if isinstance(program[name], moderngl.Uniform) and not name.startswith("gl_")
                and not (name in declarations and declarations[name].preset))
        written = self.uniforms(program).written
        return [name for name in required if name not in written]

    def declared_in_folder(self, folder: str) -> frozenset[str]:
        """Uniforms declared by the shader files of ``folder`` (in any root) and the files they
        include by path: what a material's programs can declare, whichever of them run."""
        names: set[str] = set()
        seen: set[str] = set()
        pending = [f"{folder}/{entry.name}" for root in self.roots
                   for entry in _folder_entries(root, folder)]
        while pending:
            name = pending.pop()
            if name in seen:
                continue
            seen.add(name)
            try:
                text = self.read(name)
            except ShaderError:
                continue
            names |= declared_uniforms(text)
            for line in text.splitlines():
                match = _INCLUDE.match(line)
                if match and (match.group(1) or match.group(2)):
                    pending.append(match.group(1) or match.group(2))
        return frozenset(names)

    def uniforms(self, program) -> ProgramUniforms:
        """The program's uniforms, written only when their values change."""
        uniforms = self._uniforms.get(program.glo)
        if uniforms is None:
            uniforms = self._uniforms[program.glo] = ProgramUniforms(program)
        return uniforms

    def start_frame(self, forget: bool = False) -> None:
        """A frame starts: what programs hold is forgotten where code outside a frame may have
        written it (a program looked up between frames), or with ``forget`` (strict mode counts
        a frame's writes); else a frame writes only the values changed since the last."""
        if forget or self._looked_up_outside:
            self.forget_uniform_values()
        self._looked_up_outside = False
        self._in_frame = True

    def end_frame(self) -> None:
        self._in_frame = False

    def forget_uniform_values(self) -> None:
        """Forget what each program holds (a frame starts: code between frames may have
        written uniforms directly)."""
        for uniforms in self._uniforms.values():
            uniforms.forget()

    def describe(self, program: moderngl.Program) -> str:
        return self._labels.get(program.glo, "<program>")

    def compute(self, name: str, defines: dict[str, str] | None = None) -> moderngl.ComputeShader:
        """Compile (or return the cached) compute shader of this file with these defines."""
        if not self._in_frame:
            self._looked_up_outside = True
        defines = defines or {}
        key = ("compute", name, frozenset(defines.items()), self._virtual_key)
        cached = self._programs.get(key)
        if cached is not None:
            return cached
        source = self.assemble(name, defines)
        try:
            shader = self.ctx.compute_shader(source.text)
        except moderngl.Error as exc:
            raise ShaderError(self._map_error(str(exc), {"compute_shader": source},
                                              {"compute_shader": name},
                                              self._plugins_of)) from None
        self._programs[key] = shader
        self._remember(shader, {"compute_shader": source}, name)
        self._uniforms[shader.glo] = ProgramUniforms(shader, frozenset(
            name for name in self._declared[shader.glo] if name in shader))
        return shader

    @staticmethod
    def _map_error(message: str, sources: dict[str, Source], stages: dict[str, str | None],
                   plugins_of: Callable[[list[str]], list[str]] | None = None) -> str:
        """Rewrite driver line references to ``file:line`` of the stage that failed, naming the
        plugin package of the file (or else of the program's files) where a plugin's root
        holds it."""
        headers = {line.strip() for line in message.splitlines()}
        stage = next((s for s in sources if s in headers), None)
        if stage is None and len(sources) == 1:
            stage = next(iter(sources))
        lines_out: list[str] = []
        first_location = None
        for raw in message.splitlines():
            raw = raw.strip()
            if not raw or set(raw) <= {"=", "-"} or raw in sources:
                continue
            if stage is not None:
                source = sources[stage]

                def replace(m: re.Match, source: Source = source) -> str:
                    nonlocal first_location
                    line = int(m.group(2) or m.group(4))
                    file, file_line = source.locate(line)
                    if first_location is None:
                        first_location = f"{file}:{file_line}"
                    return f"{file}:{file_line}:"

                raw = _ERROR_LOCATION.sub(replace, raw, count=1)
            lines_out.append(raw)
        head = first_location or (stages.get(stage) if stage else None) or "shader"
        detail = "; ".join(line for line in lines_out if "error" in line.lower()) or \
            "; ".join(lines_out)
        text = f"{head}: {detail}" if not detail.startswith(head) else detail
        if plugins_of is None:
            return text
        failed = first_location.rpartition(":")[0] if first_location else None
        plugins = plugins_of([failed]) if failed else []
        plugins = plugins or plugins_of([file for source in sources.values()
                                         for file, _ in source.line_map])
        return f"{text} (plugin {', '.join(plugins)})" if plugins else text

    def _plugins_of(self, files: list[str]) -> list[str]:
        """The plugin packages (or shader folders) holding ``files``, as errors name them."""
        roots = dict.fromkeys(self._origins[file] for file in files if file in self._origins)
        return [root_package(root) or str(root) for root in roots]

    def release(self) -> None:
        self.generation += 1
        for program in self._programs.values():
            program.release()
        self._programs.clear()
        self._declared.clear()
        self._declarations.clear()
        self._sources.clear()
        self._required.clear()
        self._labels.clear()
        self._uniforms.clear()


def _folder_entries(root: Traversable | Path | FrameworkShaders, folder: str) -> list[Traversable]:
    directory = root.joinpath(*folder.split("/"))
    if not directory.is_dir():
        return []
    return [entry for entry in directory.iterdir()
            if entry.is_file() and entry.name.endswith(GLSL_SUFFIXES)]


def _without_comments(text: str) -> str:
    """``text`` with its comments blanked out, its lines where they were."""
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n") or " ", text,
                  flags=re.DOTALL)
    return re.sub(r"//[^\n]*", "", text)


def _declarations(text: str):
    """(name, line of ``text`` (1-based), whether it is given a value) of each uniform
    declaration; a value: an initializer, or a layout ``binding`` (a sampler's unit)."""
    text = _without_comments(text)
    for match in _UNIFORM.finditer(text):
        bound = bool(match.group(1)) and "binding" in match.group(1)
        line = text.count("\n", 0, match.start(2)) + 1
        for part in match.group(2).split(","):
            name = part.split("[")[0].split("=")[0].strip()
            if name:
                yield name, line, bound or "=" in part


def declared_uniforms(text: str) -> set[str]:
    """Uniform names declared in GLSL ``text`` (``uniform vec3 a, b[4];`` gives a and b)."""
    return {name for name, _, _ in _declarations(text)}


@dataclass(frozen=True)
class Declaration:
    """Where a uniform is declared (``file:line``) and whether the declaration gives it a
    value (an initializer or a layout binding): a pass need not set such a one."""

    where: str
    preset: bool


def uniform_declarations(sources: list[Source]) -> dict[str, Declaration]:
    """The uniforms the assembled ``sources`` (a program's stages) declare, by name."""
    found: dict[str, Declaration] = {}
    for source in sources:
        for name, line, preset in _declarations(source.text):
            file, file_line = source.locate(line)
            known = found.get(name)
            found[name] = Declaration(known.where if known else f"{file}:{file_line}",
                                      preset or (known is not None and known.preset))
    return found


@cache
def root_package(root: Traversable | Path) -> str | None:
    """The Python package (and distribution, where one is installed) holding a shader root, as
    errors name it: ``my_plugin (my-plugin-dist)``; None for a folder outside any package."""
    path = Path(str(root))
    package = None
    for folder in (path, *path.parents):
        if (folder / "__init__.py").is_file():
            package = folder.name  # the outermost folder that is a package
        elif package is not None:
            break
    if package is None:
        return None
    dists = metadata.packages_distributions().get(package, [])
    return f"{package} ({', '.join(dists)})" if dists and dists != [package] else package
