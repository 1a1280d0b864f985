"""Evaluations per second of every built-in model, and the cost relative to reciprocal Phong.

In the spirit of 000 Table 1 / Table 5 (the paper found stretched Phong only 8 % dearer than
Phong).  One core, 2e6 random direction pairs in the upper hemisphere, best of 5 runs after
a warm-up call (so numba compilation is not timed).  The baseline (reciprocal Phong) is
measured in the same run.

    python scripts/bench/bench_eval.py [--pumped] [--spectral] [--issue55] [--tolerances]

(These are the kernels, ``_eval``.  The cost of ``BRDF.eval``'s input checks, and eval against a
fused numpy expression, is ``python scripts/bench/bench_albedo.py --eval``.)

``--issue55`` prints only the eval rows of issue 55's table (pumped and compensated models against their base), each
with its target and the old and new path measured alternating in one run (old: the chain kernel level by level,
``Pumped._eval_levelwise``, and the compensated model's two passes, ``KullaConty._eval_two_passes``; new: ``_eval``,
the level table where the chain has no product table, and the base's fused kernel where it has one; for pumped Phong
also "lit rows", its fused kernel dividing every lit row in place row by row, ``Phong._eval_divided_lit``, against
"new", which gathers the product table's rows into contiguous arrays first); 2^20 pairs, best of 9 in this thread's CPU
time (``time.thread_time``: on a shared machine the time spent waiting for a core is out).

``--tolerances`` builds the 3-level g2 pumped Phong n = 20 with three settings of the pumping tables' tolerances
(``pumpup.operators.pumping.TABLE_RTOL`` and ``TABLE_INTERP_TOL``) and prints each build's time relative to the
default's, measured in the same run, and the level-3 albedo at mu = 0.5 (:func:`tolerance_rows`).

``--spectral`` also times the spectral gold of 000 sec. 5 (8 wavelengths, n = 20) against one
wavelength (the scalar ``metal``), with input checks on both: 000 eq. 27/28 with the Fresnel factor
evaluated directly per wavelength, and eq. 28 with F(Theta_min) tabulated per wavelength.

``--pumped`` also builds a 3-level pumped Phong (g2, n = 20) and reports its evaluation cost
relative to the base and the time to build its three albedo tables (issue 4's targets: at most
2 x the base, under a second).  The build is timed twice: first in the process (n = 21, which
also loads the compiled kernels) and then warm (n = 20); tables are computed on
``pumpup.tables.THREADS`` threads (default one per core).
"""

import sys
import time

import numpy as np

import pumpup

N = 2_000_000


def directions(rng, n):
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:, 2] = np.abs(v[:, 2])
    return v


def rate(f, wi, wo, repeat=5):
    f._eval(wi[:10], wo[:10])  # compile / load the cached kernel
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        f._eval(wi, wo)
        best = min(best, time.perf_counter() - t)
    return len(wi) / best


def main():
    rng = np.random.default_rng(1)
    wi, wo = directions(rng, N), directions(rng, N)
    cases = [(name, {"type": name, **cls.examples[0]}) for name, cls in pumpup.registry().items() if cls.examples]
    base = rate(pumpup.load({"type": "phong", "n": 20}), wi, wo)
    print(f"{'model':18s} {'spec':58s} {'evals/s':>10s} {'cost vs phong':>14s}")
    print(f"{'phong (baseline)':18s} {str({'n': 20}):58s} {base:10.3g} {1.0:14.2f}")
    for name, spec in cases:
        r = rate(pumpup.load(spec), wi, wo)
        shown = {k: v for k, v in spec.items() if k != "type"}
        print(f"{name:18s} {str(shown)[:58]:58s} {r:10.3g} {base / r:14.2f}")
    ht = rate(pumpup.load({"type": "he_torrance", "sigma_0": 0.1, "tau": 1.7}), wi, wo)
    print(f"\nhe_torrance (000 Fig. 5 parameters) costs {base / ht:.1f} x Phong ({ht:.3g} evals/s); 000 Table 1: 320")
    print("\nThe pairs of 000 Table 5, at the same parameters:")
    for a, b in [({"type": "phong", "n": 20}, {"type": "stretched_phong", "n": 20}),
                 ({"type": "blinn", "n": 20}, {"type": "stretched_blinn", "n": 20}),
                 ({"type": "ward", "m": 0.1}, {"type": "modified_ward", "m": 0.1})]:
        ra, rb = rate(pumpup.load(a), wi, wo), rate(pumpup.load(b), wi, wo)
        print(f"  {b['type']:16s} costs {ra / rb:5.2f} x {a['type']} ({rb:.3g} vs {ra:.3g} evals/s)")
    if "--pumped" in sys.argv:
        def build(n):
            t = time.perf_counter()
            f = pumpup.pump({"type": "phong", "n": n}, g="g2", levels=3)
            for lev in f.chain():
                lev.lookup()
            return f, time.perf_counter() - t

        _, cold = build(21)  # the first in this process also loads the engine's compiled kernels
        f, warm = build(20)
        r = rate(f, wi, wo)
        print(f"\n3-level pumped Phong n = 20 (g2): {r:.3g} evals/s, {base / r:.2f} x the base Phong; "
              f"its 3 albedo tables took {warm:.2f} s to build ({cold:.2f} s for n = 21, the first in the process)")
    if "--spectral" in sys.argv:
        spectral_rows(wi, wo)
    if "--tolerances" in sys.argv:
        rows = tolerance_rows()
        print("\n3-level g2 pumped Phong n = 20, the pumping tables' tolerances (best of 3 builds each):")
        print(f"  {'TABLE_RTOL':>10s} {'TABLE_INTERP_TOL':>16s} {'build time / default':>20s} {'a_3(0.5)':>12s}")
        for r in rows:
            print(f"  {r['rtol']:10.0e} {r['interp_tol']:16.0e} {r['seconds'] / rows[0]['seconds']:20.2f} "
                  f"{r['albedo']:12.8f}")


