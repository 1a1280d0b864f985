"""The ``pumpup`` command line.  Heavy imports happen inside the commands, so ``--help`` is fast.

This module is over 1,000 lines because it is one function per command with its argument parser, sharing the
argument checks and the one place where errors become exit codes.
"""

from __future__ import annotations

import _thread
import argparse
import json
import math
import os
import signal
import sys
import threading


def parse_spec(text: str) -> dict:
    """A model spec from JSON (``'{"type": "phong", "n": 20}'``) or the short form ``phong:n=20,c=1``
    (:func:`pumpup.core.parse_spec`; a bad one exits with its one-line message).
    """
    from pumpup.core import SpecError
    from pumpup.core import parse_spec as _parse

    try:
        return _parse(text)
    except SpecError as exc:
        raise SystemExit(f"pumpup: {exc}") from None


def _load(text: str, spectral: bool = False):
    """The model of a SPEC argument, or of a saved BRDF file (``pumpup pump --out``, ``pumpup compensate --out``) read
    without recomputing its tables; a spectral one (a 'material' or per-wavelength lists, pumpup.spectral) only where
    the command prints or writes per wavelength (``spectral=True``).
    """
    import os

    import pumpup

    try:
        f = _load_file(text) if os.path.isfile(text) else pumpup.load(parse_spec(text))
    except pumpup.SpecError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    if getattr(f, "is_spectral", False) and not spectral:
        raise SystemExit(f"pumpup: {SPECTRAL_REFUSED}")
    return f


def _load_file(path: str):
    """The BRDF saved in the file at ``path`` (its reader by the file's kind), or exit with one line saying what the
    file is.
    """
    import pumpup
    from pumpup.tables import SAVED_BRDF_READERS, saved_kind
    from pumpup.tables.validate import TableError

    try:
        kind = saved_kind(path)
        reader = SAVED_BRDF_READERS.get(kind)
        if reader is None:
            raise SystemExit(f"pumpup: {path!r} is not a saved BRDF ({kind or 'a file of no known kind'}): a SPEC is a "
                             "model spec or a file written by 'pumpup pump --out' or 'pumpup compensate --out'")
        return getattr(pumpup, reader.removeprefix("pumpup."))(path)
    except (TableError, OSError) as exc:
        raise SystemExit(f"pumpup: {_one_line(exc)}") from None


#: the one line of a command that takes single-channel models only, given a spectral spec
SPECTRAL_REFUSED = ("this command takes a single-channel model; a spectral spec (a 'material', 'wavelengths' or "
                    "per-wavelength lists) works with albedo, table and pump")


class UsageError(SystemExit):
    """A user error (or an interruption): its one line is already on stderr; the exit status is
    ``code`` (2, or 130 after Ctrl-C).  ``str()`` gives the message.
    """

    def __init__(self, message: str, code: int = 2):
        super().__init__(code)
        self.message = message

    def __str__(self) -> str:
        return self.message


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def check_out(path: str, option: str = "--out") -> None:
    """Exit with one line naming ``path`` unless a file can be written there (checked before any work:
    :func:`pumpup.tables.check_output_path`; a ``.zarr`` store may be a directory).
    """
    import os

    from .tables import check_output_path

    try:
        if path.rstrip("/").endswith(".zarr"):  # a store is a directory: its parent must take it
            check_output_path(path.rstrip("/") + ".probe")
        else:
            check_output_path(path)
    except OSError as exc:
        raise SystemExit(f"pumpup: {option} {path}: {exc}") from None
    if os.path.exists(path) and not os.path.isdir(path) and not os.access(path, os.W_OK):
        raise SystemExit(f"pumpup: {option} {path}: the file is not writable")


def check_out_dir(path: str, option: str = "--out") -> None:
    """Exit with one line naming ``path`` unless it is a writable directory or can be made one: the
    nearest existing ancestor is a writable directory (checked before any work).
    """
    import os

    if os.path.exists(path):
        if not os.path.isdir(path):
            raise SystemExit(f"pumpup: {option} {path}: exists and is not a directory")
        if not os.access(path, os.W_OK):
            raise SystemExit(f"pumpup: {option} {path}: directory is not writable")
        return
    ancestor = os.path.dirname(os.path.abspath(path))
    while not os.path.exists(ancestor):
        ancestor = os.path.dirname(ancestor)
    if not os.path.isdir(ancestor):
        raise SystemExit(f"pumpup: {option} {path}: cannot be made: {ancestor!r} is not a directory")
    if not os.access(ancestor, os.W_OK):
        raise SystemExit(f"pumpup: {option} {path}: cannot be made: directory {ancestor!r} is not writable")


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

    text = re.sub(r":[a-z]+:`~?([^`]*)`",
                  lambda m: m.group(1).rsplit(".", 1)[-1] if "~" in m.group(0) else m.group(1), text)
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
        m = (re.search(r"return\s+(.*?)(\s+#.*)?$", src.strip(), re.S)
             or re.search(r"lambda\s+\w+\s*:\s*(.*?)[,)]*$", src))
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
    """``pumpup models``: every registered type with its summary and its parameters' ranges, defaults and meanings;
    status 0.
    """
    import pumpup

    rows = []
    for name, cls in pumpup.registry().items():
        doc = _plain_text((cls.__doc__ or "").strip().splitlines()[0]) if cls.__doc__ else ""
        params = [(k, p.range_text() if p.kind in ("float", "int", "floats") or p.choices else p.kind,
                   default_text(p), _plain_text(p.doc)) for k, p in cls.params.items()]
        rows.append((name, doc, params))
    w = [max([len(r[c]) for _, _, ps in rows for r in ps] + [len(h)])
         for c, h in enumerate(("name", "range", "default"))]
    print(f"    {'parameter':{w[0]}s}  {'range':{w[1]}s}  {'default':{w[2]}s}  meaning")
    for name, doc, params in rows:
        print(f"{name}: {doc}")
        for k, rng, dflt, meaning in params:
            print(f"    {k:{w[0]}s}  {rng:{w[1]}s}  {dflt:{w[2]}s}  {meaning}".rstrip())
    return 0


