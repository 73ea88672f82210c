"""Registries of materials, lights, shading models and effects: built-ins plus plugins.

Built-ins and plugins are found the same way: by name, through an entry point naming the class
(``module:Class``), imported only when a scene (or a listing) asks for that name. A plugin
package declares its entry points in the group ``deferred.materials`` (``deferred.lights``,
``deferred.shading_models``, ``deferred.effects``), named as the class's ``name``; the built-ins'
are the catalogue ``BUILTINS`` of their package (``deferred.materials``, ``deferred.lights``,
``deferred.effects``; the shading models' is ``deferred.materials:SHADING_MODELS``), read without
importing a built-in. Code can also call ``register``.

The built-in packages are plugins too: they import ``deferred.api``, which sits above this
layer, so the registry imports them by name (``importlib``), never by an import statement (the
layer contract, ``tests/deferred/test_layers.py``, covers import statements).

A built-in's type id (the G-buffer's id channel holds a material's) is its place in its
catalogue, whatever is loaded first; a plugin's comes after the built-ins', in the order plugins
register. Loading a name loads that class only, so a broken plugin fails only the scenes that
use it. Listing everything (``deferred params``) loads every class and skips a broken plugin
with a warning naming it.
"""

from __future__ import annotations

import importlib
import threading
import warnings
from collections.abc import Iterator
from importlib.metadata import EntryPoint, entry_points
from typing import Generic, TypeVar

from deferred.errors import InputError
from deferred.gbuffer.surface_id import MAX_MATERIAL_ID, MAX_SHADING_MODEL_ID
from deferred.validation import closest

T = TypeVar("T")


# Held while a built-in or a plugin loads (every registry: loading one module may register into
# several)
_loading = threading.RLock()


class PluginWarning(UserWarning):
    """A plugin that could not be loaded was skipped."""


