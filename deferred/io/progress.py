"""A long command's progress on stderr, one way for every command.

On a terminal: a transient line with a spinner, what is being done, and for counted work (frames,
bench runs) a bar, the count and the time left. Elsewhere (a pipe, a file, CI's log): the same
text as plain lines, at most one every :data:`LINE_INTERVAL_S` seconds and none for work that
ends sooner, from a background thread, so a single step that takes minutes (an unwrap, a
simulation settling, shaders compiling, one bench frame at 64 shells) still shows that the
command is alive: ``bench: 3/24 runs, ~40 s left: round 1 of 10, deferred (tiled)``.

The command's own messages go through :meth:`Progress.note`, above the bar on a terminal.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from types import TracebackType

from rich.console import Console
from rich.progress import BarColumn, SpinnerColumn, TextColumn
from rich.progress import Progress as RichProgress
from rich.text import Text

LINE_INTERVAL_S = 5.0  # off a terminal: at most one line this often


def duration(seconds: float) -> str:
    """``7 s``, ``2 min 5 s``, ``1 h 4 min``, ``3 days 2 h``: a time left, rounded as people
    say it (at least ``1 s``)."""
    seconds = max(1.0, seconds)
    if seconds < 59.5:
        return f"{seconds:.0f} s"
    minutes, rest = divmod(round(seconds), 60)
    if minutes < 60:
        return f"{minutes} min {rest} s" if rest else f"{minutes} min"
    hours, minutes = divmod(minutes, 60)
    if hours < 48:
        return f"{hours} h {minutes} min" if minutes else f"{hours} h"
    days, hours = divmod(hours, 24)
    return f"{days:,} days {hours} h" if hours else f"{days:,} days"


class _CountedBar(BarColumn):
    """A bar for counted work, nothing for a single step (rich would pulse one)."""

    def render(self, task):
        return Text("") if task.total is None else super().render(task)


class Progress:
    """The progress of the command ``command`` (``render``, ``bench``) on ``console``.

    ``status(text)`` names a single step (a spinner; lines say how long it has taken);
    ``count(total, unit)`` starts counted work and ``advance(done, text, seconds_left)`` moves
    it (the time left is the caller's estimate, or else the rate so far). Use it as a context
    manager; nothing shows before it is entered or after it is left.
    """

    def __init__(self, command: str, console: Console, interval: float | None = None,
                 clock: Callable[[], float] = time.monotonic, ticker: bool = True):
        self.command = command
        self.console = console
        self.interval = LINE_INTERVAL_S if interval is None else interval
        self.clock = clock
        self.terminal = console.is_terminal
        self._ticker = ticker
        self._lock = threading.Lock()
        self._text = ""
        self._total: int | None = None
        self._unit = ""
        self._done = 0
        self._seconds_left: float | None = None
        self._estimated_at = clock()
        self._started = self._step_started = self._last_line = clock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._bar: RichProgress | None = None
        self._task = None

    # -- what is being done ---------------------------------------------------------------------
    def status(self, text: str) -> None:
        """A single step that may take long: ``text`` names it."""
        with self._lock:
            if self._total is not None or text != self._text:
                self._step_started = self.clock()
            self._text, self._total, self._done, self._seconds_left = text, None, 0, None
        self._show()

    def count(self, total: int, unit: str, text: str = "") -> None:
        """Counted work: ``total`` ``unit`` (``frames``, ``runs``) to do."""
        with self._lock:
            self._text, self._total, self._unit, self._done = text, total, unit, 0
            self._seconds_left = None
            self._started = self._step_started = self.clock()
        self._show()

    def advance(self, done: int | None = None, text: str | None = None,
                seconds_left: float | None = None) -> None:
        """``done`` of the counted work finished (one more when None); ``text`` says what is
        being done now; ``seconds_left`` the caller's estimate of the time left."""
        with self._lock:
            self._done = self._done + 1 if done is None else done
            if text is not None:
                self._text = text
            self._seconds_left = seconds_left
            self._estimated_at = self.clock()
        self._show()

    def note(self, line: str) -> None:
        """A line of the command's own (above the bar on a terminal)."""
        self.console.print(line, markup=False, highlight=False)

    # -- how it shows -------------------------------------------------------------------------
    def describe(self) -> str:
        """The progress as one line, without the command's name: ``3/24 runs, ~40 s left:
        round 1 of 10``, or ``loading s.toml (12 s)``."""
        with self._lock:
            now = self.clock()
            if self._total is None:
                taken = now - self._step_started
                return f"{self._text} ({duration(taken)})" if taken >= 1.0 else self._text
            counts = f"{self._done}/{self._total} {self._unit}"
            left = self._time_left(now)
            counts += f", ~{duration(left)} left" if left is not None else ", estimating time"
            return f"{counts}: {self._text}" if self._text else counts

    def _time_left(self, now: float) -> float | None:
        if self._seconds_left is not None:
            # the estimate counts down between updates; once past, it no longer says anything
            left = self._seconds_left - (now - self._estimated_at)
            return left if left > 0.0 else None
        if self._total is None or self._done <= 0:
            return None
        return (now - self._started) / self._done * max(self._total - self._done, 0)

    def tick(self) -> bool:
        """Off a terminal: print a line if none was printed for the interval (the background
        thread calls this); whether it printed."""
        if self.terminal:
            return False
        with self._lock:
            now = self.clock()
            if now - self._last_line < self.interval or not (self._text or self._total):
                return False
            self._last_line = now
        self.note(f"{self.command}: {self.describe()}")
        return True

    def _show(self) -> None:
        if self._bar is not None and self._task is not None:
            with self._lock:
                total, done = self._total, self._done
            self._bar.update(self._task, total=total, completed=done,
                             description=f"{self.command}: {self.describe()}")

    def _run_ticker(self) -> None:
        # on a terminal, the bar's text is refreshed (a step's seconds go on counting)
        pause = 1.0 if self.terminal else min(max(self.interval / 5.0, 0.02), 1.0)
        while not self._stop.wait(pause):
            if self.terminal:
                self._show()
            else:
                self.tick()

    def __enter__(self) -> Progress:
        self._started = self._step_started = self._last_line = self.clock()
        if self.terminal:
            self._bar = RichProgress(SpinnerColumn(), TextColumn("{task.description}"),
                                     _CountedBar(), console=self.console, transient=True)
            self._bar.start()
            self._task = self._bar.add_task("", total=None)
            self._show()
        if self._ticker:
            self._thread = threading.Thread(target=self._run_ticker, name="progress",
                                            daemon=True)
            self._thread.start()
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        if self._bar is not None:
            self._bar.stop()
            self._bar = None
