"""The ``pumpup`` command line.  Heavy imports happen inside the commands, so ``--help`` is fast."""

from __future__ import annotations

import argparse
import json
import math
import sys


def parse_spec(text: str) -> dict:
    """A model spec from JSON (``'{"type": "phong", "n": 20}'``) or the short form ``phong:n=20,c=1``."""
    text = text.strip()
    if text.startswith("{"):
        try:
            return json.loads(text)
        except json.JSONDecodeError as exc:
            raise SystemExit(f"pumpup: the spec is not valid JSON: {exc}") from None
    name, _, rest = text.partition(":")
    spec: dict = {"type": name}
    for item in filter(None, rest.split(",")):
        key, eq, value = item.partition("=")
        if not eq:
            raise SystemExit(f"pumpup: spec parameter {item!r} must look like name=value")
        try:
            spec[key.strip()] = json.loads(value)
        except json.JSONDecodeError:
            spec[key.strip()] = value.strip()
    return spec


def _load(text: str):
    import pumpup

    try:
        return pumpup.load(parse_spec(text))
    except pumpup.SpecError as exc:
        raise SystemExit(f"pumpup: {exc}") from None


def cmd_models(args) -> int:
    import pumpup

    for name, cls in pumpup.registry().items():
        doc = (cls.__doc__ or "").strip().splitlines()[0] if cls.__doc__ else ""
        params = ", ".join(cls.params)
        print(f"{name:18s} {params:28s} {doc}")
    return 0


def cmd_albedo(args) -> int:
    import numpy as np

    import pumpup

    f = _load(args.spec)
    if args.theta is not None:
        mu = np.sin(np.radians(90.0 - np.asarray(args.theta, dtype=float)))  # keeps its digits near 90 deg
    else:
        mu = np.asarray(args.mu if args.mu else [1.0, 0.5, 0.1, 0.01], dtype=float)
    try:
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=args.rtol)
    except ValueError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    print(f"# {json.dumps(f.spec)}")
    print(f"{'mu':>14s} {'theta [deg]':>14s} {'albedo':>20s} {'error':>10s}")
    for m, v, err in zip(mu, a, e):
        print(f"{m:14.8g} {np.degrees(np.arccos(m)):14.8f} {v:20.15f} {err:10.2g}")
    return 0


def cmd_table(args) -> int:
    import pumpup

    f = _load(args.spec)
    ds = pumpup.tabulate(f, rtol=args.rtol)
    pumpup.write_table(ds, args.out)
    print(f"wrote {args.out}: {ds.sizes['mu']} values of mu, interpolation error {ds.attrs['interpolation_error']:.2g}")
    return 0


def cmd_check(args) -> int:
    import pumpup

    f = _load(args.spec)
    r = pumpup.check_reciprocity(f)
    print(r)
    if hasattr(f, "report"):  # a compensated BRDF (pumpup.compensate): its E table and bounds
        print(f.report())
    m = pumpup.max_albedo(f)
    print(f"max albedo (constant set to 1): {m.albedo:.12g} +- {m.error:.2g} at theta = {m.theta_deg:.6f} deg;"
          f" maximum constant {m.constant:.12g}")
    return 0 if r.reciprocal else 1


def cmd_pump(args) -> int:
    import numpy as np

    import pumpup

    f = _load(args.spec)
    try:
        p = pumpup.pump(f, g=args.g, levels=args.levels, force=args.force)
    except pumpup.SpecError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    mu = np.array([1.0, 0.5, 0.1, 0.01, 1e-4])
    print(f"{'mu':>8s} " + " ".join(f"{'level ' + str(k):>12s}" for k in range(args.levels + 1)))
    chain = [p]
    while isinstance(chain[-1], pumpup.Pumped):
        chain.append(chain[-1].base)
    values = [pumpup.albedo(lev, mu) for lev in chain[::-1]]
    for i, m in enumerate(mu):
        print(f"{m:8.2g} " + " ".join(f"{v[i]:12.9f}" for v in values))
    if args.out:
        pumpup.save_pumped(p, args.out)
        print(f"wrote {args.out}")
    return 0


def cmd_figures(args) -> int:
    from .figures import make_figures

    for path in make_figures(args.tables, args.figures):
        print("wrote", path)
    return 0