class Registry(Generic[T]):
    """One kind's classes by name. ``catalogue``: ``"package"`` or ``"package:ATTRIBUTE"``,
    the module and attribute (``BUILTINS`` unless named) holding the built-ins' catalogue, a
    dict of name to ``"module:Class"`` in the order of their type ids (none: no built-ins)."""

    def __init__(self, what: str, group: str, catalogue: str, max_id: int | None = None):
        self.what = what
        self.group = group
        self.catalogue = catalogue
        self.max_id = max_id  # ids are stored in the G-buffer for some registries
        self._classes: dict[str, type[T]] = {}
        self._ids: dict[str, int] = {}  # name -> the type id its class was given here
        self._builtin_entries: dict[str, EntryPoint] | None = None  # read on first use
        self._tried: dict[str, str | None] = {}  # entry point name -> error (None: loaded)
        # entry point name -> (the class's ``name`` it registered, what it is): named otherwise
        self._misnamed: dict[str, tuple[str, str]] = {}
        self._next_id: int | None = None  # after the built-ins'; never reused: 0 is "none"

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
            cls.type_id = self._ids[name] = self._new_id(cls, name)
            self._classes[name] = cls
        return cls

    def _new_id(self, cls: type[T], name: str) -> int:
        builtins = self._builtins()
        builtin = builtins.get(name)
        if builtin is not None:
            if builtin.value != f"{cls.__module__}:{cls.__qualname__}":
                raise ValueError(f"{self.what} '{name}' is the name of the built-in "
                                 f"{builtin.value.replace(':', '.')}")
            return list(builtins).index(name) + 1
        if self._next_id is None:
            self._next_id = len(builtins) + 1
        if self.max_id is not None and self._next_id > self.max_id:
            raise ValueError(f"cannot register {self.what} '{name}': ids 1..{self.max_id} "
                             "are used up (the G-buffer has room for no more)")
        self._next_id += 1
        return self._next_id - 1

    def unregister(self, name: str) -> None:
        self._classes.pop(name, None)

    # -- loading -----------------------------------------------------------------------------
    def _builtins(self) -> dict[str, EntryPoint]:
        """The built-ins' entry points by name, in the order of their ids (their package's
        catalogue, read once; no built-in is imported)."""
        if self._builtin_entries is None:
            module, _, attribute = self.catalogue.partition(":")
            catalogue = getattr(importlib.import_module(module), attribute or "BUILTINS", {})
            self._builtin_entries = {name: EntryPoint(name, value, self.group)
                                     for name, value in catalogue.items()}
        return self._builtin_entries

    def _load_builtin(self, name: str) -> type[T] | None:
        """The built-in named ``name``, imported and registered; None where there is none.
        A built-in that fails to import raises: that is the framework's bug, not bad input."""
        entry = self._builtins().get(name)
        if entry is None:
            return None
        with _loading:
            return self._classes.get(name) or self.register(entry.load())

    def _entry_points(self) -> list[EntryPoint]:
        return list(entry_points(group=self.group))

    def _load_entry(self, entry: EntryPoint) -> str | None:
        """Load and register one plugin; the error message, or None."""
        with _loading:
            return self._load_entry_locked(entry)

    def _load_entry_locked(self, entry: EntryPoint) -> str | None:
        if entry.name in self._tried:
            return self._tried[entry.name]
        error = None
        dist = f" ({entry.dist.name})" if entry.dist is not None else ""
        try:
            cls = self.register(entry.load())
        except Exception as exc:  # noqa: BLE001 - plugins fail in many ways; say which
            error = f"cannot load {self.what} plugin '{entry.name}'{dist}: " \
                    f"{type(exc).__name__}: {exc}"
        else:
            if cls.name != entry.name:
                self._misnamed[entry.name] = (
                    cls.name, f"{self.what} plugin entry point '{entry.name}'{dist} loads "
                              f"{entry.value}, whose name is '{cls.name}'")
        self._tried[entry.name] = error
        return error

    def _misnamed_hint(self, entry_name: str) -> str:
        """What to do about an entry point named otherwise than its class."""
        real, what = self._misnamed[entry_name]
        return f"{what}: ask for '{real}', and name the entry point '{real}' so that it loads " \
               "alone"

    def _load_all(self) -> None:
        for name in self._builtins():
            self._load_builtin(name)
        for entry in self._entry_points():
            first_time = entry.name not in self._tried
            error = self._load_entry(entry)
            if error and first_time:
                warnings.warn(f"{error} (skipped)", PluginWarning, stacklevel=3)
            elif first_time and entry.name in self._misnamed:
                warnings.warn(self._misnamed_hint(entry.name), PluginWarning, stacklevel=3)

    # -- lookup ------------------------------------------------------------------------------
    def get(self, name: str, where: str | None = None) -> type[T]:
        cls = self._classes.get(name) or self._load_builtin(name)
        if cls is not None:
            return cls
        for entry in self._entry_points():
            if entry.name == name:
                error = self._load_entry(entry)
                if error:
                    raise InputError(error, where or f"entry point {self.group}")
                if entry.name in self._misnamed:
                    raise InputError(self._misnamed_hint(entry.name), where)
        cls = self._classes.get(name)
        if cls is None:
            cls = self._from_misnamed_entry(name)
        if cls is None:
            raise InputError(self.unknown(name), where)
        return cls

    def _from_misnamed_entry(self, name: str) -> type[T] | None:
        """``name`` registered by an entry point named otherwise (every plugin loads to find
        it), with a warning saying so; None where no plugin has it."""
        self._load_all()
        cls = self._classes.get(name)
        entry = next((entry for entry, (real, _) in self._misnamed.items() if real == name),
                     None)
        if cls is not None and entry is not None:
            warnings.warn(self._misnamed_hint(entry), PluginWarning, stacklevel=3)
        return cls

    def unknown(self, name: object) -> str:
        """The message for an unknown ``name``: the closest registered name, else them all."""
        match = closest(name, self)
        # quoted as Python would where the name holds a quote or a control character (a
        # newline would split the one-line error)
        shown = repr(name[:80] if isinstance(name, str) else name)
        hint = f"did you mean '{match}'? " if match is not None else ""
        return f"unknown {self.what} {shown} ({hint}choose from {', '.join(self)})"

    def builtins(self) -> list[type[T]]:
        """The built-in classes (each imported), in the order of their ids, whatever plugins
        are installed."""
        return [self._load_builtin(name) for name in self._builtins()]

    def _in_id_order(self) -> list[tuple[str, type[T]]]:
        # the built-ins first, then plugins as they registered, whichever loaded first
        return sorted(self._classes.items(), key=lambda item: self._ids[item[0]])

    def __iter__(self) -> Iterator[str]:
        self._load_all()
        return iter([name for name, _ in self._in_id_order()])

    def items(self) -> list[tuple[str, type[T]]]:
        self._load_all()
        return self._in_id_order()


materials: Registry = Registry("material", "deferred.materials", "deferred.materials",
                               max_id=MAX_MATERIAL_ID)
# a listed light's colour texel holds its type id in w's low 8 bits (lighting/light_lists.glsl)
lights: Registry = Registry("light", "deferred.lights", "deferred.lights", max_id=255)
shading_models: Registry = Registry("shading model", "deferred.shading_models",
                                    "deferred.materials:SHADING_MODELS",
                                    max_id=MAX_SHADING_MODEL_ID)
effects: Registry = Registry("effect", "deferred.effects", "deferred.effects")
