"""Random probe of the albedo engines' honesty.

Draws built-in models with extreme parameters (lobe exponents 0.1-1e4, roughness 1e-4-1, Fresnel factors with eta
0.1-3 and k 0.01-16, Schlick r down to 1e-6, p-models), three incidences (mu log-uniform down to 1e-6, uniform, 1) and
an rtol (1e-6, 1e-8, 1e-10); computes the albedo on its default path and again with the 1-D path off
(``using(engine="nested")``: the nested engine) at rtol 1e-12, and prints every case where the two differ by more
than the default path's estimate plus the reference's, with the ratio.  A case printed is a disagreement, not yet a
culprit: decide it with a third method (``tests/reference/independent_microfacet.py`` for GGX and Beckmann, the 2-D engine,
``using(engine="2d")``).

Found this way: GGX alpha 1.3e-4 at mu = 6.05e-5.  The 1-D path (0.8967913960373392, estimate 2.3e-14) agrees with
the independent script (0.8967913960367667 +- 1.9e-8); the nested engine was 9e-9 off with estimates of 2e-10 to 3e-9
at every rtol (36-42 x at alpha 1e-4, mu 6e-5 and 1e-4; 1.3 x at alpha 1e-3, mu 1e-5), and at alpha 1e-4 the 2-D
engine too (4.7e-9 off, estimate 2.5e-9).  The cause: ``albedo.smooth_inverse`` put
the far horizon break (1 - tau_x = 1.7e-9) at 6.8e-3 (Newton from a start that rounds 1 - 2 (1 - x)); mended, both
engines agree with a half-vector quadrature to 5e-13 (``tests/engine/test_cubature.py``).  The nested engine is not
GGX's path (frame 6 is); it is the tests' second engine and the path of models without a 1-D path.

Found the same way (each mended, with a test): a pumped level's albedo kinked where its bound equals its value
at the normal (--two-d; ``Pumped._kink_normal``); a (mu, phi) dataset crashing ``AlbedoTable.from_dataset`` (--tables);
frame 4 blind to a near-real branch point of F at normal incidence (GGX alpha .003, eta .271, k .0605 at mu = 1: 6.9 x);
the nested engine blind to G1's fall at the horizon near normal incidence for alpha < 1.5e-3 (up to 26 x;
``_nested._alpha_grading``); a pumped level's mean albedo integrated across its kinks (--mean: 10 x;
``mean_albedo``'s first intervals end at them now), and across mu ~ alpha near grazing (2.6 x; two more first
intervals there).

Also found (each mended, with a test): the 2-D engine blind to G1's fall at the horizon near normal
incidence (GGX alpha 2.7e-4 at mu = 1: 62 x; it is now graded as the nested engine); the power map wrong at its split
x = 1/2 for n > 52, so the kink scan missed a cut of Torrance-Sparrow's G entering the arc (--two-d: the 2-D engine 1.77e-7
off, 1270 x); a Fresnel factor's total reflection (eta < 1, k = 0) unknown to the hints (--registry: correct, but 0.3 s
per value and minutes per table on the nested engine).

Found by --tables (each mended, with a test in tests/tables/test_tables.py): a divergent albedo bisected down to
 two nodes of one log(mu) (scipy's ValueError); a table across a jump (Beckmann with Walter's G1) whose margin hid it;
pumped plastic n = 5284 turning inside the interval at the normal, which only its midpoint checked (1.55 x its margin); and
Kulla-Conty over Torrance-Sparrow, exact at the very points the grid checks because it reads a table built on them (8.6 x).

Found by --registry 47 (each mended, with a test): lobes about the normal that carry a table in
log(N.wo) (a scaled model's 1 / U, the Kulla-Conty lobe's D, a pumped level's g) on the nested and 2-D engines, whose
features on every scale of N.wo lay in one first interval (scaled Lafortune 1.56 x, scaled lacquer 2.5 x, the Kulla-Conty
lobe of Phong n = 987 3.4 x on the 2-D engine, g2 pumped Minnaert 4.1 x: ``pumping.TABLE_DECADES``); the slope path near
normal incidence for a_x / a_y = 50, whose |e| has a branch point 0.02 off the real axis of theta (72 x); and the 2-D
engine unconverged on fresnel (eta 0.232) over plastic (n 34.4, eta 1.88, ad 0.33) at mu = 0.306, which showed that every
engine was wrong there (0.2908 for 0.4060, with estimates of 1e-9): the fresnel wrapper was one albedo term with plastic's
specular hint for its Lambert part too (``FresnelWeighted.albedo_terms`` now splits it over the base's terms).

Found by --registry 49 (mended, with tests): scaled Cook-Torrance near the normal, 1.04 x
(up to 5.3 x in a scan around it), whose E table's spline went across the jump of a'' at mu = 1 / sqrt(2) of 001 eq.
10's geometry factor (``pumpup.models.cook_torrance.RETRO_BREAK``, now an albedo break); following it, a 1/E scaling
of Beckmann with Walter's G1 in frame 6 (94 x; the nested engine takes it now).  Its other disagreement is the 2-D
engine's: anisotropic Ward a_x 0.0101, a_y 0.450 at mu = 0.957, phi 1.535, 36 x at rtol 1e-12 (the slope path, the
nested engine and tests/reference/independent_ward_aniso.py's two methods agree).
"""

