"""Cost of an 8-wavelength metal against one wavelength (issue 19's speed targets: eval <= 3x, tabulate <= 8x).

Baseline and spectral model are timed in the same run (best of several repeats); the ratios are
what to read, the absolute times depend on the load (printed).

    PYTHONPATH=. python scripts/bench/bench_spectral.py [--no-tabulate]

eval (2e5 random pairs in the upper hemisphere, input checks included everywhere):
* one wavelength: the scalar ``metal`` model (``Metal.eval``), the baseline;
* 000 eq. 27/28 direct: ``SpectralMetal.eval``, one compiled pass, geometry once per pair and
  F(eta_j + i k_j, Theta_min) computed per wavelength; also the same kernel at one wavelength;
* 8 separate ``Metal.eval`` calls (what the spectral model did before);
* 000 eq. 28 tabulated: ``SpectralMetal.eval_tabulated``, F(Theta_min) read from a per-wavelength table;
* the colour-keeping pumped metal (``SpectralPumpedLobe``: the pumped F = 1 lobe times F) against
  the pumped one-wavelength metal.
tabulate (Au, n = 20 and n = 5000, adaptive mu grid): ``Spectral.tabulate`` of 8 wavelengths
against ``pumpup.tabulate`` of one, as the number of albedo values computed (independent of the
load) and as times on one thread and on all cores.
"""

import os
import sys
import time

import numpy as np

import pumpup
from pumpup import spectral


def best(fn, repeat=5):
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return min(out)


def directions(rng, m):
    w = rng.normal(size=(m, 3))
    w[:, 2] = np.abs(w[:, 2])
    return w / np.linalg.norm(w, axis=1, keepdims=True)


def bench_eval(m=200_000):
    rng = np.random.default_rng(0)
    wi, wo = directions(rng, m), directions(rng, m)
    s = spectral.SpectralMetal("Au", n=20)
    s1 = spectral.SpectralMetal("Au", n=20, wavelengths=[520.0])
    one = s.models[3]
    for f in (s.eval, s1.eval, one.eval, s.eval_tabulated):
        f(wi[:10], wo[:10])  # compile / load the cached kernels
    t1 = best(lambda: one.eval(wi, wo))
    rows = [
        ("one wavelength (Metal.eval, baseline)", t1),
        ("one wavelength, spectral kernel", best(lambda: s1.eval(wi, wo))),
        ("8 wavelengths, eq. 27/28 direct", best(lambda: s.eval(wi, wo))),
        ("8 wavelengths, 8 separate Metal.eval", best(lambda: np.stack([f.eval(wi, wo) for f in s.models], -1))),
        ("8 wavelengths, eq. 28 tabulated F", best(lambda: s.eval_tabulated(wi, wo))),
    ]
    print(f"eval of {m} pairs, load {os.getloadavg()[0]:.2f}")
    for name, t in rows:
        print(f"  {name:42s} {t * 1e3:8.1f} ms  ratio {t / t1:5.2f}")
    print(f"  (tabulated F: max |F error| {s.fresnel_table()[1]:.1e})")
    keep = getattr(spectral, "SpectralPumpedLobe", None)
    if keep is not None:
        pm = pumpup.pump(one)
        pk = keep(s)
        pm.eval(wi[:10], wo[:10]), pk.eval(wi[:10], wo[:10])
        tp = best(lambda: pm.eval(wi, wo))
        tk = best(lambda: pk.eval(wi, wo))
        pw = s.pump()
        pw.eval(wi[:10], wo[:10])
        tw = best(lambda: pw.eval(wi, wo), repeat=3)
        print(f"  {'pumped metal, one wavelength (baseline 2)':42s} {tp * 1e3:8.1f} ms  ratio {tp / t1:5.2f}")
        print(f"  {'8 wavelengths, colour-keeping pumped':42s} {tk * 1e3:8.1f} ms  ratio {tk / t1:5.2f}"
              f"  ({tk / tp:.2f} x the pumped one)")
        print(f"  {'8 wavelengths, pumped per wavelength':42s} {tw * 1e3:8.1f} ms  ratio {tw / t1:5.2f}"
              f"  ({tw / tp:.2f} x the pumped one)")


class count_values:
    """Count the albedo values (model, mu) computed inside the block: the load-independent cost."""

    def __enter__(self):
        mod, tab = sys.modules["pumpup.engine.cubature"], sys.modules["pumpup.tables"]
        self.orig, self.n = mod.albedo, 0

        def counting(brdf, mu, *a, **k):
            self.n += np.size(mu)
            return self.orig(brdf, mu, *a, **k)

        mod.albedo = tab.albedo = counting
        return self

    def __exit__(self, *exc):
        sys.modules["pumpup.engine.cubature"].albedo = sys.modules["pumpup.tables"].albedo = self.orig


