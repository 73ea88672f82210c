from pathlib import Path

import pytest

from deferred.errors import ShaderError
from deferred.gl.shaderlib import MAX_INCLUDE_DEPTH, ShaderLibrary


@pytest.fixture
def library(gl, tmp_path):
    lib = ShaderLibrary(gl.ctx, 330)
    lib.roots = [tmp_path]
    yield lib
    lib.release()


def write(root: Path, name: str, text: str) -> None:
    path = root / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


def test_include_is_resolved_once_and_mapped_to_files(library, tmp_path):
    write(tmp_path, "a.glsl", "float a() { return 1.0; }\n")
    write(tmp_path, "b.glsl", '#include "a.glsl"\nfloat b() { return a(); }\n')
    write(tmp_path, "main.frag", '#include "a.glsl"\n#include "b.glsl"\nout vec4 c;\n'
                                 "void main() { c = vec4(b()); }\n")
    source = library.assemble("main.frag", {"FOO": "2"})
    assert source.text.startswith("#version 330 core\n#define FOO 2\n")
    assert source.text.count("float a()") == 1
    line = source.text.splitlines().index("float b() { return a(); }") + 1
    assert source.locate(line) == ("b.glsl", 2)


def test_compile_error_names_the_included_file_and_line(library, tmp_path):
    write(tmp_path, "inc/bad.glsl",
          "float ok() { return 1.0; }\n\nfloat broken() { return vec3(1.0); }\n")
    write(tmp_path, "main.frag",
          '#include "inc/bad.glsl"\nout vec4 c;\nvoid main() { c = vec4(ok()); }\n')
    write(tmp_path, "quad.vert", "void main() { gl_Position = vec4(0.0); }\n")
    with pytest.raises(ShaderError) as info:
        library.program("quad.vert", "main.frag", defines={"A": "1", "B": "2"})
    assert str(info.value).startswith("inc/bad.glsl:3:")


def test_error_in_the_main_file_after_injected_defines(library, tmp_path):
    write(tmp_path, "quad.vert",
          "void main() {\n  gl_Position = vec4(0.0);\n  undefined_call();\n}\n")
    write(tmp_path, "ok.frag", "out vec4 c;\nvoid main() { c = vec4(1.0); }\n")
    with pytest.raises(ShaderError, match=r"^quad\.vert:3:"):
        library.program("quad.vert", "ok.frag", defines={"X": "1", "Y": "2", "Z": "3"})


def test_include_through_an_injected_define(library, tmp_path):
    write(tmp_path, "surface_a.glsl", "vec4 colour() { return vec4(0.25); }\n")
    write(tmp_path, "main.frag", "#include SURFACE\nout vec4 c;\nvoid main() { c = colour(); }\n")
    source = library.assemble("main.frag", {"SURFACE": '"surface_a.glsl"'})
    assert "vec4(0.25)" in source.text
    with pytest.raises(ShaderError, match="no such define"):
        library.assemble("main.frag", {})


def test_include_cycle_and_depth_limit(library, tmp_path):
    # Include-once makes a cycle harmless: each file appears once.
    write(tmp_path, "x.glsl", '#include "y.glsl"\nfloat x;\n')
    write(tmp_path, "y.glsl", '#include "x.glsl"\nfloat y;\n')
    text = library.assemble("x.glsl").text
    assert text.count("float x;") == 1 and text.count("float y;") == 1
    for i in range(MAX_INCLUDE_DEPTH + 2):
        write(tmp_path, f"d{i}.glsl", f'#include "d{i + 1}.glsl"\n')
    write(tmp_path, f"d{MAX_INCLUDE_DEPTH + 2}.glsl", "\n")
    with pytest.raises(ShaderError, match="deeper than"):
        library.assemble("d0.glsl")


def test_missing_include_is_reported(library, tmp_path):
    write(tmp_path, "main.frag", '#include "nowhere.glsl"\n')
    with pytest.raises(ShaderError, match="nowhere.glsl"):
        library.assemble("main.frag")


def test_programs_are_cached_by_files_and_defines(library, tmp_path):
    write(tmp_path, "quad.vert", "void main() { gl_Position = vec4(0.0); }\n")
    write(tmp_path, "ok.frag", "out vec4 c;\nvoid main() { c = vec4(VALUE); }\n")
    first = library.program("quad.vert", "ok.frag", defines={"VALUE": "1.0"})
    assert library.program("quad.vert", "ok.frag", defines={"VALUE": "1.0"}) is first
    assert library.program("quad.vert", "ok.frag", defines={"VALUE": "0.5"}) is not first


