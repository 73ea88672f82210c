"""The memory budget of a command: what it will hold (render targets, a dump's captured
buffers, a GIF's frames) is counted before the first frame and refused past the budget, with one
line naming the size asked for. llvmpipe keeps render targets in system memory, and a process
that outgrows the machine is killed without a message."""

from __future__ import annotations

import os

from deferred.errors import InputError
from deferred.io.images import amount

MEMORY_BUDGET = 4 << 30  # bytes; DEFERRED_TARGET_MEMORY overrides it
BUDGET_VARIABLE = "DEFERRED_TARGET_MEMORY"


def memory_budget() -> int:
    """:data:`MEMORY_BUDGET`, or the environment's ``DEFERRED_TARGET_MEMORY`` (bytes)."""
    text = os.environ.get(BUDGET_VARIABLE)
    if text is None:
        return MEMORY_BUDGET
    try:
        budget = int(text)
    except ValueError:
        budget = 0
    if budget <= 0:
        raise InputError(f"must be a whole number of bytes > 0, got {text[:40]!r}",
                         BUDGET_VARIABLE)
    return budget


def check_memory(needed: int, what: str, where: str, remedy: str = "") -> None:
    """``InputError`` naming ``where`` when ``needed`` bytes are more than the budget: ``what``
    says what needs them, with ``{}`` where the amount goes ("4096x4096 needs {} of render
    targets"); ``remedy`` what to ask for instead."""
    budget = memory_budget()
    if needed > budget:
        raise InputError(f"{what.format(amount(needed))}; the budget is {amount(budget)} "
                         f"({BUDGET_VARIABLE})" + (f": {remedy}" if remedy else ""), where)