import math
import signal
import sys
import time
import warnings

import numpy as np

import pumpup
from pumpup.engine.routes import using


def rand_spec(rng):
    t = rng.choice(["phong", "stretched_phong", "retro", "blinn", "ward", "cook_torrance", "ggx", "beckmann",
                    "schlick", "metal", "lafortune", "plastic"])
    if t in ("phong", "retro", "blinn"):
        return {"type": t, "n": float(10 ** rng.uniform(-1, 4))}
    if t == "stretched_phong":
        return {"type": t, "n": float(10 ** rng.uniform(-1, 4)), "p": float(rng.choice([0, 1, rng.uniform(0, 1)]))}
    if t == "ward":
        return {"type": t, "m": float(10 ** rng.uniform(-2.5, 0))}
    if t == "cook_torrance":
        s = {"type": t, "m": float(10 ** rng.uniform(-2, 0))}
        if rng.random() < 0.5:
            s["ior"] = float(rng.uniform(1.05, 3))
        return s
    if t in ("ggx", "beckmann"):
        s = {"type": t, "alpha": float(10 ** rng.uniform(-4, 0))}
        if rng.random() < 0.4:
            s["eta"], s["k"] = float(10 ** rng.uniform(-1, 0.5)), float(10 ** rng.uniform(-2, 1.2))
        if t == "ggx" and rng.random() < 0.3:
            s["shadowing"] = "correlated"
        return s
    if t == "schlick":
        return {"type": t, "r": float(10 ** rng.uniform(-6, 0))}
    if t == "metal":
        return {"type": t, "n": float(rng.choice([0, 1, 5, 20, 200])), "eta": float(10 ** rng.uniform(-1, 0.5)),
                "k": float(10 ** rng.uniform(-2, 1.2))}
    if t == "lafortune":
        return {"type": t, "n": float(10 ** rng.uniform(0, 3)), "cx": -1.0, "cy": -1.0, "cz": 1.0}
    return {"type": "plastic", "n": float(10 ** rng.uniform(0, 2.5)), "eta": float(rng.uniform(1.2, 2)),
            "ad": float(rng.uniform(0, 0.5))}


def rand_spec_fmax(rng):
    """The fresnel wrapper (F(max(N.L, N.V))) over GGX, Beckmann (F = 1) or Schlick's model, some pumped (either order),
    and pumped GGX with F(wi.h): frame 6 with F per node, and with g above mu = 0.248
    (``--fmax``: the default mode's comparison with the nested engine, on these only; seed 21's 372 cases, 0
    disagreements, drew the first three kinds only, at 95ad034)."""
    base = {"type": "schlick", "r": float(10 ** rng.uniform(-4, 0))} if rng.random() < 0.2 else {
        "type": str(rng.choice(["ggx", "beckmann"])), "alpha": float(10 ** rng.uniform(-3, 0)),
        "shadowing": str(rng.choice(["separable", "correlated"]))}
    eta, k = float(10 ** rng.uniform(-1, 0.5)), float(rng.choice([0.0, 10 ** rng.uniform(-3, 1.2)]))
    kind = rng.random()
    if kind < 0.55:
        return {"type": "fresnel", "base": base, "eta": eta, "k": k}
    pumped = {"g": str(rng.choice(["g1", "g2"])), "levels": int(rng.integers(1, 3))}
    if kind > 0.85 and base["type"] == "ggx":
        f = {"ior": float(rng.uniform(1.01, 3.0))} if rng.random() < 0.3 else {"eta": eta, "k": k}
        return {"type": "pumped", "base": {**base, **f}, **pumped}
    if kind < 0.7:
        return {"type": "pumped", "base": {"type": "fresnel", "base": base, "eta": eta, "k": k}, **pumped}
    return {"type": "fresnel", "base": {"type": "pumped", "base": base, **pumped}, "eta": eta, "k": k}


