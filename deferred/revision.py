"""Revisions: how the framework notices that the user changed something between two frames.

Every object a user edits (a scene, its objects, lights, materials, effects) is
:class:`Revisioned`: assigning one of its public attributes gives it a new ``revision``, a
number drawn from one counter for the whole process. Two revisions are equal only where
nothing was assigned since; a replaced object never has its predecessor's revision. The frame
state (``deferred.scene.state``) records the revisions it was evaluated from, and the renderer
compares them (pygfx's revision tracking is the model) instead of asking whether an object is
the same one it saw last.

Values are replaced whole, never changed in place (parameters are frozen pydantic models,
transforms and cameras frozen, matrices read-only), so an assignment is the only change there
is to notice.
"""

from __future__ import annotations

import itertools
from typing import Any

_revisions = itertools.count(1)


def next_revision() -> int:
    """A revision number no object has had before."""
    return next(_revisions)


class Revisioned:
    """A mixin: each assignment to a public attribute (no leading underscore) sets
    ``revision`` anew. Private attributes are the object's own caches and bookkeeping."""

    revision: int = 0

    def __setattr__(self, name: str, value: Any) -> None:
        object.__setattr__(self, name, value)
        if name[0] != "_" and name != "revision":
            object.__setattr__(self, "revision", next(_revisions))

    def touch(self) -> None:
        """Give the object a new revision: for a change no assignment shows (a list of its
        held in place, a mesh's arrays rewritten)."""
        object.__setattr__(self, "revision", next(_revisions))
