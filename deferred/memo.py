"""Memos: the framework's one way of keeping a value that is asked for often and changes rarely.

- :func:`kept_while` keeps a method's result on its object while the attributes it is made from
  are the same objects (identity, not equality: parameters, meshes and cameras are replaced
  whole, never changed in place), one result per argument tuple. A material's uniforms are kept
  while its ``params`` are the same object, a mesh's bounds while its positions are, a frozen
  camera's matrices for its life.
- :func:`overrides` answers whether a class overrides a hook of a base class, so the framework
  can skip a hook no class changed (a pass with no ``prepare``) without calling it. Where the
  answer is wanted a draw, a class keeps it as a class attribute made when the class is
  (``ObjectPass.__init_subclass__``).

Both keep plain values: nothing is released through them (GPU objects are kept by
:class:`deferred.gl.resources.Resources`).
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])


def kept_while(*sources: str) -> Callable[[F], F]:
    """Decorate a method so its result, for each argument tuple, is kept on the instance (in its
    ``__dict__``, so frozen dataclasses take it too) while the attributes named ``sources``
    are the same objects as when it was made; with no ``sources``, for the instance's life.

    The kept value is returned itself, not a copy: a method whose callers may change what it
    returns hands out copies of a kept one. (Some of these are asked for by every object every
    frame: the wrapper is specialised to do no more than it must.)"""

    def decorate(method: F) -> F:
        slot = f"_kept_{method.__name__}"
        with_arguments = len(inspect.signature(method).parameters) > 1
        names = tuple(sources)

        def made_from(self) -> tuple:
            return tuple([getattr(self, name) for name in names])

        def fresh(held: tuple | None, current: tuple) -> bool:
            return held is not None and len(held[0]) == len(current) and \
                all(a is b for a, b in zip(held[0], current, strict=True))

        if not with_arguments and not names:
            def kept(self):
                try:
                    return self.__dict__[slot]
                except KeyError:
                    value = self.__dict__[slot] = method(self)
                    return value
        elif not with_arguments and len(names) == 1:
            (name,) = names

            def kept(self):
                source = getattr(self, name)
                held = self.__dict__.get(slot)
                if held is not None and held[0] is source:
                    return held[1]
                value = method(self)
                self.__dict__[slot] = (source, value)
                return value
        elif not with_arguments and len(names) == 2:
            first, second = names

            def kept(self):
                a, b = getattr(self, first), getattr(self, second)
                held = self.__dict__.get(slot)
                if held is not None and held[0] is a and held[1] is b:
                    return held[2]
                value = method(self)
                self.__dict__[slot] = (a, b, value)
                return value
        elif not with_arguments:
            def kept(self):
                current = made_from(self)
                held = self.__dict__.get(slot)
                if fresh(held, current):
                    return held[1]
                value = method(self)
                self.__dict__[slot] = (current, value)
                return value
        else:
            def kept(self, *args):
                current = made_from(self)
                held = self.__dict__.get(slot)
                if not fresh(held, current):
                    held = self.__dict__[slot] = (current, {})
                values = held[1]
                value = values.get(args, values)  # the dict itself: "not made yet"
                if value is values:
                    value = values[args] = method(self, *args)
                return value

        return functools.wraps(method)(kept)  # type: ignore[return-value]

    return decorate


def overrides(cls: type, base: type, *hooks: str) -> bool:
    """Whether ``cls`` (a subclass of ``base``) has its own version of any of ``hooks``: an
    attribute other than ``base``'s."""
    for hook in hooks:
        if getattr(cls, hook) is not getattr(base, hook):
            return True
    return False
