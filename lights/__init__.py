"""Built-in lights, a package each holding its Python and its GLSL.

The light registry (:mod:`deferred.interfaces.registry`) finds them by name through this
catalogue, as it finds a plugin through its entry points (``module:Class``): a scene imports only
the light types it uses. Its order gives the type ids (1, 2, ...; a listed light's record holds
its type's), so a new built-in goes at the end.
"""

BUILTINS = {
    "ambient": "deferred.lights.ambient:AmbientLight",
    "directional": "deferred.lights.directional:DirectionalLight",
    "point": "deferred.lights.point:PointLight",
    "spot": "deferred.lights.spot:SpotLight",
    "environment": "deferred.lights.environment:EnvironmentLight",
    "rect": "deferred.lights.rect:RectLight",
    "disc": "deferred.lights.disc:DiscLight",
}
