"""Strict mode catches a plugin author's silent mistakes: a uniform a program uses that nothing
sets, G-buffer data declared and never written, a parameter no pass of an effect declares; a
two-pass effect's parameters reach each pass that declares them; GLSL errors name the plugin's
package; an entry point named otherwise than its class says so."""

import numpy as np
import pytest
from strict_plugin import (
    BrokenMaterial,
    MaskedMaterial,
    PresetTintMaterial,
    RaisingMaterial,
    TintedMaterial,
    TwoPassEffect,
    UnmaskedMaterial,
    UnusedParameterEffect,
)

from deferred.errors import RenderError, ShaderError
from deferred.gl.shaderlib import ShaderLibrary
from deferred.interfaces import registry
from deferred.render.renderer import Renderer
from deferred.scene.loader import scene_from_dict

MATERIALS = (TintedMaterial, PresetTintMaterial, MaskedMaterial, UnmaskedMaterial,
             BrokenMaterial, RaisingMaterial)
EFFECTS = (TwoPassEffect, UnusedParameterEffect)
SIZE = (64, 48)


@pytest.fixture(scope="module", autouse=True)
def plugins():
    for cls in MATERIALS:
        registry.materials.register(cls)
    for cls in EFFECTS:
        registry.effects.register(cls)
    yield
    for cls in MATERIALS:
        registry.materials.unregister(cls.name)
    for cls in EFFECTS:
        registry.effects.unregister(cls.name)


def scene(material="standard", effects=()):
    return scene_from_dict({
        "size": list(SIZE), "tonemap": "none",
        "camera": {"position": [0.0, 0.0, 3.0], "target": [0.0, 0.0, 0.0]},
        "object": [{"mesh": "builtin:sphere", "material": material}],
        "light": [{"type": "ambient", "intensity": 1.0}],
        "effect": [{"type": name} for name in effects]})


def render(gl, scene, pipeline="deferred", strict=True, targets=()):
    with Renderer(scene, pipeline, gl=gl, strict=strict) as renderer:
        result = renderer.render()
        return result.image, {name: renderer.targets.read(name)[::-1] for name in targets}


@pytest.mark.parametrize("pipeline, pass_name", [("deferred", "sphere0.gbuffer"),
                                                 ("forward", "sphere0.forward")])
