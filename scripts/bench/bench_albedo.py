"""The albedo engine against scipy.integrate.dblquad, side by side in one run.

Measures, on this machine:
1. a 257-point table of stretched Phong n = 5000 (the paper's silver mirror) to rtol 1e-8;
2. pumpup against dblquad on the same model and accuracy (the time per albedo value, and the
   ratio), for stretched Phong n = 20 and n = 5000;
3. a generic ``from_function`` BRDF (a hand-written Phong n = 20) tabulated on 257 points
   to rtol 1e-6 by the generic adaptive cubature.

First, for every built-in model family (issue 14): the time of a 257-point table (mu uniform in
theta) at rtol 1e-10 on one thread (``pumpup.albedo`` on the 257 values, and ``pumpup.tabulate``
with ``threads=1``), the integrand evaluations per value of mu, the path the engine takes (1-D:
the closed-form azimuth of ``pumpup.engine.polar``; nst: the nested quadrature of ``pumpup.engine.nested``;
2-D: the cubature), and for the 1-D and nested families the previous engine (the 2-D cubature,
``using(engine="2d")``, which switches off both) measured in the same run, with
the ratio; then scipy ``dblquad`` at mu = 0.5 and epsrel 1e-10 per value (stopped after 60 s), and
the sweep cell (257 mu + mean albedo + maximum constant) and the three tables of a 3-level g2
pumped Phong n = 20, new against previous.  Best of 3 (1-D) or 1 (2-D) runs after a warm-up.

    python scripts/bench/bench_albedo.py            # the family table and the cells
    python scripts/bench/bench_albedo.py --all      # also the three measurements above
    python scripts/bench/bench_albedo.py --cells    # only the sweep cells and the pumped tables
    python scripts/bench/bench_albedo.py --eval     # only BRDF.eval's overhead (the input checks) and numpy
    python scripts/bench/bench_albedo.py --phong    # only the Phong family's rows (1-D path), no dblquad
    python scripts/bench/bench_albedo.py --slope    # only anisotropic Ward: the slope path
                                              # against the nested engine
    python scripts/bench/bench_albedo.py --p        # only the p-model with p in (0, 1): 1-D path against the nested engine
    python scripts/bench/bench_albedo.py --half     # only the models on the 1-D path by the half vector's azimuth
                                              # in closed form against the nested engine
    python scripts/bench/bench_albedo.py --arc      # only the models on the 1-D path by a rule on the half vector's
                                              # arc against the nested engine
    python scripts/bench/bench_albedo.py --fresnel  # only the models on the 1-D path by the lobe frame with
                                              # F(Theta_min) against the nested engine
    python scripts/bench/bench_albedo.py --nframe   # only GGX, Beckmann (F = 1) and Schlick, about N in closed form,
                                              # against the rule on h's arc and the nested engine
    python scripts/bench/bench_albedo.py --nframe-f # only GGX with a Fresnel factor, about N,
                                              # against the rule on h's arc and the nested engine
    python scripts/bench/bench_albedo.py --lobe-n   # only lobes with F(Theta_min), n >= 8, about N,
                                              # against frame 5 and the nested engine
    python scripts/bench/bench_albedo.py --fmax     # only the fresnel wrapper over GGX, Beckmann, Schlick (pumped or not), frame
                                              # 6 with F(Theta_min) per node,
                                              # against the nested engine
    python scripts/bench/bench_albedo.py --pumped-f # only pumped GGX with F(wi.h): frame 6 at mu >= 0.248,
                                              # against the nested engine
    python scripts/bench/bench_albedo.py --pumped   # only pumped chains (Phong family; GGX, Beckmann, Schlick in frame 6):
                                              # 1-D path against the nested engine
    python scripts/bench/bench_albedo.py --scaled   # only 1/E-scaled GGX, Beckmann, Schlick (frame 6 times Turquin's factor)
                                              # against the nested engine
    python scripts/bench/bench_albedo.py --lafortune  # only Lafortune lobes with p = 0 about their own axis
                                              # against the nested engine / the 2-D cubature
    python scripts/bench/bench_albedo.py --lobe-f   # only frame 5's lobes with n < 8 (metal, plastic, the fresnel wrapper):
                                              # Gauss-Legendre pieces with an a-priori bound against the adaptive
                                              # 7/15 rule (``using(lobe_fresnel_gauss=False)``)
    python scripts/bench/bench_albedo.py --breaks   # only the nested families with kinks or levels: the compiled break
                                              # finding against its numpy reference (issue 14 item 3)
"""

import contextlib
import signal
import sys
import math
import time

import numpy as np
from scipy.integrate import dblquad

import pumpup
from pumpup.engine.routes import one_d_everywhere, route_names, using


def dblquad_albedo(f, mu, epsrel):
    """Plain dblquad over (theta_o, phi_o) with the BRDF's numpy reference, as a user would."""
    s = np.sqrt(1 - mu * mu)
    wi = np.array([s, 0.0, mu])

    def g(ph, th):
        wo = np.array([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)])
        return float(f.reference(wi, wo)) * np.cos(th) * np.sin(th)

    v, e = dblquad(g, 0, np.pi / 2, 0, 2 * np.pi, epsabs=0, epsrel=epsrel)
    return v, e


FAMILIES = [
    {"type": "phong", "n": 20},
    {"type": "stretched_phong", "n": 20},
    {"type": "stretched_phong", "n": 20, "p": 0.0},
    {"type": "stretched_phong", "n": 5000},
    {"type": "retro", "n": 10},
    {"type": "phong_shader", "n": 20},
    {"type": "lewis_phong", "n": 20},
    {"type": "lafortune", "n": 20, "cx": 1.1, "cy": 1.1, "cz": 1.1, "p": 1.0},
    {"type": "lafortune_sum", "n": [5.0, 50.0], "c": [0.2, 3.0]},
    {"type": "lambert"},
    {"type": "stretched_phong", "n": 20, "p": 0.5},
    {"type": "blinn", "n": 16},
    {"type": "stretched_blinn", "n": 8},
    {"type": "phong_blinn", "n": 20},
    {"type": "ward", "m": 0.1},
    {"type": "modified_ward", "m": 0.1},
    {"type": "ward_aniso", "ax": 0.1, "ay": 0.3},
    {"type": "cook_torrance", "m": 0.3},
    {"type": "torrance_sparrow", "d": "D1", "s": 20},
    {"type": "schlick", "r": 0.2},
    {"type": "beckmann", "alpha": 0.1},
    {"type": "ggx", "alpha": 0.1},
    {"type": "minnaert", "k": 1.0},
    {"type": "oren_nayar"},
    {"type": "lacquer"},
    {"type": "plastic", "n": 20},
]


