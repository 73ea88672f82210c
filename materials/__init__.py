"""Built-in materials; importing this package registers them (see deferred.interfaces.registry)."""

from . import revie_fur, shell_fur, standard, stipple_glass  # noqa: F401
