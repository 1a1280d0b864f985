"""Speed of the pumpup Mitsuba plugin: sample() + eval() against Mitsuba's built-in ``roughconductor`` (GGX, alpha
0.3) measured in the same run, in an llvm variant and in scalar_rgb.

    python scripts/bench/bench_mitsuba.py [--n 1048576] [--rounds 9] [--threads 0] [--eval-at light|sample]
                                          [--scalar-n 20000] [--baseline OLD_MITSUBA_PY] [--models ggx,...]
                                          [--parts]

llvm: per round, every model in turn (alternating, so that the shared machine's load hits all alike): one wide call of
sample() and one of eval(), evaluated together (kernels compiled in a warm-up round, not timed).  eval() runs at other
directions than sample() returned, uniform on the hemisphere (``--eval-at light``, the default), as a path tracer
calls them: sample() for the next bounce, eval() towards a light.  ``--eval-at sample`` evaluates at the sampled
directions instead; then Dr.Jit computes what sample() and eval() share once, in one kernel, which favours a BSDF
whose sample() weight is its eval() (pumpup's plugin, a Python BSDF traced by Dr.Jit) over one whose sample() computes
something else (roughconductor's weight F G1), and no renderer calls them that way.  Timed in CPU seconds of the
process, which a loaded machine disturbs less than wall time.  By default (``--threads 0``) Dr.Jit runs the kernels on
the calling thread alone, so that CPU time is the kernels' work: with worker threads, a worker that waits for work
spins first, and that spinning (a few ms per call, whatever the model, counted in some rounds and not in others) made
the CPU time of a 2^20-sample call up to twice its work.  The ns column and the ratio column are both medians over the
rounds (the ratio to roughconductor is taken within each round), printed beside the target of issue 55 (the plugin
within 1.3 x of roughconductor, a pumped model within 1.5 x).  ``--baseline`` loads another copy of
``pumpup/mitsuba.py`` (e.g. ``git show main:pumpup/mitsuba.py > /tmp/old.py``) as a second plugin and prints its
ratios beside, measured in the same rounds.  scalar: a Python loop of single calls (both sides pay Python's per-call
cost).  The load average is printed with the numbers.

``--parts`` shows where a pumped model's time goes: for each of :data:`PARTS`, a copy of ``pumpup/mitsuba.py`` with one
part of the look-up taken out is measured beside the plugin, as ``--baseline`` measures a file (the values of those
copies are wrong; only their cost matters).  ``--cost-models`` measures, the same way, copies that look g up as the
plugin does not (:data:`COST_MODELS`): the cost of other designs, for the chains looked up level by level in cells.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import statistics
import time

import numpy as np

BASELINE = ("roughconductor", {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3})

#: (key, label, pumpup spec, target ratio to roughconductor)
MODELS = [
    ("ggx", "GGX alpha 0.3", {"type": "ggx", "alpha": 0.3}, 1.3),
    ("phong", "Phong n 20", {"type": "phong", "n": 20}, 1.3),
    ("pumped-phong-2", "2-level g2 pumped Phong n 20",
     {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2", "levels": 2}, 1.5),
    ("pumped-phong-3", "3-level g2 pumped Phong n 20",
     {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2", "levels": 3}, 1.5),
    ("pumped-ggx-1", "1-level g2 pumped GGX alpha 0.3",
     {"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}, "g": "g2", "levels": 1}, 1.5),
    ("pumped-ggx-2", "2-level g2 pumped GGX alpha 0.3",
     {"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}, "g": "g2", "levels": 2}, 1.5),
    ("pumped-ggx-3", "3-level g2 pumped GGX alpha 0.3",
     {"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}, "g": "g2", "levels": 3}, 1.5),
]


#: ``--parts``: (label, [(text of pumpup/mitsuba.py, what replaces it), ...]) -- the pumped value without g (the base,
#: its rounding down and the mask: what the look-up adds to is left); the tables' cells and rows read (the level
#: table's for both cosines, the product table's for the larger, the fixed cells' coefficients of _CellPolynomials) with
#: only a sum of what was read in place of the polynomials, power laws and maxima; and the level-by-level path (pairs
#: with a cosine at or below the table's mlo, or in a fixed cell whose quartic misses) left out
PARTS = [
    ("g = 1", [("val = _div(val, self.g(wl[2], v[2])) * self.ROUND_DOWN", "val = val * self.ROUND_DOWN")]),
    ("table reads only", [
        ("        ri, ro = self.rows(self.cells(mi_)), self.rows(self.cells(mo))\n",
         "        ri, ro = self.rows(self.cells(mi_)), self.rows(self.cells(mo))\n"
         "        acc = ri[0] + ro[0]\n"
         "        for x in ri[1:] + ro[1:]:\n"
         "            acc = acc + x\n"
         "        return 1.0 + 1e-30 * acc\n"),
        ("        return _horner(row, 0, d, (m - row[d + 1]) * row[d + 2])\n",
         "        acc = row[0]\n"
         "        for x in row[1:]:\n"
         "            acc = acc + x\n"
         "        return 1.0 + 1e-30 * acc\n"),
        ("            u = _horner(row, 0, deg, t)\n",
         "            u = 1.0 + 1e-30 * sum(row[1:], row[0])\n")]),
    ("no level-by-level path", [
        ("        return dr.if_stmt((mi_, mo, g), slow, lambda a, b, g: by_levels(a, b), lambda a, b, g: g)\n",
         "        return g\n")]),
]
#: the floor of a look-up by rows of pieces: the table reads with the cell's read left out (the piece index computed
#: from the cosine's bits alone), and with only the first 64-byte packet of each row read (as if every level's
#: coefficients fitted in one packet)
PARTS += [
    ("row reads, no cell read", PARTS[1][1] + [
        ("        if self.fine is not None:  # two-level",
         "        return dr.minimum(c, len(self.lo_np) - 2)\n        if self.fine is not None:  # two-level")]),
    ("one packet per row, no cell read", PARTS[1][1] + [
        ("        if self.fine is not None:  # two-level",
         "        return dr.minimum(c, len(self.lo_np) - 2)\n        if self.fine is not None:  # two-level"),
        ("        for j in range(self.packets):\n", "        for j in range(1):\n")]),
]

#: ``--cost-models``: (label, changes) -- look-ups of g by level-by-level cells (pumped GGX) that the plugin does not
#: take, their cost measured with random or truncated values: each function read as a quadratic (three coefficients
#: per function and cosine in place of five, from the same cells: the reads a looser bound than LIFT would need), and
#: a split table as pumpup's numpy path has it (g = F(mmin) H(mmax) whatever the number of levels: one pattern read
#: per pair from a 256 x 256 grid of (mmin, mmax), then two functions of the pair's pattern from the cells: 4 look-ups
#: per sample and eval() in place of 3 per level; the cells of pairs whose pattern changes inside, which would need
#: more, left out)
COST_MODELS = [
    ("three reads per function", [
        ("            row = [dr.gather(mi.Float64, self.dr, base + (j * (deg + 1) + r)) for r in range(deg + 1)]\n"
         "            u = _horner(row, 0, deg, t)\n",
         "            row = [dr.gather(mi.Float64, self.dr, base + (j * (deg + 1) + r)) for r in range(3)]\n"
         "            u = _horner(row, 0, 2, t)\n")]),
    ("split table: a pattern, then F(mmin) H(mmax)", [
        ("        g = self._levels(self.cells(mi_), self.cells(mo), mmax, dr.maximum, self.controlled)\n",
         "        if not hasattr(self, '_pattern'):\n"
         "            rng = np.random.default_rng(1)\n"
         "            self._pattern = mi.UInt32(rng.integers(0, 4, 256 * 257 // 2).astype(np.uint32))\n"
         "        mmin = dr.minimum(mi_, mo)\n"
         "        i = mi.UInt32(dr.minimum(mi.Int32(mmin * 256.0), 255))\n"
         "        k = mi.UInt32(dr.minimum(mi.Int32(mmax * 256.0), 255))\n"
         "        p = dr.gather(mi.UInt32, self._pattern, ((k * (k + 1)) >> 1) + i)\n"
         "        (ca, ta), (cb, tb) = self.cells._cell_dr(mmin), self.cells._cell_dr(mmax)\n"
         "        width = self.cells.nfun * 5\n"
         "        fa = ca * width + ((p & 1) * 5 if width > 5 else 0)\n"
         "        fb = cb * width + ((p >> 1) * 5 if width > 5 else 0)\n"
         "        ra = [dr.gather(mi.Float64, self.cells.dr, fa + r) for r in range(5)]\n"
         "        rb = [dr.gather(mi.Float64, self.cells.dr, fb + r) for r in range(5)]\n"
         "        return _horner(ra, 0, 4, ta) * _horner(rb, 0, 4, tb)\n")]),
]


def _part_file(label: str, changes) -> str:
    """A copy of pumpup/mitsuba.py with each (old, new) of ``changes`` made (a temporary file's path)."""
    import tempfile

    import pumpup.mitsuba as pm

    with open(pm.__file__) as fh:
        text = fh.read()
    for old, new in changes:
        if old not in text:
            raise SystemExit(f"bench_mitsuba: {label!r}: pumpup/mitsuba.py no longer holds {old.strip()!r}")
        text = text.replace(old, new, 1)
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as tmp:
        tmp.write(text)
    return tmp.name


def _load_baseline(path):
    """Another copy of pumpup/mitsuba.py as a module of the pumpup package, its plugin registered as
    ``pumpup_baseline`` (for the current variant; a later call registers its own in its place).
    """
    import mitsuba as mi

    spec = importlib.util.spec_from_file_location("pumpup._bench_baseline_mitsuba", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    cls = mod._plugin_class()
    mi.register_bsdf("pumpup_baseline", lambda props: cls(props))
    return mod


def hemisphere(rng, n: int) -> np.ndarray:
    """``n`` directions uniform on the upper hemisphere, (n, 3): where eval() looks, as towards a light."""
    d = rng.normal(size=(n, 3))
    d[:, 2] = np.abs(d[:, 2])
    return d / np.linalg.norm(d, axis=1)[:, None]


def _bsdf(pm, spec, plugin="pumpup"):
    import json

    import mitsuba as mi

    if spec["type"] == "roughconductor":
        return mi.load_dict(spec)
    return mi.load_dict({"type": plugin, "spec": json.dumps(spec)})


def bench_llvm(pm, models, n, rounds, baseline, threads=0, eval_at="light"):
    """CPU and wall seconds of sample() + eval() per round for roughconductor and every model (and its baseline),
    with Dr.Jit's thread pool set to ``threads`` (0: the calling thread alone) for the duration; eval() at
    ``eval_at`` ("light": other directions, "sample": the sampled ones).
    """
    import drjit as dr

    before = dr.thread_count()
    dr.set_thread_count(threads)
    try:
        return _rounds(pm, models, n, rounds, baseline, eval_at)
    finally:
        dr.set_thread_count(before)


def _rounds(pm, models, n, rounds, baseline, eval_at="light"):
    import drjit as dr
    import mitsuba as mi

    rng = np.random.default_rng(1)
    u = rng.random((3, n)).astype(np.float32)
    ctx = mi.BSDFContext()
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(math.sin(0.6), 0.0, math.cos(0.6))
    s1, s2 = mi.Float(u[0]), mi.Point2f(mi.Float(u[1]), mi.Float(u[2]))
    light = None
    if eval_at == "light":  # directions uniform on the upper hemisphere
        light = mi.Vector3f(*[mi.Float(x.astype(np.float32)) for x in hemisphere(rng, n).T])
    dr.eval(s1, s2, si)
    runs = [("roughconductor", _bsdf(pm, BASELINE[1]))]
    for key, _, spec, _ in models:
        runs.append((key, _bsdf(pm, spec)))
        if baseline:
            runs.append((key + " (baseline)", _bsdf(pm, spec, "pumpup_baseline")))
    cpu = {k: [] for k, _ in runs}
    wall = {k: [] for k, _ in runs}
    for r in range(rounds + 1):
        for key, b in runs:
            w0, c0 = time.perf_counter(), time.process_time()
            bs, w = b.sample(ctx, si, s1, s2)
            v = b.eval(ctx, si, bs.wo if light is None else light)
            dr.eval(bs, w, v)
            dr.sync_thread()
            if r > 0:  # round 0 compiles the kernels
                cpu[key].append(time.process_time() - c0)
                wall[key].append(time.perf_counter() - w0)
    return cpu, wall


def _report_llvm(models, cpu, wall, n, baseline, label="baseline"):
    rc_cpu, rc_wall = cpu["roughconductor"], wall["roughconductor"]
    head = ("| model | ns CPU per sample (median of rounds) | ratio to roughconductor (CPU, median of rounds) "
            "| wall ratio | target |")
    if baseline:
        head += f" {label} ratio (CPU) | this / {label} (CPU) |"
    print(head)
    print("|---" * (head.count("|") - 1) + "|")
    print(f"| roughconductor GGX 0.3 (built-in) | {1e9 * statistics.median(rc_cpu) / n:.2f} | 1 | 1 | |"
          + (" | |" if baseline else ""))
    for key, label, _, target in models:
        ratio = statistics.median(a / b for a, b in zip(cpu[key], rc_cpu))
        wratio = statistics.median(a / b for a, b in zip(wall[key], rc_wall))
        met = "met" if ratio <= target else "missed"
        line = (f"| {label} | {1e9 * statistics.median(cpu[key]) / n:.2f} | {ratio:.2f} x | {wratio:.2f} x "
                f"| <= {target} x, {met} |")
        if baseline:
            old = statistics.median(a / b for a, b in zip(cpu[key + " (baseline)"], rc_cpu))
            new_old = statistics.median(a / b for a, b in zip(cpu[key], cpu[key + " (baseline)"]))
            line += f" {old:.2f} x | {new_old:.3f} |"
        print(line)


def bench_scalar(pm, models, n):
    """Samples per CPU second of a Python loop of single sample() + eval() calls, printed as a table."""
    import mitsuba as mi

    rng = np.random.default_rng(1)
    u = rng.random((n, 3))
    light = hemisphere(rng, n)  # eval() towards other directions
    out = []
    for label, spec in [("roughconductor GGX 0.3 (built-in)", BASELINE[1])] + [(m[1], m[2]) for m in models]:
        b = _bsdf(pm, spec)
        ctx = mi.BSDFContext()
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(math.sin(0.6), 0.0, math.cos(0.6))
        b.sample(ctx, si, 0.5, mi.Point2f(0.5, 0.5))
        t0 = time.process_time()
        for (a, c, d), e in zip(u, light):
            bs, w = b.sample(ctx, si, float(a), mi.Point2f(float(c), float(d)))
            b.eval(ctx, si, mi.Vector3f(*e))
        out.append((label, n / (time.process_time() - t0)))
    base = out[0][1]
    print("| model | samples/s (sample + eval) | ratio to roughconductor |\n|---|---|---|")
    for label, rate in out:
        print(f"| {label} | {rate:.3g} | {base / rate:.2f} x |")


def main(argv=None):
    """Run the llvm rounds (and the scalar loop) and print the tables with the load average."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1 << 20, help="samples per llvm call")
    ap.add_argument("--rounds", type=int, default=9, help="timed llvm rounds (all models in each)")
    ap.add_argument("--threads", type=int, default=0,
                    help="Dr.Jit threads for the llvm rounds (0: the calling thread alone, CPU time = work)")
    ap.add_argument("--eval-at", choices=("light", "sample"), default="light",
                    help="eval() at other directions than sample() returned, as towards a light (default), or at "
                         "the sampled ones (then Dr.Jit shares their work in one kernel)")
    ap.add_argument("--scalar-n", type=int, default=20000, help="samples in the scalar loop (0: skip scalar)")
    ap.add_argument("--baseline", help="another copy of pumpup/mitsuba.py to measure beside (llvm)")
    ap.add_argument("--parts", action="store_true", help="measure copies of the plugin with parts of the look-up "
                    "taken out (PARTS), each beside the plugin in a run of its own")
    ap.add_argument("--cost-models", action="store_true", help="measure copies of the plugin that look g up in "
                    "other ways (COST_MODELS), each beside the plugin in a run of its own")
    ap.add_argument("--models", help="comma-separated keys of the models to run (default all): "
                    + ", ".join(m[0] for m in MODELS))
    args = ap.parse_args(argv)
    models = MODELS
    if args.models:
        keys = args.models.split(",")
        unknown = [k for k in keys if k not in {m[0] for m in MODELS}]
        if unknown:
            ap.error(f"--models: unknown key(s) {', '.join(unknown)}; known: {', '.join(m[0] for m in MODELS)}")
        models = [m for m in MODELS if m[0] in keys]
    import pumpup
    import pumpup.mitsuba as pm

    for _, _, spec, _ in models:  # the albedo tables first (built once, not timed)
        f = pumpup.load(spec)
        f.eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))
    print(f"load average before: {os.getloadavg()}")
    ok, why = pm.probe("llvm_ad_rgb")
    if ok:
        pm.register("llvm_ad_rgb")
        where = 'other directions (as towards a light)' if args.eval_at == 'light' else 'the sampled ones'
        copies = (PARTS if args.parts else []) + (COST_MODELS if args.cost_models else [])
        runs = [(_part_file(label, changes), label) for label, changes in copies] if copies else \
            [(args.baseline, "baseline")]
        for path, label in runs:
            if path:
                _load_baseline(path)
                if copies:  # (a temporary copy: loaded, it is no longer needed)
                    os.unlink(path)
            print(f"\nllvm_ad_rgb, {args.n} samples per call, {args.rounds} rounds, {args.threads} Dr.Jit worker "
                  f"threads, eval() at {where}" + (f"; beside: {label}" if path else ""))
            cpu, wall = bench_llvm(pm, models, args.n, args.rounds, bool(path), args.threads, args.eval_at)
            _report_llvm(models, cpu, wall, args.n, bool(path), label)
    else:
        print(f"llvm_ad_rgb skipped: {why}")
    if args.scalar_n > 0:
        pm.register("scalar_rgb")
        print(f"\nscalar_rgb, {args.scalar_n} single calls")
        bench_scalar(pm, models, args.scalar_n)
    print(f"\nload average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
