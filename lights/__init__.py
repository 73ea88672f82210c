"""Built-in lights; importing this package registers them (see deferred.registry)."""

from . import ambient, directional, point, spot  # noqa: F401
