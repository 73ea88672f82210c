"""Built-in lights; importing this package registers them (see deferred.interfaces.registry)."""

from . import ambient, directional, point, spot  # noqa: F401
