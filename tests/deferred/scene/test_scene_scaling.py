"""Issue #22: loading a scene costs in proportion to its events and objects (800 events in
reverse time order took 137 s, 8,000 objects 25.6 s)."""

from __future__ import annotations

import time

import pytest

import deferred.scene.objects as scene_model
from deferred.scene.loader import scene_from_toml


def events_scene(count: int) -> str:
    """One object and ``count`` colour events, latest first (each is the earliest yet)."""
    text = 'size = [32, 32]\n[[object]]\nname = "a"\nmesh = "builtin:cube"\n'
    return text + "".join(f'[[event]]\ntime = {t}.0\nobject = "a"\n'
                          f'params = {{ color = [0.5, 0.5, {t % 10 / 10}] }}\n'
                          for t in range(count, 0, -1))


def objects_scene(count: int) -> str:
    """``count`` unnamed objects of one mesh (each named by the loader)."""
    return 'size = [32, 32]\n' + '[[object]]\nmesh = "builtin:cube"\n' * count


def test_each_state_of_a_timeline_is_validated_once(monkeypatch):
    """Validations counted, not timed: a file's events are added at once and each distinct
    state is validated once (it was every later state again at every event: n squared)."""
    validated = []
    real = scene_model.validate_params

    def counting(*args, **kwargs):
        validated.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(scene_model, "validate_params", counting)
    for count in (50, 500):
        validated.clear()
        scene = scene_from_toml(events_scene(count))
        assert len(validated) == count  # one state an event time
        obj = scene.objects[0]
        assert obj.params_at(0.5) is obj.base_params
        assert obj.params_at(3.0).color == (0.5, 0.5, 0.3)
        assert obj.params_at(1e9).color == (0.5, 0.5, count % 10 / 10)
        assert len(validated) == count  # asking again validates nothing


@pytest.mark.slow
def test_ten_times_the_objects_costs_about_ten_times():
    """Timed with a generous bound (30x for 10x; the quadratic naming took about 100x): the
    best of three loads each."""
    def best(count: int) -> float:
        text = objects_scene(count)
        times = []
        for _ in range(3):
            start = time.perf_counter()
            scene = scene_from_toml(text)
            times.append(time.perf_counter() - start)
        assert len({obj.label for obj in scene.objects}) == count  # every name its own
        return min(times)

    small, large = best(300), best(3000)
    assert large < 30 * small, (small, large)


def test_labels_fill_gaps_left_by_named_objects():
    scene = scene_from_toml('size = [32, 32]\n'
                            '[[object]]\nname = "cube1"\nmesh = "builtin:cube"\n'
                            '[[object]]\nmesh = "builtin:cube"\n'
                            '[[object]]\nmesh = "builtin:cube"\n'
                            '[[object]]\nname = "cube5"\nmesh = "builtin:cube"\n'
                            '[[object]]\nmesh = "builtin:cube"\n')
    assert [obj.label for obj in scene.objects] == ["cube1", "cube0", "cube2", "cube5", "cube3"]
