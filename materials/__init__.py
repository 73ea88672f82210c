"""Built-in materials; importing this package registers them (see deferred.registry)."""

from . import standard  # noqa: F401
