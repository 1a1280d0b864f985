"""How honest and how tight is the albedo engines' error estimate?  (issue 14 item 4)

For every independent reference in ``tests/`` and every tolerance rtol in 1e-6 .. 1e-12, each
engine computes a(mu) with its error estimate, and the ratio true error / estimate is recorded,
where the true error is |a - reference|.  A ratio above 1 is a dishonest estimate; a ratio far
below 1 is an estimate that buys needless refinement.  A reference whose own error exceeds the
tolerance cannot judge that tolerance: such a case is skipped (and counted).  A case whose
reference error is above a tenth of the estimate only bounds the ratio from above (by
(|a - ref| + ref_err) / estimate); it is shown separately as "unresolved".

The references (all computed without pumpup):

* ``tests/data/independent_reference.json``: nested QUADPACK in spherical coordinates about N,
  three methods (the Phong, Blinn, Ward and Cook-Torrance families), relative error ~1e-14;
* ``tests/data/independent_p.json``: the p-model (stretched Phong, retro) with p in {0, 0.25, 0.5, 0.75, 1},
  30-digit mpmath about the lobe axis checked by two scipy orders about N (``tests/reference/independent_p.py``);
* ``tests/data/independent_anisotropic.json``: ward_aniso and anisotropic Lafortune, two nested
  quadratures (at the azimuths of incidence stored there);
* 30-digit mpmath 1-D quadratures of reciprocal and stretched Phong (the azimuth about R in
  closed form, ``tests/reference/independent_reference.py``'s ``phong_1d``), n in {0, 1, 20, 5000, 1e5},
  from normal to grazing incidence;
* closed forms: Lambert (its albedo exactly), reciprocal and stretched Phong at normal incidence
  (1, 000 eq. 6), Lewis's Phong (k_rho at every mu, 002 eq. 22).

Engines are a small registry, :data:`ENGINES`: name -> (context manager, applies(brdf)).  The
"1-D" engine is the closed-form-azimuth path of ``pumpup.engine.polar`` (it applies to the models with
a Polar hint), "2-D" the adaptive cubature of ``pumpup.albedo`` (``using(engine="2d")``); a new
engine (the nested 1-D x 1-D engine of issue 14 item 2) is one more entry.  Estimates
(:data:`ESTIMATES`): "raw" is |K - G| everywhere (the engines before issue 14), "quadpack"
QUADPACK's calibration everywhere, "min" the smaller of the two, "default" what the engines use
now (the 1-D path calibrated, the 2-D engine raw: ``pumpup.physics.quadrature`` says why).
``tests/physics/test_error_calibration.py`` uses the same functions, with "default".

Beside the independent references, "self" cases judge the 2-D engine against itself at rtol
1e-13 with the raw estimate (its own error subtracted) on integrands with kinks that no hint
marks (a pumped Blinn, Kulla-Conty lobes: the knots of their albedo tables); there the
"quadpack" estimate was measured below the true error.

    PYTHONPATH=. python scripts/calibration/error_calibration.py            # every engine, both estimates
    PYTHONPATH=. python scripts/calibration/error_calibration.py --quick    # the default test's subset
    PYTHONPATH=. python scripts/calibration/error_calibration.py --worst    # also the four largest ratios of each
    PYTHONPATH=. python scripts/calibration/error_calibration.py --cost     # evaluations per mu, each estimate
"""

from __future__ import annotations

import contextlib
import functools
import itertools
import json
import math
import pathlib
import sys
import time
import warnings

import numpy as np
from pumpup.engine.routes import using

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
sys.path.insert(0, str(ROOT / "tests"))  # tests/reference: the independent references
RTOLS = (1e-6, 1e-8, 1e-10, 1e-12)

#: mpmath Phong references: (n, p) and mu
MP_LOBES = [(0, 0), (1, 1), (20, 0), (20, 1), (5000, 1), (1e5, 0)]
MP_MU = [1.0, 0.9, math.sqrt(3) / 2, 1 / math.sqrt(2), 0.5, 0.2, 0.05, 1e-3, 1e-6, 1e-8]


def _has_polar(f) -> bool:
    return all(t.azimuth_hint() is not None for _, t in f.albedo_terms())