def rand_spec_2d(rng):
    """A model that has no 1-D path, or a wrapper of one: the default path (mostly the nested engine) against the 2-D
    engine (``--two-d``)."""
    t = rng.choice(["pumped", "ward_aniso", "fresnel", "lafortune", "torrance_sparrow", "plastic", "mix"])
    if t == "pumped":
        base = rand_spec(rng)
        while base["type"] in ("metal", "plastic") or base.get("n", 1.0) > 2000 or base.get("alpha", 1.0) < 3e-3:
            base = rand_spec(rng)  # keep the levels' tables cheap
        return {"type": "pumped", "base": base, "g": str(rng.choice(["g1", "g2"])), "levels": int(rng.integers(1, 3))}
    if t == "ward_aniso":
        return {"type": t, "ax": float(10 ** rng.uniform(-2, 0)), "ay": float(10 ** rng.uniform(-2, 0))}
    if t == "fresnel":
        return {"type": t, "base": {"type": "stretched_phong", "n": float(10 ** rng.uniform(0, 3)), "p": 1.0},
                "eta": float(10 ** rng.uniform(-1, 0.5)), "k": float(10 ** rng.uniform(-2, 1.2))}
    if t == "lafortune":
        return {"type": t, "n": float(10 ** rng.uniform(0, 3)), "cx": float(rng.uniform(-1.3, 1.3)),
                "cy": float(rng.uniform(-1.3, 1.3)), "cz": float(rng.uniform(0.2, 1.3))}
    if t == "torrance_sparrow":
        d = str(rng.choice(["D1", "D2", "D3"]))
        s = {"D1": 10 ** rng.uniform(0, 3), "D2": 10 ** rng.uniform(0, 1.5), "D3": 10 ** rng.uniform(-2, -0.1)}[d]
        return {"type": t, "d": d, "s": float(s), "ior": float(rng.uniform(1.1, 3))}
    if t == "plastic":
        return {"type": t, "n": float(10 ** rng.uniform(0, 2.5)), "eta": float(rng.uniform(1.2, 2)),
                "ad": float(rng.uniform(0, 0.5))}
    return {"type": "mix", "a": {"type": "lambert"}, "b": rand_spec(rng), "m": float(rng.uniform(0, 1))}


def _draws(rng, budget, draw):
    """(spec, BRDF) pairs from ``draw(rng)`` for ``budget`` seconds (specs the models refuse are skipped)."""
    t0 = time.time()
    while time.time() - t0 < budget:
        spec = draw(rng)
        try:
            yield spec, pumpup.load(spec)
        except ValueError:
            continue


def main_2d(rng, budget):
    """The default path against the 2-D engine (``using(engine="2d")``) at rtol 1e-12, with wi turned out of the
    xz-plane (phi) for the anisotropic models."""
    bad = n = 0
    for spec, f in _draws(rng, budget, rand_spec_2d):
        mu = np.array([10 ** rng.uniform(-6, 0), rng.uniform(0, 1), 1.0])
        phi = float(rng.uniform(0, 2 * np.pi)) if spec["type"] == "ward_aniso" else 0.0
        rtol = float(rng.choice([1e-6, 1e-8, 1e-10]))
        a, e = pumpup.albedo(f, mu, rtol=rtol, return_error=True, phi=phi)
        with using(engine="2d"):
            b, eb = pumpup.albedo(f, mu, rtol=1e-12, return_error=True, max_regions=200000, phi=phi)
        n += 1
        r = (np.abs(a - b) - eb) / np.maximum(e, 1e-300)
        r[~np.isfinite(r)] = np.inf  # an inf or a NaN from either engine is a disagreement too
        if np.any(r > 1):
            bad += 1
            # a third opinion, the nested engine at rtol 1e-12 (the default path's own engine for most of these, but
            # its 1-D path for a mix's GGX): which of the two is the odd one
            with using(engine="nested"):
                c, ec = pumpup.albedo(f, mu[r > 1], rtol=1e-12, return_error=True, max_regions=200000, phi=phi)
            odd = np.where(np.abs(b[r > 1] - c) > eb[r > 1] + ec, "2-D", "default")
            print("DISAGREE", spec, "phi", phi, "rtol", rtol, "mu", mu[r > 1], "a", a[r > 1], "2-D", b[r > 1],
                  "est", e[r > 1], "2-D est", eb[r > 1], "ratio", r[r > 1], "nested", c, "+-", ec, "odd one", odd,
                  flush=True)
    print(f"cases {n}, disagreements {bad}")


