"""Energy compensation side by side (issue 15): Kulla-Conty, 1/E scaling, and pumping g1/g2.

For GGX and Beckmann (alpha 0.05, 0.1, 0.3, 0.6, 1.0), reciprocal Phong and Blinn (n = 5, 20,
100; Blinn at its maximum constant, so its albedo peaks at 1) and Ward (m = 0.1, 0.3), all with
Fresnel 1, and each method, it measures

* the white furnace toward the viewer, integral f(wi, wo) cos(theta_i) d omega_i at 11 values
  of mu_o from 1 to 1e-6 (the albedo, for the reciprocal methods): max |1 - a| and min a;
* the reciprocity asymmetry of :func:`pumpup.check_reciprocity`;
* the radiance under a point light seen in the mirror direction against the base's,
  f_c(wi, R) / f(wi, R) at theta_i = 0 ... 89.9 deg (001 sec. 3's super-metal measure), and
  the peak-to-base ratio near grazing, max_wo f_c(wi, wo) / max_wo f(wi, wo) at theta_i = 85 deg;
* how much the lobe's shape moves: max over the lobe (f >= f_peak / 10) of |r / r_peak - 1|,
  r = f_c / f, at theta_i = 0, 30, 60, 80 deg (0 for a pure rescaling);
* the evaluation cost relative to the base (2^18 random pairs, best of 5, same run);

and the intermediate-metalness furnace: (1 - m) Lambert + m GGX (alpha 0.3 and 1.0, Fresnel 1)
for m = 0 ... 1, with each method applied to the conductor before mixing ("lobe") and to the
mix itself ("mix").  Writes tables/compensation.nc and figures/compensation.png.

    python scripts/make/compensation_study.py [--out tables] [--figures figures] [--quick]

(about 15 minutes on a shared 2-core machine; --quick runs two models, for a smoke test)
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time

import numpy as np

import pumpup

METHODS = ("base", "kulla_conty", "scale", "g1", "g2")
MU = np.array([1.0, 0.9, 0.7, 0.5, 0.3, 0.1, 0.03, 1e-2, 1e-3, 1e-4, 1e-6])
THETA_MIRROR = np.array([0.0, 30.0, 60.0, 75.0, 85.0, 89.0, 89.9])
THETA_SHAPE = (0.0, 30.0, 60.0, 80.0)
THETA_PEAK = 85.0
METALNESS = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
RTOL = 1e-9


def models(quick: bool = False) -> dict:
    """name -> spec of the study's bases (Fresnel 1)."""
    out = {}
    for kind in ("ggx", "beckmann"):
        for a in ((0.3,) if quick else (0.05, 0.1, 0.3, 0.6, 1.0)):
            out[f"{kind} alpha={a:g}"] = {"type": kind, "alpha": a}
    if quick:
        out["ward m=0.1"] = {"type": "ward", "m": 0.1}
        return out
    for n in (5, 20, 100):
        out[f"phong n={n}"] = {"type": "phong", "n": n}
    for n in (5, 20, 100):
        c, _ = pumpup.max_constant(pumpup.load({"type": "blinn", "n": n}))
        out[f"blinn n={n}"] = {"type": "blinn", "n": n, "c": float(c)}
    for m in (0.1, 0.3):
        out[f"ward m={m:g}"] = {"type": "ward", "m": m}
    return out


def build(spec, method):
    """The compensated BRDF, or (None, reason) when the method refuses the base."""
    f = pumpup.load(spec)
    if method == "base":
        return f, ""
    try:
        return pumpup.compensate(f, method=method), ""
    except pumpup.SpecError as exc:
        return None, str(exc)


def _dir(theta_deg, phi=0.0):
    t = math.radians(theta_deg)
    mu = math.sin(math.radians(90.0 - theta_deg))  # keeps its digits near 90 deg
    s = math.sin(t)
    return np.array([s * math.cos(phi), s * math.sin(phi), mu])