def _two_d():

    return using(engine="2d")


def _without_1d():
    return using(engine="nested")


def _nested_applies(f) -> bool:
    """The nested quadrature (pumpup.engine.nested) integrates f: every term with a lobe hint (a
    from_function BRDF stays on the 2-D engine).  It is judged with the 1-D path off (``_without_1d``),
    so also on the models that path takes (the Phong family, and the half
    vector's models: the nested engine is their second engine in the tests)."""
    for _, t in f.albedo_terms():
        lobe = t.lobe(0.5)
        if lobe.generic:
            return False
    return True


#: name -> (context manager factory, applies(brdf) -> bool); "nested" is what pumpup.albedo runs by
#: default where there is no closed-form azimuth, "2-D" the cubature everywhere (the reference)
ENGINES = {
    "1-D": (contextlib.nullcontext, _has_polar),
    "nested": (_without_1d, _nested_applies),
    "2-D": (_two_d, lambda f: True),
}

def _estimates(mode):
    from pumpup.physics import quadrature as _errors

    return _errors.estimates(mode)


def _raw():
    from pumpup.physics import quadrature as _errors

    return _errors.raw_estimate()


#: "default": what the engines use (the 1-D path calibrated, the 2-D engine raw, pumpup.physics.quadrature);
#: "raw": |K - G| everywhere (before issue 14); "quadpack" / "min": that estimate everywhere
ESTIMATES = {
    "default": contextlib.nullcontext,
    "raw": _raw,
    "quadpack": functools.partial(_estimates, "quadpack"),
    "min": functools.partial(_estimates, "min"),
}


SELF_SPECS = [{"type": "pumped", "base": {"type": "blinn", "n": 16}, "g": "g1"},
              {"type": "kulla_conty", "base": {"type": "ggx", "alpha": 0.3}},
              {"type": "kulla_conty", "base": {"type": "phong", "n": 20}}]
SELF_MU = [0.9, 0.7, 0.3, 0.05, 1e-3]


@functools.cache
def _self_reference(spec_json, mu):
    import pumpup

    with _raw(), _two_d(), warnings.catch_warnings():
        warnings.simplefilter("ignore", pumpup.albedo_module.AlbedoWarning)
        a, e = pumpup.albedo(pumpup.load(json.loads(spec_json)), mu, rtol=1e-13, atol=0.0, max_regions=200000,
                             return_error=True)
    return float(a), float(e)


@functools.cache
def _mp_phong(n, p, mu):
    from reference import independent_reference as ref

    return ref.phong_1d(ref.SPHONG if p else ref.PHONG, n, mu)


