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

A plugin is checked as it loads: its module imports, the entry point gives a class deriving
from the registry's interface (``Material``, ``Light``, ...) with what a scene needs of it
(``name``, ``Params``, ``from_dict``), and no other distribution declares the same name.
Each failure is one line naming the entry point, its distribution and what is wrong.
"""

from __future__ import annotations

import importlib
import threading
import types
import warnings
from collections.abc import Iterator
from importlib.metadata import EntryPoint, entry_points
from typing import Generic, TypeVar

from deferred.errors import InputError
from deferred.gbuffer.surface_id import MAX_MATERIAL_ID, MAX_SHADING_MODEL_ID
from deferred.params import Params
from deferred.validation import closest

T = TypeVar("T")


# Held while a built-in or a plugin loads (every registry: loading one module may register into
# several)
_loading = threading.RLock()


class PluginWarning(UserWarning):
    """A plugin that could not be loaded was skipped."""


MAX_PLUGIN_ERROR = 300  # characters of a plugin's own exception message said


class Registry(Generic[T]):
    """One kind's classes by name. ``catalogue``: ``"package"`` or ``"package:ATTRIBUTE"``,
    the module and attribute (``BUILTINS`` unless named) holding the built-ins' catalogue, a
    dict of name to ``"module:Class"`` in the order of their type ids (none: no built-ins).
    ``interface``: ``"module:Class"``, the base every plugin's class derives from, and
    ``requires`` the class attributes a plugin's class must have (none: anything with a
    ``name`` registers); ``check``: ``"module:function"`` saying what else is wrong with a
    class (after "which"), or None."""

    def __init__(self, what: str, group: str, catalogue: str, max_id: int | None = None,
                 interface: str | None = None, requires: tuple[str, ...] = (),
                 check: str | None = None):
        self.what = what
        self.check = check
        self.group = group
        self.catalogue = catalogue
        self.max_id = max_id  # ids are stored in the G-buffer for some registries
        self.interface = interface
        self.requires = requires
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
            problem = self.class_problem(cls)
            if problem is not None:
                raise TypeError(f"{self.what} class {cls.__qualname__} {problem}")
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
        named = f"{self.what} plugin '{entry.name}'{distribution(entry)}"
        try:
            loaded = entry.load()
        except (Exception, SystemExit) as exc:  # noqa: BLE001 - plugins fail in many ways
            error = f"cannot load {named}: {type(exc).__name__}: {shortened(exc)}"
        else:
            problem = self.interface_problem(loaded)
            if problem is not None:
                error = f"{named} loads {entry.value}, which {problem}"
            else:
                try:
                    cls = self.register(loaded)
                except (TypeError, ValueError) as exc:
                    error = f"cannot load {named}: {exc}"
                else:
                    if cls.name != entry.name:
                        self._misnamed[entry.name] = (
                            cls.name, f"{self.what} plugin entry point '{entry.name}'"
                                      f"{distribution(entry)} loads {entry.value}, whose name "
                                      f"is '{cls.name}'")
        self._tried[entry.name] = error
        return error

    def interface_problem(self, loaded: object) -> str | None:
        """What keeps ``loaded`` (what an entry point gave) from being one of this registry's
        classes, said after "which"; None where nothing does."""
        if not isinstance(loaded, type):
            return f"is not a class but {kind_of(loaded)}"
        if self.interface is not None:
            base = self.interface_class()
            if not issubclass(loaded, base):
                bases = [b.__qualname__ for b in loaded.__mro__[1:-1]]
                derives = f"derives from {', '.join(bases)}" if bases else "derives from nothing"
                return f"is not a {base.__qualname__} subclass (it {derives})"
        missing = [attribute for attribute in ("name", *self.requires)
                   if getattr(loaded, attribute, None) is None]
        if missing:
            return f"lacks {', '.join(missing)}"
        if not isinstance(loaded.name, str) or not loaded.name:
            return f"has name {loaded.name!r}, not a non-empty string"
        if "Params" in self.requires and not (isinstance(loaded.Params, type) and
                                              issubclass(loaded.Params, Params)):
            return f"has a Params that is not a deferred.api.Params subclass ({loaded.Params!r})"
        if "from_dict" in self.requires and not callable(loaded.from_dict):
            return "has a from_dict that cannot be called"
        return self.class_problem(loaded)

    def class_problem(self, cls: type) -> str | None:
        """What this registry's ``check`` finds wrong with ``cls`` (None: nothing, or no
        check)."""
        if self.check is None:
            return None
        module, _, attribute = self.check.partition(":")
        return getattr(importlib.import_module(module), attribute)(cls)

    def interface_class(self) -> type:
        """The interface's class, imported on first use (it imports this module)."""
        module, _, attribute = self.interface.partition(":")
        return getattr(importlib.import_module(module), attribute)

    def _declared_twice(self, entries: list[EntryPoint]) -> str | None:
        """The error for a name that several distributions declare with different classes."""
        values = {entry.value for entry in entries}
        if len(values) < 2:
            return None
        said = " and ".join(f"{entry.value}{distribution(entry)}" for entry in entries)
        return f"{self.what} plugin '{entries[0].name}' is declared twice, by {said}: " \
               "uninstall one, or rename its entry point and class"

    def _entries_by_name(self) -> dict[str, list[EntryPoint]]:
        by_name: dict[str, list[EntryPoint]] = {}
        for entry in self._entry_points():
            by_name.setdefault(entry.name, []).append(entry)
        return by_name

    def _misnamed_hint(self, entry_name: str) -> str:
        """What to do about an entry point named otherwise than its class."""
        real, what = self._misnamed[entry_name]
        return f"{what}: ask for '{real}', and name the entry point '{real}' so that it loads " \
               "alone"

    def _load_all(self) -> None:
        for name in self._builtins():
            self._load_builtin(name)
        for name, entries in self._entries_by_name().items():
            first_time = name not in self._tried
            error = self._declared_twice(entries)
            if error is not None:
                self._tried[name] = error  # neither is loaded: which one is meant is unknown
            else:
                error = self._load_entry(entries[0])
            if error and first_time:
                warnings.warn(f"{error} (skipped)", PluginWarning, stacklevel=3)
            elif first_time and name in self._misnamed:
                warnings.warn(self._misnamed_hint(name), PluginWarning, stacklevel=3)

    # -- lookup ------------------------------------------------------------------------------
    def get(self, name: str, where: str | None = None) -> type[T]:
        cls = self._classes.get(name) or self._load_builtin(name)
        if cls is not None:
            return cls
        entries = self._entries_by_name().get(name, []) if isinstance(name, str) else []
        if entries:
            error = self._declared_twice(entries) or self._load_entry(entries[0])
            if error:
                raise InputError(error, where or f"entry point {self.group}")
            if name in self._misnamed:
                raise InputError(self._misnamed_hint(name), where)
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


