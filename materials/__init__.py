"""Built-in materials, a package each holding its Python and its GLSL, and the shading models.

The registries (:mod:`deferred.interfaces.registry`) find them by name through these catalogues,
as they find a plugin through its entry points (``module:Class``): a scene imports only the
materials it uses. A catalogue's order gives the type ids (1, 2, ...; the G-buffer's id channel
holds them), so a new built-in goes at the end.
"""

BUILTINS = {
    "cartoon_hair": "deferred.materials.cartoon_hair:CartoonHairMaterial",
    "revie_fur": "deferred.materials.revie_fur:RevieFurMaterial",
    "shell_fur": "deferred.materials.shell_fur:ShellFurMaterial",
    "standard": "deferred.materials.standard:StandardMaterial",
    "stipple_glass": "deferred.materials.stipple_glass:StippleGlassMaterial",
    "pbr": "deferred.materials.pbr:PbrMaterial",
    "glass": "deferred.materials.glass:GlassMaterial",
    "subsurface": "deferred.materials.subsurface:SubsurfaceMaterial",
}

# One package for them all: small classes sharing G-buffer data (the strand tangent), loaded
# together
SHADING_MODELS = {
    "blinn_phong": "deferred.materials.shading_models:BlinnPhong",
    "kajiya_kay": "deferred.materials.shading_models:KajiyaKay",
    "toon": "deferred.materials.shading_models:Toon",
    "marschner": "deferred.materials.shading_models:Marschner",
    "pbr": "deferred.materials.shading_models:Pbr",
    "toon_strands": "deferred.materials.shading_models:ToonStrands",
    "subsurface": "deferred.materials.shading_models:Subsurface",
}
