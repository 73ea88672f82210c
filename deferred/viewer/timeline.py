"""The viewer's clock: play, pause, scrub and step through the scene's timeline.

Frames are drawn at the time the clock says; a frame at time t is the frame ``deferred render
--time t`` draws (simulations step from 0 to t as in a render), so a scrubbed frame is
deterministic whatever was shown before it.
"""

from __future__ import annotations

import math

from deferred.scene.scene import Scene

DEFAULT_DURATION = 10.0  # seconds, for a scene whose timeline says nothing longer


def scene_duration(scene: Scene) -> float:
    """The end of the scene's timeline: its last event or track key (or the turntable's
    period), else ``DEFAULT_DURATION``."""
    times = [t for obj in scene.objects for t in obj.event_times]
    times += [t for track in scene.tracks for t in track.key_times]
    times += [t for obj in scene.objects for track in obj.tracks for t in track.key_times]
    if scene.turntable is not None:
        times.append(scene.turntable.start + scene.turntable.period)
    end = max(times, default=0.0)
    return end if end > 0.0 else DEFAULT_DURATION


class Timeline:
    """The time of the frame shown, and whether it runs."""

    def __init__(self, duration: float = DEFAULT_DURATION, fps: float = 24.0,
                 time: float = 0.0):
        self.duration = duration
        self.fps = fps
        self.time = time
        self.playing = False
        self.loop = True
        self._unspent = 0.0  # wall seconds played that do not make a whole frame yet

    def scrub(self, time: float) -> None:
        self.time = min(max(float(time), 0.0), self.duration)
        self._unspent = 0.0

    def step(self, frames: int = 1) -> None:
        """Move by whole frames (1 / fps each) and pause."""
        self.playing = False
        self.scrub(self.time + frames / self.fps)

    def toggle(self) -> None:
        self.playing = not self.playing
        self._unspent = 0.0

    def advance(self, seconds: float) -> bool:
        """Run the clock by ``seconds`` of wall time while playing, in whole frames (1 / fps
        each; the rest is carried to the next call), so that the frames shown are the
        sequence's and a temporal effect sees steps of whole frames; whether the time
        changed."""
        if not self.playing or seconds <= 0.0:
            return False
        self._unspent += seconds
        frames = math.floor(self._unspent * self.fps + 1e-9)
        if frames < 1:
            return False
        self._unspent = max(self._unspent - frames / self.fps, 0.0)
        time = self.time + frames / self.fps
        if time > self.duration:
            time = time % self.duration if self.loop else self.duration
            if not self.loop:
                self.playing = False
        self.time = time
        return True
