"""Compiling pumpup's numba kernels: a one-line notice before the first compile, and ``warmup``.

Every kernel is compiled with ``cache=True``: numba writes the machine code beside the source
(``__pycache__``, or ``NUMBA_CACHE_DIR`` when it is set), so only the first process on a machine
that uses a feature compiles it; every later one loads it in milliseconds.  On a new machine that
first compile takes tens of seconds.  :func:`notify_compiles` tells the user once, on stderr,
when it starts; :func:`warmup` (``pumpup warmup``) compiles the kernels of every command ahead of time.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO

#: the range of a first command's compile on a new machine (2 cores): seconds, as scripts/bench/bench_startup.py
#: measures
COLD_SECONDS = (10, 60)

NOTICE = ("pumpup: compiling pumpup's kernels for this machine, once: about {lo}-{hi} s "
          "('pumpup warmup' compiles them all ahead of time)")

_notified = False
_installed = False


def notify_compiles(stream: TextIO | None = None) -> None:
    """Print :data:`NOTICE` on ``stream`` (stderr) once per process, before numba compiles a pumpup kernel
    that is not in its on-disk cache.  Loading a cached kernel says nothing.  Imports numba.
    """
    global _installed
    if _installed:
        return
    from numba.core import event

    class _Notice(event.Listener):
        def on_start(self, ev) -> None:
            global _notified
            dispatcher = (ev.data or {}).get("dispatcher")
            module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
            if _notified or not module.startswith("pumpup"):
                return
            _notified = True
            out = sys.stderr if stream is None else stream
            print(NOTICE.format(lo=COLD_SECONDS[0], hi=COLD_SECONDS[1]), file=out, flush=True)

        def on_end(self, ev) -> None:
            pass

    event.register("numba:compile", _Notice())
    _installed = True


def warmup_steps() -> list[tuple[str, Callable[[], object]]]:
    """(what, thunk) pairs that together compile the kernels of every command: the albedo of every
    registered model's examples, tables, pumping (g1, g2, nested), compensation, sampling.
    """
    import numpy as np

    import pumpup

    mu = np.array([1.0, 0.5, 0.05, 1e-4])
    steps: list[tuple[str, Callable[[], object]]] = []
    for name, cls in pumpup.registry().items():
        for params in cls.examples:
            spec = {"type": name, **params}
            steps.append((f"albedo of {name}", lambda spec=spec: pumpup.albedo(pumpup.load(spec), mu)))
    phong = {"type": "phong", "n": 20}
    ggx = {"type": "ggx", "alpha": 0.3}
    steps += [
        ("a table", lambda: pumpup.tabulate(pumpup.load(phong))),
        ("pumping g1", lambda: pumpup.albedo(pumpup.pump(phong, g="g1", levels=2), mu)),
        ("pumping g2", lambda: pumpup.albedo(pumpup.pump({"type": "cook_torrance", "m": 0.3}, g="g2"), mu)),
        ("Kulla-Conty", lambda: pumpup.furnace(pumpup.compensate(ggx, method="kulla_conty"), mu)),
        ("1/E scaling", lambda: pumpup.furnace(pumpup.compensate(ggx, method="scale"), mu)),
        ("sampling", lambda: pumpup.mc_albedo(pumpup.load(phong), 0.5, 4096, np.random.default_rng(0))),
    ]
    return steps


def warmup(progress: Callable[[str], None] | None = None) -> float:
    """Compile (or load from the cache) the kernels of every command; returns the seconds it took.

    ``progress`` is called with a line per step (``None``: silent).  A second call, or a call on a
    machine whose cache is already full, takes a few seconds.
    """
    t0 = time.perf_counter()
    steps = warmup_steps()
    for i, (what, thunk) in enumerate(steps, 1):
        if progress is not None:
            progress(f"[{i}/{len(steps)}] {what}")
        thunk()
    return time.perf_counter() - t0
