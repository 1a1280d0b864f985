"""Calibration of the mean albedo taken from a table (pumpup/tables/reuse.py).

For built-in models from wide to very narrow lobes, Ward's divergent grazing albedo and sharp Fresnel features, on the
sweep's grid (``pumpup.sweeps.default_mu(257)``): the table, then ``pumpup.mean_albedo`` at rtol 1e-9 (from the table,
the table cut short, or afresh), against ``pumpup.mean_albedo`` on a fresh object at rtol 1e-12 (no table: adaptive
Gauss-Kronrod in mu over fresh values), its own error counted in the reused value's favour.  Prints, per model, which way
the mean was taken, the true error / the estimate, and the time of the mean; then the worst ratio.

The spline's estimate is not |quintic - cubic| alone: with that, Phong n = 20000 was 1.1e-9 off with an estimate of
3.5e-10 (ratio 3.2): the grid barely resolves a feature there, and both splines are off alike.

    PYTHONPATH=. python scripts/calibration/reuse_calibration.py
"""

import time
import warnings

import pumpup
from pumpup.tables import reuse as _reuse
from pumpup.sweeps import default_mu

SPECS = ([{"type": "phong", "n": n} for n in (20, 300, 1000, 3000, 5000, 10000, 20000, 50000)]
         + [{"type": "stretched_phong", "n": n} for n in (20, 1000, 3000, 5000, 20000)]
         + [{"type": "stretched_phong", "n": 20, "p": 0.5}, {"type": "retro", "n": 2000}, {"type": "blinn", "n": 16},
            {"type": "blinn", "n": 5000}, {"type": "ggx", "alpha": 0.3}, {"type": "ggx", "alpha": 0.01},
            {"type": "beckmann", "alpha": 0.3}, {"type": "cook_torrance", "m": 0.3}, {"type": "ward", "m": 0.1},
            {"type": "ward", "m": 0.3}, {"type": "ward_aniso", "ax": 0.1, "ay": 0.3},
            {"type": "ward_aniso", "ax": 0.05, "ay": 0.5}, {"type": "metal", "n": 7.5, "eta": 0.6, "k": 0.3},
            {"type": "metal", "n": 0, "eta": 0.999, "k": 0.001}, {"type": "plastic", "n": 3, "eta": 1.5, "ad": 0.3}])
RTOL = 1e-9


def how(f) -> str:
    """Which way mean_albedo takes the mean of the freshly tabulated ``f``: 'table', 'cut short' or 'afresh'."""
    t = _reuse.recall(f)
    fresh = lambda mu_min, scale: _reuse.fresh_low(f, mu_min, 0.25 * RTOL * scale, RTOL / 10)  # noqa: E731
    if _reuse._mean_of(*t[:3], RTOL, fresh)[0] is not None:
        return "table"
    return "cut short" if _reuse.mean_from_table(f, RTOL, fresh) is not None else "afresh"


def main():
    warnings.simplefilter("ignore")
    mu = default_mu(257)
    worst, worst_at = 0.0, None
    print(f"{'model':58s} {'way':>9s} {'|m - ref|':>10s} {'estimate':>10s} {'ratio':>6s} {'mean ms':>8s}")
    for spec in SPECS:
        f = pumpup.load(spec)
        pumpup.tabulate(f, mu=mu, threads=1, progress=False)
        way = how(f)
        t0 = time.perf_counter()
        m, e = pumpup.mean_albedo(f, rtol=RTOL, return_error=True)
        dt = time.perf_counter() - t0
        ref, ref_e = pumpup.mean_albedo(pumpup.load(spec), rtol=1e-12, return_error=True)
        ratio = max(abs(m - ref) - ref_e, 0.0) / e
        if ratio > worst:
            worst, worst_at = ratio, spec
        print(f"{str(spec)[:58]:58s} {way:>9s} {abs(m - ref):10.2e} {e:10.2e} {ratio:6.2f} {dt * 1e3:8.1f}", flush=True)
    print(f"worst true error / estimate: {worst:.2f} ({worst_at})")


if __name__ == "__main__":
    main()
