"""deferred.memo: a value kept while what it is made from is the same objects, and overrides."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from deferred.memo import kept_while, overrides


class Counted:
    """Each kept method counts its calls; ``a``, ``b``, ``c`` are what they are made from."""

    def __init__(self) -> None:
        self.a, self.b, self.c = [1], [2], [3]
        self.calls: dict[str, int] = {}

    def _count(self, name: str) -> None:
        self.calls[name] = self.calls.get(name, 0) + 1

    @kept_while()
    def forever(self):
        self._count("forever")
        return object()

    @kept_while("a")
    def one(self):
        self._count("one")
        return (self.a, object())

    @kept_while("a", "b")
    def two(self):
        self._count("two")
        return (self.a, self.b, object())

    @kept_while("a", "b", "c")
    def three(self):
        self._count("three")
        return (self.a, self.b, self.c, object())

    @kept_while("a")
    def per_argument(self, x, y=0):
        self._count("per_argument")
        return (self.a, x, y, object())


@pytest.mark.parametrize("method, sources", [("forever", ""), ("one", "a"), ("two", "ab"),
                                             ("three", "abc")])
def test_a_value_is_kept_while_its_sources_are_the_same_objects(method, sources):
    obj = Counted()
    first = getattr(obj, method)()
    assert getattr(obj, method)() is first and obj.calls[method] == 1
    for name in "abc":
        equal = list(getattr(obj, name))  # equal but another object
        setattr(obj, name, equal)
        value = getattr(obj, method)()
        if name in sources:
            assert value is not first and obj.calls[method] > 1, name  # made again
            assert value[sources.index(name)] is equal
            first = value
        else:
            assert value is first, name  # not a source: kept
    calls = obj.calls[method]
    assert getattr(obj, method)() is first and obj.calls[method] == calls


def test_values_are_kept_per_argument_and_dropped_with_their_source():
    obj = Counted()
    one, two = obj.per_argument(1), obj.per_argument(2)
    assert one is not two and obj.per_argument(1) is one and obj.per_argument(2) is two
    assert obj.calls["per_argument"] == 2
    obj.a = [1]
    assert obj.per_argument(1) is not one and obj.calls["per_argument"] == 3
    assert obj.per_argument(2) is not two and obj.calls["per_argument"] == 4


def test_instances_keep_their_own_values_and_arrays_are_compared_by_identity():
    @dataclass(frozen=True)
    class Frozen:
        positions: np.ndarray

        @kept_while("positions")
        def lowest(self) -> float:
            return float(self.positions.min())

    a, b = Frozen(np.array([1.0, 2.0])), Frozen(np.array([3.0, 4.0]))
    assert (a.lowest(), b.lowest()) == (1.0, 3.0)  # a frozen dataclass keeps them too
    object.__setattr__(a, "positions", np.array([1.0, 2.0]) - 5.0)  # a new array: made again
    assert a.lowest() == -4.0 and b.lowest() == 3.0


def test_overrides_names_a_hook_a_subclass_changes():
    class Base:
        def prepare(self):
            pass

        def draw(self):
            pass

    class Same(Base):
        pass

    class Own(Base):
        def draw(self):
            pass

    assert not overrides(Same, Base, "prepare", "draw")
    assert overrides(Own, Base, "draw") and overrides(Own, Base, "prepare", "draw")
    assert not overrides(Own, Base, "prepare")
    Same.prepare = lambda self: None  # patched later: seen (the answer is not kept)
    assert overrides(Same, Base, "prepare")
