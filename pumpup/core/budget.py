"""Time budgets for long work: the ``max_seconds=`` of :func:`pumpup.pump`, :func:`pumpup.tabulate`,
:func:`pumpup.compensate`, :func:`pumpup.lut`, :func:`pumpup.sweep` and :func:`pumpup.albedo`.

A budget holds for the block of :func:`time_budget` in this thread or task (a context variable), and work run on other
threads for it takes it along (:func:`current` before, :meth:`Deadline.check` there).  The engine and the tables check
it between pieces of work: a batch of albedo values, a round of the adaptive cubature, a level's table.  A piece
already started runs to its end, so the error comes at most one piece late; the pieces are short (milliseconds to a
few seconds) next to any budget worth giving.

Examples
--------
>>> import pumpup
>>> from pumpup.core.budget import BudgetExceeded
>>> try:
...     pumpup.tabulate(pumpup.load("phong:n=20"), max_seconds=1e-9)
... except BudgetExceeded as exc:
...     print(str(exc).split(",")[0])
tabulate: stopped after 0.0 s
"""

from __future__ import annotations

import contextlib
import contextvars
import math
import time
from dataclasses import dataclass

__all__ = ["BudgetExceeded", "Deadline", "check", "check_max_seconds", "current", "time_budget"]


class BudgetExceeded(TimeoutError):
    """Work given ``max_seconds=`` ran past it (a :class:`TimeoutError`; the command line exits with status 2)."""


@dataclass(frozen=True)
class Deadline:
    """The budget of one call: ``function`` (its name in the message) may run ``max_seconds`` from ``start`` (a
    :func:`time.monotonic` time).
    """

    function: str
    max_seconds: float
    start: float
    option: str = "max_seconds"  #: how the message names the budget (the command line's ``--max-seconds``)

    @property
    def end(self) -> float:
        """The monotonic time at which the budget is spent."""
        return self.start + self.max_seconds

    def check(self, doing: str = "") -> None:
        """Raise :class:`BudgetExceeded` if the budget is spent; ``doing`` says what was under way."""
        now = time.monotonic()
        if now > self.end:
            raise BudgetExceeded(
                f"{self.function}: stopped after {now - self.start:.1f} s, past its {self.option} {self.max_seconds:g}"
                + (f", while {doing}" if doing else "") + f"; give a larger {self.option}"
                + (" (or None: no bound)" if self.option == "max_seconds" else ""))


_DEADLINE: contextvars.ContextVar = contextvars.ContextVar("pumpup_deadline", default=None)


def check_max_seconds(function: str, max_seconds) -> float | None:
    """``max_seconds`` checked: None (no bound) or a number > 0 (one line naming the argument otherwise)."""
    if max_seconds is None:
        return None
    ok = isinstance(max_seconds, (int, float)) and not isinstance(max_seconds, bool)
    if not ok:
        try:  # numpy scalars
            import numpy as np

            ok = isinstance(max_seconds, (np.integer, np.floating))
        except ImportError:  # pragma: no cover - numpy is a dependency
            ok = False
    if not ok or not (float(max_seconds) > 0.0) or math.isnan(float(max_seconds)):
        raise ValueError(f"{function}: max_seconds must be a number > 0 (seconds) or None, got {max_seconds!r}")
    return float(max_seconds)


def current() -> Deadline | None:
    """The deadline in force here, or None."""
    return _DEADLINE.get()


def check(doing: str = "") -> None:
    """Raise :class:`BudgetExceeded` if the deadline in force here is past; ``doing`` says what was under way."""
    deadline = _DEADLINE.get()
    if deadline is not None:
        deadline.check(doing)


@contextlib.contextmanager
def time_budget(function: str, max_seconds, option: str = "max_seconds"):
    """Within the block, the work of ``function`` may take ``max_seconds`` (None: no bound of its own); a budget
    given by a caller further out that ends sooner stays in force.  ``option`` names the budget in messages.
    """
    seconds = check_max_seconds(function, max_seconds)
    outer = _DEADLINE.get()
    if seconds is None:
        yield outer
        return
    new = Deadline(function, seconds, time.monotonic(), option)
    if outer is not None and outer.end <= new.end:
        new = outer
    token = _DEADLINE.set(new)
    try:
        yield new
    finally:
        _DEADLINE.reset(token)
