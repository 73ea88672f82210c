"""deferred-wax: an example translucent plugin for the deferred framework.

- the shading model ``wax``: a wrapped diffuse part and a Blinn-Phong highlight answered apart
  (``diffuse_function``, ``specular_function``: the lighting writes the diffuse light into
  ``DIFFUSE_LIGHT`` for an effect to scatter, the highlight stays out of it), and light through
  thin parts from the shadowed lights behind them (``transmission_function``), reading a
  G-buffer channel of its own, ``wax`` (the wrap and the mean free path);
- the material ``wax``, lit by that model in both pipelines.
"""

from importlib import resources

from pydantic import Field

from deferred.api import BlinnPhongParams, GBufferData, Material, ShadingModel

SHADERS = resources.files(__name__) / "shaders"

# wrap (0..1) and the mean free path (world units) of the light under the surface
WAX = GBufferData("wax", "RG16F", ("wrap", "mean_free_path"), "wax wrap and mean free path")


class WaxModel(ShadingModel):
    name = "wax"
    glsl_file = "wax/model.glsl"
    glsl_function = "wax"  # the whole answer, where the scene does not split its light
    diffuse_function = "wax_diffuse"
    specular_function = "wax_specular"
    transmission_function = "wax_transmission"
    gbuffer_data = (WAX,)
    shader_root = SHADERS


class WaxParams(BlinnPhongParams):
    color: tuple[float, float, float] = Field((0.9, 0.75, 0.45), description="albedo")
    wrap: float = Field(0.5, ge=0.0, le=1.0, description="light wrapping past the terminator")
    mean_free_path: float = Field(0.1, gt=0.0, le=10.0,
                                  description="world units light travels inside before it "
                                  "is scattered out: how far light gets through")


class WaxMaterial(Material):
    name = "wax"
    Params = WaxParams
    surface_shader = "wax/surface.glsl"
    shader_root = SHADERS
    shading_model = "wax"