#: the tolerance settings of ``--tolerances`` (the first is pumpup's default)
TOLERANCES = ((1e-9, 1e-7), (1e-8, 1e-6), (1e-7, 1e-5))


def tolerance_rows(settings=TOLERANCES, repeat: int = 3, mu: float = 0.5) -> list[dict]:
    """Build a 3-level g2 pumped Phong n = 20 with each (TABLE_RTOL, TABLE_INTERP_TOL) of ``settings``, each
    from empty table caches; return each setting's best build time of ``repeat`` and its level-3 albedo at ``mu``.
    The module constants and caches are restored afterwards.
    """
    from pumpup.operators import pumping

    saved = pumping.TABLE_RTOL, pumping.TABLE_INTERP_TOL, pumping._TABLES
    out = []
    try:
        for rtol, interp_tol in settings:
            pumping.TABLE_RTOL, pumping.TABLE_INTERP_TOL = rtol, interp_tol
            best, f = float("inf"), None
            for _ in range(repeat):
                pumping._TABLES = {}
                t = time.perf_counter()
                f = pumpup.pump({"type": "phong", "n": 20}, g="g2", levels=3)
                for lev in f.chain():
                    lev.lookup()
                best = min(best, time.perf_counter() - t)
            out.append({"rtol": rtol, "interp_tol": interp_tol, "seconds": best,
                        "albedo": float(pumpup.albedo(f, mu))})
    finally:
        pumping.TABLE_RTOL, pumping.TABLE_INTERP_TOL, pumping._TABLES = saved
    return out


def spectral_rows(wi, wo, repeat=5):
    """000 eq. 28 tabulated vs eq. 27/28 direct vs one wavelength, in this run (``--spectral``)."""
    from pumpup import spectral

    gold = spectral.SpectralMetal("Au", n=20)
    one = gold.models[3]  # 520 nm

    def secs(fn):
        fn(wi[:10], wo[:10])
        best = np.inf
        for _ in range(repeat):
            t = time.perf_counter()
            fn(wi, wo)
            best = min(best, time.perf_counter() - t)
        return best

    t1 = secs(one.eval)
    td = secs(gold.eval)
    tt = secs(gold.eval_tabulated)
    print(f"\nspectral gold, n = 20, {len(wi):.0e} pairs (input checks included):")
    print(f"  one wavelength (metal, 520 nm)               {len(wi) / t1:10.3g} pairs/s  1.00")
    print(f"  8 wavelengths, eq. 27/28 Fresnel direct      {len(wi) / td:10.3g} pairs/s  {td / t1:.2f} x one")
    print(f"  8 wavelengths, eq. 28 F(Theta_min) tabulated {len(wi) / tt:10.3g} pairs/s  {tt / t1:.2f} x one"
          f"  (|F error| <= {gold.fresnel_table()[1]:.1e})")


