"""The time budget (deferred.io.cost): a prediction's terms counted by how often they are done,
refused past the budget in one line naming the key to change, with the numbers, warned of past
a minute, and the budget raised by DEFERRED_TARGET_TIME."""

from __future__ import annotations

import pytest

from deferred.errors import InputError
from deferred.io.cost import (
    BUDGET_VARIABLE,
    TIME_BUDGET_SECONDS,
    Per,
    Prediction,
    Work,
    check_time,
    duration,
    time_budget,
)

OPTIONS = {Per.SAMPLE: "--samples", Per.FRAME: "--frames"}


def prediction(frames: int = 1, samples: int = 1, sample_seconds: float = 1.0) -> Prediction:
    return Prediction((Work("setup", 1, 2.0, "s.toml: size", Per.RENDER),
                       Work("writing", 1, 0.5, "s.toml: size", Per.FRAME),
                       Work("torus: 24 shells over 1.0M pixels", 1e6, sample_seconds * 1e-6,
                            "s.toml: object[1].params.shells")), frames, samples)


def test_each_term_counts_as_often_as_it_is_done():
    counted = prediction(frames=3, samples=4)
    assert counted.seconds == pytest.approx(2.0 + 3 * 0.5 + 12 * 1.0)
    assert counted.sample_seconds() == pytest.approx(1.0)
    assert counted.largest(1)[0].what.startswith("torus")
    assert counted.repetition() == "3 frames x 4 samples"


def test_past_the_budget_one_line_names_the_option_that_repeats_the_work(monkeypatch):
    monkeypatch.delenv(BUDGET_VARIABLE, raising=False)
    with pytest.raises(InputError) as refused:
        check_time(prediction(samples=1024, sample_seconds=10.0), "render", "fewer samples",
                   OPTIONS)
    error = refused.value
    assert error.where == "--samples"
    assert "\n" not in str(error)
    for fragment in ("2 h 50 min", "1,024 samples", "torus: 24 shells", "the budget is 1 h",
                     BUDGET_VARIABLE, "fewer samples"):
        assert fragment in error.message, error.message


def test_one_frame_of_one_sample_names_the_terms_own_key():
    with pytest.raises(InputError) as refused:
        check_time(prediction(sample_seconds=2 * TIME_BUDGET_SECONDS), "render", "less",
                   OPTIONS)
    assert refused.value.where == "s.toml: object[1].params.shells"


def test_a_warning_past_a_minute_and_nothing_below(monkeypatch):
    monkeypatch.delenv(BUDGET_VARIABLE, raising=False)
    said = check_time(prediction(samples=100), "render", "less", OPTIONS)
    assert said is not None and said.startswith("render predicted to take about 1 min 42 s")
    assert check_time(prediction(samples=2), "render", "less", OPTIONS) is None


def test_the_variable_raises_the_budget_and_a_bad_value_is_named(monkeypatch):
    work = prediction(samples=1024, sample_seconds=10.0)
    monkeypatch.setenv(BUDGET_VARIABLE, "20000")
    assert time_budget() == 20000.0
    assert check_time(work, "render", "less", OPTIONS) is not None  # warned, not refused
    for bad in ("soon", "-5", "0", "nan", "inf"):
        monkeypatch.setenv(BUDGET_VARIABLE, bad)
        with pytest.raises(InputError, match="must be a finite number of seconds") as refused:
            time_budget()
        assert refused.value.where == BUDGET_VARIABLE


@pytest.mark.parametrize("seconds, said", [(0.04, "40 ms"), (7.2, "7 s"), (125, "2 min 5 s"),
                                           (3840, "1 h 4 min"), (266400, "3 days 2 h")])
def test_durations_as_people_say_them(seconds, said):
    assert duration(seconds) == said


def test_a_lower_bound_is_refused_as_at_least_and_never_warned_of(monkeypatch):
    monkeypatch.delenv(BUDGET_VARIABLE, raising=False)
    counted = prediction(samples=1024, sample_seconds=10.0)
    lower = Prediction(counted.works, counted.frames, counted.samples, lower_bound=True)
    with pytest.raises(InputError, match="render predicted to take at least 2 h 50 min"):
        check_time(lower, "render", "less", OPTIONS)
    warned = Prediction(lower.works, 1, 100, lower_bound=True)
    assert check_time(warned, "render", "less", OPTIONS) is None
