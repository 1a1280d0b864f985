"""Where a pumped GGX shader's time goes on Mesa's llvmpipe: the shader of pumpup.shader timed beside variants of it
with one part of its look-up taken out (the results of those variants are wrong; only their cost matters).

    python scripts/bench/bench_shader_parts.py [--pairs 524288] [--repeat 9] [--g g1 g2]

Needs moderngl and an EGL driver.  llvmpipe rasterizes in this thread (``LP_NUM_THREADS=0``) and each draw is timed
by the thread's CPU time, every variant drawn once per round, best of the rounds; each line gives ns per pair and the
ratio to the base GGX shader measured in the same run.  The variants of the 3-level pumped GGX (alpha 0.3):

- ``g = 1``: the base, its bound and the final division, without the table;
- ``no search steps``: the piece is the cell's first candidate (the binary search's reads left out);
- ``no sub-cells``: the crowded cells' second read left out;
- ``no centre``: the piece's centre read left out (t from m and the octave alone);
- ``no coefficients``: every coefficient read replaced by arithmetic on the piece number;
- ``branch never taken``: the whole look-up inside an ``if`` that no pair takes (llvmpipe runs it anyway);
- ``coefficients from a texture`` / ``from a uniform buffer``: the same shader with the level table's coefficients read
  as 3 RGBA32F texels (``texelFetch``) or 3 vec4 of a std140 uniform block per cosine instead of 12 constant-array
  reads (the same values: checked equal to the full shader's, pair by pair);
- ``N reads``: the base GGX plus N reads from a constant array of 1,000 floats at an index computed from N.wi.
"""

from __future__ import annotations

import argparse
import functools
import os
import re
import sys
import time

import numpy as np

import pumpup
from pumpup.shaders import shader

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # bench_shader, beside this script
from bench_shader import Draws  # noqa: E402

GGX = {"type": "ggx", "alpha": 0.3}
def _function(src: str, name: str) -> tuple[int, int]:
    """The start and end of a GLSL function's definition in ``src``."""
    i = src.index(f"float {name}(float mi, float mo) {{")
    return i, src.index("\n}\n", i) + 3


def variants(lib: str) -> dict[str, str]:
    """The pumped shader ``lib`` and its variants (see the module's docstring)."""
    out = {"full": lib}
    i, j = _function(lib, "pumpup_g")
    out["g = 1"] = lib[:i] + "float pumpup_g(float mi, float mo) { return 1.0; }\n" + lib[j:]
    out["no search steps"] = re.sub(r"    i \+= pumpup_lt_b\[i \+ \d+\] <= m \? \d+ : 0;\n", "", lib)
    if "pumpup_lt_sub[" in lib:
        out["no sub-cells"] = re.sub(r"    i = i >= 0 \? i : pumpup_lt_sub\[.*\n", "", lib)
    out["no centre"] = re.sub(r"pumpup_lt_cen\[s[io]\]", "0.75", lib)
    out["no coefficients"] = re.sub(r"pumpup_lt_c\[b([io]) \+ (\d+)\]",
                                    lambda mm: f"(float(b{mm.group(1)}) * {0.001 * (int(mm.group(2)) + 1):.3f})", lib)
    body = lib[i:j].replace("float pumpup_g(float mi, float mo) {", "float pumpup_gfull(float mi, float mo) {")
    out["branch never taken"] = (lib[:i] + body + "float pumpup_g(float mi, float mo) {\n    float g = 1.0;\n"
                                 "    if (mi < -1.0) {\n        g = pumpup_gfull(mi, mo);\n    }\n    return g;\n}\n"
                                 + lib[j:])
    for name, src in list(out.items()):  # a pattern that no longer matches the shader would time it unchanged
        if name != "full" and src == lib:
            raise SystemExit(f"bench_shader_parts: the variant {name!r} no longer changes the shader")
    return out


