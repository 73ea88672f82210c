"""The velvet shading model and the G-buffer channel it reads."""

from deferred.api import GBufferData, ShadingModel

from . import SHADERS

# Declared by the model, so every material lit by velvet writes it and the lights read it.
SHEEN = GBufferData("sheen", "RGBA8", ("R", "G", "B", "wrap"),
                    "velvet sheen colour and diffuse wrap")


class VelvetModel(ShadingModel):
    name = "velvet"
    glsl_file = "velvet/model.glsl"
    glsl_function = "velvet"
    gbuffer_data = (SHEEN,)
    shader_root = SHADERS