def _any_spec(rng):
    r = rng.random()
    return rand_spec(rng) if r < 0.5 else (rand_spec_2d(rng) if r < 0.7 else rand_spec_registry(rng))


def main_tables(rng, budget):
    """A table's interpolant against fresh values (``--tables``): ``pumpup.tabulate`` at its defaults, then the albedo at
    40 random mu (log-uniform from the table's first node to 1, and uniform) at rtol 1e-12; a miss larger than the
    table's margin (``AlbedoTable.margin``: 2 x the interpolation error measured at midpoints + the largest quadrature
    error; ``margin_below`` below the first node) plus the fresh value's estimate is printed."""
    from pumpup.tables import AlbedoTable

    _arm_alarm()
    bad = n = slow = 0
    for spec, f in _draws(rng, budget, _any_spec):
        phi = None if f.azimuth_range() is None else 0.0
        signal.alarm(CASE_SECONDS)
        try:
            t = AlbedoTable.from_dataset(pumpup.tabulate(f, phi=phi).isel(phi=0) if phi is not None else pumpup.tabulate(f))
            mu = np.sort(np.concatenate([10 ** rng.uniform(np.log10(t.mu[0]), 0, 30), rng.uniform(t.mu[0], 1, 10)]))
            a, e = pumpup.albedo(f, mu, rtol=1e-12, return_error=True, max_regions=200000, phi=phi or 0.0)
        except TimeoutError:
            slow += 1
            print("SLOW", spec, flush=True)
            continue
        except Exception as err:  # a crash is a finding too
            bad += 1
            print("ERROR", spec, type(err).__name__, str(err).splitlines()[0], flush=True)
            continue
        finally:
            signal.alarm(0)
        miss = np.abs(t(mu) - a) - e
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(miss > 0, miss / t.margin, 0.0)  # (a zero albedo, table and margin: no miss)
        r[~np.isfinite(r)] = np.inf
        n += 1
        if np.any(r > 1):
            bad += 1
            i = int(np.argmax(r))
            print("MISS", spec, "mu", mu[i], "table", t(mu[i : i + 1])[0], "fresh", a[i], "+-", e[i], "margin", t.margin,
                  "ratio", r[i], "nodes", len(t.mu), flush=True)
    print(f"tables {n}, misses {bad}, slow {slow}")


#: --mean prints a case that takes longer than this (seconds)
SLOW = 60.0


def main_mean(rng, budget):
    """``pumpup.mean_albedo(f, return_error=True)`` (a table's spline where one was just made, else afresh) against
    scipy's quad of 2 mu a(mu) over [0, 1] with the albedo at rtol 1e-13 (``--mean``); half the cases tabulate first."""
    from scipy.integrate import quad

    bad = n = 0
    for spec, f in _draws(rng, budget, _any_spec):
        if f.azimuth_range() is not None:
            continue  # (an anisotropic model's mean needs an azimuth)
        t0 = time.time()
        try:
            if rng.random() < 0.5:
                pumpup.tabulate(f)
            m, em = pumpup.mean_albedo(f, return_error=True)
        except Exception as err:
            bad += 1
            print("ERROR", spec, type(err).__name__, str(err).splitlines()[0], flush=True)
            continue
        errs = []

        def g(x):
            a, e = pumpup.albedo(f, x, rtol=1e-13, return_error=True)
            errs.append(float(e) * 2 * x)
            return 2.0 * x * float(a)

        t1 = time.time()
        ref, eref = quad(g, 0.0, 1.0, epsabs=1e-15, epsrel=1e-12, limit=400, points=[1e-6, 1e-4, 1e-2, 0.1, 0.5])
        if time.time() - t0 > SLOW:  # a slow case is worth a look too (which of the two is slow)
            print("SLOW", spec, f"mean {t1 - t0:.1f} s, quad {time.time() - t1:.1f} s ({len(errs)} values)", flush=True)
        eref += max(errs)  # each value's own error, integrated over [0, 1] at most
        n += 1
        r = (abs(m - ref) - eref) / em if em > 0 else (math.inf if abs(m - ref) > eref else 0.0)
        if not np.isfinite(m) or r > 1:
            bad += 1
            print("MEAN", spec, "mean", m, "+-", em, "quad", ref, "+-", eref, "ratio", r, flush=True)
    print(f"means {n}, misses {bad}")


