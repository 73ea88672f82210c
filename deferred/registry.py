"""Registries of materials and lights: built-ins plus the entry-point groups of plugins.

Built-in materials and lights register themselves when the ``materials`` / ``lights`` packages are
imported. Third-party packages declare an entry point in the group ``deferred.materials`` (or
``deferred.lights``) that points at the class; code can also call ``register`` at runtime.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator
from importlib.metadata import entry_points
from typing import Generic, TypeVar

from .errors import InputError

T = TypeVar("T")


class Registry(Generic[T]):
    def __init__(self, what: str, group: str, builtin_package: str):
        self.what = what
        self.group = group
        self.builtin_package = builtin_package
        self._classes: dict[str, type[T]] = {}
        self._loaded = False
        self._next_id = 1  # ids are never reused: 0 means "none" in GPU buffers

    def register(self, cls: type[T]) -> type[T]:
        """Register ``cls`` under ``cls.name``; usable as a class decorator."""
        name = getattr(cls, "name", None)
        if not isinstance(name, str) or not name:
            raise TypeError(f"{cls.__name__} has no 'name' to register it under")
        existing = self._classes.get(name)
        if existing is not None and existing is not cls:
            raise ValueError(f"{self.what} '{name}' is already registered by "
                             f"{existing.__module__}.{existing.__qualname__}")
        if existing is None:
            self._classes[name] = cls
            cls.type_id = self._next_id
            self._next_id += 1
        return cls

    def unregister(self, name: str) -> None:
        self._classes.pop(name, None)

    def _load(self) -> None:
        if self._loaded:
            return
        importlib.import_module(self.builtin_package)
        self._loaded = True
        for entry in entry_points(group=self.group):
            try:
                cls = entry.load()
            except Exception as exc:  # noqa: BLE001 - plugins fail in many ways; say which
                raise InputError(f"cannot load {self.what} plugin '{entry.name}': {exc}",
                                 f"entry point {self.group}") from None
            self.register(cls)

    def get(self, name: str, where: str | None = None) -> type[T]:
        self._load()
        cls = self._classes.get(name)
        if cls is None:
            raise InputError(f"unknown {self.what} '{name}' (choose from {', '.join(self)})",
                             where)
        return cls

    def __iter__(self) -> Iterator[str]:
        self._load()
        return iter(list(self._classes))

    def items(self) -> list[tuple[str, type[T]]]:
        self._load()
        return list(self._classes.items())


materials: Registry = Registry("material", "deferred.materials", "deferred.materials")
lights: Registry = Registry("light", "deferred.lights", "deferred.lights")