def _hemisphere(n_theta=300, n_phi=96):
    """A grid of viewing directions, dense near grazing (mu from 1 to 1e-4)."""
    mu = np.concatenate([np.linspace(1.0, 0.05, n_theta // 2), np.geomspace(0.05, 1e-4, n_theta // 2)])
    phi = np.linspace(0.0, np.pi, n_phi)  # the lobes are even in phi
    M, P = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt((1 - M) * (1 + M))
    return np.stack([s * np.cos(P + np.pi), s * np.sin(P + np.pi), M], -1)  # phi = pi: the mirror side


def measure(f, base, timing: bool = True) -> dict:
    """The study's numbers for one compensated BRDF f against its base."""
    out = {}
    a, e = pumpup.furnace(f, MU, return_error=True, rtol=RTOL)
    out["furnace"], out["furnace_error"] = a, e
    out["furnace_residual"] = float(np.max(np.abs(1.0 - a)))
    out["min_albedo"] = float(np.min(a))
    out["asymmetry"] = float(pumpup.check_reciprocity(f).max_rel_error)
    ratio = []
    for t in THETA_MIRROR:
        wi = _dir(t)
        wo = wi * np.array([-1.0, -1.0, 1.0])
        fb = float(base.eval(wi, wo))
        ratio.append(float(f.eval(wi, wo)) / fb if fb > 0 else math.nan)
    out["mirror_ratio"] = np.array(ratio)
    grid = _hemisphere()
    wi = _dir(THETA_PEAK)
    out["peak_ratio"] = float(np.max(f.eval(wi, grid)) / np.max(base.eval(wi, grid)))
    shape = 0.0
    for t in THETA_SHAPE:
        wi = _dir(t)
        fb = base.eval(wi, grid)
        fc = f.eval(wi, grid)
        k = np.unravel_index(np.argmax(fb), fb.shape)
        lobe = fb >= 0.1 * fb[k]
        r = fc[lobe] / fb[lobe]
        shape = max(shape, float(np.max(np.abs(r / (fc[k] / fb[k]) - 1.0))))
    out["shape_change"] = shape
    if timing:
        rng = np.random.default_rng(0)
        v = rng.normal(size=(2, 1 << 18, 3))
        v[..., 2] = np.abs(v[..., 2])
        v /= np.linalg.norm(v, axis=-1, keepdims=True)
        out["eval_seconds"] = _best(lambda: f._eval(v[0], v[1]))
        out["base_seconds"] = _best(lambda: base._eval(v[0], v[1]))
    return out


def _best(fn, repeat=5):
    fn()
    best = math.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def metalness(alpha: float, arrangement: str, method: str, m: float) -> tuple[float, float]:
    """(max |1 - a|, min a) of (1 - m) Lambert + m GGX(alpha) under ``method``, applied to the
    lobe before mixing or to the mix."""
    ggx = {"type": "ggx", "alpha": alpha}
    lam = {"type": "lambert"}
    if method == "base":
        f = pumpup.load({"type": "mix", "a": lam, "b": ggx, "m": float(m)})
    elif arrangement == "lobe":
        f = pumpup.load({"type": "mix", "a": lam, "b": pumpup.compensate(ggx, method=method).spec, "m": float(m)})
    else:
        f = pumpup.compensate({"type": "mix", "a": lam, "b": ggx, "m": float(m)}, method=method)
    a = pumpup.furnace(f, MU, rtol=RTOL)
    return float(np.max(np.abs(1.0 - a))), float(np.min(a))


def study(quick: bool = False, progress=print):
    """The whole study as one xarray.Dataset (the function the regression test calls on one row)."""
    import xarray as xr

    specs = models(quick)
    names = list(specs)
    shape = (len(names), len(METHODS))
    scalars = {k: np.full(shape, np.nan) for k in ("furnace_residual", "min_albedo", "asymmetry", "peak_ratio",
                                                     "shape_change", "cost_ratio")}
    furn = np.full(shape + (len(MU),), np.nan)
    mirror = np.full(shape + (len(THETA_MIRROR),), np.nan)
    refused = np.full(shape, "", dtype=object)
    for i, name in enumerate(names):
        base = pumpup.load(specs[name])
        for j, method in enumerate(METHODS):
            t0 = time.perf_counter()
            f, why = build(specs[name], method)
            if f is None:
                refused[i, j] = why
                progress(f"{name:18s} {method:12s} refused: {why[:90]}")
                continue
            r = measure(f, base)
            for k in ("furnace_residual", "min_albedo", "asymmetry", "peak_ratio", "shape_change"):
                scalars[k][i, j] = r[k]
            scalars["cost_ratio"][i, j] = r["eval_seconds"] / r["base_seconds"]
            furn[i, j] = r["furnace"]
            mirror[i, j] = r["mirror_ratio"]
            progress(f"{name:18s} {method:12s} |1-a| {r['furnace_residual']:.2e} min a {r['min_albedo']:.6f} "
                     f"asym {r['asymmetry']:.2g} mirror60 {r['mirror_ratio'][2]:.4f} peak85 {r['peak_ratio']:.3f} "
                     f"shape {r['shape_change']:.3g} cost {scalars['cost_ratio'][i, j]:.2f} "
                     f"({time.perf_counter() - t0:.1f} s)")
    alphas = (0.3,) if quick else (0.3, 1.0)
    arr = ("lobe", "mix")
    metal = np.full((len(alphas), len(arr), len(METHODS), len(METALNESS)), np.nan)
    metal_min = np.full_like(metal, np.nan)
    for ia, alpha in enumerate(alphas):
        for ib, arrangement in enumerate(arr):
            for j, method in enumerate(METHODS):
                if method == "base" and ib == 1:
                    metal[ia, ib, j], metal_min[ia, ib, j] = metal[ia, 0, j], metal_min[ia, 0, j]
                    continue
                for k, m in enumerate(METALNESS):
                    metal[ia, ib, j, k], metal_min[ia, ib, j, k] = metalness(alpha, arrangement, method, m)
                progress(f"metalness ggx {alpha:g} {arrangement:4s} {method:12s} max|1-a| "
                         + " ".join(f"{v:.1e}" for v in metal[ia, ib, j]))
    coords = {"model": names, "method": list(METHODS)}
    ds = xr.Dataset(
        {
            "furnace_residual": (("model", "method"), scalars["furnace_residual"],
                                 {"long_name": "max over mu_o of |1 - furnace(mu_o)|", "units": "1"}),
            "min_albedo": (("model", "method"), scalars["min_albedo"], {"long_name": "min over mu_o of the furnace"}),
            "asymmetry": (("model", "method"), scalars["asymmetry"],
                          {"long_name": "check_reciprocity max relative asymmetry"}),
            "peak_ratio": (("model", "method"), scalars["peak_ratio"],
                           {"long_name": f"max_wo f_c / max_wo f at theta_i = {THETA_PEAK:g} deg"}),
            "shape_change": (("model", "method"), scalars["shape_change"],
                             {"long_name": "max over the lobe (f >= f_peak / 10) of |r / r_peak - 1|, r = f_c / f"}),
            "cost_ratio": (("model", "method"), scalars["cost_ratio"],
                           {"long_name": "evaluation time / base evaluation time (2^18 pairs, best of 5)"}),
            "furnace": (("model", "method", "mu"), furn,
                        {"long_name": "white furnace toward the viewer, integral f cos(theta_i) d omega_i"}),
            "mirror_ratio": (("model", "method", "theta_i"), mirror,
                             {"long_name": "f_c(wi, R) / f(wi, R): point-light radiance in the mirror direction "
                                           "against the base (001 sec. 3)"}),
            "refused": (("model", "method"), refused.astype(str), {"long_name": "why a method refused the base"}),
            "metal_residual": (("alpha", "arrangement", "method", "metalness"), metal,
                               {"long_name": "max over mu_o of |1 - furnace| of (1 - m) lambert + m ggx(alpha)"}),
            "metal_min": (("alpha", "arrangement", "method", "metalness"), metal_min),
        },
        coords={**coords, "mu": ("mu", MU, {"units": "1", "long_name": "cos(theta_o) of the viewer"}),
                "theta_i": ("theta_i", THETA_MIRROR, {"units": "degree"}),
                "alpha": ("alpha", np.array(alphas)), "arrangement": ("arrangement", list(arr)),
                "metalness": ("metalness", METALNESS)},
        attrs={"pumpup_kind": "pumpup compensation study", "title": "Energy compensation side by side (issue 15)",
               "specs": json.dumps(specs, sort_keys=True), "albedo_rtol": RTOL,
               "pumpup_version": pumpup.__version__, "script": "scripts/make/compensation_study.py"},
    )
    return ds


def plot(ds, path):
    """figures/compensation.png: :func:`pumpup.plots.compensation` (the gallery draws it with the same function)."""
    from pumpup.plots import compensation

    return compensation(ds, path)


def markdown(ds) -> str:
    """The README's table: one row per model, the four methods as kulla_conty / scale / g1 / g2."""
    meth = [m for m in ds.method.values if m != "base"]
    i60, i89 = list(ds.theta_i.values).index(60.0), list(ds.theta_i.values).index(89.0)

    def cells(model, fn):
        out = []
        for m in meth:
            s = ds.sel({"model": model, "method": m})
            out.append("refused" if str(s.refused.values) else fn(s))
        return " / ".join(out)

    lines = ["| model | base min a | max \\|1 - a\\| | min a | asymmetry | mirror 60° | mirror 89° | peak 85° | "
             "shape | cost |", "|---|---|---|---|---|---|---|---|---|---|"]
    for model in ds.model.values:
        b = ds.sel({"model": model, "method": "base"})
        lines.append("| " + " | ".join([
            model, f"{float(b.min_albedo):.3f}",
            cells(model, lambda s: f"{float(s.furnace_residual):.1e}"),
            cells(model, lambda s: f"{float(s.min_albedo):.6f}"),
            cells(model, lambda s: f"{float(s.asymmetry):.2g}"),
            cells(model, lambda s: f"{float(s.mirror_ratio[i60]):.3f}"),
            cells(model, lambda s: f"{float(s.mirror_ratio[i89]):.3f}"),
            cells(model, lambda s: f"{float(s.peak_ratio):.3g}"),
            cells(model, lambda s: f"{float(s.shape_change):.2g}"),
            cells(model, lambda s: f"{float(s.cost_ratio):.1f}")]) + " |")
    return "\n".join(lines)


def metal_markdown(ds) -> str:
    """The metalness furnace: max over mu and m of |1 - a|, per method and arrangement."""
    lines = ["| GGX alpha | applied to | " + " | ".join(ds.method.values) + " |",
             "|---|---|" + "---|" * len(ds.method)]
    for a in ds.alpha.values:
        for arr in ds.arrangement.values:
            r = ds.metal_residual.sel({"alpha": a, "arrangement": arr})
            lines.append(f"| {a:g} | {arr} | " + " | ".join(
                f"{float(r.sel({'method': m}).max()):.1e}" + (" ✓" if float(r.sel({"method": m}).max()) <= 1e-6 else "")
                for m in ds.method.values) + " |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="tables")
    ap.add_argument("--figures", default="figures")
    ap.add_argument("--quick", action="store_true", help="two models only (a smoke test)")
    ap.add_argument("--replot", action="store_true", help="redraw the figure and tables from the stored file")
    a = ap.parse_args(argv)
    if a.replot:
        ds = pumpup.open_table(os.path.join(a.out, "compensation.nc"))
        print(plot(ds, os.path.join(a.figures, "compensation.png")))
        print(markdown(ds))
        print(metal_markdown(ds))
        return
    os.makedirs(a.out, exist_ok=True)
    os.makedirs(a.figures, exist_ok=True)
    t0 = time.perf_counter()
    ds = study(quick=a.quick)
    ds.attrs["seconds"] = time.perf_counter() - t0
    from pumpup.tables.provenance import write_generated  # stamps the commit that made it (issue 13 item 15)

    path = os.path.join(a.out, "compensation.nc")
    write_generated(ds, path)
    fig = plot(ds, os.path.join(a.figures, "compensation.png"))
    print(markdown(ds))
    print(metal_markdown(ds))
    print(f"wrote {path} and {fig} in {ds.attrs['seconds']:.0f} s")


if __name__ == "__main__":
    main()