def cmd_reproduce(args) -> int:
    from .reproduce import reproduce

    try:
        out = reproduce(args.out, args.only)
    except (ValueError, OSError) as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    seconds = out.pop("_seconds")
    total = sum(ds.sizes["entry"] for ds in out.values())
    agree = sum(int(ds["agrees"].sum()) for ds in out.values())
    with open(f"{args.out}/report.md") as fh:
        print(fh.read())
    print(f"{agree} of {total} published values reproduced to their printed digits; "
          f"{len(out)} tables and report.md written to {args.out}/ in {seconds:.0f} s")
    return 0


def cmd_divergence(args) -> int:
    from .divergence import analysis_dataset, divergence, plot
    from .tables import write_table

    if args.spec == "all":
        ds = analysis_dataset()
        write_table(ds, f"{args.tables}/divergence.nc")
        plot(ds, f"{args.figures}/divergence.png")
        for i, name in enumerate(ds.model.values):
            print(f"{name:24s} {ds.verdict.values[i]:10s} k = {float(ds.k[i]):.5f} +- {float(ds.k_error[i]):.1g}")
        print(f"wrote {args.tables}/divergence.nc and {args.figures}/divergence.png")
        return 0
    r = divergence(parse_spec(args.spec), mu_min=args.mu_min)
    print(f"{'mu':>12s} {'albedo':>20s} {'error':>9s}")
    for m, a, e in zip(r.mu, r.albedo, r.albedo_error):
        print(f"{m:12.4g} {a:20.12g} {e:9.2g}")
    print(r)
    return 0


def parse_values(text: str) -> tuple[str, list]:
    """``name=v1,v2,...`` (JSON numbers, else strings), ``name=lin:a:b:k`` or ``name=geom:a:b:k``."""
    name, eq, rest = text.partition("=")
    name = name.strip()
    if not eq or not name:
        raise SystemExit(f"pumpup: --param {text!r} must look like name=v1,v2,... (or name=lin:a:b:k, name=geom:a:b:k)")
    kind, _, rng = rest.partition(":")
    if kind in ("lin", "geom") and rng:
        import numpy as np

        try:
            a, b, k = rng.split(":")
            a, b, k = float(a), float(b), int(k)
            if k < 1 or (kind == "geom" and (a <= 0 or b <= 0)):
                raise ValueError
        except ValueError:
            raise SystemExit(f"pumpup: --param {text!r}: {kind}:a:b:k needs numbers a, b (> 0 for geom) and a "
                             "count k >= 1") from None
        return name, (np.linspace(a, b, k) if kind == "lin" else np.geomspace(a, b, k)).tolist()
    values = []
    for item in rest.split(","):
        item = item.strip()
        if not item:
            continue
        try:
            values.append(json.loads(item))
        except json.JSONDecodeError:
            values.append(item)
    return name, values


def cmd_sweep(args) -> int:
    import time

    import pumpup
    from pumpup.sweep import default_mu

    spec = parse_spec(args.spec)
    params: dict = {}
    for text in args.param:
        name, values = parse_values(text)
        if name in params:
            raise SystemExit(f"pumpup: --param {name!r} is given twice")
        params[name] = values
    pump = None
    if args.pump:
        g, _, levels = args.pump.partition(":")
        try:
            pump = {"g": g, "levels": int(levels) if levels else 1}
        except ValueError:
            raise SystemExit(f"pumpup: --pump {args.pump!r} must look like g2 or g2:LEVELS") from None
    if args.mu is None and args.n_mu < 2:
        raise SystemExit("pumpup: --n-mu must be at least 2")
    mu = args.mu if args.mu is not None else default_mu(args.n_mu)
    if args.scheduler and args.local:
        raise SystemExit("pumpup: give --scheduler ADDRESS or one of --threads/--processes/--serial, not both")
    t0 = time.perf_counter()
    try:
        ds = pumpup.sweep(spec, params, mu=mu, pump=pump, scheduler=args.scheduler or args.local,
                          workers=args.workers, chunks=args.chunk, out=args.out, rtol=args.rtol,
                          mean=not args.no_mean, maximum=not args.no_maximum)
    except (ValueError, OSError, TypeError) as exc:  # SpecError is a ValueError
        raise SystemExit(f"pumpup: {exc}") from None
    shape = " x ".join(f"{d} {n}" for d, n in ds["albedo"].sizes.items())
    print(f"wrote {args.out}: {shape} in {time.perf_counter() - t0:.1f} s")
    return 0