def cmd_albedo(args) -> int:
    """``pumpup albedo SPEC``: the albedo and its error estimate at each mu (``--mu``, ``--theta`` or a default set),
    per wavelength for a spectral model and per azimuth with ``--phi``; status 0.
    """
    import numpy as np

    import pumpup

    if args.theta is not None:
        bad = [t for t in args.theta if not 0 <= t < 90]
        if bad:
            raise SystemExit(f"pumpup: --theta {bad[0]:g}: the incidence angle theta must be in [0, 90) degrees")
    f = _load(args.spec, spectral=True)
    if args.theta is not None:
        mu = np.sin(np.radians(90.0 - np.asarray(args.theta, dtype=float)))  # keeps its digits near 90 deg
    else:
        mu = np.asarray(args.mu if args.mu else [1.0, 0.5, 0.1, 0.01], dtype=float)
    if getattr(f, "is_spectral", False):
        return _albedo_spectral(f, mu, args)
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


def _no_phi(args) -> None:
    if getattr(args, "phi", None) is not None:
        raise SystemExit("pumpup: --phi: a spectral metal or plastic is isotropic; its albedo does not depend on phi")


def _albedo_spectral(f, mu, args) -> int:
    """``pumpup albedo`` of a spectral model: one row per (mu, wavelength)."""
    import numpy as np

    import pumpup

    _no_phi(args)
    try:
        a, e = pumpup.albedo(f, mu, return_error=True, rtol=args.rtol)
    except ValueError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    print(f"# {json.dumps(f.spec)}")
    print(f"{'mu':>14s} {'theta [deg]':>14s} {'wavelength [nm]':>16s} {'albedo':>20s} {'error':>10s}")
    for i, m in enumerate(mu):
        for j, w in enumerate(f.wavelengths):
            print(f"{m:14.8g} {np.degrees(np.arccos(m)):14.8f} {w:16.6g} {a[i, j]:20.15f} {e[i, j]:10.2g}")
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
    """``pumpup table SPEC --out FILE``: the albedo tabulated on an adaptive grid (over wavelengths for a spectral
    model, over ``--phi`` for an anisotropic one) and written as netCDF; status 0.
    """
    import numpy as np

    import pumpup

    check_out(args.out)
    f = _load(args.spec, spectral=True)
    if getattr(f, "is_spectral", False):  # one table with dims (mu, wavelength)
        _no_phi(args)
        try:
            ds = pumpup.tabulate(f, rtol=args.rtol)
        except ValueError as exc:
            raise SystemExit(f"pumpup: {exc}") from None
        pumpup.write_table(ds, args.out)
        print(f"wrote {args.out}: {ds.sizes['mu']} values of mu x {ds.sizes['wavelength']} wavelengths, "
              f"interpolation error {float(ds['interpolation_error'].max()):.2g} (the largest)")
        return 0
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
    """``pumpup check SPEC``: the reciprocity check, a compensated model's report, and the maximum albedo with the
    maximum constant; status 0 if reciprocal, else 1.
    """
    import pumpup

    f = _load(args.spec)
    r = pumpup.check_reciprocity(f)
    print(r)
    if hasattr(f, "report"):  # a compensated BRDF (pumpup.compensate): its E table and bounds
        print(f.report())
    m = pumpup.max_albedo(f)
    print(f"max albedo (constant set to 1): {m}")
    return 0 if r.reciprocal else 1


def cmd_pump(args) -> int:
    """``pumpup pump SPEC``: the model pumped up ``--levels`` times with ``--g``, the albedo of every level at each mu
    (per wavelength for a spectral model), and the pumped BRDF saved with ``--out``; status 0.
    """
    import numpy as np

    import pumpup
    from pumpup.operators.pumping import MAX_LEVELS

    if not 1 <= args.levels <= MAX_LEVELS:
        raise SystemExit(f"pumpup: --levels: levels must be an integer in [1, {MAX_LEVELS}], got {args.levels}")
    if args.out:
        check_out(args.out)
    f = _load(args.spec, spectral=True)
    try:
        p = pumpup.pump(f, g=args.g, levels=args.levels, force=args.force)
    except pumpup.SpecError as exc:
        raise SystemExit(f"pumpup: {exc}") from None
    mu = np.array([1.0, 0.5, 0.1, 0.01, 1e-4])
    if getattr(p, "is_spectral", False):  # one row per (mu, wavelength), every level's albedo
        print(f"{'mu':>8s} {'wavelength':>10s} "
              + " ".join(f"{'level ' + str(k):>12s}" for k in range(args.levels + 1)))
        per = []  # per wavelength: the albedo of levels 0..L, each of shape mu.shape
        for m in p.models:
            chain = m.chain()  # innermost first
            per.append([pumpup.albedo(chain[0].base, mu)] + [pumpup.albedo(lev, mu) for lev in chain])
        for i, mv in enumerate(mu):
            for j, w in enumerate(p.wavelengths):
                print(f"{mv:8.2g} {w:10.6g} " + " ".join(f"{v[i]:12.9f}" for v in per[j]))
        if args.out:
            pumpup.save_pumped(p, args.out)
            print(f"wrote {args.out}")
        return 0
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
    """``pumpup figures``: the pumping figures' data into ``--tables`` and their plots into ``--figures``; status 0."""
    from .figures import make_figures

    check_out(args.tables.rstrip("/") + "/x", "--tables")
    check_out(args.figures.rstrip("/") + "/x", "--figures")
    for path in make_figures(args.tables, args.figures):
        print("wrote", path)
    return 0