#: --registry: practical ranges (log-uniform where both ends are positive) of the registry's parameters, by name;
#: a scale (c, b, ks, albedo, ...) keeps its default
_RANGES = {"n": (0.1, 1e4), "alpha": (1e-4, 3.0), "m": (1e-3, 3.0), "r": (1e-8, 1.0), "ax": (1e-3, 3.0), "ay": (1e-3, 3.0),
           "sigma": (0.0, 1.5), "k": (0.01, 30.0), "eta": (0.1, 5.0), "ior": (1.01, 3.0), "sigma_0": (0.02, 3.0),
           "tau": (0.05, 10.0), "wavelength": (0.35, 0.8), "cx": (-1.3, 1.3), "cy": (-1.3, 1.3), "cz": (0.2, 1.3),
           "s": (0.0, 1.0)}
_SCALES = ("c", "b", "ks", "albedo", "k_rho", "k_sigma")
_S_OF_D = {"D1": (1.0, 1e3), "D2": (1.0, 30.0), "D3": (0.01, 0.8), "D4": (0.01, 1.0)}


def _draw_value(rng, name, prm, spec):
    lo, hi = _RANGES.get(name, (max(prm.lo, -2.0), min(prm.hi, 2.0)))  # (a scale: up to 2)
    if name == "s" and "d" in spec:  # torrance_sparrow's shape parameter depends on its distribution
        lo, hi = _S_OF_D[spec["d"]]
    lo, hi = max(lo, prm.lo), min(hi, prm.hi)
    if lo > 0 and hi / lo > 20:
        return float(10 ** rng.uniform(math.log10(lo), math.log10(hi)))
    return float(rng.uniform(lo, hi))


def rand_spec_registry(rng, depth=0):
    """Any registered model (``--registry``), its parameters drawn from their declared ranges (cut to ``_RANGES``);
    a wrapper's base from the same draw (one level deep) or from :func:`rand_spec`."""
    from pumpup.core import REQUIRED, registry

    types = [t for t in registry() if t != "function"]
    t = str(rng.choice(types))
    spec = {"type": t}
    for name, prm in registry()[t].params.items():
        if prm.kind == "spec":
            if prm.default is REQUIRED:
                spec[name] = rand_spec_registry(rng, depth + 1) if depth == 0 and rng.random() < 0.5 else rand_spec(rng)
            continue
        if prm.kind == "bool" or (name in _SCALES and rng.random() < 0.8):
            continue
        if prm.kind == "str":
            if prm.choices:
                spec[name] = str(rng.choice(prm.choices))
            continue
        if prm.kind == "int":
            spec[name] = int(rng.integers(1, 3))
            continue
        if prm.default is None and rng.random() < 0.6:
            continue  # an optional parameter (a Fresnel factor): often left out
        if prm.kind == "floats":
            if name == "n":
                spec[name] = [_draw_value(rng, name, prm, spec) for _ in range(int(rng.integers(1, 4)))]
            elif name in _RANGES:
                spec[name] = [_draw_value(rng, name, prm, spec) for _ in spec["n"]]
            continue
        if prm.default is REQUIRED or rng.random() < 0.7:
            spec[name] = _draw_value(rng, name, prm, spec)
    return spec


#: --registry and --tables stop a case that takes longer than this (seconds) and print it
CASE_SECONDS = 120


