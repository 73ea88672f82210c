"""Built-in scene effects (``[[effect]]`` in scene files: ssao, fxaa, edges, taa), a package each
holding its Python and its GLSL (see :mod:`deferred.interfaces.effect`).

The effect registry (:mod:`deferred.interfaces.registry`) finds them by name through this
catalogue, as it finds a plugin through its entry points (``module:Class``): a scene imports only
the effects it uses. Its order gives the type ids, so a new built-in goes at the end.
"""

BUILTINS = {
    "edges": "deferred.effects.edges:Edges",
    "fxaa": "deferred.effects.fxaa:FXAA",
    "ssao": "deferred.effects.ssao:SSAO",
    "taa": "deferred.effects.taa:TAA",
}
