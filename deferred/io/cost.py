"""The time budget of a command: the work it will do, predicted from counts before anything
heavy is loaded or made, warned of above :data:`WARN_SECONDS` and refused above the budget
(:data:`TIME_BUDGET_SECONDS`, or ``DEFERRED_TARGET_TIME``), as :mod:`deferred.io.memory` does
for memory.

A prediction is a list of :class:`Work` terms, each a count of units (pixels times layers,
triangles, strand steps...) times the seconds a unit takes on the reference machine
(benchmarks/README.md, "The cost model"), done once a render, once a frame or once a sample.
What the terms are is the caller's (``deferred.render.cost`` for a render, the materials'
``work``); this module adds them up, names the largest and says the refusal in one line.
"""

from __future__ import annotations

import os
from collections.abc import Iterable
from dataclasses import dataclass
from enum import Enum

from deferred.errors import InputError
from deferred.io.progress import duration as time_left

TIME_BUDGET_SECONDS = 3600.0  # DEFERRED_TARGET_TIME overrides it
WARN_SECONDS = 60.0  # a prediction past this is said before the work starts
BUDGET_VARIABLE = "DEFERRED_TARGET_TIME"


class WorkWarning(UserWarning):
    """A command predicted to take longer than :data:`WARN_SECONDS`, within the budget."""


class Per(str, Enum):
    """How often a term's work is done: once a render, once a frame, once a sample (a frame
    averaged over ``--samples N`` renders each of its sample terms N times)."""

    RENDER = "render"
    FRAME = "frame"
    SAMPLE = "sample"


@dataclass(frozen=True)
class Work:
    """``units`` of work at ``unit_seconds`` each, done once ``per`` render, frame or sample:
    ``what`` says the counts (``20,000 strands x 64 samples x 16 sides``), ``where`` the key
    that sets them (``s.toml: object[0].params.strands``)."""

    what: str
    units: float
    unit_seconds: float
    where: str
    per: Per = Per.SAMPLE

    @property
    def seconds(self) -> float:
        """The seconds of one render, frame or sample of it."""
        return self.units * self.unit_seconds


@dataclass(frozen=True)
class Prediction:
    """The work of a command: its terms and how many frames of how many samples it renders;
    ``lower_bound`` where some of its work is not counted (it is said as "at least")."""

    works: tuple[Work, ...]
    frames: int = 1
    samples: int = 1
    lower_bound: bool = False

    def repeats(self, work: Work) -> int:
        """How many times the command does ``work``."""
        return {Per.RENDER: 1, Per.FRAME: self.frames,
                Per.SAMPLE: self.frames * self.samples}[work.per]

    def total(self, work: Work) -> float:
        """The seconds ``work`` takes over the whole command."""
        return work.seconds * self.repeats(work)

    @property
    def seconds(self) -> float:
        """The predicted seconds of the whole command."""
        return sum(self.total(work) for work in self.works)

    def sample_seconds(self) -> float:
        """The predicted seconds of one sample (a frame's sample terms)."""
        return sum(work.seconds for work in self.works if work.per is Per.SAMPLE)

    def largest(self, count: int = 3) -> list[Work]:
        """The ``count`` terms that take longest over the whole command, longest first."""
        return sorted(self.works, key=self.total, reverse=True)[:count]

    def breakdown(self, count: int = 3) -> str:
        """The largest terms as ``what (time)``, for a line: ``torus: 24 shells over 3.1M
        pixels (2 h 5 min), ...``."""
        return ", ".join(f"{work.what} ({duration(self.total(work))})"
                         for work in self.largest(count) if self.total(work) > 0.0)

    def repetition(self) -> str:
        """``1024 samples``, ``48 frames x 4 samples``, or nothing for one of each."""
        parts = []
        if self.frames > 1:
            parts.append(f"{self.frames:,} frames")
        if self.samples > 1:
            parts.append(f"{self.samples:,} samples")
        return " x ".join(parts)

    def key(self, options: dict[Per, str] | None = None) -> str:
        """The key to change: the option repeating the largest term where it is repeated
        (``options``: ``{Per.SAMPLE: "--samples", Per.FRAME: "--frames"}``), else the term's
        own key."""
        largest = self.largest(1)
        if not largest:
            return ""
        work = largest[0]
        options = options or {}
        if work.per is Per.SAMPLE and self.samples > 1 and Per.SAMPLE in options:
            return options[Per.SAMPLE]
        if work.per is not Per.RENDER and self.frames > 1 and Per.FRAME in options:
            return options[Per.FRAME]
        return work.where

    def add(self, works: Iterable[Work]) -> Prediction:
        return Prediction((*self.works, *works), self.frames, self.samples, self.lower_bound)


def duration(seconds: float) -> str:
    """``40 ms``, ``7 s``, ``2 min 5 s``, ``1 h 4 min``, ``3 days 2 h``: a predicted time as
    people say it."""
    return f"{seconds * 1000.0:.0f} ms" if seconds < 0.95 else time_left(seconds)


def time_budget() -> float:
    """:data:`TIME_BUDGET_SECONDS`, or the environment's ``DEFERRED_TARGET_TIME`` (seconds)."""
    text = os.environ.get(BUDGET_VARIABLE)
    if text is None:
        return TIME_BUDGET_SECONDS
    try:
        budget = float(text)
    except ValueError:
        budget = 0.0
    if not budget > 0.0 or budget == float("inf"):
        raise InputError(f"must be a finite number of seconds > 0, got {text[:40]!r}",
                         BUDGET_VARIABLE)
    return budget


def check_time(prediction: Prediction, command: str, remedy: str,
               options: dict[Per, str] | None = None) -> str | None:
    """Refuse ``prediction`` past the time budget: an ``InputError`` naming the key to change
    (:meth:`Prediction.key`), with the predicted time, the budget and the largest terms;
    ``remedy`` says what to ask for instead. Past :data:`WARN_SECONDS` (and within the budget)
    the warning to say is returned; else None (and for a lower bound, which is only refused)."""
    seconds = prediction.seconds
    budget = time_budget()
    repeated = prediction.repetition()
    shown = f"{repeated}: " if repeated else ""
    if seconds > budget:
        least = "at least " if prediction.lower_bound else ""
        raise InputError(f"{command} predicted to take {least}{duration(seconds)} on the reference "
                         f"machine ({shown}{prediction.breakdown()}); the budget is "
                         f"{duration(budget)} ({BUDGET_VARIABLE}, seconds): {remedy}",
                         prediction.key(options))
    if seconds > min(WARN_SECONDS, budget) and not prediction.lower_bound:
        return (f"{command} predicted to take about {duration(seconds)} ({shown}"
                f"{prediction.breakdown()})")
    return None