def cases(quick: bool = False):
    """Every reference: dicts with id, spec, mu, phi, value (a thunk for the mpmath ones), ref_err."""
    out = []
    data = json.loads((DATA / "independent_reference.json").read_text())
    for e in data["entries"]:
        if e["quantity"] != "directional_albedo" or not e["mu"] > 0:
            continue
        if quick and e["model"] in ("cook_torrance", "ward", "modified_ward") and e["mu"] < 0.05:
            continue  # (grazing Ward: each takes a few seconds at rtol 1e-12 in the 2-D engine)
        out.append({"id": f"ref-{e['model']}-{json.dumps(e['params'])}-mu{e['mu']:.3g}",
                        "spec": {"type": e["model"], **e["params"]}, "mu": e["mu"], "phi": 0.0,
                        "value": e["value"], "ref_err": e["abs_err_estimate"]})
    for r in json.loads((DATA / "independent_anisotropic.json").read_text())["rows"]:
        out.append({"id": f"aniso-{r['model']}-{json.dumps(r['params'])}-mu{r['mu']}-phi{r['phi']:.3f}",
                        "spec": {"type": r["model"], **r["params"]}, "mu": r["mu"], "phi": r["phi"],
                        "value": r["albedo"], "ref_err": r["abs_err_estimate"]})
    # the p-model with p in (0, 1) and its p = 0, 1 checks (tests/reference/independent_p.py: 30-digit mpmath
    # about the lobe axis, checked by two scipy orders about N; stretched Phong and retro, equal albedos)
    for e in json.loads((DATA / "independent_p.json").read_text())["entries"]:
        if quick and (e["model"] == "retro" or e["p"] in (0.0, 1.0) or e["mu"] in (0.9, 1e-4)):
            continue
        out.append({"id": f"p-{e['model']}-n{e['n']:g}-p{e['p']:g}-mu{e['mu']:.3g}",
                    "spec": {"type": e["model"], "n": float(e["n"]), "p": float(e["p"])}, "mu": e["mu"], "phi": 0.0,
                    "value": e["value"], "ref_err": e["abs_err_estimate"]})
    for n, p in MP_LOBES:
        if quick and n == 0:
            continue  # (2.5 s of mpmath: the indicator (R.V)_+^0 has a jump)
        spec = {"type": "stretched_phong", "n": float(n), "p": float(p)} if p else {"type": "phong", "n": float(n)}
        for mu in (MP_MU[::3] if quick else MP_MU):
            out.append({"id": f"mpmath-{spec['type']}-n{n}-mu{mu:.3g}", "spec": spec, "mu": mu, "phi": 0.0,
                            "value": functools.partial(_mp_phong, n, p, mu), "ref_err": None})
    # not independent: the 2-D engine itself at rtol 1e-13 with the raw estimate (its own error
    # subtracted), on integrands with kinks no hint marks (the knots of an albedo table)
    for spec in SELF_SPECS:
        for mu in ((0.7, 1e-3) if quick else SELF_MU):
            out.append({"id": f"self-{json.dumps(spec)}-mu{mu:g}", "spec": spec, "mu": mu, "phi": 0.0,
                        "value": functools.partial(_self_reference, json.dumps(spec), mu), "ref_err": None})
    for n in (0.0, 1.0, 20.0, 1e3, 1e6):
        for t in ("phong", "stretched_phong"):
            out.append({"id": f"closed-{t}-n{n:g}-normal", "spec": {"type": t, "n": n}, "mu": 1.0, "phi": 0.0,
                            "value": 1.0, "ref_err": 0.0})  # 000 eq. 6
    for mu in (1.0, 0.3, 1e-6):
        out.append({"id": f"closed-lambert-mu{mu:g}", "spec": {"type": "lambert", "albedo": 0.7}, "mu": mu, "phi": 0.0,
                        "value": 0.7, "ref_err": 1e-16})
        out.append({"id": f"closed-lewis_phong-mu{mu:g}", "spec": {"type": "lewis_phong", "n": 20, "k_rho": 0.9},
                        "mu": mu, "phi": 0.0, "value": 0.9, "ref_err": 1e-16})  # 002 eq. 22
    return out


def reference(case):
    """(value, its error) of a case."""
    v = case["value"]
    if callable(v):
        return v()
    return v, case["ref_err"]


def measure(case, engine: str, rtol: float, estimate: str = "default"):
    """(a, estimate, true error |a - ref|, ref error) of one case in one engine, or None when the
    engine does not apply to the model."""
    import pumpup

    f = pumpup.load(case["spec"])
    ctx, applies = ENGINES[engine]
    if not applies(f):
        return None
    ref, ref_err = reference(case)
    with ctx(), ESTIMATES[estimate](), warnings.catch_warnings():
        warnings.simplefilter("ignore", pumpup.albedo_module.AlbedoWarning)
        a, e = pumpup.albedo(f, case["mu"], phi=case["phi"], rtol=rtol, atol=0.0, return_error=True)
    return float(a), float(e), abs(float(a) - ref), ref_err


def judge(result, rtol):
    """'skip' (the reference is coarser than the tolerance), 'dishonest', 'unresolved' (the
    reference error exceeds a tenth of the estimate) or 'resolved'; and the ratio."""
    a, e, true, ref_err = result
    if ref_err > rtol * max(abs(a), 1e-300):
        return "skip", math.nan
    if true > e + ref_err:
        return "dishonest", true / e if e > 0 else math.inf
    if ref_err > 0.1 * e:
        return "unresolved", (true + ref_err) / e if e > 0 else math.inf
    return "resolved", true / e if e > 0 else (0.0 if true == 0 else math.inf)