def test_every_packaged_shader_program_compiles(gl):
    """The built-in programs compile on this driver (both light-buffer variants), with every
    built-in light type and shading model and their G-buffer data; installed plugins play no
    part."""
    from deferred.gbuffer.layout import GBufferLayout
    from deferred.interfaces import registry
    from deferred.materials.standard import StandardMaterial
    from deferred.render.generated import generated_glsl

    lights = registry.lights.builtins()
    models = registry.shading_models.builtins()
    assert {m.name for m in models} >= {"blinn_phong", "kajiya_kay", "toon"}
    layout = GBufferLayout({d.name: d for m in models for d in m.gbuffer_data})
    files = generated_glsl(lights, models, layout, [StandardMaterial()])
    for version, defines in ((430, {"DEFERRED_STORAGE_BUFFERS": "1"}), (330, {})):
        if version > gl.ctx.version_code:
            continue
        lib = ShaderLibrary(gl.ctx, version, defines)
        for name, text in files.items():
            lib.set_virtual_file(name, text)
        surface = {"SURFACE_FILE": '"materials/standard/surface.glsl"',
                   "GBUFFER_DATA_WRITE": '"generated/gbuffer_write/none.glsl"'}
        lib.program("common/mesh.vert", "gbuffer/geometry.frag", defines=surface)
        lib.program("common/mesh.vert", "forward/lit.frag", defines=surface)
        lib.program("lighting/volume.vert", "lighting/accumulate.frag")
        lib.program("lighting/fullscreen.vert", "lighting/accumulate.frag")
        lib.program("post/fullscreen.vert", "post/tonemap.frag")
        lib.release()


def test_a_public_include_by_its_former_name_says_what_to_write(gl):
    library = ShaderLibrary(gl.ctx, 330)
    with pytest.raises(ShaderError, match='techniques/stipple.glsl: the framework names it '
                                          'materials/techniques/stipple.glsl; write #include '
                                          '"materials/techniques/stipple.glsl"'):
        library.read("techniques/stipple.glsl")
    with pytest.raises(ShaderError, match='write #include "lighting/shadows.glsl"'):
        library.read("lights/shadows.glsl")
    with pytest.raises(ShaderError, match="shader file not found: techniques/nope.glsl "
                                          "\\(searched: "):
        library.read("techniques/nope.glsl")


def test_builtin_features_glsl_is_found_beside_their_python(gl):
    """A name's first folder materials/, lights/ or effects/ is the feature package's: the
    files sit beside the Python; any other name is a file of deferred.shaders."""
    from importlib import resources

    library = ShaderLibrary(gl.ctx, 330)
    for name, package, file in (
            ("materials/revie_fur/shell.frag", "deferred.materials.revie_fur", "shell.frag"),
            ("lights/point/point.glsl", "deferred.lights.point", "point.glsl"),
            ("effects/ssao/ssao.frag", "deferred.effects.ssao", "ssao.frag"),
            ("lighting/shadows.glsl", "deferred.shaders", "lighting/shadows.glsl")):
        assert library.read(name) == resources.files(package).joinpath(file).read_text("utf-8")


def test_missing_file_lists_the_roots_searched(library, tmp_path):
    with pytest.raises(ShaderError, match=f"shader file not found: nope.glsl \\(searched: "
                                          f"{tmp_path}\\)"):
        library.read("nope.glsl")


@pytest.mark.parametrize("driver_line", [
    "0:5(12): error: `foo' undeclared",  # Mesa
    "0(5) : error C1008: undefined variable \"foo\"",  # NVIDIA
])
def test_driver_error_formats_map_to_file_and_line(library, tmp_path, driver_line):
    write(tmp_path, "inc.glsl", "// one\n// two\nfloat f() { return foo; }\n")
    write(tmp_path, "main.frag", '#include "inc.glsl"\nvoid main() {}\n')
    source = library.assemble("main.frag", {"A": "1"})  # version + 1 define + 2 comment lines
    assert source.locate(5) == ("inc.glsl", 3)
    message = f"GLSL Compiler failed\n\nfragment_shader\n===============\n{driver_line}\n"
    mapped = ShaderLibrary._map_error(message, {"fragment_shader": source},
                                      {"fragment_shader": "main.frag"})
    assert mapped.startswith("inc.glsl:3: ") and "foo" in mapped


def test_a_root_added_first_replaces_files_and_only_before_any_program(library, tmp_path):
    write(tmp_path, "a.glsl", "float a() { return 1.0; }\n")
    write(tmp_path, "main.frag", '#include "a.glsl"\nout vec4 c;\nvoid main() { c = vec4(a()); }\n')
    variant = tmp_path / "variant"
    write(variant, "a.glsl", "float a() { return 2.0; }\n")
    library.add_root(variant, first=True)
    assert "return 2.0" in library.assemble("main.frag").text  # the variant's file wins
    assert "return 1.0" not in library.assemble("main.frag").text
    later = tmp_path / "later"
    write(later, "a.glsl", "float a() { return 3.0; }\n")
    library.add_root(later)  # appended: searched after the others
    assert "return 2.0" in library.assemble("main.frag").text
    write(tmp_path, "main.vert", "void main() { gl_Position = vec4(0.0); }\n")
    library.program("main.vert", "main.frag")
    with pytest.raises(RuntimeError, match="before any program is compiled"):
        library.add_root(tmp_path / "too_late", first=True)  # compiled from what it would hide


def test_declared_uniforms_read_through_layouts_and_qualifiers():
    from deferred.gl.shaderlib import declared_uniforms

    text = ("layout(rgba32f) uniform writeonly image2D u_image;\n"
            "uniform highp float u_a, u_b[4];\n"
            "layout(binding = 1) uniform restrict readonly image2D u_source;\n"
            "layout(r32f) coherent uniform image2D u_before;\n"
            "// uniform float u_commented;\n"
            "uniform Block { vec4 inside; };\n")
    assert declared_uniforms(text) == {"u_image", "u_a", "u_b", "u_source", "u_before"}