def _arm_alarm():
    """SIGALRM raises TimeoutError (``signal.alarm(CASE_SECONDS)`` before a case, ``signal.alarm(0)`` after it)."""
    def alarm(*_):
        raise TimeoutError

    signal.signal(signal.SIGALRM, alarm)


def main_registry(rng, budget):
    """Every registered model (``--registry``): the default path at rtol 1e-6 ... 1e-10 against the 2-D engine at rtol
    1e-12 (with wi at a random azimuth for an anisotropic model), the nested engine as a third opinion where the two
    disagree.  A case slower than ``CASE_SECONDS`` is stopped and printed (SLOW)."""
    _arm_alarm()
    bad = n = slow = 0
    for spec, f in _draws(rng, budget, rand_spec_registry):
        mu = np.array([10 ** rng.uniform(-6, 0), rng.uniform(0, 1), 1.0])
        phi = 0.0 if f.azimuth_range() is None else float(rng.uniform(0, 2 * np.pi))
        rtol = float(rng.choice([1e-6, 1e-8, 1e-10]))
        signal.alarm(CASE_SECONDS)
        try:
            a, e = pumpup.albedo(f, mu, rtol=rtol, return_error=True, phi=phi)
            with using(engine="2d"):
                b, eb = pumpup.albedo(f, mu, rtol=1e-12, return_error=True, max_regions=200000, phi=phi)
            n += 1
            r = (np.abs(a - b) - eb) / np.maximum(e, 1e-300)
            r[~np.isfinite(r)] = np.inf
            if np.any(r > 1):
                bad += 1
                with using(engine="nested"):
                    c, ec = pumpup.albedo(f, mu[r > 1], rtol=1e-12, return_error=True, max_regions=200000, phi=phi)
                print("DISAGREE", spec, "phi", phi, "rtol", rtol, "mu", mu[r > 1], "a", a[r > 1], "2-D", b[r > 1],
                      "est", e[r > 1], "2-D est", eb[r > 1], "ratio", r[r > 1], "nested", c, "+-", ec, flush=True)
        except TimeoutError:
            slow += 1
            print("SLOW", spec, "phi", phi, "rtol", rtol, "mu", mu, flush=True)
        except Exception as err:  # a crash on a valid spec is a finding too
            bad += 1
            print("ERROR", spec, "phi", phi, "mu", mu, type(err).__name__, str(err).splitlines()[0], flush=True)
        finally:
            signal.alarm(0)
    print(f"cases {n}, disagreements {bad}, slow {slow}")


def main():
    for flag, mode in (("--mean", main_mean), ("--tables", main_tables), ("--two-d", main_2d),
                       ("--registry", main_registry)):
        if flag in sys.argv:
            sys.argv.remove(flag)
            warnings.simplefilter("ignore")
            mode(np.random.default_rng(int(sys.argv[1]) if len(sys.argv) > 1 else 0),
                 float(sys.argv[2]) if len(sys.argv) > 2 else 300.0)
            return
    warnings.simplefilter("ignore")
    draw = rand_spec
    if "--fmax" in sys.argv:
        sys.argv.remove("--fmax")
        draw = rand_spec_fmax
    rng = np.random.default_rng(int(sys.argv[1]) if len(sys.argv) > 1 else 0)
    budget = float(sys.argv[2]) if len(sys.argv) > 2 else 300.0
    bad = n = 0
    for spec, f in _draws(rng, budget, draw):
        mu = np.array([10 ** rng.uniform(-6, 0), rng.uniform(0, 1), 1.0])
        rtol = float(rng.choice([1e-6, 1e-8, 1e-10]))
        a, e = pumpup.albedo(f, mu, rtol=rtol, return_error=True)
        with using(engine="nested"):
            b, eb = pumpup.albedo(f, mu, rtol=1e-12, return_error=True, max_regions=200000)
        n += 1
        r = (np.abs(a - b) - eb) / np.maximum(e, 1e-300)
        r[~np.isfinite(r)] = np.inf  # an inf or a NaN from either engine is a disagreement too
        if np.any(r > 1):
            bad += 1
            print("DISAGREE", spec, "rtol", rtol, "mu", mu[r > 1], "a", a[r > 1], "nested", b[r > 1], "est", e[r > 1],
                  "nested est", eb[r > 1], "ratio", r[r > 1], flush=True)
    print(f"cases {n}, disagreements {bad}")


if __name__ == "__main__":
    main()