def cmd_mc(args) -> int:
    import numpy as np

    import pumpup

    f = _load(args.spec)
    mu = np.asarray(args.mu if args.mu else [1.0, 0.5, 0.1, 0.01], dtype=float)
    if args.n < 1:
        raise SystemExit(f"pumpup: --n must be >= 1, got {args.n}")
    rng = np.random.default_rng(args.seed)
    try:
        est, se = pumpup.mc_albedo(f, mu, args.n, rng, kind=args.strategy)
        a = pumpup.albedo(f, mu)
    except ValueError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    print(f"# {json.dumps(f.spec)}: {pumpup.sampling.strategy(f, float(mu[0]), args.strategy)}, "
          f"{args.n} samples per mu, seed {args.seed}")
    print(f"{'mu':>10s} {'Monte Carlo':>14s} {'std error':>10s} {'quadrature':>18s} {'(MC - q) / se':>14s}")
    worst = 0.0
    for m, v, s_, q in zip(mu, est, se, a):
        z = (v - q) / s_ if s_ > 0 else (0.0 if v == q else np.inf)
        worst = max(worst, abs(z))
        print(f"{m:10.6g} {v:14.8f} {s_:10.2g} {q:18.12f} {z:14.2f}")
    if args.chi2:
        from pumpup.testing import chi2_test

        views = np.stack([np.sqrt((1 - mu) * (1 + mu)), np.zeros_like(mu), mu], axis=-1)
        res = chi2_test(lambda wo, n, r: pumpup.sample(f, wo, n, r, kind=args.strategy),
                        lambda wi, wo: pumpup.sampling.pdf(f, wi, wo, kind=args.strategy), views, seed=args.seed)
        print(res)
        if not res.passed:
            return 1
    return 0 if worst < 4 else 1


def cmd_compensate(args) -> int:
    import os

    import numpy as np

    import pumpup

    def die(msg):  # a user error: one line on stderr, exit status 2
        print(f"pumpup: {msg}", file=sys.stderr)
        raise SystemExit(2)

    try:
        f = pumpup.load(parse_spec(args.spec))
    except SystemExit as exc:  # parse_spec's message
        die(str(exc.code).removeprefix("pumpup: "))
    except pumpup.SpecError as exc:
        die(str(exc))
    for name, v in (("--f0", args.f0), ("--f-avg", args.f_avg)):
        if v is not None and not 0.0 <= v <= 1.0:
            die(f"{name} must be in [0, 1], got {v:g}")
    if args.method in ("g1", "g2") and (args.f0 is not None or args.f_avg is not None):
        die(f"--method {args.method} (pumping) takes no --f0 or --f-avg")
    if args.method == "scale" and args.f_avg is not None:
        die("--f-avg belongs to --method kulla_conty; --method scale takes --f0")
    if args.out:
        d = os.path.dirname(os.path.abspath(args.out))
        if not os.path.isdir(d):
            die(f"cannot write {args.out!r}: directory {d!r} does not exist")
    kw = {}
    if args.f0 is not None:
        kw["f0"] = args.f0
    if args.f_avg is not None:
        kw["f_avg"] = args.f_avg
    try:
        c = pumpup.compensate(f, method=args.method, force=args.force, **kw)
    except pumpup.SpecError as exc:
        die(str(exc))
    print(f"# {json.dumps(c.spec)}")
    if hasattr(c, "report"):
        print(f"# {c.report()}")
    mu = np.array([1.0, 0.5, 0.1, 0.01, 1e-4])
    a0 = pumpup.albedo(f, mu)
    a1, e1 = pumpup.furnace(c, mu, return_error=True)
    print(f"{'mu':>8s} {'base albedo':>14s} {'compensated':>14s} {'error':>9s}   (furnace toward wo = mu)")
    for i, m in enumerate(mu):
        print(f"{m:8.2g} {a0[i]:14.10f} {a1[i]:14.10f} {e1[i]:9.2g}")
    if args.out:
        pumpup.save_compensated(c, args.out)
        print(f"wrote {args.out}")
    return 0