def cmd_reproduce(args) -> int:
    """``pumpup reproduce``: the papers' tables regenerated into ``--out`` and compared with the published values;
    prints the report; status 0.
    """
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
    """``pumpup divergence SPEC``: the albedo down to ``--mu-min`` and the fit a ~ K mu^-k (001 sec. 2.1); SPEC ``all``
    writes the whole analysis (netCDF and plot); status 0.
    """
    from pumpup.core import check_open_unit

    from .divergence import analysis_dataset, divergence, plot
    from .tables.provenance import write_generated

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
    """``pumpup sweep SPEC --param ...``: albedo tables over a grid of parameters (pumped with ``--pump``), computed in
    chunks on dask and written to ``--out``; status 0.
    """
    import time

    import pumpup
    from pumpup.sweeps import default_mu

    spec = parse_spec(args.spec)
    from pumpup.core import is_spectral_spec

    if is_spectral_spec(spec):
        raise SystemExit(f"pumpup: {SPECTRAL_REFUSED}")
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
    """``pumpup mc SPEC``: the Monte Carlo albedo by importance sampling beside the quadrature at each mu, and with
    ``--chi2`` a chi-square test of the sampler against its density; status 1 if an estimate is 4 standard errors or
    more off, or the test fails, else 0.
    """
    import numpy as np

    import pumpup

    f = _load(args.spec)
    mu = np.asarray(args.mu if args.mu else [1.0, 0.5, 0.1, 0.01], dtype=float)
    if not 1 <= args.n <= pumpup.sampling.MAX_SAMPLES:
        raise SystemExit(f"pumpup: --n must be an integer in [1, {pumpup.sampling.MAX_SAMPLES:.0e}], got {args.n}")
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
    """``pumpup compensate SPEC``: the model energy-compensated by ``--method``, its furnace toward wo = mu beside the
    base's albedo, and the compensated BRDF saved with ``--out``; user errors exit with status 2.
    """
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
    if getattr(f, "is_spectral", False):
        die(SPECTRAL_REFUSED)
    for name, v in (("--f0", args.f0), ("--f-avg", args.f_avg)):
        if v is not None and not 0.0 <= v <= 1.0:
            die(f"{name} must be in [0, 1], got {v:g}")
    if args.method in ("g1", "g2") and (args.f0 is not None or args.f_avg is not None):
        die(f"--method {args.method} (pumping) takes no --f0 or --f-avg")
    if args.method == "scale" and args.f_avg is not None:
        die("--f-avg belongs to --method kulla_conty; --method scale takes --f0")
    if args.out:
        check_out(args.out)
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


def cmd_fit(args) -> int:
    """``pumpup fit TARGET``: the fit of a model family to a target (:func:`_fit`); user errors are one line on stderr,
    status 2.
    """
    try:
        return _fit(args)
    except SystemExit as exc:  # user errors: one line on stderr, status 2
        if isinstance(exc.code, str):
            print(exc.code, file=sys.stderr)
            raise SystemExit(2) from None
        raise


def _fit(args) -> int:
    import pumpup
    from pumpup.fitting import plot_fits

    if args.out:
        check_out(args.out)
    target = _load(args.target)
    params, fixed = {}, {}
    for item in args.param:
        name, eq, rng = item.partition("=")
        lo, colon, hi = rng.partition(":")
        try:
            if not (eq and colon):
                raise ValueError
            params[name.strip()] = (float(lo), float(hi))
        except ValueError:
            raise SystemExit(f"pumpup: --param {item!r} must look like NAME=LO:HI, e.g. n=1:10000") from None
    for item in args.fixed or []:
        name, eq, value = item.partition("=")
        if not eq:
            raise SystemExit(f"pumpup: --fixed {item!r} must look like NAME=VALUE, e.g. p=1")
        try:
            fixed[name.strip()] = json.loads(value)
        except json.JSONDecodeError:
            fixed[name.strip()] = value.strip()
    ties = {}
    for item in args.tie or []:
        name, eq, src = item.partition("=")
        if not eq:
            raise SystemExit(f"pumpup: --tie {item!r} must look like NAME=OTHER, e.g. cy=cx")
        ties[name.strip()] = src.strip()
    pump = None
    if args.pump:
        g, _, levels = args.pump.partition(":")
        try:
            pump = {"g": g, "levels": int(levels or 1)}
        except ValueError:
            raise SystemExit(f"pumpup: --pump {args.pump!r} must look like G[:LEVELS], e.g. g2:2") from None
    methods = ("perceptual", "least_squares") if args.method == "both" else (args.method,)
    results = []
    for m in methods:
        try:
            r = pumpup.fit(target, args.family, params=params, fixed=fixed, pump=pump, ties=ties, method=m,
                           weights=(args.w_brdf, args.w_albedo), lobe_fraction=args.lobe_fraction, mu_min=args.mu_min)
        except (pumpup.SpecError, ValueError, TypeError) as exc:
            raise SystemExit(f"pumpup: {exc}") from None
        print(r)
        results.append(r)
    if args.out:
        try:
            plot_fits(results, args.out)
        except OSError as exc:
            raise SystemExit(f"pumpup: {exc}") from None
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
        lights = [render.check_light(v, from_text=True) for v in args.light.split(",")] if args.what == "sphere" else []
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
    try:
        check_out_dir(args.out)
    except SystemExit as exc:
        return fail(str(exc.code).removeprefix("pumpup: "))
    models = []
    for text in args.spec:
        try:
            models.append(pumpup.load(parse_spec(text)))
        except SystemExit as exc:  # parse_spec's own message
            return fail(f"SPEC {text!r}: {str(exc.code).removeprefix('pumpup: ')}")
        except (pumpup.SpecError, ValueError, TypeError) as exc:
            return fail(f"SPEC {text!r} does not load: {exc}")
        if getattr(models[-1], "is_spectral", False):
            return fail(f"SPEC {text!r}: {SPECTRAL_REFUSED}")
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


