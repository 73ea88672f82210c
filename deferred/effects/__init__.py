"""Built-in scene effects (``[[effect]]`` in scene files: ssao, fxaa, edges); importing this
package registers them (see :mod:`deferred.effect` and :mod:`deferred.registry`)."""

from . import edges, fxaa, ssao  # noqa: F401
