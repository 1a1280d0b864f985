"""Benchmark of pumpup.shader: generation time, and the GLSL's evaluation cost on Mesa's llvmpipe (pumped and
compensated against their base, measured in the same run).

    python scripts/bench/bench_shader.py [--pairs 1048576] [--repeat 5]

Needs moderngl and an EGL driver (Debian: libegl1, libgl1-mesa-dri).  The evaluation renders one float32 value per
pixel (directions from two float32 textures) and times the draws after a first, compiling one.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import pumpup
from pumpup.shaders import shader, uniforms

GGX = {"type": "ggx", "alpha": 0.3}
PHONG = {"type": "phong", "n": 20}
CASES = [
    ("ggx", GGX, None),
    ("ggx pumped g1 x3", {"type": "pumped", "base": GGX, "g": "g1", "levels": 3}, "ggx"),
    ("ggx pumped g2 x3", {"type": "pumped", "base": GGX, "g": "g2", "levels": 3}, "ggx"),
    ("ggx kulla_conty", {"type": "kulla_conty", "base": GGX}, "ggx"),
    ("ggx scaled", {"type": "scaled", "base": GGX}, "ggx"),
    ("phong", PHONG, None),
    ("phong pumped g1 x3", {"type": "pumped", "base": PHONG, "g": "g1", "levels": 3}, "phong"),
]

VS = "#version 430 core\nin vec2 p;\nvoid main() { gl_Position = vec4(p, 0.0, 1.0); }\n"
FS = """
uniform highp sampler2D bench_wi;
uniform highp sampler2D bench_wo;
out vec4 bench_out;
void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    bench_out = vec4(pumpup_brdf(texelFetch(bench_wi, q, 0).xyz, texelFetch(bench_wo, q, 0).xyz));
}
"""


def generation_times() -> None:
    """Print the time to build a 3-level pumped GGX's tables and to generate its shader."""
    print("generation (pumpup.shader, target glsl-es):")
    for g in ("g1", "g2"):
        spec = {"type": "pumped", "base": GGX, "g": g, "levels": 3}
        t = time.perf_counter()
        f = pumpup.load(spec)
        f.eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))  # builds the three levels' tables
        tables = time.perf_counter() - t
        t = time.perf_counter()
        src = shader(f, target="glsl-es")
        gen = time.perf_counter() - t
        t = time.perf_counter()
        shader(f, target="glsl")
        again = time.perf_counter() - t
        print(f"  3-level pumped GGX {g}: tables {tables:.2f} s (once per session), shader {gen:.3f} s "
              f"(again: {again:.3f} s), {len(src) / 1e3:.0f} kB of GLSL ES")


def evaluation_times(pairs: int, repeat: int) -> None:
    """Print the cost per pair of each case's GLSL on llvmpipe, and its ratio to its base's."""
    import moderngl

    ctx = moderngl.create_standalone_context(backend="egl", require=430)
    print(f"evaluation on {ctx.info['GL_RENDERER']}, {pairs} pairs per draw, best of {repeat}:")
    width = 1024
    h = pairs // width
    rng = np.random.default_rng(1)

    def hemi(n):
        z = rng.uniform(0, 1, n)
        phi = rng.uniform(0, 2 * np.pi, n)
        s = np.sqrt(1 - z * z)
        a = np.zeros((n, 4), np.float32)
        a[:, 0], a[:, 1], a[:, 2] = s * np.cos(phi), s * np.sin(phi), z
        return a

    twi = ctx.texture((width, h), 4, hemi(width * h).tobytes(), dtype="f4")
    two = ctx.texture((width, h), 4, hemi(width * h).tobytes(), dtype="f4")
    for t in (twi, two):
        t.filter = (moderngl.NEAREST, moderngl.NEAREST)
    out = ctx.texture((width, h), 4, dtype="f4")
    fbo = ctx.framebuffer([out])
    vbo = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], "f4").tobytes())
    seconds = {}
    for name, spec, base in CASES:
        lib = shader(spec, target="glsl")
        t = time.perf_counter()
        prog = ctx.program(vertex_shader=VS, fragment_shader="#version 430 core\n" + lib + FS)
        for k, v in uniforms(spec).items():
            if k in prog:
                prog[k].value = v
        prog["bench_wi"].value = 0
        prog["bench_wo"].value = 1
        vao = ctx.vertex_array(prog, [(vbo, "2f", "p")])
        fbo.use()
        twi.use(0)
        two.use(1)
        vao.render(moderngl.TRIANGLES)
        ctx.finish()
        compile_s = time.perf_counter() - t
        best = np.inf
        for _ in range(repeat):
            t = time.perf_counter()
            vao.render(moderngl.TRIANGLES)
            ctx.finish()
            best = min(best, time.perf_counter() - t)
        seconds[name] = best
        ratio = f", {best / seconds[base]:.2f} x {base}" if base else ""
        print(f"  {name:22s} {best * 1e9 / (width * h):7.1f} ns per pair{ratio}  (compile + first draw "
              f"{compile_s:.2f} s)")
        vao.release()
        prog.release()


def main() -> None:
    """Run both measurements."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=1 << 20)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    generation_times()
    evaluation_times(args.pairs, args.repeat)


if __name__ == "__main__":
    main()
