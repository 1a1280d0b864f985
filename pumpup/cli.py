"""The ``pumpup`` command line.  Heavy imports happen inside the commands, so ``--help`` is fast."""

from __future__ import annotations

import argparse
import json
import sys


def parse_spec(text: str) -> dict:
    """A model spec from JSON (``'{"type": "phong", "n": 20}'``) or the short form ``phong:n=20,c=1``
    (:func:`pumpup.core.parse_spec`; a bad one exits with its one-line message)."""
    from pumpup.core import SpecError
    from pumpup.core import parse_spec as _parse

    try:
        return _parse(text)
    except SpecError as exc:
        raise SystemExit(f"pumpup: {exc}") from None


def _load(text: str):
    import pumpup

    try:
        return pumpup.load(parse_spec(text))
    except pumpup.SpecError as exc:
        raise SystemExit(f"pumpup: {exc}") from None


class UsageError(SystemExit):
    """A user error (or an interruption): its one line is already on stderr; the exit status is
    ``code`` (2, or 130 after Ctrl-C).  ``str()`` gives the message."""

    def __init__(self, message: str, code: int = 2):
        super().__init__(code)
        self.message = message

    def __str__(self) -> str:
        return self.message


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def check_out(path: str, option: str = "--out") -> None:
    """Exit with one line unless ``path`` can be written: its directory exists and is writable,
    and it is not itself a directory (checked before any work)."""
    import os

    directory = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(directory):
        raise SystemExit(f"pumpup: {option} {path}: directory {directory!r} does not exist")
    if not os.access(directory, os.W_OK):
        raise SystemExit(f"pumpup: {option} {path}: directory {directory!r} is not writable")
    if os.path.isdir(path) and not path.rstrip("/").endswith(".zarr"):
        raise SystemExit(f"pumpup: {option} {path}: is a directory")


def check_dir(path: str, option: str) -> None:
    """Exit with one line unless ``path`` is a writable directory."""
    import os

    if not os.path.isdir(path):
        raise SystemExit(f"pumpup: {option} {path}: directory does not exist (create it, or give {option} DIR)")
    if not os.access(path, os.W_OK):
        raise SystemExit(f"pumpup: {option} {path}: directory is not writable")


def _plain_text(text: str) -> str:
    """A docstring line without reST markup: ``x`` -> x, :func:`~a.b` -> b, *x* -> x."""
    import re

    text = re.sub(r":[a-z]+:`~?([^`]*)`", lambda m: m.group(1).rsplit(".", 1)[-1] if "~" in m.group(0) else m.group(1), text)
    text = re.sub(r"``([^`]*)``", r"\1", text)
    text = re.sub(r"(?<![\w*])\*([^*\s][^*]*)\*(?![\w*])", r"\1", text)
    return text


def default_text(param) -> str:
    """A Param's default for people: the value, 'required', 'none', or the formula of a computed one."""
    import inspect
    import re

    from pumpup.core import REQUIRED

    d = param.default
    if d is REQUIRED:
        return "required"
    if d is None:
        return "none"
    if callable(d):
        doc = (getattr(d, "__doc__", None) or "").strip()
        if doc:
            return _plain_text(doc.splitlines()[0])
        try:
            src = inspect.getsource(d)
        except (OSError, TypeError):
            return "computed"
        m = re.search(r"return\s+(.*?)(\s+#.*)?$", src.strip(), re.S) or re.search(r"lambda\s+\w+\s*:\s*(.*?)[,)]*$", src)
        if not m:
            return "computed"
        expr = m.group(1).strip().splitlines()[0]
        expr = re.sub(r"\w+\[[\"']([A-Za-z_]\w*)[\"']\]", r"\1", expr)  # p["n"] -> n
        expr = re.sub(r"\bmath\.|\bnp\.", "", expr)
        expr = re.sub(r"(\d)\.0\b", r"\1", expr)
        expr = re.sub(r"\[(.+?)\] \* len\((\w+)\)", r"\1 for each of \2", expr).replace(" * ", " ")
        return expr
    if isinstance(d, bool):
        return str(d).lower()
    if isinstance(d, float):
        return f"{d:g}"
    return str(d)


def cmd_models(args) -> int:
    import pumpup

    rows = []
    for name, cls in pumpup.registry().items():
        doc = _plain_text((cls.__doc__ or "").strip().splitlines()[0]) if cls.__doc__ else ""
        params = [(k, p.range_text() if p.kind in ("float", "int", "floats") or p.choices else p.kind,
                   default_text(p), _plain_text(p.doc)) for k, p in cls.params.items()]
        rows.append((name, doc, params))
    w = [max([len(r[c]) for _, _, ps in rows for r in ps] + [len(h)]) for c, h in enumerate(("name", "range", "default"))]
    print(f"    {'parameter':{w[0]}s}  {'range':{w[1]}s}  {'default':{w[2]}s}  meaning")
    for name, doc, params in rows:
        print(f"{name}: {doc}")
        for k, rng, dflt, meaning in params:
            print(f"    {k:{w[0]}s}  {rng:{w[1]}s}  {dflt:{w[2]}s}  {meaning}".rstrip())
    return 0


