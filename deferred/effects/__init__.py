"""Built-in scene effects (``[[effect]]`` in scene files: ssao, fxaa, edges, taa); importing this
package registers them (see :mod:`deferred.interfaces.effect` and
:mod:`deferred.interfaces.registry`)."""

from deferred.effects import edges, fxaa, ssao, taa  # noqa: F401