def _best(fn, repeat):
    out, best = None, np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return out, best


def evaluations(f, mu, rtol, phi=0.0):
    """Integrand evaluations of pumpup.albedo(f, mu, phi=phi): the 1-D path's or the slope path's own count, the nested
    engine's (``pumpup.engine.nested.LAST_EVALS`` of every call), the 2-D engine's points counted at its
    accumulation step (once per sign of beta)."""
    from pumpup.engine import nested as _nested
    from pumpup.engine import polar as _polar
    from pumpup.engine import slope as _slope

    A = pumpup.albedo_module
    count = [0]
    orig = A.accumulate
    orig_nested = _nested.integrate

    def counting(fv, cos_o, weight, total):
        count[0] += fv.shape[0]
        return orig(fv, cos_o, weight, total)

    def counting_nested(*args):
        out = orig_nested(*args)
        count[0] += int(_nested.LAST_EVALS.sum())
        return out

    A.accumulate = counting
    _nested.integrate = counting_nested
    try:
        for _, term in f.albedo_terms():
            if set(route_names(term, mu).ravel()) == {"slope"}:
                count[0] += int(_slope.slope_albedo(term, mu, np.full(mu.shape, phi), rtol, 1e-14, 20000)[3].sum())
                continue
            fast = _polar.albedo_1d(term, mu, rtol, 1e-14, 20000) if phi == 0.0 else None
            if fast is not None:
                count[0] += int(fast[3].sum())
            else:
                pumpup.albedo(term, mu, phi=phi, rtol=rtol)
    finally:
        A.accumulate = orig
        _nested.integrate = orig_nested
    return count[0] / len(mu)


def path_of(f):
    """'1-D' (closed-form azimuth), 'slp' (anisotropic Ward in slope space), 'axs' (a power lobe about its own axis,
    Lafortune p = 0), 'nst' (nested quadrature) or '2-D' (cubature) for f at phi = 0."""
    from pumpup.engine import nested as _nested

    if all(route_names(t, [0.5])[0, 0] == "slope" for _, t in f.albedo_terms()):
        return "slp"
    if all(one_d_everywhere(t, np.array([0.5, 1e-3])) for _, t in f.albedo_terms()):
        return "1-D"
    if all(t.azimuth_hint() is not None or t.lobe_axis(np.array([0.5, 1e-3]), np.zeros(2)) is not None for _, t in f.albedo_terms()):
        return "axs"
    A = pumpup.albedo_module
    ok = all(_nested.supports(g) for _, t in f.albedo_terms() for _, g in A._groups(t, np.array([0.5, 1e-3])))
    return "nst" if ok else "2-D"


class _Timeout(Exception):
    pass


def _alarm(signum, frame):
    raise _Timeout


def dblquad_seconds(f, mu, epsrel, limit=60):
    """Seconds of one dblquad albedo (None after ``limit`` seconds)."""
    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(limit)
    t = time.perf_counter()
    try:
        dblquad_albedo(f, mu, epsrel)
    except _Timeout:
        return None
    finally:
        signal.alarm(0)
    return time.perf_counter() - t


#: the Phong family of the issue's 2 ms target (the 1-D path)
PHONG_FAMILY = [{"type": "phong", "n": 20}, {"type": "stretched_phong", "n": 20},
                {"type": "stretched_phong", "n": 20, "p": 0.0}, {"type": "retro", "n": 10}]


def families(rtol=1e-10, specs=None, dblquad=True):

    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    print(f"257-point tables at rtol {rtol:g}, one thread (ms); evaluations per mu; previous = the 2-D engine "
          f"(paths: 1-D closed-form azimuth, slp slope space, nst nested quadrature, 2-D cubature)")
    print(f"{'model':58s} {'path':4s} {'albedo':>9s} {'tabulate':>9s} {'evals/mu':>9s} "
          f"{'previous':>9s} {'evals/mu':>9s} {'ratio':>7s} {'dblquad/value':>14s} {'x per value':>11s}")
    for spec in FAMILIES if specs is None else specs:
        f = pumpup.load(spec)
        path = path_of(f)
        one_d = path in ("1-D", "slp")
        repeat = (3 if one_d else 1) if dblquad else 20
        pumpup.albedo(f, [0.5, 1e-3])  # compile / load the kernels
        _, t_new = _best(lambda: pumpup.albedo(f, mu, rtol=rtol), repeat)
        _, t_tab = _best(lambda: pumpup.tabulate(f, mu=mu, rtol=rtol, threads=1, progress=False), repeat)
        ev = evaluations(f, mu, rtol)
        if path != "2-D":
            with using(engine="2d"):
                pumpup.albedo(f, [0.5, 1e-3])
                _, t_old = _best(lambda: pumpup.albedo(f, mu, rtol=rtol), 1)
                ev_old = evaluations(f, mu, rtol)
            old = f"{t_old * 1e3:9.1f} {ev_old:9.0f} {t_old / t_new:7.1f}"
        else:
            old = f"{'(same)':>9s} {'':9s} {1.0:7.0f}"
        td = dblquad_seconds(f, 0.5, rtol) if spec["type"] not in ("lafortune_sum",) and dblquad else None
        per_value = t_new / len(mu)
        dq = f"{td:14.3f} {td / per_value:11.0f}" if td is not None else f"{'> 60 s':>14s} {'':11s}"
        shown = {k: v for k, v in spec.items()}
        print(f"{str(shown)[:58]:58s} {path:4s} {t_new * 1e3:9.1f} {t_tab * 1e3:9.1f} "
              f"{ev:9.0f} {old} {dq}", flush=True)