def _lut_fail(msg: str) -> int:
    print(f"pumpup: {msg}", file=sys.stderr)
    return 2


def cmd_lut(args) -> int:
    """``pumpup lut``: a renderer's albedo look-up table of ``--preset``, computed and written to ``--out``, with its
    quadrature, storage and look-up errors; status 1 if the look-up error exceeds ``--max-lookup-error``, 2 for a bad
    argument, else 0.
    """
    import pumpup
    from pumpup import luts

    if args.preset not in luts.PRESETS:
        return _lut_fail(f"--preset must be one of {', '.join(luts.PRESETS)}; got {args.preset!r}")
    p = luts.PRESETS[args.preset]
    want = {"c": (".h", ".c", ".tables", ".inc", ".txt"), "filament": (".inc", ".h", ".txt"), "npy": (".npy",),
            "netcdf": (".nc",), "exr": (".exr",)}[p.fmt]
    if not args.out.endswith(want):
        return _lut_fail(f"--out for preset {p.name} must end in {' or '.join(want)}; got {args.out!r}")
    check_out(args.out)
    try:
        ds = pumpup.lut(args.model, preset=args.preset, rtol=args.rtol, lookup_check=not args.no_lookup_check,
                        max_lookup_error=args.max_lookup_error, eavg=False if args.no_eavg else None)
    except luts.LutError as exc:
        print(f"pumpup: {exc}", file=sys.stderr)
        return 1
    except (pumpup.SpecError, ValueError, TypeError) as exc:
        return _lut_fail(str(exc))
    try:
        luts.write_lut(ds, args.out)
    except OSError as exc:
        return _lut_fail(str(exc))
    a = ds.attrs
    print(f"wrote {args.out}: {p.renderer} {ds.sizes['mu']} x {ds.sizes['rough']} table of {a['spec']}")
    print(f"  quadrature error at the nodes <= {a['quadrature_error']:.2g} ({a['nodes_over_tolerance']} node(s) "
          f"above rtol); storage ({a['storage']}) rounds by {a['quantisation_error']:.2g} (bound "
          f"{a['quantisation_bound']:.2g})")
    if "E_avg_error" in a:
        print(f"  E_avg error <= {a['E_avg_error']:.2g}")
    if "lookup_error" in a:
        print(f"  the renderer's look-up: max error {a['lookup_error']:.3g} at mu = {a['lookup_error_mu']:.6g}, "
              f"rough = {a['lookup_error_rough']:.6g} (rms {a['lookup_error_rms']:.2g}; {a['lookup_domain']})")
    return 0


def cmd_audit(args) -> int:
    """``pumpup audit FILE --preset NAME`` or ``--conventions FILE.toml``: a shipped albedo table graded against
    pumpup's values (:func:`pumpup.audit`), read as a preset or a description says; status 1 beyond ``--tol`` or
    ``--max-lookup-error``, 2 for a bad argument, a wrong description or a file that does not match it, else 0.
    """
    import pumpup
    from pumpup import luts

    if (args.preset is None) == (args.conventions is None):
        return _lut_fail("give --preset NAME or --conventions FILE.toml (one of them)")
    if args.preset is not None and args.preset not in luts.PRESETS:
        return _lut_fail(f"--preset must be one of {', '.join(luts.PRESETS)}; got {args.preset!r}")
    if args.conventions is not None:
        from pumpup.conventions import ConventionsError, load_conventions

        try:  # the description is checked before the file is read
            conventions = load_conventions(args.conventions)
        except ConventionsError as exc:
            return _lut_fail(str(exc))
    else:
        conventions = None
    for name in ("tol", "max_lookup_error"):
        v = getattr(args, name)
        if v is not None and not v > 0:
            return _lut_fail(f"--{name.replace('_', '-')} must be > 0, got {v}")
    if args.png:
        check_out(args.png, "--png")
    try:
        res = pumpup.audit(args.file, preset=args.preset, model=args.model, conventions=conventions, rtol=args.rtol,
                           lookup_check=not args.no_lookup_check, png=args.png, eavg=not args.no_eavg)
    except (luts.LutError, pumpup.SpecError, ValueError, TypeError, OSError) as exc:
        return _lut_fail(str(exc))
    print(res.report())
    if args.png:
        print(f"  error map: {args.png}")
    if not res.ok(args.tol, args.max_lookup_error):
        what = []
        if args.tol is not None and res.max_abs > args.tol:
            what.append(f"node error {res.max_abs:.3g} > --tol {args.tol:g} at {res.labels[0]} = "
                        f"{res.where_abs[0]:.6g}, {res.labels[1]} = {res.where_abs[1]:.6g}")
        if args.max_lookup_error is not None and res.lookup and res.lookup["max_abs"] > args.max_lookup_error:
            lk = res.lookup
            what.append(f"look-up error {lk['max_abs']:.3g} > --max-lookup-error {args.max_lookup_error:g} at "
                        f"{res.labels[0]} = {lk['where'][0]:.6g}, {res.labels[1]} = {lk['where'][1]:.6g}")
        print("pumpup: table fails: " + "; ".join(what), file=sys.stderr)
        return 1
    return 0


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (the usage is one ``--help`` away); exit status 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {_one_line(message)} (see {self.prog} --help)\n")


