"""Rendering past one process: a sequence's frames on local worker processes or Ray actors,
resumable, byte-identical to a single renderer's (``deferred render --workers/--ray/--resume``),
and ``deferred bench --sweep``'s grid as tasks."""