def test_a_uniform_nothing_sets_fails_naming_the_pass_file_and_uniform(gl, pipeline, pass_name):
    with pytest.raises(RenderError) as info:
        render(gl, scene("test_strict_tinted"), pipeline)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"pass {pass_name}: program ")
    assert "nothing sets uniform 'u_tint' (materials/test_strict/tinted.glsl:7)" in message
    # not strict, the mistake is silent: the albedo times an unset tint is black
    image, _ = render(gl, scene("test_strict_tinted"), pipeline, strict=False)
    assert image[SIZE[1] // 2, SIZE[0] // 2, :3].max() == 0


def test_a_uniform_its_declaration_gives_a_value_needs_none(gl):
    image, _ = render(gl, scene("test_strict_preset_tint"))
    assert image[SIZE[1] // 2, SIZE[0] // 2, 0] > 100  # the colour, tinted by 1


def test_uniforms_and_samplers_written_before_a_frame_started_are_unset_again(gl):
    library = ShaderLibrary(gl.ctx, 330)
    library.virtual_files["quad.vert"] = "void main() { gl_Position = vec4(0.0); }\n"
    library.virtual_files["use.frag"] = (
        "uniform float u_gain;\nuniform sampler2D u_image;\nuniform float u_unused;\n"
        "uniform float u_preset = 2.0;\nout vec4 c;\n"
        "void main() { c = texture(u_image, vec2(0.5)) * u_gain * u_preset; }\n")
    try:
        program = library.program("quad.vert", "use.frag")
        # the unused and the initialised uniform are no one's to set
        assert sorted(library.unset_uniforms(program)) == ["u_gain", "u_image"]
        library.uniforms(program).set({"u_gain": 0.5, "u_image": 0})
        assert library.unset_uniforms(program) == []
        library.forget_uniform_values()  # a frame starts: values kept from the last count not
        assert sorted(library.unset_uniforms(program)) == ["u_gain", "u_image"]
        assert library.declaration(program, "u_gain") == "use.frag:1"
    finally:
        library.release()


def test_g_buffer_data_never_written_fails_naming_the_material_datum_and_file(gl):
    for pipeline in ("deferred", "forward"):  # the forward pipeline writes no G-buffer
        if pipeline == "forward":
            render(gl, scene("test_strict_unmasked"), pipeline)
            continue
        with pytest.raises(RenderError) as info:
            render(gl, scene("test_strict_unmasked"), pipeline)
        message = str(info.value)
        assert "\n" not in message
        assert message.startswith("material test_strict_unmasked: its surface code "
                                  "(materials/test_strict/unmasked.glsl) never writes the "
                                  "G-buffer data 'gloss_mask'")


def test_g_buffer_data_written_passes_and_holds_its_value(gl):
    _, targets = render(gl, scene("test_strict_masked"), targets=("gloss_mask",))
    centre = targets["gloss_mask"][SIZE[1] // 2, SIZE[0] // 2]
    assert np.allclose(centre[:2], (0.5, 0.25))


def test_each_pass_of_a_two_pass_effect_gets_the_parameters_its_program_declares(gl):
    plain, _ = render(gl, scene())
    image, _ = render(gl, scene(effects=["test_strict_two_pass"]))
    # 8-bit sRGB round trips: gain 0.5 over the copy, then 0.25 added
    expected = np.clip(plain[..., :3] / 255.0 * 0.5 + 0.25, 0.0, 1.0) * 255.0
    assert np.abs(image[..., :3].astype(float) - expected).max() <= 2.0


def test_an_effect_parameter_no_pass_declares_fails_naming_the_effect(gl):
    with pytest.raises(RenderError, match=r"^effect test_strict_unused_parameter: no program "
                                          r"of its passes declares uniform 'u_grain'$"):
        render(gl, scene(effects=["test_strict_unused_parameter"]))


def test_a_plugin_glsl_error_names_the_package_file_and_line(gl):
    with pytest.raises(ShaderError) as info:
        render(gl, scene("test_strict_broken"), strict=False)
    message = str(info.value)
    assert message.startswith("pass sphere0.gbuffer: materials/test_strict/broken.glsl:9:")
    assert message.endswith("(plugin strict_plugin)")


def test_a_plugin_pass_raising_names_the_pass_and_the_package(gl):
    with pytest.raises(RenderError, match=r"^pass sphere0\.gbuffer: ValueError: the plugin's own "
                                          r"bug \(plugin strict_plugin\)$"):
        render(gl, scene("test_strict_raising"), strict=False)


def misnamed_distribution(tmp_path, monkeypatch, group):
    info = tmp_path / "misnamed_plugin-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: misnamed-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        f"[{group}]\nmisnamed_entry = strict_plugin:MisnamedMaterial\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    return registry.Registry("material", group, "json")  # no built-ins


HINT = ("material plugin entry point 'misnamed_entry' (misnamed-plugin) loads "
        "strict_plugin:MisnamedMaterial, whose name is 'test_strict_misnamed': ask for "
        "'test_strict_misnamed', and name the entry point 'test_strict_misnamed' so that it "
        "loads alone")


def test_an_entry_point_named_otherwise_than_its_class_says_so_when_asked_by_either(
        tmp_path, monkeypatch):
    from deferred.errors import InputError

    materials = misnamed_distribution(tmp_path, monkeypatch, "deferred.test_misnamed")
    with pytest.raises(InputError) as info:
        materials.get("misnamed_entry", "scene.toml: object[0].material")
    assert str(info.value) == f"scene.toml: object[0].material: {HINT}"
    # by the class's name it is found, with the same advice
    materials = misnamed_distribution(tmp_path / "again", monkeypatch, "deferred.test_misnamed2")
    with pytest.warns(registry.PluginWarning) as warned:
        assert materials.get("test_strict_misnamed").__name__ == "MisnamedMaterial"
    assert str(warned[0].message) == HINT


def test_listing_plugins_warns_of_an_entry_point_named_otherwise(tmp_path, monkeypatch):
    materials = misnamed_distribution(tmp_path, monkeypatch, "deferred.test_misnamed3")
    with pytest.warns(registry.PluginWarning, match="whose name is 'test_strict_misnamed'"):
        assert list(materials) == ["test_strict_misnamed"]


def test_a_glsl_error_names_an_installed_plugin_by_package_and_distribution(
        gl, tmp_path, monkeypatch):
    package = tmp_path / "my_shader_plugin"
    (package / "shaders").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "shaders" / "bad.frag").write_text("out vec4 c;\nvoid main() { c = 1; }\n")
    info = tmp_path / "my_shader_plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: my-shader-plugin\n"
                                   "Version: 0.1\n")
    (info / "top_level.txt").write_text("my_shader_plugin\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    library = ShaderLibrary(gl.ctx, 330)
    library.add_root(package / "shaders")
    try:
        with pytest.raises(ShaderError) as raised:
            library.program("post/fullscreen.vert", "bad.frag")
    finally:
        library.release()
    message = str(raised.value)
    assert message.startswith("bad.frag:2:")
    assert message.endswith("(plugin my_shader_plugin (my-shader-plugin))")