def cmd_shader(args) -> int:
    """``pumpup shader SPEC --target T [--out FILE]``: shader source with the tables baked in (:func:`pumpup.shader`),
    written atomically to ``--out`` or printed; status 2 and one line for a bad argument or an unsupported model.
    """
    from . import shaders

    if args.target not in shaders.TARGETS:
        raise SystemExit(f"pumpup: --target must be one of {', '.join(shaders.TARGETS)}; got {args.target!r}")
    if args.out:
        check_out(args.out)
    f = _load(args.model, spectral=True)
    command = shaders.command_line(args.model, args.target, args.out)
    if args.out:
        shaders.write_shader(f, args.target, args.out, command=command)
        print(f"wrote {args.out}: {args.target} shader of {json.dumps(f.spec)}")
    else:
        sys.stdout.write(shaders.shader(f, target=args.target, command=command))
    return 0


def cmd_render_scene(args) -> int:
    """``pumpup render scene NAME``: the papers' scenes path-traced by Mitsuba 3 (pumpup.scenes); every
    argument is checked (one line, status 2) before rendering; without mitsuba, the ``render`` extra is named.
    """
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
    try:
        check_out_dir(args.out)
    except SystemExit as exc:
        return fail(str(exc.code).removeprefix("pumpup: "))
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