def issue55_rows(repeat=9, n=1 << 20):
    """Issue 55's eval rows: target, the old paths and the new (alternating), as ratios to the base measured in the
    same rounds, and the time and memory of the tables the new path reads.
    """
    import os

    rng = np.random.default_rng(1)
    wi, wo = directions(rng, n), directions(rng, n)
    ggx = pumpup.load({"type": "ggx", "alpha": 0.3})
    phong = pumpup.load({"type": "phong", "n": 20})
    rows = []  # (label, base, {path: callable}, target)
    built = []
    for levels in (1, 2, 3, 5):
        p = pumpup.pump({"type": "ggx", "alpha": 0.3}, g="g2", levels=levels)
        built.append((levels, *table_cost(p)))
        rows.append((f"pumped GGX alpha 0.3, g2, {levels} level{'s' * (levels > 1)}", ggx,
                     {"levelwise": p._eval_levelwise, "level table": p._eval_level_table, "new": p._eval}, 1.5))
    for levels in (1, 3, 5):
        pp = pumpup.pump({"type": "phong", "n": 20}, g="g2", levels=levels)
        rows.append((f"pumped Phong n 20, g2, {levels} level{'s' * (levels > 1)}", phong,
                     {"levelwise": pp._eval_levelwise, "level table": pp._eval_level_table,
                      "lit rows": lambda wi, wo, pp=pp: phong._eval_divided_lit(wi, wo, pp._chain_args()),
                      "new": pp._eval}, 1.3))
    kc = pumpup.compensate({"type": "ggx", "alpha": 0.3}, method="kulla_conty")
    rows.append(("GGX alpha 0.3 + Kulla-Conty lobe", ggx, {"levelwise": kc._eval_two_passes,
                                                          "level table": kc._eval_two_passes, "new": kc._eval}, 1.3))
    paths = ("levelwise", "level table", "lit rows", "new")
    fns = {"ggx": ggx._eval, "phong": phong._eval}
    for label, _, fn, _ in rows:
        for path in paths:
            if path in fn:
                fns[label + " " + path] = fn[path]
    for fn in fns.values():
        fn(wi[:10], wo[:10])
        fn(wi, wo)
    best = dict.fromkeys(fns, np.inf)
    for _ in range(repeat):
        for key, fn in fns.items():  # every path once per round: old and new alternate under the same load
            t = time.thread_time()  # CPU time of this thread: the time it waits for a core on a loaded machine is out
            fn(wi, wo)
            best[key] = min(best[key], time.thread_time() - t)

    print(f"issue 55, eval against the base, {n} pairs, best of {repeat} (load {os.getloadavg()[0]:.1f}):")
    print("  levelwise: every level's bound looked up level by level (Pumped._eval_levelwise; Kulla-Conty: two "
          "passes)\n  level table: every level's bound from one polynomial piece per direction "
          "(Pumped._eval_level_table, the split table off)\n"
          "  new: Pumped._eval (the split table, one product of two look-ups; Phong: only the lit rows divided)\n"
          "  lit rows (Phong): its fused kernel dividing each lit row in place (Phong._eval_divided_lit); new gathers "
          "the product table's rows first")
    print(f"{'':40s} {'target':>7s} {'levelwise':>10s} {'lvl table':>10s} {'lit rows':>9s} {'new':>7s} {'base ns':>8s} "
          f"{'new ns':>7s}")
    for label, base, _, target in rows:
        b = best["ggx" if base is ggx else "phong"]
        r = {path: best[label + " " + path] / b for path in paths if label + " " + path in best}
        met = "met" if r["new"] <= target else "missed"
        lit = f"{r['lit rows']:8.2f}x" if "lit rows" in r else f"{'-':>9s}"
        print(f"{label:40s} {target:6.1f}x {r['levelwise']:9.2f}x {r['level table']:9.2f}x {lit} {r['new']:6.2f}x "
              f"{b / n * 1e9:8.1f} {best[label + ' new'] / n * 1e9:7.1f}  {met}")
    print("\ntables of the pumped GGX chains (built again from the levels' albedo tables, which are cached):")
    for levels, secs, kb, share in built:
        print(f"  {levels} level{'s' * (levels > 1)}: product/level/split tables {secs * 1e3:7.1f} ms, {kb:8.1f} kB; "
              f"the split table serves {share:.1%} of uniform (N.wi, N.wo)")


def table_cost(p):
    """Build time (s) and size (kB) of the look-up tables of pumped chain ``p`` (its levels' albedo tables already
    built), and the share of pairs the split table serves.
    """
    from pumpup.operators.pumping import Pumped

    for lev in p.chain():
        lev.lookup()
    fresh = Pumped(base=p.base, g=p.p["g"])  # the same chain, its tables not yet built
    for lev in fresh.chain():
        lev.lookup()
    t = time.perf_counter()
    args = fresh._chain_args()
    secs = time.perf_counter() - t
    kb = sum(a.nbytes for a in args if isinstance(a, np.ndarray)) / 1e3
    r = fresh.split_table()
    return secs, kb, (r.share() if r is not None else 0.0)


if __name__ == "__main__":
    if "--issue55" in sys.argv:
        issue55_rows()
    else:
        main()