def against_nested(specs, label, rtol=1e-10, repeat=3):
    """Models on the 1-D path against the nested engine they take without it (the 1-D path switched off alone,
    ``using(engine="nested")``; ``engine="2d"`` would switch off the nested engine too), same run, same rtol: a
    257-point table (mu uniform in theta) and a sweep cell (257 mu of ``default_mu`` + mean albedo + maximum
    constant), one thread, best of ``repeat``."""
    from pumpup.sweeps import default_mu

    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    cell_mu = default_mu(257)

    def cell(f):
        pumpup.tabulate(f, mu=cell_mu, threads=1, progress=False)
        pumpup.mean_albedo(f)
        pumpup.max_albedo(f)

    print(f"{label}, one thread, ms (best of {repeat}); table: 257 mu at rtol {rtol:g}; cell: sweep cell")
    print(f"{'model':48s} {'table 1-D':>10s} {'nested':>9s} {'ratio':>6s} {'cell 1-D':>9s} {'nested':>9s} {'ratio':>6s}")
    for spec in specs:
        out = []
        for one_d in (True, False):
            with contextlib.nullcontext() if one_d else using(engine="nested"):
                f = pumpup.load(spec)
                pumpup.albedo(f, [0.5, 1e-3], rtol=rtol)
                _, t_table = _best(lambda: pumpup.albedo(f, mu, rtol=rtol), repeat if one_d else 1)
                _, t_cell = _best(lambda: cell(pumpup.load(spec)), repeat if one_d else 1)
            out.append((t_table, t_cell))
        (a, b), (c, d) = out
        print(f"{str(spec):48s} {a * 1e3:10.1f} {c * 1e3:9.1f} {c / a:6.1f} {b * 1e3:9.1f} {d * 1e3:9.1f} {d / b:6.1f}",
              flush=True)


def _against_second_path(specs, title, first, second, width, rtol, repeat, lobe=lambda spec, f: f):
    """A 257-point table (mu uniform in theta) at ``rtol`` by the 1-D path as it is (``first``), by its second path
    (``using(without={"normal", "lobe_normal"})``: frame 4 or frame 5, ``second``) and by the nested engine, one thread, best of ``repeat``
    (nested: 1), with the evaluations per mu of the first (of ``lobe(spec, f)``, the term that takes it)."""
    from pumpup.engine import polar as _polar

    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    print(f"{title}, one thread, ms; 257 mu at rtol {rtol:g}")
    print(f"{'model':{width}s} {first:>8s} {'evals/mu':>8s} {second:>8s} {'ratio':>6s} {'nested':>8s} {'ratio':>6s}")
    for spec in specs:
        f = pumpup.load(spec)
        times = []
        for ctx, rep in ((contextlib.nullcontext(), repeat), (using(without={"normal", "lobe_normal"}), repeat), (using(engine="nested"), 1)):
            with ctx:
                pumpup.albedo(f, [0.5, 1e-3], rtol=rtol)
                times.append(_best(lambda: pumpup.albedo(f, mu, rtol=rtol), rep)[1])
        ev = np.mean(_polar.albedo_1d(lobe(spec, f), mu, rtol, 0.0, 200)[3])
        t1, t2, tn = times
        print(f"{str(spec):{width}s} {t1 * 1e3:8.1f} {ev:8.0f} {t2 * 1e3:8.1f} {t2 / t1:6.1f} {tn * 1e3:8.1f} {tn / t1:6.1f}",
              flush=True)


def n_frame(rtol=1e-10, repeat=3):
    """GGX and Beckmann with F = 1 and Schlick's model, about N with the weight's azimuth in closed form (frame 6)
    against frame 4, the rule on h's arc (their route without frame 6), and the nested engine
    (:func:`_against_second_path`)."""
    specs = [{"type": "ggx", "alpha": a} for a in (0.001, 0.1, 0.5)] + [
        {"type": "ggx", "alpha": 0.3, "shadowing": "correlated"}, {"type": "schlick", "r": 0.2}, {"type": "schlick", "r": 0.001}] + [
        {"type": "beckmann", "alpha": a} for a in (0.001, 0.1, 0.5)] + [{"type": "beckmann", "alpha": 0.3, "g1": "walter"}]
    _against_second_path(specs, "frame 6 against frame 4 and the nested engine", "frame 6", "frame 4", 48, rtol, repeat)


def n_frame_fresnel(rtol=1e-10, repeat=3):
    """GGX with a Fresnel factor about N (frame 6 with the ring's product rule, pumpup.engine.normal_frame._ggx_ring_f;
    frame 4 below mu = N_FRESNEL_MU_MIN) against frame 4, the rule on h's arc (their route without frame 6), and the
    nested engine (:func:`_against_second_path`)."""
    specs = [{"type": "ggx", "alpha": 0.3, "eta": 0.2, "k": 3.0}, {"type": "ggx", "alpha": 0.02, "ior": 1.5},
             {"type": "ggx", "alpha": 0.5, "shadowing": "correlated", "eta": 1.1, "k": 6.0},
             {"type": "ggx", "alpha": 0.001, "eta": 1.1, "k": 30.0}, {"type": "ggx", "alpha": 1.0, "ior": 1.33}]
    _against_second_path(specs, "GGX with F: frame 6 (mu >= 0.248, frame 4 below) against frame 4 and the nested engine",
                         "frame 6", "frame 4", 72, rtol, repeat)