def _budget_option(s) -> None:
    s.add_argument("--max-seconds", type=float, default=None, metavar="S",
                   help="stop with one line after S seconds instead of running on (default: no bound)")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``pumpup`` command, one subcommand per ``cmd_*`` function (its ``func`` default)."""
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
                                                            "costs (default: all but costs)")
    s.set_defaults(func=cmd_reproduce)
    s = sub.add_parser("models", help="list the registered model types and their parameters")
    s.set_defaults(func=cmd_models)
    s = sub.add_parser("warmup", help="compile pumpup's kernels for this machine ahead of time (once; later "
                                      "processes load them from numba's cache)")
    s.add_argument("--quiet", action="store_true", help="no progress lines (default: one per step, on stderr)")
    s.set_defaults(func=cmd_warmup)
    s = sub.add_parser("albedo", help="directional albedo of a model, with error estimates")
    _budget_option(s)
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. phong:n=20")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--mu", type=float, nargs="+", help="cos(theta_i) values in (0, 1] (default: 1 0.5 0.1 0.01)")
    g.add_argument("--theta", type=float, nargs="+", help="incidence angles in degrees, in [0, 90) (default: use --mu)")
    s.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance of the cubature (default: 1e-10)")
    s.add_argument("--phi", type=float, nargs="+", metavar="DEG",
                   help="azimuths of the light in DEGREES from the tangent x axis (default: 0, the xz-plane); "
                        "anisotropic models depend on it, isotropic ones do not")
    s.set_defaults(func=cmd_albedo)
    s = sub.add_parser("table", help="tabulate the albedo on an adaptive grid into a netCDF file")
    _budget_option(s)
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. phong:n=20")
    s.add_argument("--out", required=True, help="the netCDF file to write (required; its directory must exist)")
    s.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance of every value (default: 1e-10)")
    s.add_argument("--phi", type=float, nargs="+", metavar="DEG",
                   help="tabulate over (mu, phi) at these azimuths of the light in DEGREES (default: a table over "
                        "mu at phi = 0)")
    s.set_defaults(func=cmd_table)
    s = sub.add_parser("pump", help="pump up a model's albedo (001 sec. 3) and print the albedo of every level")
    _budget_option(s)
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
    _budget_option(s)
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. phong:n=20")
    s.add_argument("--param", action="append", required=True, metavar="NAME=VALUES",
                   help="a swept parameter: n=1,2,4 or n=geom:1:1000:64 or p=lin:0:1:64 (required; repeat for more)")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--mu", type=float, nargs="+", help="cos(theta_i) values in (0, 1] (default: use --n-mu)")
    g.add_argument("--n-mu", type=int, default=257,
                   help="else this many mu, theta uniform in [0, 90) deg (default 257)")
    s.add_argument("--pump", metavar="G[:LEVELS]", help="pump each cell's model first, e.g. g2:2 (default: no pumping)")
    s.add_argument("--out", required=True, help="netCDF file, or a zarr store if it ends in .zarr; "
                                                "finished chunks wait in OUT.parts/ so a rerun resumes (required)")
    s.add_argument("--scheduler", metavar="ADDRESS", help="a dask.distributed scheduler, e.g. tcp://host:8786 "
                                                          "(default: local threads)")
    g = s.add_mutually_exclusive_group()
    g.add_argument("--threads", dest="local", action="store_const", const="threads", help="local threads (default)")
    g.add_argument("--processes", dest="local", action="store_const", const="processes",
                   help="local processes (default: threads)")
    g.add_argument("--serial", dest="local", action="store_const", const="synchronous",
                   help="one cell at a time (default: threads)")
    s.add_argument("--workers", type=int, help="local threads or processes (default: one per core)")
    s.add_argument("--chunk", type=int, help="cells per chunk along the last parameter (default 8)")
    s.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance of the albedo values (default: 1e-10)")
    s.add_argument("--no-mean", action="store_true", help="skip the mean albedo (default: computed)")
    s.add_argument("--no-maximum", action="store_true", help="skip the maximum constant (default: computed)")
    s.add_argument("--overwrite", action="store_true", help="replace OUT (and discard OUT.parts/) when they hold "
                                                            "a different sweep (default: refuse)")
    s.set_defaults(func=cmd_sweep)
    s = sub.add_parser("compensate", help="energy compensation: Kulla-Conty lobe, 1/E scaling (not reciprocal), or "
                                          "pumping g1/g2; prints the furnace and saves the BRDF with its tables")
    _budget_option(s)
    s.add_argument("spec", help="a model SPEC: JSON or short, e.g. ggx:alpha=0.3")
    s.add_argument("--method", choices=("kulla_conty", "scale", "g1", "g2"), default="kulla_conty",
                   help="the compensation (default: kulla_conty)")
    s.add_argument("--f0", type=float,
                   help="Fresnel F0 in [0, 1] (scale: Turquin's F0; kulla_conty: Schlick F_avg) (default: none)")
    s.add_argument("--f-avg", type=float, help="kulla_conty: the Fresnel average F_avg in [0, 1] (default: 1)")
    s.add_argument("--force", action="store_true", help="accept a base that is not reciprocal (default: refuse)")
    s.add_argument("--out", help="save the compensated BRDF and its tables to this netCDF file (default: not saved)")
    s.set_defaults(func=cmd_compensate)
    s = sub.add_parser("render", help="exact images of a sphere: Lewis's directional-light test (002 Fig. 2) "
                                      "and the white furnace (pixel = albedo)")
    render_sub = s.add_subparsers(dest="what", required=True, help="sphere or furnace")
    r = render_sub.add_parser("sphere", help="orthographic unit sphere under one directional light at Phi_L "
                                             "from the view: radiance = E f_r(L, V) cos(theta_L)")
    r.add_argument("spec", nargs="+", help="one or more model specs (one row of the grid each)")
    r.add_argument("--light", default="0,30,60,80", help="Phi_L values in [0, 180) degrees, comma-separated "
                                                        "(default 0,30,60,80)")
    r.add_argument("--irradiance", default="1", help="E, irradiance on a surface facing the light (default 1)")
    r.add_argument("--size", default="256", help="pixels per side, >= 8 (default 256)")
    r.add_argument("--exposure", default="0", help="PNG tone map: radiance x 2^EXPOSURE, sRGB (default: 0)")
    r.add_argument("--out", required=True, help="directory for the EXR and PNG files and sphere_grid.png (required)")
    r.set_defaults(func=cmd_render)
    r = render_sub.add_parser("furnace", help="the sphere in a white furnace: pixel = albedo a(mu_V) "
                                              "(one albedo table per model, its error bound reported)")
    r.add_argument("spec", nargs="+", help="one or more isotropic model specs")
    r.add_argument("--size", default="256", help="pixels per side, >= 8 (default 256)")
    r.add_argument("--exposure", default="0", help="PNG tone map: radiance x 2^EXPOSURE, sRGB (default: 0)")
    r.add_argument("--out", required=True, help="directory for the EXR and PNG files and furnace_grid.png (required)")
    r.set_defaults(func=cmd_render)
    s = sub.add_parser("lut", help="a renderer's albedo look-up table, computed exactly, with its node, storage and "
                                   "look-up errors")
    _budget_option(s)
    s.add_argument("model", nargs="?", default="ggx", help="ggx (default), beckmann, or a spec such as "
                                                           "ggx:shadowing=separable")
    s.add_argument("--preset", required=True, help="cycles, filament, filament-centred, appleseed, bsdl, mitsuba, "
                                                  "netcdf, exr (required)")
    s.add_argument("--out", required=True, help="the table file (.h for C arrays, .inc, .npy, .nc, .exr) (required)")
    s.add_argument("--rtol", type=float, help="quadrature tolerance of the nodes (default 1e-8; 1e-6 for half floats)")
    s.add_argument("--max-lookup-error", type=float,
                   help="fail (status 1, saying where) above this look-up error (default: no limit)")
    s.add_argument("--no-lookup-check", action="store_true",
                   help="skip the look-up error between the nodes (default: measured)")
    s.add_argument("--no-eavg", action="store_true", help="skip E_avg (default: computed)")
    s.set_defaults(func=cmd_lut)
    s = sub.add_parser("shader", help="shader code of a model with its tables baked in: GLSL, GLSL ES, HLSL, Metal "
                                      "or a BRDF Explorer file")
    s.add_argument("model", help="a spec: a closed-form model, pumped or compensated (e.g. ggx:alpha=0.3)")
    s.add_argument("--target", default="glsl", help="glsl, glsl-es, hlsl, msl or brdf-explorer (default: glsl)")
    s.add_argument("--out", help="the file to write (atomically); default: standard output")
    s.set_defaults(func=cmd_shader)
    s = sub.add_parser("audit", help="grade a shipped albedo table against pumpup's truth (status 1 beyond --tol)")
    s.add_argument("file", help="the shipped table to audit")
    s.add_argument("--preset", help="cycles, filament, filament-centred, appleseed, bsdl, mitsuba, netcdf, exr "
                                    "(this or --conventions is required)")
    s.add_argument("--conventions", help="a TOML or JSON file describing the table (model, quantity, format, "
                                         "storage, shape, axes, look-up; see docs/user-guide/renderer-tables.md; "
                                         "this or --preset is required)")
    s.add_argument("--model", help="the model the table claims (default: ggx with the preset's Smith, or the "
                                   "conventions' model)")
    s.add_argument("--tol", type=float, help="fail (status 1) if a node is off by more than this (default: no limit)")
    s.add_argument("--max-lookup-error", type=float,
                   help="fail (status 1) if the look-up error exceeds this (default: no limit)")
    s.add_argument("--rtol", type=float, default=1e-7, help="quadrature tolerance of the truth (default 1e-7)")
    s.add_argument("--png", help="write an error map here (default: none)")
    s.add_argument("--no-lookup-check", action="store_true",
                   help="skip the look-up error between the nodes (default: measured)")
    s.add_argument("--no-eavg", action="store_true", help="skip the E_avg checks (default: checked)")
    s.set_defaults(func=cmd_audit)
    r = render_sub.add_parser("scene", help="the papers' scenes path-traced by Mitsuba 3 with the pumpup plugin, "
                                            "original and stretched or pumped side by side (needs the render extra)")
    r.add_argument("name", help="000-fig8, 000-fig9 or 001-fig8")
    r.add_argument("--spp", default="64", help="samples per pixel (default 64)")
    r.add_argument("--size", default="256", help="pixels per side, >= 8 (default 256)")
    r.add_argument("--variant", default="auto", help="Mitsuba variant, or auto: llvm_ad_rgb if it runs here, "
                                                     "else scalar_rgb (default auto)")
    r.add_argument("--exposure", default="0", help="PNG tone map: radiance x 2^EXPOSURE, sRGB (default: 0)")
    r.add_argument("--out", default="scenes", help="directory for NAME.png and the panels' EXR (default scenes)")
    r.add_argument("--quiet", action="store_true", help="no progress lines (default: progress shown)")
    r.set_defaults(func=cmd_render_scene)
    s = sub.add_parser("explore", help="look at BRDFs live in the browser: lobe, albedo, pumped and compensated, "
                                       "lit and furnace spheres (needs the 'explore' extra)")
    s.add_argument("spec", nargs="*", help="one to four model SPECs to open (default: phong:n=20)")
    s.add_argument("--port", type=int, default=8765, help="the port, 0 for a free one (default: 8765)")
    s.add_argument("--host", default="127.0.0.1",
                   help="the address to listen on; any host but this machine's prints a warning (default: 127.0.0.1)")
    s.add_argument("--no-browser", action="store_true", help="do not open the page in a browser (default: open it)")
    s.add_argument("--time-limit", type=float, default=60.0,
                   help="seconds one computation may take, in (0, 3600] (default: 60)")
    s.set_defaults(func=cmd_explore)
    s = sub.add_parser("fit", help="fit a model family to a target: max relative error of f cos(theta_L) and of "
                                   "the albedo (perceptual, 001 sec. 1.1) or least squares")
    s.add_argument("target", help="the target's SPEC, e.g. ggx:alpha=0.1")
    s.add_argument("--family", required=True, help="a model type, e.g. stretched_phong (required)")
    s.add_argument("--param", action="append", required=True, metavar="NAME=LO:HI",
                   help="a free parameter and its range, e.g. n=1:10000 (required; repeat for more)")
    s.add_argument("--fixed", action="append", metavar="NAME=VALUE",
                   help="a parameter held fixed, e.g. p=0.5 (default: the family's defaults)")
    s.add_argument("--tie", action="append", metavar="NAME=OTHER",
                   help="a parameter equal to another, e.g. cy=cx (default: none)")
    s.add_argument("--pump", metavar="G[:LEVELS]", help="fit the family pumped up, e.g. g2:2 (default: not pumped)")
    s.add_argument("--method", choices=("perceptual", "least_squares", "both"), default="perceptual",
                   help="the objective (default: perceptual)")
    s.add_argument("--w-brdf", type=float, default=1.0, help="weight of the point-light error (default 1)")
    s.add_argument("--w-albedo", type=float, default=1.0, help="weight of the albedo error (default 1)")
    s.add_argument("--lobe-fraction", type=float, default=0.1,
                   help="lobe region: f_t cos(theta_L) >= this fraction of its peak per view (default 0.1)")
    s.add_argument("--mu-min", type=float, default=0.05, help="smallest mu of the albedo and the views (default 0.05)")
    s.add_argument("--out", help="write the comparison figure (PNG) here (default: none)")
    s.set_defaults(func=cmd_fit)
    return p


def cmd_explore(args) -> int:
    """``pumpup explore``: serve the explorer until Ctrl-C (bad specs, a taken port or a missing extra: status 2)."""
    if len(args.spec) > 4:
        raise SystemExit(f"pumpup: explore takes at most 4 specs, got {len(args.spec)}")
    if not (0 <= args.port <= 65535):
        raise SystemExit(f"pumpup: --port must be in [0, 65535], got {args.port}")
    if not (math.isfinite(args.time_limit) and 0 < args.time_limit <= 3600):
        raise SystemExit(f"pumpup: --time-limit must be in (0, 3600] seconds, got {args.time_limit:g}")
    from . import explore

    explore.serve(args.spec or None, host=args.host, port=args.port, open_browser=not args.no_browser,
                  time_limit=args.time_limit)
    return 0


#: commands that compute nothing, so they never compile a kernel (no compile notice)
QUIET_COMMANDS = ("models", "warmup")


def cmd_warmup(args) -> int:
    """``pumpup warmup``: compile pumpup's kernels into numba's cache (progress on stderr unless
    ``--quiet``); status 0.
    """
    from .warmup import warmup

    seconds = warmup(progress=None if args.quiet else (lambda line: print(line, file=sys.stderr, flush=True)))
    print(f"pumpup's kernels are compiled for this machine ({seconds:.1f} s)")
    return 0


def _interrupted() -> UsageError:
    """The one line of Ctrl-C; later Ctrl-Cs are ignored while the process exits."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    print("pumpup: interrupted", file=sys.stderr, flush=True)
    return UsageError("pumpup: interrupted", 130)


