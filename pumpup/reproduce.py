"""``pumpup reproduce``: regenerate the tables of the source papers and compare them with the
published values (:mod:`pumpup.published`).

Every table is a netCDF file in long form (one entry per printed number: ``source``,
``row``, ``column``, the ``published`` text, the ``computed`` value, its ``error``
estimate, ``agrees``), and the run writes a Markdown report beside them.  The script that
makes the tables and the regression test that checks them share :func:`compute`.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

from .core import load
from .engine.cubature import albedo
from .published import TABLE2, TABLE3, TABLE4, TEXT, Published, agrees
from .tables import atomic_path, max_albedo, mean_albedo

__all__ = ["TABLES", "compute", "reproduce", "LIMITS"]

#: the n -> infinity limits of the mean albedo (000 Table 3, last row), derived in
#: docs/notes_on_published_tables.md: Phong a -> mu, stretched Phong a -> 1, Blinn (with its
#: maximum constant) a -> mu^2, stretched Blinn a -> mu; mean = 2 int a mu dmu
LIMITS = {"phong": 2.0 / 3.0, "stretched_phong": 1.0, "blinn": 0.5, "stretched_blinn": 2.0 / 3.0}
LARGE_N = 1e4  # the numerical check of the limit row


@dataclass
class Row:
    published: Published | None
    source: str
    row: str
    column: str
    computed: float
    error: float
    extra: dict = field(default_factory=dict)

    @property
    def agrees(self) -> bool | None:
        return None if self.published is None else agrees(self.computed, self.published, self.error)


class _Cache:
    """Results shared between tables within one run (maximum albedos, mean albedos)."""

    def __init__(self):
        self.max = {}
        self.mean = {}

    def max_albedo(self, spec, mu_min=1e-6):
        key = (tuple(sorted(spec.items())), mu_min)
        if key not in self.max:
            self.max[key] = max_albedo(load(spec), mu_min=mu_min)
        return self.max[key]

    def mean_albedo(self, spec):
        key = tuple(sorted(spec.items()))
        if key not in self.mean:
            self.mean[key] = mean_albedo(load(spec), return_error=True)
        return self.mean[key]


def _table2(cache, bar):
    rows = []
    for p in TABLE2:
        m = cache.max_albedo({"type": p.column, "n": float(p.row)})
        rows.append(Row(p, p.source, p.row, p.column, m.constant, m.constant_error, {"theta_deg": m.theta_deg}))
        bar.update(1)
    return rows


def _mean_with_constant(cache, model, n):
    """Mean albedo of the model with its paper constant: (n+2)/(2 pi) for the Phong family,
    the maximum constant (000 Table 2, computed) for the Blinn family.
    """
    spec = {"type": model, "n": float(n)}
    if model in ("phong", "stretched_phong"):
        return cache.mean_albedo(spec)
    m, e = cache.mean_albedo(dict(spec, c=1.0))
    mx = cache.max_albedo(spec)
    value = m * mx.constant
    return value, value * (e / m + mx.constant_error / mx.constant)


def _table3(cache, bar):
    rows = []
    for p in TABLE3:
        if p.row == "inf":
            check, check_err = _mean_with_constant(cache, p.column, LARGE_N)
            rows.append(Row(p, p.source, p.row, p.column, LIMITS[p.column], 0.0,
                            {"check_large_n": check, "check_large_n_error": check_err}))
        else:
            v, e = _mean_with_constant(cache, p.column, int(p.row))
            rows.append(Row(p, p.source, p.row, p.column, v, e))
        bar.update(1)
    return rows


def _table4(cache, bar):
    rows = []
    for p in TABLE4:
        m = cache.max_albedo({"type": "modified_ward", "m": float(p.row)})
        rows.append(Row(p, p.source, p.row, p.column, m.constant, m.constant_error, {"theta_deg": m.theta_deg}))
        bar.update(1)
    return rows


def _mu_of(theta_deg: float) -> float:
    return math.sin(math.radians(90.0 - theta_deg))  # keeps its digits near grazing


def _text(cache, bar):
    rows = []
    for p in TEXT:
        col = p.column
        if col == "schlick C_max":
            r = float(p.row.split("=")[1])
            # the albedo rises towards grazing incidence: its supremum is the limit mu -> 0, which
            # mu = 1e-12 resolves to 1e-8 (docs/notes_on_published_tables.md)
            m = cache.max_albedo({"type": "schlick", "r": r}, mu_min=1e-12)
            row = Row(p, p.source, p.row, col, m.constant, m.constant_error, {"theta_deg": m.theta_deg})
        elif col.startswith("stretched_phong overshoot"):
            m = cache.max_albedo({"type": "stretched_phong", "n": 1.0})
            c = 3.0 / (2.0 * math.pi)
            if "angle" in col:
                row = Row(p, p.source, p.row, col, m.theta_deg, m.theta_error)  # located to sqrt(err / curvature)
            else:
                row = Row(p, p.source, p.row, col, m.albedo * c - 1.0, m.error * c)
        elif col == "stretched_phong a(90 deg)":
            n = float(p.row.split("=")[1])
            a, e = albedo(load({"type": "stretched_phong", "n": n}), 1e-8, return_error=True)
            row = Row(p, p.source, p.row, col, float(a), float(e), {"mu": 1e-8, "eq26": (n + 2) / (2 * (n + 1))})
        elif col == "ward m=0.1 a(theta)":
            mu = _mu_of(float(p.row))
            a, e = albedo(load({"type": "ward", "m": 0.1}), mu, return_error=True)
            row = Row(p, p.source, p.row, col, float(a), float(e), {"mu": mu})
        elif col in ("blinn a(90 deg)", "stretched_blinn a(90 deg)"):
            model = col.split()[0]
            mx = cache.max_albedo({"type": model, "n": 128.0})
            a, e = albedo(load({"type": model, "n": 128.0, "c": mx.constant}), 1e-8, return_error=True)
            row = Row(p, p.source, p.row, col, float(a), float(e), {"mu": 1e-8, "c": mx.constant})
        elif col in ("blinn mean albedo", "stretched_blinn mean albedo"):
            v, e = _mean_with_constant(cache, col.split()[0], 128)
            row = Row(p, p.source, p.row, col, v, e)
        else:  # pragma: no cover - every TEXT entry has a branch
            raise AssertionError(col)
        rows.append(row)
        bar.update(1)
    return rows


TABLES = {
    "table2": ("000 Table 2: maximum constants of Blinn and stretched Blinn", TABLE2, _table2),
    "table3": ("000 Table 3: mean albedo", TABLE3, _table3),
    "table4": ("000 Table 4: maximum constants of modified Ward", TABLE4, _table4),
    "text": ("numbers stated in the text of 000", TEXT, _text),
}


def _dataset(name, rows):
    import xarray as xr

    from ._version import __version__

    extras = sorted({k for r in rows for k in r.extra})
    data = {
        "computed": ("entry", np.array([r.computed for r in rows]), {"long_name": "value computed by pumpup"}),
        "error": ("entry", np.array([r.error for r in rows]), {"long_name": "estimated absolute error of computed"}),
        "published_value": ("entry", np.array([r.published.value for r in rows]),
                            {"long_name": "value printed in the paper"}),
        "agrees": ("entry", np.array([int(bool(r.agrees)) for r in rows], dtype=np.int8),
                   {"long_name": "1 if computed rounds to the printed value"}),
    }
    for k in extras:
        data[k] = ("entry", np.array([r.extra.get(k, np.nan) for r in rows], dtype=float))
    return xr.Dataset(
        data,
        coords={
            "entry": np.arange(len(rows)),
            "source": ("entry", np.array([r.source for r in rows], dtype=object)),
            "row": ("entry", np.array([r.row for r in rows], dtype=object)),
            "column": ("entry", np.array([r.column for r in rows], dtype=object)),
            "published": ("entry", np.array([r.published.text for r in rows], dtype=object),
                          {"long_name": "the number exactly as printed"}),
        },
        attrs={"pumpup_kind": "pumpup reproduced table", "title": TABLES[name][0], "table": name,
               "pumpup_version": __version__},
    )


def compute(name: str, progress: bool | None = None, cache: _Cache | None = None):
    """Compute one table (a key of :data:`TABLES`) as an xarray.Dataset."""
    from .tables import _progress

    if name not in TABLES:
        raise ValueError(f"unknown table {name!r}; choose from {', '.join(TABLES)}")
    _, entries, fn = TABLES[name]
    with _progress(len(entries), name, progress) as bar:
        bar.unit = "value"
        rows = fn(cache or _Cache(), bar)
    return _dataset(name, rows)


def _fmt(v, e):
    return f"{v:.6g} ± {e:.1g}" if e > 0 else f"{v:.6g}"


def report(datasets: dict) -> str:
    """The Markdown comparison report."""
    lines = ["# pumpup reproduce: the papers' tables against the published values", ""]
    bad = []
    for name, ds in datasets.items():
        lines += [f"## {ds.attrs['title']}", "", "| row | column | published | computed | agrees |",
                  "|---|---|---|---|---|"]
        for i in range(ds.sizes["entry"]):
            e = ds.isel(entry=i)
            ok = bool(e.agrees)
            extra = ""
            if "theta_deg" in ds and np.isfinite(e.theta_deg):
                extra = f" (max at {float(e.theta_deg):.2f} deg)"
            if "check_large_n" in ds and np.isfinite(e.check_large_n):
                extra = f" (limit; n = 1e4 gives {float(e.check_large_n):.4f})"
            lines.append(f"| {e.row.item()} | {e.column.item()} | {e.published.item()} | "
                         f"{_fmt(float(e.computed), float(e.error))}{extra} | {'yes' if ok else '**no**'} |")
            if not ok:
                bad.append(f"- {e.source.item()}, {e.column.item()}, {e.row.item()}: printed {e.published.item()}, "
                           f"computed {_fmt(float(e.computed), float(e.error))}{extra}")
        lines.append("")
    lines += ["## Disagreements", ""] + (bad or ["none"]) + ["",
              "See docs/notes_on_published_tables.md for the investigation of each disagreement."]
    return "\n".join(lines) + "\n"


#: the analysis of 001 sec. 2.1 (pumpup.divergence), written as divergence.nc with its plot
DIVERGENCE = "divergence"
#: 000 Tables 1 and 5 (pumpup.costs): evaluation and sampling cost measured here, in report.md only
COSTS = "costs"


def _divergence_report(ds) -> str:
    lines = ["## Divergence at grazing incidence (001 sec. 2.1; fit a ~ K mu^-k for mu in [1e-8, 1e-5])", "",
             "| model | verdict | k | a(mu = 1e-8) |", "|---|---|---|---|"]
    for i, name in enumerate(ds.model.values):
        lines.append(f"| {name} | {ds.verdict.values[i]} | {float(ds.k[i]):.5f} ± {float(ds.k_error[i]):.1g} | "
                     f"{float(ds.albedo[i, -1]):.6g} |")
    lines += ["", ("001 claims that Ward and Cook-Torrance diverge; "
                   "see docs/studies/papers.md for why Cook-Torrance does not."), ""]
    return "\n".join(lines)


def reproduce(out: str = "tables", only: list[str] | None = None, progress: bool | None = None) -> dict:
    """Compute the tables, write ``<out>/<name>.nc`` and ``<out>/report.md``, return the datasets.

    Besides :data:`TABLES`, ``divergence`` runs the divergence analysis
    (:func:`pumpup.divergence.analysis_dataset`) into ``<out>/divergence.nc`` and
    ``<out>/divergence.png``. ``costs`` (only when named in ``only``: its timings change from run to run) measures
    000 Tables 1 and 5 on this machine (:mod:`pumpup.costs`) into a section of ``report.md``.
    """
    choices = list(TABLES) + [DIVERGENCE, COSTS]
    # costs are timings of this machine: only on request, so a default run leaves the checkout as it was
    names = list(only) if only else [n for n in choices if n != COSTS]
    unknown = [n for n in names if n not in choices]
    if unknown:
        raise ValueError(f"unknown table(s) {', '.join(map(repr, unknown))}; choose from {', '.join(choices)}")
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as exc:
        raise OSError(f"cannot create the output directory {out!r}: {exc}") from None
    if not os.access(out, os.W_OK):
        raise OSError(f"the output directory {out!r} is not writable")
    from .tables.provenance import write_generated

    cache = _Cache()
    t0 = time.perf_counter()
    datasets = {n: compute(n, progress=progress, cache=cache) for n in names if n not in (DIVERGENCE, COSTS)}
    extra = ""
    if DIVERGENCE in names:
        from .divergence import analysis_dataset, plot

        div = analysis_dataset(progress=progress)
        write_generated(div, os.path.join(out, "divergence.nc"))
        plot(div, os.path.join(out, "divergence.png"))
        extra = _divergence_report(div)
    if COSTS in names:
        from .costs import report as costs_report

        extra += ("\n" if extra else "") + costs_report()  # timings: reported, never asserted
    for n, ds in datasets.items():
        write_generated(ds, os.path.join(out, f"{n}.nc"))
    with atomic_path(os.path.join(out, "report.md")) as tmp:
        with open(tmp, "w") as fh:
            fh.write(report(datasets) + ("\n" + extra if extra else ""))
    datasets["_seconds"] = time.perf_counter() - t0
    return datasets