def lobe_n_frame(rtol=1e-10, repeat=3):
    """Lobes with 000 eq. 28's F(Theta_min) (metal, plastic with an index, the fresnel wrapper; n >= 8) about N with the ring
    table and g = 1 against frame 5, the lobe frame with a rule on the arc (their route without the ring table),
    and the nested engine (:func:`_against_second_path`)."""
    specs = [{"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}, {"type": "metal", "n": 8, "eta": 1.5},
             {"type": "metal", "n": 500, "eta": 1.1, "k": 6.0}, {"type": "metal", "n": 10, "eta": 0.6, "k": 0.3},
             {"type": "metal", "n": 20, "eta": 0.5, "k": 0.002}, {"type": "plastic", "n": 20, "eta": 1.5, "ad": 0.3},
             {"type": "fresnel", "base": {"type": "phong", "n": 20}, "eta": 0.2, "k": 3.0},
             {"type": "fresnel", "base": {"type": "retro", "n": 10}, "eta": 1.1, "k": 30.0}]
    _against_second_path(specs, "a lobe with F(Theta_min) about N against frame 5 and the nested engine", "about N", "frame 5",
                         60, rtol, repeat,
                         lobe=lambda spec, f: pumpup.load(dict(spec, ad=0.0)) if spec["type"] == "plastic" else f)


def p_model(rtol=1e-10, repeat=3):
    """The p-model with p in (0, 1) (000 eq. 12; the 1-D path's inner rule since issue 14) against the
    nested engine it replaces (:func:`against_nested`)."""
    against_nested([{"type": "stretched_phong", "n": 20, "p": p} for p in (1.0, 0.25, 0.5, 0.75)] + [
        {"type": "stretched_phong", "n": 1, "p": 0.5}, {"type": "stretched_phong", "n": 1000, "p": 0.5},
        {"type": "retro", "n": 10, "p": 0.5}], "p-model", rtol, repeat)


def half_and_closed(rtol=1e-10, repeat=3):
    """The models on the 1-D path by the half vector's azimuth about N in closed form (
    the Blinn family, 000 eq. 31, 32 and 002 eq. 24; Ward and modified Ward, 000 eq. 34, 35; Cook-Torrance and
    Torrance-Sparrow with F = 1, 001 eq. 9-10 and 002 eq. 10; plastic without Fresnel, 000 eq. 30; and the closed
    forms of Oren-Nayar, Minnaert and the lacquer) against the nested engine (:func:`against_nested`)."""
    against_nested([{"type": "blinn", "n": 16}, {"type": "blinn", "n": 512, "c": 20.6}, {"type": "stretched_blinn", "n": 8},
                    {"type": "phong_blinn", "n": 20}, {"type": "ward", "m": 0.1}, {"type": "ward", "m": 0.4},
                    {"type": "modified_ward", "m": 0.1}, {"type": "cook_torrance", "m": 0.3},
                    {"type": "cook_torrance", "m": 0.05}, {"type": "torrance_sparrow", "d": "D1", "s": 20},
                    {"type": "plastic", "n": 20}, {"type": "oren_nayar"}, {"type": "minnaert", "k": 1.0},
                    {"type": "lacquer"}], "1-D (half vector, closed forms)", rtol, repeat)


def on_the_arc(rtol=1e-10, repeat=3):
    """The models on the 1-D path by the half vector's azimuth by a rule on its arc
    (pumpup.engine.half_arc._k_numeric: GGX and Beckmann with Smith G, with and without a Fresnel factor; Cook-Torrance and
    Torrance-Sparrow with one; Schlick, 000 eq. 36) and Torrance-Sparrow D3 in closed form under the GGX weight,
    against the nested engine (:func:`against_nested`)."""
    against_nested([{"type": "ggx", "alpha": 0.1}, {"type": "ggx", "alpha": 0.5, "shadowing": "correlated"},
                    {"type": "ggx", "alpha": 0.02, "ior": 1.5}, {"type": "ggx", "alpha": 0.001},
                    {"type": "beckmann", "alpha": 0.1}, {"type": "beckmann", "alpha": 0.3, "g1": "walter"},
                    {"type": "beckmann", "alpha": 1.0, "eta": 0.2, "k": 3.0, "shadowing": "correlated", "g1": "walter"},
                    {"type": "cook_torrance", "m": 0.3, "ior": 1.5}, {"type": "torrance_sparrow", "d": "D4", "s": 0.4, "ior": 1.33},
                    {"type": "torrance_sparrow", "d": "D3", "s": 0.3}, {"type": "schlick", "r": 0.2},
                    {"type": "schlick", "r": 0.001}], "1-D (a rule on the half vector's arc)", rtol, repeat)


def lobe_fresnel(rtol=1e-10, repeat=3):
    """The models on the 1-D path by the lobe frame with 000 eq. 28's F(Theta_min) by a rule
    on the arc where N.V >= N.L (pumpup.engine.lobe_fresnel._k_lobe_fresnel: metal, plastic with an index, the fresnel wrapper of a
    Phong-family lobe) and the pumped lobe's frame of N with it (a pumped metal, the fresnel wrapper of a pumped lobe),
    against the nested engine (:func:`against_nested`)."""
    against_nested([{"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}, {"type": "metal", "n": 1, "eta": 1.5},
                    {"type": "metal", "n": 500, "eta": 1.1, "k": 6.0}, {"type": "metal", "n": 7.5, "eta": 0.6, "k": 0.3},
                    {"type": "metal", "n": 20, "eta": 0.5, "k": 0.002}, {"type": "plastic", "n": 20, "eta": 1.5, "ad": 0.3},
                    {"type": "fresnel", "base": {"type": "phong", "n": 20}, "eta": 0.2, "k": 3.0},
                    {"type": "fresnel", "base": {"type": "phong", "n": 1}, "eta": 1.1, "k": 30.0},
                    {"type": "pumped", "base": {"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}},
                    {"type": "fresnel", "base": {"type": "pumped", "base": {"type": "stretched_phong", "n": 20}},
                     "eta": 0.2, "k": 3.0}],
                   "1-D (the lobe frame with F(Theta_min))", rtol, repeat)


def scaled(rtol=1e-10, repeat=3):
    """1/E-scaled GGX, Beckmann and Schlick models (Turquin eq. 6, ``pumpup.compensate(..., method="scale")``; frame 6
    times the factor) against the nested engine (:func:`against_nested`)."""
    against_nested([{"type": "scaled", "base": b, "f0": f0} for b, f0 in [
        ({"type": "ggx", "alpha": 0.3}, 1.0), ({"type": "ggx", "alpha": 0.05}, 1.0), ({"type": "ggx", "alpha": 1.0}, 0.5),
        ({"type": "beckmann", "alpha": 0.1}, 1.0), ({"type": "schlick", "r": 0.2}, 1.0)]],
        "1/E-scaled, frame 6", rtol, repeat)


def fresnel_max(rtol=1e-10, repeat=3):
    """The fresnel wrapper (000 eq. 28's F(max(N.L, N.V))) over GGX, Beckmann and Schlick's model, pumped or not: frame 6
    with F a factor of each node (``Polar.fmax``), against the nested engine (:func:`against_nested`)."""
    ggx = {"type": "fresnel", "base": {"type": "ggx", "alpha": 0.1}, "eta": 0.2, "k": 3.0}
    against_nested([{"type": "fresnel", "base": {"type": "ggx", "alpha": 0.3}, "eta": 0.2, "k": 3.0}, ggx,
                    {"type": "fresnel", "base": {"type": "ggx", "alpha": 0.02, "shadowing": "correlated"}, "eta": 1.5},
                    {"type": "fresnel", "base": {"type": "beckmann", "alpha": 0.1}, "eta": 1.1, "k": 6.0},
                    {"type": "fresnel", "base": {"type": "schlick", "r": 0.2}, "eta": 0.2, "k": 3.0},
                    {"type": "pumped", "base": ggx, "g": "g2", "levels": 2},
                    {"type": "fresnel", "base": {"type": "pumped", "base": {"type": "ggx", "alpha": 0.1}}, "eta": 0.2,
                     "k": 3.0}],
                   "F(Theta_min) over frame 6's models, 1-D", rtol, repeat)


def pumped_fresnel(rtol=1e-10, repeat=3):
    """Pumped GGX with a Fresnel factor F(wi.h): frame 6 divided by g at mu >= N_FRESNEL_MU_MIN,
    the nested engine below (``pumpup.engine.routes``), against the nested engine at every mu
    (:func:`against_nested`)."""
    against_nested([{"type": "pumped", "base": {"type": "ggx", "alpha": 0.1, "eta": 0.2, "k": 3.0}, "g": "g2"},
                    {"type": "pumped", "base": {"type": "ggx", "alpha": 0.3, "ior": 1.5}, "g": "g1", "levels": 2},
                    {"type": "pumped", "base": {"type": "ggx", "alpha": 0.02, "eta": 1.1, "k": 6.0}, "g": "g2"}],
                   "pumped GGX with F(wi.h), frame 6 at mu >= 0.248", rtol, repeat)


def pumped_chains(rtol=1e-10, repeat=3):
    """Pumped Phong-family BRDFs (001 eq. 16; the 1-D path) and pumped GGX, Beckmann
    and Schlick models (frame 6 divided by g) against the nested engine (``Pumped.polar``
    switched off: the base keeps its 1-D path), same run: a 257-point table at rtol ``rtol`` (mu uniform in theta,
    the chain's tables built first), one thread, best of ``repeat``; then the three tables of a 3-level g2 pumped
    Phong n = 20 and GGX alpha = 0.3 as ``pumpup.pump`` builds them (``tabulate``'s threads, rtol 1e-9, adaptive
    grids)."""
    from pumpup.operators.pumping import _TABLES, Pumped

    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    polar = Pumped.polar
    print(f"pumped chains, one thread, ms (best of {repeat}); table: 257 mu at rtol {rtol:g}; first: the first such table, "
          f"whose kinks of g (Pumped.kink_levels, cached per mu) are searched in it")
    print(f"{'chain':52s} {'first':>8s} {'1-D':>8s} {'nested':>9s} {'ratio':>6s}")
    for spec, g, levels in [({"type": "phong", "n": 20}, "g2", 1), ({"type": "phong", "n": 20}, "g2", 2),
                            ({"type": "phong", "n": 20}, "g2", 3), ({"type": "stretched_phong", "n": 20}, "g1", 2),
                            ({"type": "phong", "n": 200}, "g2", 2),
                            # frame 6 divided by g
                            ({"type": "ggx", "alpha": 0.3}, "g2", 1), ({"type": "ggx", "alpha": 0.1, "shadowing": "correlated"}, "g2", 2),
                            ({"type": "beckmann", "alpha": 0.3}, "g1", 2), ({"type": "schlick", "r": 0.2}, "g1", 1)]:
        f = pumpup.pump(spec, g=g, levels=levels)
        for lev in f.chain():
            lev.lookup()
        out = []
        first = math.nan
        for on in (True, False):
            if not on:
                Pumped.polar = lambda self: None
            try:
                pumpup.albedo(f, [0.5, 1e-3], rtol=rtol)
                if on:
                    t0 = time.perf_counter()
                    pumpup.albedo(f, mu, rtol=rtol)
                    first = time.perf_counter() - t0
                out.append(_best(lambda: pumpup.albedo(f, mu, rtol=rtol), repeat if on else 1)[1])
            finally:
                Pumped.polar = polar
        name = ", ".join(f"{k} {v}" for k, v in spec.items() if k != "type")
        name = f"{spec['type']} {name}, {g} x {levels}"
        print(f"{name:52s} {first * 1e3:8.1f} {out[0] * 1e3:8.1f} {out[1] * 1e3:9.1f} {out[1] / out[0]:6.1f}", flush=True)

    def build(spec):
        _TABLES.clear()
        t = time.perf_counter()
        for lev in pumpup.pump(spec, g="g2", levels=3).chain():
            lev.lookup()
        return time.perf_counter() - t

    for spec, warm in (({"type": "phong", "n": 20}, {"type": "phong", "n": 21}),
                       ({"type": "ggx", "alpha": 0.3}, {"type": "ggx", "alpha": 0.31})):
        build(warm)
        new = min(build(spec) for _ in range(repeat))
        Pumped.polar = lambda self: None
        try:
            old = build(spec)
        finally:
            Pumped.polar = polar
        print(f"3-level g2 pumped {spec}, its three tables (tabulate's threads): 1-D {new * 1e3:.0f} ms, "
              f"nested {old * 1e3:.0f} ms, ratio {old / new:.1f}", flush=True)


#: the nested engine's families (FAMILIES) whose hints have levels or kinks, a pumped one, and three
#: without (their break finding is empty) for comparison
BREAK_FAMILIES = [
    {"type": "stretched_blinn", "n": 8}, {"type": "modified_ward", "m": 0.1}, {"type": "ward_aniso", "ax": 0.1, "ay": 0.3},
    {"type": "cook_torrance", "m": 0.3}, {"type": "torrance_sparrow", "d": "D1", "s": 20}, {"type": "oren_nayar"},
    {"type": "plastic", "n": 20}, {"type": "pumped", "base": {"type": "blinn", "n": 16}, "g": "g2", "levels": 2},
    {"type": "ggx", "alpha": 0.1}, {"type": "blinn", "n": 16}, {"type": "ward", "m": 0.1},
]


def breaks(rtol=1e-10, repeat=7):
    """A 257-point table (mu uniform in theta) at rtol ``rtol``, one thread, with the compiled break finding
    (``albedo.kink_breaks``) and with its plain numpy reference (``albedo.kink_breaks_reference``, the
    previous code) in the same run, round robin, best of ``repeat``; beside each, the time of the break
    finding alone (its calls during the table).  The two give the same breaks bit for bit, so the same
    tables: the script checks the values and errors are identical."""
    from pumpup.engine import nested as _nested

    A = pumpup.albedo_module
    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    impl = {"compiled": A.kink_breaks, "reference": A.kink_breaks_reference}

    def use(fn):
        A.kink_breaks = fn
        _nested.kink_breaks = fn

    print(f"257-point tables at rtol {rtol:g}, one thread, ms (best of {repeat}, round robin); breaks: the "
          f"break finding's share")
    print(f"{'model':72s} {'reference':>9s} {'compiled':>9s} {'ratio':>6s} {'breaks ref':>10s} {'compiled':>9s} "
          f"{'ratio':>6s}")
    try:
        for spec in BREAK_FAMILIES:
            f = pumpup.load(spec)
            pumpup.albedo(f, mu[:3], rtol=rtol)  # the pumped model's tables, the compiled kernels
            best = {k: np.inf for k in impl}
            best_breaks = {k: np.inf for k in impl}
            out = {}
            for _ in range(repeat):
                for name, fn in impl.items():
                    spent = [0.0]

                    def timed(*args, fn=fn, spent=spent, **kw):
                        t = time.perf_counter()
                        r = fn(*args, **kw)
                        spent[0] += time.perf_counter() - t
                        return r

                    use(timed)
                    t = time.perf_counter()
                    out[name] = pumpup.albedo(f, mu, rtol=rtol, return_error=True)
                    t = time.perf_counter() - t
                    use(impl["compiled"])
                    best[name] = min(best[name], t)
                    best_breaks[name] = min(best_breaks[name], spent[0])
            same = all(np.array_equal(a, b) for a, b in zip(out["compiled"], out["reference"]))
            r, c = best["reference"], best["compiled"]
            br, bc = best_breaks["reference"], best_breaks["compiled"]
            ratio = f"{br / bc:6.1f}" if bc > 1e-4 else f"{'':6s}"
            print(f"{str(spec)[:72]:72s} {r * 1e3:9.1f} {c * 1e3:9.1f} {r / c:6.2f} {br * 1e3:10.1f} {bc * 1e3:9.1f} "
                  f"{ratio} {'same values' if same else 'VALUES DIFFER'}", flush=True)
    finally:
        use(impl["compiled"])


def cells():
    from pumpup.tables import reuse as _reuse
    from pumpup.operators.pumping import _TABLES
    from pumpup.sweeps import default_mu

    mu = default_mu(257)

    def cell(spec):
        f = pumpup.load(spec)
        t = time.perf_counter()
        pumpup.tabulate(f, mu=mu, threads=1, progress=False)
        pumpup.mean_albedo(f)
        pumpup.max_albedo(f)
        return time.perf_counter() - t

    def pumped(n):
        _TABLES.clear()
        t = time.perf_counter()
        g = pumpup.pump({"type": "phong", "n": n}, g="g2", levels=3)
        for lev in g.chain():
            lev.lookup()
        return time.perf_counter() - t

    for spec in [{"type": "stretched_phong", "n": 20}, {"type": "stretched_phong", "n": 20, "p": 0.5},
                 {"type": "blinn", "n": 16}]:
        cell(spec)
        new = min(cell(spec) for _ in range(3))
        recall = _reuse.recall
        _reuse.recall = lambda brdf: None  # the previous engine: no reuse of the table either
        try:
            with using(engine="2d"):
                old = cell(spec)
        finally:
            _reuse.recall = recall
        print(f"sweep cell (257 mu + mean albedo + maximum constant, one thread) {spec}: {new * 1e3:.1f} ms, "
              f"previous engine {old * 1e3:.1f} ms, ratio {old / new:.1f}", flush=True)
    pumped(21)  # the first build in the process loads the compiled kernels
    new = min(pumped(20) for _ in range(2))
    with using(engine="2d"):
        old = pumped(20)
    print(f"3-level g2 pumped Phong n = 20, its three tables (tabulate's threads): {new * 1e3:.0f} ms, "
          f"previous engine {old * 1e3:.0f} ms, ratio {old / new:.2f}")


def eval_overhead(n=1_000_000, repeat=15):
    """BRDF.eval of Phong (with the input checks) against its kernel (_eval) and against a plain fused
    numpy expression of the same formula, on 1e6 pairs (issue 14 item 6: numpy / eval >= 2 and
    eval / _eval <= 1.2); beside them the previous eval, measured in the same run: two
    ``as_directions`` passes, then the broadcasting ufunc ``kernel`` (the previous _eval).

    Everything runs on one thread (numba's parallel is not used; numpy is single-threaded here).
    The candidates are timed round-robin, ``repeat`` rounds, so a burst of load on the machine hits
    all of them; the ratios are of the best wall times, then of the medians and of the best CPU
    times of this thread in parentheses (a loaded machine preempts the wall times)."""
    from pumpup.core import as_directions, check_pair, split

    rng = np.random.default_rng(1)

    def directions():
        v = rng.normal(size=(n, 3))
        v /= np.linalg.norm(v, axis=-1, keepdims=True)
        v[:, 2] = np.abs(v[:, 2])
        return v

    wi, wo = directions(), directions()
    for spec in [{"type": "phong", "n": 20}, {"type": "phong", "n": 10.5}, {"type": "phong", "n": 5000}]:
        f = pumpup.load(spec)
        c, e = f.p["c"], f.p["n"]

        def numpy_fused():
            rv = 2 * wi[:, 2] * wo[:, 2] - (wi[:, 0] * wo[:, 0] + wi[:, 1] * wo[:, 1] + wi[:, 2] * wo[:, 2])
            return np.where((wi[:, 2] > 0) & (wo[:, 2] > 0) & (rv > 0), c * np.maximum(rv, 0) ** e, 0.0)

        def ufunc():  # the previous _eval: the broadcasting kernel
            return f.kernel(*split(wi), *split(wo), *f.kernel_args())

        def previous_eval():  # the checks as separate passes, then the ufunc
            a, b = as_directions(wi, "wi"), as_directions(wo, "wo")
            check_pair(a, b)
            return f.kernel(*split(a), *split(b), *f.kernel_args())

        cands = {"eval": lambda: f.eval(wi, wo), "_eval": lambda: f._eval(wi, wo), "numpy": numpy_fused,
                 "previous eval": previous_eval, "previous _eval": ufunc}
        for fn in cands.values():
            fn()  # compile / load the cached kernels, touch the memory
        assert np.array_equal(f.eval(wi, wo), ufunc()) and np.array_equal(f._eval(wi, wo), ufunc())
        wall = {k: [] for k in cands}
        cpu = {k: [] for k in cands}  # this thread's CPU time: what a busy machine's other jobs do not add
        for _ in range(repeat):
            for k, fn in cands.items():
                t, u = time.perf_counter(), time.thread_time()
                fn()
                wall[k].append(time.perf_counter() - t)
                cpu[k].append(time.thread_time() - u)
        best = {k: min(v) for k, v in wall.items()}
        med = {k: float(np.median(v)) for k, v in wall.items()}
        bcpu = {k: min(v) for k, v in cpu.items()}

        def ratio(a, b):
            return f"{best[a] / best[b]:.2f} ({med[a] / med[b]:.2f}; cpu {bcpu[a] / bcpu[b]:.2f})"

        print(f"{spec} on {n:.0e} pairs, one thread, ms best (median; best cpu) of {repeat}: "
              + ", ".join(f"{k} {best[k] * 1e3:.1f} ({med[k] * 1e3:.1f}; {bcpu[k] * 1e3:.1f})" for k in cands))
        print(f"    now:      numpy / eval = {ratio('numpy', 'eval')}   eval / _eval = {ratio('eval', '_eval')}")
        print(f"    previous: numpy / eval = {ratio('numpy', 'previous eval')}   "
              f"eval / _eval = {ratio('previous eval', 'previous _eval')}", flush=True)


def slope(rtol=1e-10, repeat=3):
    """Anisotropic Ward in slope space (pumpup.engine.slope) against the nested engine
    (``using(engine="nested")`` leaves both out), same run: a 257-point table (mu uniform in theta) at phi = 0 and at
    phi = 0.7, one thread, best of ``repeat`` (nested: 1), with the slope path's evaluations per mu."""

    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    specs = [{"type": "ward_aniso", "ax": 0.1, "ay": 0.3}, {"type": "ward_aniso", "ax": 0.05, "ay": 0.5},
             {"type": "ward_aniso", "ax": 0.4, "ay": 0.02}, {"type": "ward_aniso", "ax": 0.01, "ay": 0.01},
             {"type": "ward_aniso", "ax": 0.001, "ay": 1.0}]
    print(f"anisotropic Ward: the slope path against the nested engine, one thread, ms; 257 mu at rtol {rtol:g}")
    print(f"{'model':48s} {'phi':>4s} {'slope':>8s} {'evals/mu':>8s} {'nested':>8s} {'evals/mu':>8s} {'ratio':>6s}")
    for spec in specs:
        f = pumpup.load(spec)
        for phi in (0.0, 0.7):
            pumpup.albedo(f, [0.5, 1e-3], phi=phi, rtol=rtol)
            _, t1 = _best(lambda: pumpup.albedo(f, mu, phi=phi, rtol=rtol), repeat)
            ev1 = evaluations(f, mu, rtol, phi)
            with using(engine="nested"):
                pumpup.albedo(f, [0.5, 1e-3], phi=phi, rtol=rtol)
                _, t2 = _best(lambda: pumpup.albedo(f, mu, phi=phi, rtol=rtol), 1)
                ev2 = evaluations(f, mu, rtol, phi)
            print(f"{str(spec):48s} {phi:4.1f} {t1 * 1e3:8.1f} {ev1:8.0f} {t2 * 1e3:8.1f} {ev2:8.0f} {t2 / t1:6.1f}",
                  flush=True)


def lobe_f_gauss(rtol=1e-10, repeat=3):
    """Frame 5's lobes with F(Theta_min) and n < LOBE_N_MIN (metal, plastic, the fresnel wrapper) with the arcs by
    Gauss-Legendre pieces and their a-priori bound (``pumpup.engine.lobe_fresnel._lobe_f_gauss``)
    against the adaptive 7/15 rule (``using(lobe_fresnel_gauss=False)``), same run: a 257-point table (mu
    uniform in theta) at ``rtol`` and a sweep cell (257 mu + mean albedo + maximum constant), one thread, best of
    ``repeat`` each, alternating."""
    from pumpup.engine import chain_frame as _chain_frame
    from pumpup.sweeps import default_mu

    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    cell_mu = default_mu(257)

    def cell(spec):
        f = pumpup.load(spec)
        pumpup.tabulate(f, mu=cell_mu, threads=1, progress=False)
        pumpup.mean_albedo(f)
        pumpup.max_albedo(f)

    specs = [{"type": "metal", "n": 1, "eta": 1.5}, {"type": "metal", "n": 7.5, "eta": 0.6, "k": 0.3},
             {"type": "metal", "n": 5, "eta": 0.2, "k": 3.0}, {"type": "metal", "n": 2, "eta": 1.1, "k": 6.0},
             {"type": "metal", "n": 0, "eta": 0.999, "k": 0.001}, {"type": "plastic", "n": 3, "eta": 1.5, "ad": 0.3},
             {"type": "fresnel", "base": {"type": "phong", "n": 1}, "eta": 1.1, "k": 30.0},
             {"type": "fresnel", "base": {"type": "retro", "n": 4}, "eta": 0.2, "k": 3.0}]
    print(f"frame 5, n < {_chain_frame.LOBE_N_MIN:g}: Gauss-Legendre pieces against the adaptive 7/15 rule, one thread, ms (best of "
          f"{repeat}); table: 257 mu at rtol {rtol:g}; cell: sweep cell")
    print(f"{'model':62s} {'table':>7s} {'before':>7s} {'ratio':>6s} {'cell':>7s} {'before':>7s} {'ratio':>6s}")
    for spec in specs:
        f = pumpup.load(spec)
        best = {True: [np.inf, np.inf], False: [np.inf, np.inf]}
        for _ in range(repeat):
            for gauss in (True, False):
                with contextlib.nullcontext() if gauss else using(lobe_fresnel_gauss=False):
                    pumpup.albedo(f, [0.5, 1e-3], rtol=rtol)
                    _, t_table = _best(lambda: pumpup.albedo(f, mu, rtol=rtol), 1)
                    _, t_cell = _best(lambda: cell(spec), 1)
                best[gauss] = [min(best[gauss][0], t_table), min(best[gauss][1], t_cell)]
        (a, b), (c, d) = best[True], best[False]
        print(f"{str(spec):62s} {a * 1e3:7.1f} {c * 1e3:7.1f} {c / a:6.2f} {b * 1e3:7.1f} {d * 1e3:7.1f} {d / b:6.2f}",
              flush=True)


def lafortune_axis(rtol=1e-10, repeat=3):
    """Lafortune lobes with p = 0 about their own axis v^ (``BRDF.lobe_axis``, ``pumpup.engine.polar.axis_albedo``)
    against the engine they take without it (``lobe_axis`` switched off: the nested engine at phi = 0, the
    2-D cubature at phi != 0), same run: a 257-point table (mu uniform in theta) at rtol 1e-10 by the axis path, one
    thread, best of ``repeat``; the engine before on every 16th of those mu (17 values, once; the 2-D cubature takes
    seconds per value), compared per value of mu."""
    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    few = mu[::16]
    specs = [{"type": "lafortune", "n": 10, "cx": 0.8, "cy": 1.2, "cz": 1.1},
             {"type": "lafortune", "n": 5, "cx": 0.6, "cy": 0.6, "cz": 1.0},
             {"type": "lafortune", "n": 30, "cx": -0.5, "cy": 0.5, "cz": 0.7, "c": 2.0},
             {"type": "lafortune_sum", "n": [3.0, 20.0], "cx": [0.7, -1.0], "cy": [1.3, -1.0], "c": [0.5, 1.0]}]
    print(f"Lafortune p = 0 about its own axis against the engine before, one thread; 257 mu at rtol {rtol:g} (before: "
          f"17 of them, per value)")
    print(f"{'model':60s} {'phi':>4s} {'table ms':>9s} {'us/mu':>8s} {'before us/mu':>13s} {'ratio':>7s}")
    for spec in specs:
        f = pumpup.load(spec)
        for phi in (0.0, 0.7):
            pumpup.albedo(f, [0.5, 1e-3], phi=phi, rtol=rtol)
            _, t1 = _best(lambda: pumpup.albedo(f, mu, phi=phi, rtol=rtol), repeat)
            lobes = f.lobes() if hasattr(f, "lobes") else [f]
            cls = type(lobes[0])
            saved = cls.lobe_axis
            cls.lobe_axis = lambda self, m, p: None
            try:
                pumpup.albedo(f, [0.5], phi=phi, rtol=rtol)
                _, t2 = _best(lambda: pumpup.albedo(f, few, phi=phi, rtol=rtol), 1)
            finally:
                cls.lobe_axis = saved
            per1, per2 = t1 / mu.size, t2 / few.size
            print(f"{str(spec)[:60]:60s} {phi:4.1f} {t1 * 1e3:9.2f} {per1 * 1e6:8.1f} {per2 * 1e6:13.0f} "
                  f"{per2 / per1:7.0f}", flush=True)


def main():
    import os

    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f} "
          f"on {os.cpu_count()} cores")
    if "--eval" in sys.argv:
        eval_overhead()
        return
    if "--phong" in sys.argv:
        families(specs=PHONG_FAMILY, dblquad=False)
        return
    if "--half" in sys.argv:
        half_and_closed()
        return
    if "--p" in sys.argv:
        p_model()
        return
    if "--arc" in sys.argv:
        on_the_arc()
        return
    if "--fresnel" in sys.argv:
        lobe_fresnel()
        return
    if "--nframe" in sys.argv:
        n_frame()
        return
    if "--nframe-f" in sys.argv:
        n_frame_fresnel()
        return
    if "--lobe-n" in sys.argv:
        lobe_n_frame()
        return
    if "--pumped-f" in sys.argv:
        pumped_fresnel()
        return
    if "--fmax" in sys.argv:
        fresnel_max()
        return
    if "--pumped" in sys.argv:
        pumped_chains()
        return
    if "--scaled" in sys.argv:
        scaled()
        return
    if "--breaks" in sys.argv:
        breaks()
        return
    if "--slope" in sys.argv:
        slope()
        return
    if "--lafortune" in sys.argv:
        lafortune_axis()
        return
    if "--lobe-f" in sys.argv:
        lobe_f_gauss()
        return
    if "--cells" not in sys.argv:
        families()
    cells()
    eval_overhead()
    if "--all" in sys.argv:
        legacy()


def legacy():
    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    f = pumpup.load({"type": "stretched_phong", "n": 5000})
    pumpup.albedo(f, 0.5)  # load the compiled kernels
    times = []
    for _ in range(3):
        t = time.perf_counter()
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-8)
        times.append(time.perf_counter() - t)
    print(f"1. 257-point table of stretched Phong n = 5000 to rtol 1e-8: best {min(times):.2f} s, "
          f"median {sorted(times)[1]:.2f} s of 3 (largest relative error estimate {np.max(e / a):.2g})")

    print("2. pumpup against scipy dblquad, same model, same mu, requested relative accuracy 1e-8:")
    for n, mus in [(20, [0.9, 0.5, 0.1]), (5000, [0.5])]:
        g = pumpup.load({"type": "stretched_phong", "n": n})
        for m in mus:
            t = time.perf_counter()
            ref, ref_err = dblquad_albedo(g, m, 1e-8)
            td = time.perf_counter() - t
            t = time.perf_counter()
            for _ in range(5):
                v, err = pumpup.albedo(g, m, return_error=True, rtol=1e-8)
            tp = (time.perf_counter() - t) / 5
            print(f"   n={n:5d} mu={m:4.2f}: dblquad {td:8.3f} s (a={ref:.12f}), pumpup {tp * 1e3:7.2f} ms "
                  f"(a={float(v):.12f} +- {float(err):.1g}); pumpup is {td / tp:7.0f} x faster")

    def phong20(wi, wo):
        rv = 2 * wi[..., 2] * wo[..., 2] - np.sum(wi * wo, axis=-1)
        return 22 / (2 * np.pi) * np.maximum(rv, 0) ** 20

    user = pumpup.from_function(phong20, name="phong20-bench")
    t = time.perf_counter()
    a, e = pumpup.albedo(user, mu, return_error=True, rtol=1e-6)
    tu = time.perf_counter() - t
    exact = pumpup.albedo(pumpup.load({"type": "phong", "n": 20}), mu)
    print(f"3. from_function Phong n = 20, 257 points to rtol 1e-6: {tu:.2f} s "
          f"(largest true relative error {np.max(np.abs(a - exact) / exact):.2g})")


if __name__ == "__main__":
    main()