def _closed_stdout() -> int:
    """Output piped into a reader that has gone (``pumpup models | head -1``): no error line, status 141
    (128 + SIGPIPE, as a shell tool killed by the broken pipe).  stdout goes to /dev/null so that the
    interpreter's last flush does not complain.
    """
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass
    return 141


def main(argv: list[str] | None = None, notify: bool = False) -> int:
    """Run one command.  A user error prints one line on stderr and exits with status 2 (raised as
    :class:`UsageError`, a SystemExit); Ctrl-C, at any moment of the run, prints one line and exits
    with 130.  The arguments are parsed before the library is imported.  Set PUMPUP_TRACEBACK=1 to
    see the traceback of an error instead.  ``notify``: before numba compiles a kernel that is not in its
    cache, say so in one line on stderr (when stderr is a terminal; the console script sets it).
    """
    debug = bool(os.environ.get("PUMPUP_TRACEBACK"))
    try:
        args = build_parser().parse_args(argv)
        if notify and args.command not in QUIET_COMMANDS and sys.stderr.isatty():
            from .warmup import notify_compiles

            notify_compiles()
        if getattr(args, "max_seconds", None) is not None:
            from .core.budget import time_budget

            if not args.max_seconds > 0 or args.max_seconds == float("inf"):
                raise SystemExit(f"pumpup: --max-seconds must be a number > 0 (seconds), got {args.max_seconds:g}")
            with time_budget(args.command, args.max_seconds, option="--max-seconds"):
                return args.func(args)
        return args.func(args)
    except UsageError:
        raise
    except KeyboardInterrupt:
        raise _interrupted() from None
    except BrokenPipeError:
        return _closed_stdout()
    except SystemExit as exc:
        if not isinstance(exc.code, str):
            raise
        message = _one_line(exc.code)
    except (ValueError, TypeError, OSError, ImportError) as exc:  # SpecError is a ValueError; ImportError: an extra
        if _PENDING_INTERRUPT or _caused_by_interrupt(exc):
            raise _interrupted() from None
        if debug:
            raise
        message = _one_line(f"pumpup: {exc}")
    try:
        print(message, file=sys.stderr)
    except KeyboardInterrupt:
        raise _interrupted() from None
    raise UsageError(message) from None


