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
    s = sub.add_parser("check", help="reciprocity and maximum albedo of a model")
    s.add_argument("spec")
    s.set_defaults(func=cmd_check)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
