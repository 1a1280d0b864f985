"""The ``pumpup`` command line.  Heavy imports happen inside the commands, so ``--help`` is fast."""

from __future__ import annotations

import argparse
import json
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
    if getattr(args, "phi", None) is not None:  # azimuths of the light in degrees: every mu at every phi
        return _albedo_phi(f, mu, args)
    try:
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=args.rtol)
    except ValueError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    print(f"# {json.dumps(f.spec)}")
    print(f"{'mu':>14s} {'theta [deg]':>14s} {'albedo':>20s} {'error':>10s}")
    for m, v, err in zip(mu, a, e):
        print(f"{m:14.8g} {np.degrees(np.arccos(m)):14.8f} {v:20.15f} {err:10.2g}")
    return 0


def _albedo_phi(f, mu, args) -> int:
    """``pumpup albedo --phi DEG...``: the albedo at every (mu, phi), phi in degrees."""
    import numpy as np

    import pumpup

    phi = np.asarray(args.phi, dtype=float)
    if not np.all(np.isfinite(phi)):
        raise SystemExit("pumpup: --phi must be finite angles in degrees")
    try:
        a, e = pumpup.albedo(f, mu[:, None], phi=np.radians(phi)[None, :], return_error=True, rtol=args.rtol)
    except ValueError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    print(f"# {json.dumps(f.spec)}" + ("" if f.azimuth_range() is not None else "  (isotropic: phi does not matter)"))
    print(f"{'mu':>14s} {'theta [deg]':>14s} {'phi [deg]':>10s} {'albedo':>20s} {'error':>10s}")
    for i, m in enumerate(mu):
        for j, p in enumerate(phi):
            print(f"{m:14.8g} {np.degrees(np.arccos(m)):14.8f} {p:10.4f} {a[i, j]:20.15f} {e[i, j]:10.2g}")
    return 0


def cmd_table(args) -> int:
    import numpy as np

    import pumpup

    f = _load(args.spec)
    phi = getattr(args, "phi", None)
    if phi is not None:
        if not np.all(np.isfinite(phi)):
            raise SystemExit("pumpup: --phi must be finite angles in degrees")
        phi = np.radians(np.asarray(phi, dtype=float))
    try:
        ds = pumpup.tabulate(f, rtol=args.rtol, phi=phi)
    except ValueError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    pumpup.write_table(ds, args.out)
    extra = f" x {ds.sizes['phi']} values of phi" if "phi" in ds.dims else ""
    print(f"wrote {args.out}: {ds.sizes['mu']} values of mu{extra}, "
          f"interpolation error {ds.attrs['interpolation_error']:.2g}")
    return 0


def cmd_check(args) -> int:
    import pumpup

    f = _load(args.spec)
    r = pumpup.check_reciprocity(f)
    print(r)
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
    s.add_argument("--phi", type=float, nargs="+", metavar="DEG",
                   help="azimuths of the light in DEGREES from the tangent x axis (default: 0, the xz-plane); "
                        "anisotropic models depend on it, isotropic ones do not")
    s.set_defaults(func=cmd_albedo)
    s = sub.add_parser("table", help="tabulate the albedo on an adaptive grid into a netCDF file")
    s.add_argument("spec")
    s.add_argument("--out", required=True)
    s.add_argument("--rtol", type=float, default=1e-10)
    s.add_argument("--phi", type=float, nargs="+", metavar="DEG",
                   help="tabulate over (mu, phi) at these azimuths of the light in DEGREES (default: a table over "
                        "mu at phi = 0)")
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
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