def _caused_by_interrupt(exc: BaseException) -> bool:
    """Whether a KeyboardInterrupt is in ``exc``'s chain: Ctrl-C while a C extension imports (numpy's import of
    datetime) surfaces as that module's ImportError.
    """
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


#: set when a Ctrl-C was swallowed in a callback from C: whatever the command does next (numba, its compile broken
#: off, may raise an error of its own before the interrupt arrives again), it ends as an interruption
_PENDING_INTERRUPT: list = []


def _redeliver_interrupts(hook):
    """An unraisable-exception hook that sends a KeyboardInterrupt on again instead of printing it: Ctrl-C that lands
    in a callback from C (llvmlite's, while numba compiles) cannot propagate there, and Python would print it as
    "Exception ignored" and go on.  The interrupt is sent again 10 ms later, from a timer thread, so that it arrives
    in ordinary Python code (and again, should it land in a callback once more).  Once a Ctrl-C has arrived, other
    unraisable errors are not printed either: they come from finalizers of objects the interrupt left half-built
    (llvmlite's ``ObjectRef.__del__`` of an object whose constructor it broke off), and the command ends as interrupted.
    """

    def unraisable(args) -> None:
        if args.exc_type is not None and issubclass(args.exc_type, KeyboardInterrupt):
            _PENDING_INTERRUPT.append(True)
            timer = threading.Timer(0.01, _thread.interrupt_main)
            timer.daemon = True
            timer.start()
            return
        if _PENDING_INTERRUPT:  # the interrupt's fallout: a finalizer of an object it broke off half-built (llvmlite's)
            return
        hook(args)

    return unraisable


def _record_interrupt(signum, frame) -> None:
    """Python's own SIGINT handler, raising KeyboardInterrupt, that also records the interrupt: a C extension whose
    import the KeyboardInterrupt lands in (numpy's ``PyCapsule_Import`` of datetime) may replace it by an ImportError
    that does not chain it, and the command must still end as interrupted.
    """
    _PENDING_INTERRUPT.append(True)
    raise KeyboardInterrupt


def console_main() -> None:
    """The ``pumpup`` console script: :func:`main`, then an exit in which a late Ctrl-C or a closed pipe
    prints nothing more (Ctrl-C is ignored once the command has finished and flushed its output).
    """
    try:
        sys.unraisablehook = _redeliver_interrupts(sys.unraisablehook)
        signal.signal(signal.SIGINT, _record_interrupt)
        code = main(notify=True)
        sys.stdout.flush()
        if _PENDING_INTERRUPT:
            raise KeyboardInterrupt
    except KeyboardInterrupt:
        code = _interrupted().code
    except BrokenPipeError:
        code = _closed_stdout()
    except SystemExit as exc:
        code = exc.code
    except Exception as exc:
        if not (_PENDING_INTERRUPT or _caused_by_interrupt(exc)):
            raise
        code = _interrupted().code
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    except ValueError:  # not the main thread
        pass
    sys.exit(code)


if __name__ == "__main__":
    console_main()