def value_counts(n) -> dict:
    """How many albedo values Au at exponent ``n`` costs: each wavelength's own ``pumpup.tabulate`` (``own``, in
    the order of the wavelengths) and ``Spectral.tabulate`` of all (``spectral``, on ``grid`` mu).
    """
    s = spectral.SpectralMetal("Au", n=n)
    own = []
    for m in s.models:
        with count_values() as c:
            pumpup.tabulate(pumpup.load(m.spec), threads=1, progress=False)
        own.append(c.n)
    with count_values() as c:
        ds = spectral.SpectralMetal("Au", n=n).tabulate(threads=1)
    return {"own": own, "spectral": c.n, "grid": ds.sizes["mu"], "wavelengths": [float(w) for w in s.wavelengths]}


def bench_counts(n):
    r = value_counts(n)
    own, c, i520 = r["own"], r["spectral"], r["wavelengths"].index(520.0)
    print(f"albedo values computed, Au n = {n:g}: one wavelength's own adaptive table {min(own)} to {max(own)} "
          f"(520 nm: {own[i520]}, sum of the 8: {sum(own)}); Spectral.tabulate (one shared grid, {r['grid']} mu) "
          f"{c} = {c / own[i520]:.2f} x the 520 nm one, {c / (sum(own) / 8):.2f} x the mean one")


def bench_tabulate(n):
    s = spectral.SpectralMetal("Au", n=n)
    one = s.models[3]
    pumpup.tabulate(s.models[0], mu=[0.5, 0.01], threads=1, progress=False)  # load the compiled kernels

    def timed(fn):
        t = time.perf_counter()
        out = fn()
        return out, time.perf_counter() - t

    d1, t1 = timed(lambda: pumpup.tabulate(one, threads=1, progress=False))
    sep = [timed(lambda m=m: pumpup.tabulate(m, threads=1, progress=False))[1] for m in s.models]
    d8, t8 = timed(lambda: s.tabulate(threads=1))
    fresh = pumpup.load(s.models[2].spec)  # a fresh object: nothing reused
    _, t1p = timed(lambda: pumpup.tabulate(fresh, progress=False))  # default threads (tables.THREADS)
    _, t8p = timed(lambda: spectral.SpectralMetal("Au", n=n).tabulate())  # a fresh object: nothing reused
    mean1 = sum(sep) / len(sep)
    print(f"tabulate Au n = {n:g} (adaptive grid), load {os.getloadavg()[0]:.2f}:")
    print(f"  one thread: one wavelength (520 nm) {t1:.2f} s ({d1.sizes['mu']} mu); the 8 one at a time "
          f"{sum(sep):.2f} s (from {min(sep):.2f} to {max(sep):.2f} s each, mean {mean1:.2f} s); "
          f"Spectral.tabulate {t8:.2f} s ({d8.sizes['mu']} mu, one shared grid): {t8 / t1:.2f} x the 520 nm one, "
          f"{t8 / mean1:.2f} x the mean one")
    print(f"  {pumpup.tables._cores()} threads: one wavelength (480 nm) {t1p:.2f} s, Spectral.tabulate {t8p:.2f} s: "
          f"{t8p / t1p:.2f} x")


def bench_albedo():
    s = spectral.SpectralMetal("Au", n=20)
    one = s.models[3]
    mu = np.linspace(0.05, 1.0, 20)
    pumpup.albedo(one, mu[:2]), s.albedo(mu[:2], threads=1)
    ta1 = best(lambda: pumpup.albedo(one, mu), repeat=2)
    ta8 = best(lambda: s.albedo(mu, threads=1), repeat=2)
    tap = best(lambda: s.albedo(mu), repeat=2)
    print(f"albedo at {mu.size} mu, load {os.getloadavg()[0]:.2f}: one wavelength {ta1:.3f} s; 8 wavelengths "
          f"{ta8:.3f} s on one thread ({ta8 / ta1:.2f} x), {tap:.3f} s on {pumpup.tables._cores()} ({tap / ta1:.2f} x)")


def main():
    bench_eval()
    bench_albedo()
    if "--no-tabulate" not in sys.argv:
        for n in (20, 5000):
            bench_counts(n)
            bench_tabulate(n)


if __name__ == "__main__":
    main()
