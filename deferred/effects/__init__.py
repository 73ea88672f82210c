"""Built-in scene effects (``[[effect]]`` in scene files); importing this package registers
them (see :mod:`deferred.effect` and :mod:`deferred.registry`)."""