def vec4_variants(lib: str) -> dict[str, tuple[str, np.ndarray]]:
    """The full shader with the level table's coefficients (``pumpup_lt_c``, 12 per piece) read as 3 vec4 per cosine
    from a texture or a uniform block, and those coefficients as (3 x pieces, 4) float32 rows.
    """
    m = re.search(r"const float pumpup_lt_c\[(\d+)\] = float\[\d+\]\((.*?)\);\n", lib, re.S)
    rows = np.array([float(x) for x in m.group(2).split(",")], np.float32).reshape(-1, 4)
    out = {}
    for name, decl, fetch in (
            ("coefficients from a texture", "uniform highp sampler2D pumpup_lt_tex;\n",
             "texelFetch(pumpup_lt_tex, ivec2(3 * s{side} + {k}, 0), 0)"),
            ("coefficients from a uniform buffer",
             f"layout(std140) uniform pumpup_lt_block {{ vec4 pumpup_lt_v[{len(rows)}]; }};\n",
             "pumpup_lt_v[3 * s{side} + {k}]")):
        src = lib[:m.start()] + decl + lib[m.end():]
        for side, b in (("i", "bi"), ("o", "bo")):
            line = f"    highp int {b} = 12 * s{side};\n"
            src = src.replace(line, line + "".join(f"    vec4 c{side}{k} = {fetch.format(side=side, k=k)};\n"
                                                   for k in range(3)))
            for k in range(12):
                src = src.replace(f"pumpup_lt_c[{b} + {k}]", f"c{side}{k // 4}.{'xyzw'[k % 4]}")
        if "pumpup_lt_c[" in src:
            raise SystemExit(f"bench_shader_parts: the variant {name!r} no longer replaces every coefficient read")
        out[name] = (src, rows)
    return out


def reads(base: str, n: int) -> str:
    """The base GGX library, divided by a sum of ``n`` reads from a constant array at an index computed from N.wi."""
    rng = np.random.default_rng(0)
    vals = ", ".join(f"{x:.6f}" for x in rng.uniform(0.5, 1.0, 1000))
    terms = " + ".join(f"pumpup_a[s + {r}]" for r in range(n)) or "1.0"
    i = base.index("float pumpup_brdf")
    return (base[:i] + f"const float pumpup_a[1000] = float[1000]({vals});\n"
            f"float pumpup_sum(float mi) {{\n    highp int s = int(mi * 900.0);\n    return {terms};\n}}\n"
            + base[i:].replace("return pumpup_base(wi, wo).x", "return pumpup_base(wi, wo).x / pumpup_sum(wi.z)"))


def main() -> None:
    """Time the variants and print where the time goes."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=1 << 19)
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("--g", nargs="+", default=["g1", "g2"])
    args = ap.parse_args()
    libs = {"ggx": shader(GGX, target="glsl")}
    for n in (6, 12, 24):
        libs[f"ggx + {n} reads"] = reads(libs["ggx"], n)
    tables = {}  # the variants that read a texture or a uniform block: their data
    for g in args.g:
        f = pumpup.load({"type": "pumped", "base": GGX, "g": g, "levels": 3})
        lib = shader(f, target="glsl")
        for name, src in variants(lib).items():
            libs[f"{g} x3: {name}"] = src
        for name, (src, rows) in vec4_variants(lib).items():
            libs[f"{g} x3: {name}"] = src
            tables[f"{g} x3: {name}"] = rows

    os.environ["LP_NUM_THREADS"] = "0"  # (read when the driver starts: before the context)
    draws = Draws(args.pairs)
    runs = {}
    for name, lib in libs.items():
        bind = None
        if name in tables and "texture" in name:
            tex = draws.ctx.texture((len(tables[name]), 1), 4, tables[name].tobytes(), dtype="f4")
            tex.filter = (draws.moderngl.NEAREST, draws.moderngl.NEAREST)
            bind = functools.partial(tex.use, 2)
        elif name in tables:
            buf = draws.ctx.buffer(tables[name].tobytes())
            bind = functools.partial(buf.bind_to_uniform_block, 2)
        if bind is not None:
            bind()
        prog, vao = draws.program(lib, {"pumpup_alpha": 0.3, "pumpup_lt_tex": 2})
        if "pumpup_lt_block" in prog:
            prog["pumpup_lt_block"].binding = 2
        runs[name] = (vao, bind)

    def values(name):
        vao, bind = runs[name]
        if bind is not None:
            bind()
        draws.draw(vao)
        return np.frombuffer(draws.fbo.color_attachments[0].read(), np.float32)[::4].copy()

    for name in tables:  # the same numbers as the full shader's, or the comparison would say nothing
        full = values(name.split(": ")[0] + ": full")
        if not np.array_equal(values(name), full):
            raise SystemExit(f"bench_shader_parts: {name!r} does not give the full shader's values")
    print(f"{draws.ctx.info['GL_RENDERER']}, {draws.pairs} pairs per draw, in this thread (thread CPU time), best of "
          f"{args.repeat} rounds, load average before: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    best = dict.fromkeys(runs, np.inf)
    for _ in range(args.repeat):
        for name, (vao, bind) in runs.items():
            if bind is not None:
                bind()
            t = time.thread_time()
            draws.draw(vao)
            best[name] = min(best[name], time.thread_time() - t)
    base = best["ggx"]
    for name, t in best.items():
        print(f"  {name:44s} {t * 1e9 / draws.pairs:6.1f} ns  {t / base:5.2f} x ggx")
    print("load average after: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))


if __name__ == "__main__":
    main()