COST_SPECS = [{"type": "phong", "n": 20}, {"type": "stretched_phong", "n": 20}, {"type": "retro", "n": 10},
              {"type": "stretched_phong", "n": 20, "p": 0.5}, {"type": "blinn", "n": 16},
              {"type": "ward", "m": 0.1}, {"type": "cook_torrance", "m": 0.3}, {"type": "ggx", "alpha": 0.1}]


def cost(rtol=1e-10, n_mu=65):
    """Evaluations per mu and seconds of an n_mu-point table (mu uniform in theta) at ``rtol``, each
    engine with each estimate of ESTIMATE_SET, measured in the same run."""
    from bench_albedo import evaluations

    import pumpup

    mu = np.cos(np.linspace(0, np.pi / 2, n_mu + 1)[:-1])
    print(f"{n_mu}-point tables at rtol {rtol:g}: evaluations per mu (and ms), " + " -> ".join(ESTIMATE_SET))
    for spec in COST_SPECS:
        f = pumpup.load(spec)
        row = []
        for engine, (ctx, applies) in ENGINES.items():
            if not applies(f):
                continue
            out = []
            for estimate in ESTIMATE_SET:
                with ctx(), ESTIMATES[estimate]():
                    pumpup.albedo(f, mu[:2], rtol=rtol)
                    t = time.perf_counter()
                    pumpup.albedo(f, mu, rtol=rtol)
                    dt = time.perf_counter() - t
                    out.append((evaluations(f, mu, rtol), dt))
            row.append(f"{engine} " + " -> ".join(f"{e:7.0f}" for e, _ in out) + " ("
                       + " -> ".join(f"{t * 1e3:7.1f}" for _, t in out) + " ms)")
        print(f"  {spec!s:52s} " + "   ".join(row), flush=True)


ESTIMATE_SET = [e for e in ("raw", "min", "quadpack", "default") if "--min" in sys.argv or e != "min"]


def main():
    quick = "--quick" in sys.argv
    import os

    if "--cost" in sys.argv:
        print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
        cost()
        return

    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    cs = cases(quick)
    print(f"{len(cs)} references, rtol {', '.join(f'{r:g}' for r in RTOLS)}; ratio = true error / estimate")
    worst_rows = []
    for engine in ENGINES:
        for estimate in ESTIMATE_SET:
            t = time.perf_counter()
            ratios, top, counts = [], [], {"skip": 0, "dishonest": 0, "unresolved": 0, "resolved": 0}
            for rtol in RTOLS:
                for c in cs:
                    r = measure(c, engine, rtol, estimate)
                    if r is None:
                        continue
                    verdict, q = judge(r, rtol)
                    counts[verdict] += 1
                    if verdict == "dishonest":
                        worst_rows.append((engine, estimate, rtol, c["id"], r))
                    if verdict in ("resolved", "dishonest"):
                        ratios.append(q)
                        top.append((q, rtol, c["id"], r))
            q = np.array(ratios)
            dt = time.perf_counter() - t
            if len(q):
                qs = np.quantile(q, [0.5, 0.9, 0.99, 1.0])
                lq = np.log10(np.maximum(q, 1e-300))
                edges = [-np.inf] + list(range(-6, 1)) + [np.inf]
                hist = " ".join(f"{np.count_nonzero((lq >= lo) & (lq < hi))}" for lo, hi in itertools.pairwise(edges))
                print(f"{engine:5s} {estimate:10s} resolved {counts['resolved']:4d}  unresolved {counts['unresolved']:4d}  "
                      f"skipped {counts['skip']:4d}  dishonest {counts['dishonest']:3d} | ratio median {qs[0]:.2g}, "
                      f"90% {qs[1]:.2g}, 99% {qs[2]:.2g}, max {qs[3]:.2g} | per decade <1e-6, 1e-6.. .. 1e0, >1: {hist}  ({dt:.0f} s)",
                      flush=True)
                for q_, rtol, cid, r in sorted(top, key=lambda x: -x[0])[:4 if "--worst" in sys.argv else 0]:
                    print(f"      ratio {q_:.3g} at rtol {rtol:g}: {cid} (a {r[0]:.15g}, estimate {r[1]:.2g}, "
                          f"true {r[2]:.2g}, reference error {r[3]:.2g})")
    for row in worst_rows:
        print("DISHONEST", row)


if __name__ == "__main__":
    main()