def cmd_render(args) -> int:
    """``pumpup render sphere|furnace``: every argument is checked (one line, status 2) before rendering."""
    import os

    import pumpup
    from pumpup import render

    def fail(msg: str) -> int:
        print(f"pumpup render {args.what}: {msg}", file=sys.stderr)
        return 2

    try:
        size = render.check_size(int(args.size) if args.size.strip().lstrip("+-").isdigit() else args.size)
        lights = [render.check_light(v) for v in args.light.split(",")] if args.what == "sphere" else []
        exposure = float(args.exposure)
        if not math.isfinite(exposure):
            raise ValueError(f"--exposure must be a finite number of stops, got {args.exposure!r}")
        irradiance = float(getattr(args, "irradiance", "1"))
        if not (math.isfinite(irradiance) and irradiance > 0):
            raise ValueError(f"--irradiance must be a finite number > 0, got {args.irradiance!r}")
    except ValueError as exc:
        msg = str(exc)
        if msg.startswith("could not convert"):
            msg = f"--exposure and --irradiance must be numbers: {msg}"
        return fail(msg.replace("size must", "--size must").replace("light angle", "--light angle"))
    models = []
    for text in args.spec:
        try:
            models.append(pumpup.load(parse_spec(text)))
        except SystemExit as exc:  # parse_spec's own message
            return fail(f"SPEC {text!r}: {str(exc.code).removeprefix('pumpup: ')}")
        except (pumpup.SpecError, ValueError, TypeError) as exc:
            return fail(f"SPEC {text!r} does not load: {exc}")
    if args.what == "furnace":
        for f, text in zip(models, args.spec):
            a = render._anisotropy(f)
            if a > render.ISOTROPY_TOL:
                return fail(f"SPEC {text!r} is anisotropic (f changes by {a:.2g} under a rotation about N): "
                            "its furnace radiance depends on the azimuth of V")
    try:
        render._openexr()
    except ImportError as exc:
        return fail(str(exc))
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        return fail(f"--out {args.out!r} exists and is not a directory")
    try:
        os.makedirs(args.out, exist_ok=True)
    except OSError as exc:
        return fail(f"--out {args.out!r}: {exc}")
    try:
        if args.what == "sphere":
            render.render_spheres(models, lights, size, args.out, exposure=exposure, irradiance=irradiance)
        else:
            render.render_furnaces(models, size, args.out, exposure=exposure)
    except (ValueError, OSError) as exc:  # SpecError is a ValueError
        return fail(str(exc))
    return 0


