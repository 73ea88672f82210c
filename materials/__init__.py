"""Built-in materials; importing this package registers them (see deferred.interfaces.registry)."""

from . import cartoon_hair, revie_fur, shell_fur, standard, stipple_glass  # noqa: F401