def distribution(entry: EntryPoint) -> str:
    """`` (its distribution)`` of an entry point, where it has one."""
    return f" ({entry.dist.name})" if entry.dist is not None else ""


def kind_of(value: object) -> str:
    """What a value is, for a message: ``a function``, ``a module``, ``an instance of Boom``."""
    kind = "a module" if isinstance(value, types.ModuleType) else \
        "a function" if callable(value) and hasattr(value, "__code__") else \
        f"an instance of {type(value).__qualname__}"
    return kind


def shortened(exc: BaseException) -> str:
    """A plugin's own exception message, cut to :data:`MAX_PLUGIN_ERROR` characters."""
    text = str(exc)
    return text if len(text) <= MAX_PLUGIN_ERROR else f"{text[:MAX_PLUGIN_ERROR]}..."


# what a scene needs of a material, a light or an effect class (loader.py: Params, from_dict)
_FROM_A_SCENE = ("Params", "from_dict")

materials: Registry = Registry("material", "deferred.materials", "deferred.materials",
                               max_id=MAX_MATERIAL_ID,
                               interface="deferred.interfaces.material:Material",
                               requires=_FROM_A_SCENE)
# a listed light's colour texel holds its type id in w's low 8 bits (lighting/light_lists.glsl)
lights: Registry = Registry("light", "deferred.lights", "deferred.lights", max_id=255,
                            interface="deferred.interfaces.light:Light", requires=_FROM_A_SCENE,
                            check="deferred.interfaces.light:check_light_data")
shading_models: Registry = Registry("shading model", "deferred.shading_models",
                                    "deferred.materials:SHADING_MODELS",
                                    max_id=MAX_SHADING_MODEL_ID,
                                    interface="deferred.interfaces.shading:ShadingModel",
                                    requires=("glsl_file", "glsl_function"))
effects: Registry = Registry("effect", "deferred.effects", "deferred.effects",
                             interface="deferred.interfaces.effect:Effect",
                             requires=_FROM_A_SCENE)
