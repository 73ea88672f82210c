"""The velvet material: a surface function and parameters; the framework does the rest."""

from pydantic import Field

from deferred.api import Material, MaterialParams

from . import SHADERS

Vec3 = tuple[float, float, float]


class VelvetParams(MaterialParams):
    color: Vec3 = Field((0.35, 0.05, 0.12), description="linear RGB albedo")
    sheen_color: Vec3 = Field((1.0, 0.75, 0.8), description="colour of the grazing sheen")
    sheen: float = Field(0.8, ge=0.0, le=1.0, description="sheen strength")
    sheen_falloff: float = Field(4.0, ge=1.0, le=16.0, description="exponent of 1 - N.V")
    wrap: float = Field(0.4, ge=0.0, le=1.0, description="light wrapping past the terminator")


class VelvetMaterial(Material):
    name = "velvet"
    Params = VelvetParams
    surface_shader = "velvet/surface.glsl"
    shader_root = SHADERS
    shading_model = "velvet"
