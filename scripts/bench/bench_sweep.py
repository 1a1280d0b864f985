"""Scale benchmark of :func:`pumpup.sweep` (issue 7, item 4).

A sweep of stretched Phong (000 eq. 7, 12) over n x p x mu, n geometric in [1, 1000], p
uniform in [0, 1], mu = the 257 values of :func:`pumpup.sweeps.default_mu`; and the same
sweep pumped with g2 at 2 levels (001 eq. 21).  Each grid size k x k samples the same
parameter ranges, so the mean cost of a cell does not depend on k and the time should be
linear in the number of cells: t = t0 + b * cells.  Every size runs in a fresh process
(``--one``) so that its peak memory is its own: the peak of the summed resident set size of
the process and its dask worker processes, sampled every 0.2 s.  The CPU time (user +
system, of the process and its workers) is reported beside the wall time: on a shared
machine it is the steadier measure of the cost per cell.

Usage::

    PYTHONPATH=. nice python scripts/bench/bench_sweep.py --sizes 4 8 16 32 --pumped-sizes 2 4 \
        --log bench_sweep.jsonl
    python scripts/bench/bench_sweep.py --report bench_sweep.jsonl   # fit and extrapolate to 64 x 64

Every run appends one JSON line to the log as soon as it ends, so a long benchmark can be
stopped at any time and reported from what it measured.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np

FULL = 64  # the grid: 64 x 64 x 257


def grid(k: int) -> dict:
    """The k x k parameter grid: n geometric in [1, 1000], p uniform in [0, 1]."""
    return {"n": np.geomspace(1.0, 1000.0, k).tolist(), "p": np.linspace(0.0, 1.0, k).tolist()}


def _peak_rss(stop: threading.Event, out: list) -> None:
    import psutil

    me = psutil.Process()
    peak = 0
    while not stop.is_set():
        try:
            total = me.memory_info().rss + sum(c.memory_info().rss for c in me.children(recursive=True))
        except psutil.Error:
            total = 0
        peak = max(peak, total)
        stop.wait(0.2)
    out.append(peak)


def run_one(k: int, pumped: bool, n_mu: int, scheduler: str, workers: int) -> dict:
    """One sweep of a k x k grid in this process; its wall time and peak memory."""
    import resource

    import pumpup
    from pumpup.sweeps import default_mu

    def cpu() -> float:  # user + system seconds of this process and its finished (reaped) workers
        return sum(r.ru_utime + r.ru_stime for r in (resource.getrusage(resource.RUSAGE_SELF),
                                                     resource.getrusage(resource.RUSAGE_CHILDREN)))

    cpu0 = cpu()
    stop, peak = threading.Event(), []
    sampler = threading.Thread(target=_peak_rss, args=(stop, peak), daemon=True)
    sampler.start()
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "sweep.nc")
        t0 = time.perf_counter()
        ds = pumpup.sweep({"type": "stretched_phong"}, grid(k), mu=default_mu(n_mu),
                          pump={"g": "g2", "levels": 2} if pumped else None,
                          scheduler=scheduler, workers=workers, out=out, progress=False)
        seconds = time.perf_counter() - t0
        cpu_seconds = cpu() - cpu0
        load = os.getloadavg()[1]
        size = os.path.getsize(out)
    stop.set()
    sampler.join()
    assert bool(np.isfinite(ds["albedo"]).all())
    try:  # which pumpup was measured (other work may land between runs)
        commit = subprocess.run(["git", "-C", os.path.dirname(os.path.abspath(__file__)), "describe", "--always",
                                 "--dirty"], check=False, capture_output=True, text=True).stdout.strip()
    except OSError:
        commit = ""
    return {"k": k, "cells": k * k, "commit": commit, "n_mu": n_mu, "pumped": pumped, "scheduler": scheduler, "workers": workers,
            "seconds": seconds, "cpu_seconds": cpu_seconds, "load_5min": load, "peak_rss_mb": peak[0] / 2**20, "file_mb": size / 2**20,
            "max_albedo": float(ds["albedo"].max())}


def fit(rows: list[dict], key: str = "seconds") -> dict | None:
    """Least-squares t = t0 + b * cells of ``key`` (wall or CPU seconds), with the largest relative residual."""
    rows = [r for r in rows if key in r]
    if len({r["cells"] for r in rows}) < 2:
        return None
    c = np.array([r["cells"] for r in rows], float)
    t = np.array([r[key] for r in rows], float)
    b, t0 = np.polyfit(c, t, 1)
    resid = np.max(np.abs(t0 + b * c - t) / t)
    # the exponent of a power law t ~ cells^e through the two largest grids (1 = linear)
    order = np.argsort(c)
    e = float(np.log(t[order[-1]] / t[order[-2]]) / np.log(c[order[-1]] / c[order[-2]]))
    return {"t0": float(t0), "per_cell": float(b), "max_rel_residual": float(resid), "exponent_last_two": e,
            "full_cells": FULL * FULL, "full_seconds": float(t0 + b * FULL * FULL)}


def report(path: str) -> str:
    with open(path) as fh:
        rows = [json.loads(line) for line in fh if line.strip()]
    rows = list({(r["k"], r["pumped"]): r for r in rows}.values())  # the latest run of each grid
    lines = []
    for pumped in (False, True):
        sub = sorted((r for r in rows if r["pumped"] == pumped), key=lambda r: r["cells"])
        if not sub:
            continue
        name = "stretched Phong, pumped g2 x 2" if pumped else "stretched Phong"
        lines.append(f"## {name} (n_mu = {sub[0]['n_mu']}, {sub[0]['scheduler']}, {sub[0]['workers']} workers)")
        lines.append("| grid | cells | wall time [s] | wall s / cell | CPU s / cell | peak memory [MB] | file [MB] "
                     "| load (5 min) |")
        lines.append("|---|---|---|---|---|---|---|---|")
        for r in sub:
            cpu = f"{r['cpu_seconds'] / r['cells']:.2f}" if "cpu_seconds" in r else "-"
            load = f"{r['load_5min']:.1f}" if "load_5min" in r else "-"
            lines.append(f"| {r['k']} x {r['k']} | {r['cells']} | {r['seconds']:.1f} | {r['seconds'] / r['cells']:.2f}"
                         f" | {cpu} | {r['peak_rss_mb']:.0f} | {r['file_mb']:.2f} | {load} |")
        measured = any(r["k"] == FULL for r in sub)
        big = sub[-1]
        if "cpu_seconds" in big:  # the cost of a cell on the finest measured grid, on every worker
            t = big["cpu_seconds"] / big["cells"] * FULL * FULL / big["workers"]
            lines.append(f"CPU per cell of the {big['k']} x {big['k']} grid x {FULL * FULL} cells / {big['workers']} "
                         f"workers: {t:.0f} s = {t / 3600:.2f} h for {FULL} x {FULL} "
                         + ("(measured grid)" if measured else "(EXTRAPOLATED, not measured)"))
        for key, what in (("seconds", "wall"), ("cpu_seconds", "CPU")):
            f = fit(sub, key)
            if not f:
                continue
            lines.append(f"{what}: fit t = {f['t0']:.1f} s + {f['per_cell']:.3f} s x cells (largest relative residual "
                         f"{f['max_rel_residual']:.2f}; exponent between the two largest grids {f['exponent_last_two']:.2f})")
            lines.append(f"{what}: {FULL} x {FULL}: {f['full_seconds']:.0f} s = {f['full_seconds'] / 3600:.2f} h "
                         + ("(fit; also measured above)" if measured else "(EXTRAPOLATED from the fit, not measured)"))
        lines.append("")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="*", default=[4, 8, 16, 32], help="k of the k x k plain sweeps")
    ap.add_argument("--pumped-sizes", type=int, nargs="*", default=[2, 4], help="k of the pumped sweeps")
    ap.add_argument("--n-mu", type=int, default=257)
    ap.add_argument("--scheduler", default="processes")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--log", default="bench_sweep.jsonl", help="append one JSON line per run here")
    ap.add_argument("--report", metavar="LOG", help="only print the tables and fits of a log")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--pumped", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.report:
        print(report(a.report))
        return 0
    if a.one:
        print(json.dumps(run_one(a.one, a.pumped, a.n_mu, a.scheduler, a.workers)))
        return 0
    runs = [(k, False) for k in a.sizes] + [(k, True) for k in a.pumped_sizes]
    for k, pumped in runs:
        cmd = [sys.executable, __file__, "--one", str(k), "--n-mu", str(a.n_mu), "--scheduler", a.scheduler,
               "--workers", str(a.workers)] + (["--pumped"] if pumped else [])
        res = subprocess.run(cmd, check=False, capture_output=True, text=True)
        if res.returncode != 0:
            print(res.stderr, file=sys.stderr)
            return res.returncode
        row = json.loads(res.stdout.strip().splitlines()[-1])
        with open(a.log, "a") as fh:
            fh.write(json.dumps(row) + "\n")
        print(f"{'pumped ' if pumped else ''}{k} x {k}: {row['seconds']:.1f} s, peak {row['peak_rss_mb']:.0f} MB",
              flush=True)
    print(report(a.log))
    return 0


if __name__ == "__main__":
    sys.exit(main())