def cmd_render_scene(args) -> int:
    """``pumpup render scene NAME``: the papers' scenes path-traced by Mitsuba 3 (pumpup.scenes); every
    argument is checked (one line, status 2) before rendering; without mitsuba, the ``render`` extra is named."""
    import os

    from pumpup import scenes

    def fail(msg: str) -> int:
        print(f"pumpup render scene: {msg}", file=sys.stderr)
        return 2

    try:
        scenes.check_scene(args.name)
        spp = int(args.spp) if args.spp.strip().isdigit() else None
        if spp is None:
            raise ValueError(f"spp must be an integer number of samples per pixel >= 1, got {args.spp!r}")
        size = int(args.size) if args.size.strip().isdigit() else args.size
        exposure = float(args.exposure)
        if not math.isfinite(exposure):
            raise ValueError(f"--exposure must be a finite number of stops, got {args.exposure!r}")
        scenes.check_args(args.name, spp, size, args.variant)
    except ValueError as exc:
        msg = str(exc)
        if msg.startswith("could not convert"):
            msg = f"--exposure must be a number: {msg}"
        return fail(msg.replace("size must", "--size must").replace("spp must", "--spp must"))
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        return fail(f"--out {args.out!r} exists and is not a directory")
    try:
        import mitsuba as mi
    except ImportError:
        return fail("needs Mitsuba 3: install the render extra, pip install -e \".[render]\" "
                    "(or pip install \"pumpup[render]\")")
    rgb = [v for v in mi.variants() if v.endswith("_rgb")]  # the scenes' colours are RGB
    if args.variant != "auto" and args.variant not in rgb:
        return fail(f"--variant must be auto or one of {', '.join(rgb)}; got {args.variant!r}")
    try:
        os.makedirs(args.out, exist_ok=True)
        variant, rows, times = scenes.render_scene(args.name, spp, size, args.variant, progress=not args.quiet)
        paths = scenes.write_scene(args.name, rows, args.out, exposure=exposure, variant=variant, spp=spp)
    except (ValueError, OSError, ImportError) as exc:
        return fail(str(exc))
    print(f"variant {variant}; {len(times)} panels in {sum(times):.1f} s ("
          + ", ".join(f"{t:.1f}" for t in times) + " s each)")
    for p in paths:
        print(f"wrote {p}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="pumpup",
        description="Physically plausible BRDFs: accurate albedo, the albedo pumping-up operator, "
        "and the tables of Neumann, Neumann and Szirmay-Kalos.",
        epilog="A SPEC is JSON ('{\"type\": \"phong\", \"n\": 20}') or short ('phong:n=20'). "
        "'pumpup models' lists the types.",
    )
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("reproduce", help="regenerate the papers' tables and compare them with the published values")
    s.add_argument("--out", default="tables", help="output directory (default: tables)")
    s.add_argument("--only", nargs="+", metavar="NAME", help="only these: table2 table3 table4 text divergence")
    s.set_defaults(func=cmd_reproduce)
    s = sub.add_parser("models", help="list the registered model types and their parameters")
    s.set_defaults(func=cmd_models)
    s = sub.add_parser("albedo", help="directional albedo of a model, with error estimates")
    s.add_argument("spec")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--mu", type=float, nargs="+", help="cos(theta_i) values in (0, 1]")
    g.add_argument("--theta", type=float, nargs="+", help="incidence angles in degrees")
    s.add_argument("--rtol", type=float, default=1e-10)
    s.set_defaults(func=cmd_albedo)
    s = sub.add_parser("table", help="tabulate the albedo on an adaptive grid into a netCDF file")
    s.add_argument("spec")
    s.add_argument("--out", required=True)
    s.add_argument("--rtol", type=float, default=1e-10)
    s.set_defaults(func=cmd_table)
    s = sub.add_parser("pump", help="pump up a model's albedo (001 sec. 3) and print the albedo of every level")
    s.add_argument("spec")
    s.add_argument("--g", choices=("g1", "g2"), default="g1")
    s.add_argument("--levels", type=int, default=1)
    s.add_argument("--force", action="store_true", help="pump a base that is not reciprocal")
    s.add_argument("--out", help="save the pumped BRDF and its tables to this netCDF file")
    s.set_defaults(func=cmd_pump)
    s = sub.add_parser("figures", help="data and plots of 001 Figs. 3-7 and 000 Fig. 3 (takes minutes)")
    s.add_argument("--tables", default="tables")
    s.add_argument("--figures", default="figures")
    s.set_defaults(func=cmd_figures)
    s = sub.add_parser("divergence", help="albedo down to mu = 1e-8 and the fit a ~ K mu^-k (001 sec. 2.1); "
                                          "SPEC 'all' runs the whole analysis into tables/ and figures/")
    s.add_argument("spec")
    s.add_argument("--mu-min", type=float, default=1e-8)
    s.add_argument("--tables", default="tables")
    s.add_argument("--figures", default="tables")
    s.set_defaults(func=cmd_divergence)
    s = sub.add_parser("mc", help="Monte Carlo albedo by importance sampling (000 sec. 4) beside the quadrature; "
                                  "exit status 1 if they differ by 4 standard errors or more")
    s.add_argument("spec")
    s.add_argument("--mu", type=float, nargs="+", help="cos(theta_i) values in (0, 1]")
    s.add_argument("--n", type=int, default=1_000_000, help="samples per mu (default 1e6)")
    s.add_argument("--seed", type=int, default=0)
    s.add_argument("--strategy", choices=("lobe", "cosine"), default="lobe")
    s.add_argument("--chi2", action="store_true", help="also run the chi-square test of the sampler at these mu")
    s.set_defaults(func=cmd_mc)
    s = sub.add_parser("check", help="reciprocity and maximum albedo of a model")
    s.add_argument("spec")
    s.set_defaults(func=cmd_check)
    s = sub.add_parser("sweep", help="albedo tables over a grid of model parameters, in chunks on dask "
                                     "(resumable; a dask.distributed cluster with --scheduler)")
    s.add_argument("spec")
    s.add_argument("--param", action="append", required=True, metavar="NAME=VALUES",
                   help="a swept parameter: n=1,2,4 or n=geom:1:1000:64 or p=lin:0:1:64 (repeat for more)")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--mu", type=float, nargs="+", help="cos(theta_i) values in (0, 1]")
    g.add_argument("--n-mu", type=int, default=257, help="else this many mu, theta uniform in [0, 90) deg (default 257)")
    s.add_argument("--pump", metavar="G[:LEVELS]", help="pump each cell's model first, e.g. g2:2")
    s.add_argument("--out", required=True, help="netCDF file, or a zarr store if it ends in .zarr; "
                                                "finished chunks wait in OUT.parts/ so a rerun resumes")
    s.add_argument("--scheduler", metavar="ADDRESS", help="a dask.distributed scheduler, e.g. tcp://host:8786")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--threads", dest="local", action="store_const", const="threads", help="local threads (default)")
    g.add_argument("--processes", dest="local", action="store_const", const="processes", help="local processes")
    g.add_argument("--serial", dest="local", action="store_const", const="synchronous", help="one cell at a time")
    s.add_argument("--workers", type=int, help="local threads or processes (default: one per core)")
    s.add_argument("--chunk", type=int, help="cells per chunk along the last parameter (default 8)")
    s.add_argument("--rtol", type=float, default=1e-10)
    s.add_argument("--no-mean", action="store_true", help="skip the mean albedo")
    s.add_argument("--no-maximum", action="store_true", help="skip the maximum constant")
    s.set_defaults(func=cmd_sweep)
    s = sub.add_parser("compensate", help="energy compensation: Kulla-Conty lobe, 1/E scaling (not reciprocal), or "
                                          "pumping g1/g2; prints the furnace and saves the BRDF with its tables")
    s.add_argument("spec")
    s.add_argument("--method", choices=("kulla_conty", "scale", "g1", "g2"), default="kulla_conty")
    s.add_argument("--f0", type=float, help="Fresnel F0 in [0, 1] (scale: Turquin's F0; kulla_conty: Schlick F_avg)")
    s.add_argument("--f-avg", type=float, help="kulla_conty: the Fresnel average F_avg in [0, 1]")
    s.add_argument("--force", action="store_true", help="accept a base that is not reciprocal")
    s.add_argument("--out", help="save the compensated BRDF and its tables to this netCDF file")
    s.set_defaults(func=cmd_compensate)
    s = sub.add_parser("render", help="exact images of a sphere: Lewis's directional-light test (002 Fig. 2) "
                                      "and the white furnace (pixel = albedo)")
    render_sub = s.add_subparsers(dest="what", required=True)
    r = render_sub.add_parser("sphere", help="orthographic unit sphere under one directional light at Phi_L "
                                             "from the view: radiance = E f_r(L, V) cos(theta_L)")
    r.add_argument("spec", nargs="+", help="one or more model specs (one row of the grid each)")
    r.add_argument("--light", default="0,30,60,80", help="Phi_L values in [0, 180) degrees, comma-separated "
                                                        "(default 0,30,60,80)")
    r.add_argument("--irradiance", default="1", help="E, irradiance on a surface facing the light (default 1)")
    r.add_argument("--size", default="256", help="pixels per side, >= 8 (default 256)")
    r.add_argument("--exposure", default="0", help="PNG tone map: radiance x 2^EXPOSURE, sRGB; default 0")
    r.add_argument("--out", required=True, help="directory for the EXR and PNG files and sphere_grid.png")
    r.set_defaults(func=cmd_render)
    r = render_sub.add_parser("furnace", help="the sphere in a white furnace: pixel = albedo a(mu_V) "
                                              "(one albedo table per model, its error bound reported)")
    r.add_argument("spec", nargs="+", help="one or more isotropic model specs")
    r.add_argument("--size", default="256", help="pixels per side, >= 8 (default 256)")
    r.add_argument("--exposure", default="0", help="PNG tone map: radiance x 2^EXPOSURE, sRGB; default 0")
    r.add_argument("--out", required=True, help="directory for the EXR and PNG files and furnace_grid.png")
    r.set_defaults(func=cmd_render)
    r = render_sub.add_parser("scene", help="the papers' scenes path-traced by Mitsuba 3 with the pumpup plugin, "
                                            "original and stretched or pumped side by side (needs the render extra)")
    r.add_argument("name", help="000-fig8, 000-fig9 or 001-fig8")
    r.add_argument("--spp", default="64", help="samples per pixel (default 64)")
    r.add_argument("--size", default="256", help="pixels per side, >= 8 (default 256)")
    r.add_argument("--variant", default="auto", help="Mitsuba variant, or auto: llvm_ad_rgb if it runs here, "
                                                     "else scalar_rgb (default auto)")
    r.add_argument("--exposure", default="0", help="PNG tone map: radiance x 2^EXPOSURE, sRGB; default 0")
    r.add_argument("--out", default="scenes", help="directory for NAME.png and the panels' EXR (default scenes)")
    r.add_argument("--quiet", action="store_true", help="no progress lines")
    r.set_defaults(func=cmd_render_scene)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