def cmd_albedo(args) -> int:
    import numpy as np

    import pumpup

    if args.theta is not None:
        bad = [t for t in args.theta if not 0 <= t < 90]
        if bad:
            raise SystemExit(f"pumpup: --theta {bad[0]:g}: the incidence angle theta must be in [0, 90) degrees")
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

    check_out(args.out)
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

    from pumpup.pump import MAX_LEVELS

    if not 1 <= args.levels <= MAX_LEVELS:
        raise SystemExit(f"pumpup: --levels: levels must be an integer in [1, {MAX_LEVELS}], got {args.levels}")
    if args.out:
        check_out(args.out)
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

    check_out(args.tables.rstrip("/") + "/x", "--tables")
    check_out(args.figures.rstrip("/") + "/x", "--figures")
    for path in make_figures(args.tables, args.figures):
        print("wrote", path)
    return 0


def cmd_reproduce(args) -> int:
    from .reproduce import reproduce

    try:  # reproduce checks (and creates) its output directory before any work
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
    from .provenance import write_generated

    from pumpup.core import check_open_unit

    try:
        check_open_unit("divergence", "--mu-min", args.mu_min)
    except ValueError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    if args.spec == "all":
        check_dir(args.tables, "--tables")
        check_dir(args.figures, "--figures")
        ds = analysis_dataset()
        write_generated(ds, f"{args.tables}/divergence.nc")
        plot(ds, f"{args.figures}/divergence.png")
        for i, name in enumerate(ds.model.values):
            print(f"{name:24s} {ds.verdict.values[i]:10s} k = {float(ds.k[i]):.5f} +- {float(ds.k_error[i]):.1g}")
        print(f"wrote {args.tables}/divergence.nc and {args.figures}/divergence.png")
        return 0
    r = divergence(_load(args.spec), mu_min=args.mu_min)
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
    check_out(args.out)
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
                          mean=not args.no_mean, maximum=not args.no_maximum, overwrite=args.overwrite)
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


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (the usage is one ``--help`` away); exit status 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {_one_line(message)} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(
        prog="pumpup",
        description="Physically plausible BRDFs: accurate albedo, the albedo pumping-up operator, "
        "and the tables of Neumann, Neumann and Szirmay-Kalos.",
        epilog="A SPEC is JSON ('{\"type\": \"phong\", \"n\": 20}') or short ('phong:n=20'). "
        "'pumpup models' lists the types.",
    )
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("reproduce", help="regenerate the papers' tables and compare them with the published values")
    s.add_argument("--out", default="tables", help="output directory (default: tables)")
    s.add_argument("--only", nargs="+", metavar="NAME", help="only these: table2 table3 table4 text divergence "
                                                            "(default: all)")
    s.set_defaults(func=cmd_reproduce)
    s = sub.add_parser("models", help="list the registered model types and their parameters")
    s.set_defaults(func=cmd_models)
    s = sub.add_parser("albedo", help="directional albedo of a model, with error estimates")
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. phong:n=20")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--mu", type=float, nargs="+", help="cos(theta_i) values in (0, 1] (default: 1 0.5 0.1 0.01)")
    g.add_argument("--theta", type=float, nargs="+", help="incidence angles in degrees, in [0, 90) (default: use --mu)")
    s.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance of the cubature (default: 1e-10)")
    s.set_defaults(func=cmd_albedo)
    s = sub.add_parser("table", help="tabulate the albedo on an adaptive grid into a netCDF file")
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. phong:n=20")
    s.add_argument("--out", required=True, help="the netCDF file to write (required; its directory must exist)")
    s.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance of every value (default: 1e-10)")
    s.set_defaults(func=cmd_table)
    s = sub.add_parser("pump", help="pump up a model's albedo (001 sec. 3) and print the albedo of every level")
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. phong:n=20")
    s.add_argument("--g", choices=("g1", "g2"), default="g1",
                   help="g1 = max(a(wi), a(wo)) (001 eq. 20) or the controlled g2 (001 eq. 21) (default: g1)")
    s.add_argument("--levels", type=int, default=1, help="nested pumpings, 1 to 64 (default: 1)")
    s.add_argument("--force", action="store_true", help="pump a base that is not reciprocal (default: refuse)")
    s.add_argument("--out", help="save the pumped BRDF and its tables to this netCDF file (default: not saved)")
    s.set_defaults(func=cmd_pump)
    s = sub.add_parser("figures", help="data and plots of 001 Figs. 3-7 and 000 Fig. 3 (takes minutes)")
    s.add_argument("--tables", default="tables", help="directory of the figure data, netCDF (default: tables)")
    s.add_argument("--figures", default="figures", help="directory of the plots, PNG (default: figures)")
    s.set_defaults(func=cmd_figures)
    s = sub.add_parser("divergence", help="albedo down to mu = 1e-8 and the fit a ~ K mu^-k (001 sec. 2.1); "
                                          "SPEC 'all' runs the whole analysis into tables/divergence.nc and "
                                          "tables/divergence.png")
    s.add_argument("spec", help="a model SPEC, or 'all' for the analysis of 001 sec. 2.1")
    s.add_argument("--mu-min", type=float, default=1e-8, help="smallest mu, in (0, 1) (default: 1e-8)")
    s.add_argument("--tables", default="tables", help="with 'all': directory of divergence.nc (default: tables)")
    s.add_argument("--figures", default="tables", help="with 'all': directory of divergence.png (default: tables)")
    s.set_defaults(func=cmd_divergence)
    s = sub.add_parser("mc", help="Monte Carlo albedo by importance sampling (000 sec. 4) beside the quadrature; "
                                  "exit status 1 if they differ by 4 standard errors or more")
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. phong:n=20")
    s.add_argument("--mu", type=float, nargs="+", help="cos(theta_i) values in (0, 1] (default: 1 0.5 0.1 0.01)")
    s.add_argument("--n", type=int, default=1_000_000, help="samples per mu (default: 1000000)")
    s.add_argument("--seed", type=int, default=0, help="seed of the random generator (default: 0)")
    s.add_argument("--strategy", choices=("lobe", "cosine"), default="lobe",
                   help="sample the model's lobe or the cosine-weighted hemisphere (default: lobe)")
    s.add_argument("--chi2", action="store_true", help="also run the chi-square test of the sampler at these mu "
                                                       "(default: off)")
    s.set_defaults(func=cmd_mc)
    s = sub.add_parser("check", help="reciprocity and maximum albedo of a model")
    s.add_argument("spec", help="a model SPEC")
    s.set_defaults(func=cmd_check)
    s = sub.add_parser("sweep", help="albedo tables over a grid of model parameters, in chunks on dask "
                                     "(resumable; a dask.distributed cluster with --scheduler)")
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. phong:n=20")
    s.add_argument("--param", action="append", required=True, metavar="NAME=VALUES",
                   help="a swept parameter: n=1,2,4 or n=geom:1:1000:64 or p=lin:0:1:64 (required; repeat for more)")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--mu", type=float, nargs="+", help="cos(theta_i) values in (0, 1] (default: use --n-mu)")
    g.add_argument("--n-mu", type=int, default=257, help="else this many mu, theta uniform in [0, 90) deg (default 257)")
    s.add_argument("--pump", metavar="G[:LEVELS]", help="pump each cell's model first, e.g. g2:2 (default: no pumping)")
    s.add_argument("--out", required=True, help="netCDF file, or a zarr store if it ends in .zarr; "
                                                "finished chunks wait in OUT.parts/ so a rerun resumes (required)")
    s.add_argument("--scheduler", metavar="ADDRESS", help="a dask.distributed scheduler, e.g. tcp://host:8786 "
                                                          "(default: local threads)")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--threads", dest="local", action="store_const", const="threads", help="local threads (default)")
    g.add_argument("--processes", dest="local", action="store_const", const="processes", help="local processes (default: threads)")
    g.add_argument("--serial", dest="local", action="store_const", const="synchronous", help="one cell at a time (default: threads)")
    s.add_argument("--workers", type=int, help="local threads or processes (default: one per core)")
    s.add_argument("--chunk", type=int, help="cells per chunk along the last parameter (default 8)")
    s.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance of the albedo values (default: 1e-10)")
    s.add_argument("--no-mean", action="store_true", help="skip the mean albedo (default: computed)")
    s.add_argument("--no-maximum", action="store_true", help="skip the maximum constant (default: computed)")
    s.add_argument("--overwrite", action="store_true", help="replace OUT (and discard OUT.parts/) when they hold "
                                                            "a different sweep (default: refuse)")
    s.set_defaults(func=cmd_sweep)
    return p


def main(argv: list[str] | None = None) -> int:
    """Run one command.  A user error prints one line on stderr and exits with status 2 (raised as
    :class:`UsageError`, a SystemExit); Ctrl-C prints one line and exits with 130.  Set
    PUMPUP_TRACEBACK=1 to see the traceback of an error instead."""
    import os

    from pumpup.core import SpecError

    args = build_parser().parse_args(argv)
    debug = bool(os.environ.get("PUMPUP_TRACEBACK"))
    try:
        return args.func(args)
    except UsageError:
        raise
    except SystemExit as exc:
        if not isinstance(exc.code, str):
            raise
        message = _one_line(exc.code)
    except KeyboardInterrupt:
        print("pumpup: interrupted", file=sys.stderr)
        raise UsageError("pumpup: interrupted", 130) from None
    except (SpecError, ValueError, TypeError, OSError) as exc:
        if debug:
            raise
        message = _one_line(f"pumpup: {exc}")
    print(message, file=sys.stderr)
    raise UsageError(message) from None


if __name__ == "__main__":
    sys.exit(main())
