"""Benchmark of pumpup.shader: generation time, and the GLSL's evaluation cost on Mesa's llvmpipe (pumped and
compensated against their base, measured in the same run).

    python scripts/bench/bench_shader.py [--pairs 1048576] [--repeat 5] [--against OLD_SHADERS_PY] [--cpu]

Needs moderngl and an EGL driver (Debian: libegl1, libgl1-mesa-dri).  The evaluation renders one float32 value per
pixel (directions from two float32 textures) and times the draws after a first, compiling one.  With ``--against`` (a
file holding another version of pumpup/shaders.py, e.g. ``<(git show main:pumpup/shaders.py)``) each case's shader
from that version is timed too, the two draws alternating, and the table gives both.  With ``--cpu`` llvmpipe
rasterizes in the calling thread (``LP_NUM_THREADS=0``) and each draw is timed by that thread's CPU time, which a
loaded machine disturbs less than the wall-clock time of llvmpipe's worker threads.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np

import pumpup
from pumpup.shaders import shader, uniforms

GGX = {"type": "ggx", "alpha": 0.3}
PHONG = {"type": "phong", "n": 20}
BASES = ("ggx", "phong")
CASES = [
    ("ggx", GGX, None),
    ("ggx pumped g1 x1", {"type": "pumped", "base": GGX, "g": "g1"}, "ggx"),
    ("ggx pumped g2 x1", {"type": "pumped", "base": GGX, "g": "g2"}, "ggx"),
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


#: a fresh process that makes the shader of a 3-level pumped GGX (GGX_G in the environment: g1 or g2), timing its parts
_COLD = """
import os, time
t0 = time.perf_counter()
import numpy as np
import pumpup
spec = {"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}, "g": os.environ["GGX_G"], "levels": 3}
pumpup.registry()
t1 = time.perf_counter()
f = pumpup.load(spec)
t2 = time.perf_counter()
f.eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))
t3 = time.perf_counter()
pumpup.shader(f, target="glsl-es")
t4 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2, t4 - t3, t4 - t0)
"""


def generation_times(runs: int = 3) -> None:
    """Print the time to generate a 3-level pumped GGX's shader with its tables (target: under 1 s): in a process that
    has made one before (for another alpha: its kernels loaded), and in a fresh process, split into its parts.
    """
    import subprocess
    import sys

    print("generation of a 3-level pumped GGX's shader, tables included (pumpup.shader, target glsl-es; target 1 s):")
    for g in ("g1", "g2"):
        f = pumpup.load({"type": "pumped", "base": {"type": "ggx", "alpha": 0.5}, "g": g, "levels": 3})
        shader(f, target="glsl-es")  # (the kernels of a 3-level chain loaded in this process)
        times, tables = [], []
        for k in range(runs):
            alpha = 0.3 + 0.01 * k  # (a new chain each time: its tables are made anew)
            t = time.perf_counter()
            f = pumpup.load({"type": "pumped", "base": {"type": "ggx", "alpha": alpha}, "g": g, "levels": 3})
            f.eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))  # builds the three levels' tables
            tables.append(time.perf_counter() - t)
            shader(f, target="glsl-es")
            times.append(time.perf_counter() - t)
        print(f"  {g}, in a process that made one before: {np.median(times):.2f} s (median of {runs}; tables "
              f"{np.median(tables):.2f} s)")
        cold = []
        for _ in range(runs):
            out = subprocess.run([sys.executable, "-c", _COLD], capture_output=True, text=True, check=True,
                                 env={**os.environ, "GGX_G": g})
            cold.append([float(v) for v in out.stdout.split()])
        imports, load, tables, text, total = np.median(np.array(cold), axis=0)
        print(f"  {g}, in a fresh process: {total:.2f} s (median of {runs}): importing pumpup, numba and the models "
              f"{imports:.2f} s, load {load:.2f} s (numba's first call), tables {tables:.2f} s (kernels loaded from "
              f"numba's cache, then computed), shader {text:.3f} s")


def load_other(path: str):
    """Another version of pumpup/shaders.py, imported as a module of the installed pumpup package."""
    import importlib.util
    import sys

    with open(path) as fh:
        text = fh.read()
    with tempfile.NamedTemporaryFile("w", suffix=".py", delete=False) as tmp:
        tmp.write(text)
    spec = importlib.util.spec_from_file_location("pumpup._shaders_other", tmp.name)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["pumpup._shaders_other"] = mod
    spec.loader.exec_module(mod)
    os.unlink(tmp.name)
    return mod


class Draws:
    """A standalone EGL context (llvmpipe here) holding ``pairs`` random direction pairs of the upper hemisphere in
    two float textures, and a full-screen triangle whose fragment shader evaluates a library's ``pumpup_brdf`` at
    each pixel's pair (``FS``): :meth:`program` compiles one, :meth:`draw` evaluates every pair once.
    """

    def __init__(self, pairs: int, seed: int = 1):
        import moderngl

        self.moderngl = moderngl
        self.ctx = moderngl.create_standalone_context(backend="egl", require=430)
        self.width, self.height = 1024, pairs // 1024
        rng = np.random.default_rng(seed)

        def hemi(n):
            z = rng.uniform(0, 1, n)
            phi = rng.uniform(0, 2 * np.pi, n)
            s = np.sqrt(1 - z * z)
            a = np.zeros((n, 4), np.float32)
            a[:, 0], a[:, 1], a[:, 2] = s * np.cos(phi), s * np.sin(phi), z
            return a

        size = (self.width, self.height)
        self.wi = self.ctx.texture(size, 4, hemi(self.pairs).tobytes(), dtype="f4")
        self.wo = self.ctx.texture(size, 4, hemi(self.pairs).tobytes(), dtype="f4")
        for t in (self.wi, self.wo):
            t.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.fbo = self.ctx.framebuffer([self.ctx.texture(size, 4, dtype="f4")])
        self.vbo = self.ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], "f4").tobytes())

    @property
    def pairs(self) -> int:
        """The number of direction pairs one draw evaluates."""
        return self.width * self.height

    def program(self, lib: str, values: dict[str, float]):
        """Compile ``lib`` (a GLSL library snippet) with its uniforms set to ``values`` and draw it once; return the
        program and its vertex array.
        """
        prog = self.ctx.program(vertex_shader=VS, fragment_shader="#version 430 core\n" + lib + FS)
        for k, v in values.items():
            if k in prog:
                prog[k].value = v
        prog["bench_wi"].value = 0
        prog["bench_wo"].value = 1
        vao = self.ctx.vertex_array(prog, [(self.vbo, "2f", "p")])
        self.draw(vao)
        return prog, vao

    def draw(self, vao) -> None:
        """Evaluate every pair once with ``vao``'s program, and wait until it is done."""
        self.fbo.use()
        self.wi.use(0)
        self.wo.use(1)
        vao.render(self.moderngl.TRIANGLES)
        self.ctx.finish()


def evaluation_times(pairs: int, repeat: int, other=None, cpu: bool = False) -> None:
    """Print the cost per pair of each case's GLSL on llvmpipe, and its ratio to its base's (and, with ``other``, the
    same for that module's shaders, the draws alternating; with ``cpu``, in the calling thread, timed by its CPU time).
    """
    if cpu:
        os.environ["LP_NUM_THREADS"] = "0"  # (read when the driver starts: before the context)
    clock = time.thread_time if cpu else time.perf_counter
    draws = Draws(pairs)
    print(f"evaluation on {draws.ctx.info['GL_RENDERER']}, {draws.pairs} pairs per draw, best of {repeat} rounds "
          f"(each round draws every shader once{', thread CPU time, no worker threads' if cpu else ''}), load average "
          "before: " + " ".join(f"{x:.2f}" for x in os.getloadavg()) + ":")
    modules = [("this", shader, uniforms)] + ([("other", other.shader, other.uniforms)] if other else [])

    def prepare(make, unif, spec):
        lib = make(spec, target="glsl")
        t = time.perf_counter()
        prog, vao = draws.program(lib, unif(spec))
        return prog, vao, time.perf_counter() - t

    runs = {}
    for name, spec, _ in CASES:
        for label, make, unif in modules:
            if label == "other" and name in BASES:
                continue  # the same base shader
            runs[label, name] = prepare(make, unif, spec)
    best = dict.fromkeys(runs, np.inf)
    for _ in range(repeat):  # every shader once per round: all of them under the same load
        for key, (_, vao, _) in runs.items():
            t = clock()
            draws.draw(vao)
            best[key] = min(best[key], clock() - t)
    for name, _, base in CASES:
        cols = []
        for label, _, _ in modules:
            key = (label, name) if (label, name) in best else ("this", name)
            if label == "other" and key[0] == "this":
                continue
            ns = best[key] * 1e9 / draws.pairs
            ratio = f" ({best[key] / best['this', base]:.2f} x {base})" if base else ""
            cols.append(f"{label} {ns:6.1f} ns{ratio}")
        compile_s = ", ".join(f"{runs[k][2]:.2f}" for k in runs if k[1] == name)
        print(f"  {name:20s} " + ", ".join(cols) + f"  (compile + first draw {compile_s} s)")
    for prog, vao, _ in runs.values():
        vao.release()
        prog.release()


def main() -> None:
    """Run both measurements."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=1 << 20)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--against", help="another version of pumpup/shaders.py to time alternately")
    ap.add_argument("--no-generation", action="store_true", help="skip the generation times")
    ap.add_argument("--cpu", action="store_true", help="rasterize in this thread and time its CPU time")
    args = ap.parse_args()
    if not args.no_generation:
        generation_times()
    evaluation_times(args.pairs, args.repeat, load_other(args.against) if args.against else None, cpu=args.cpu)


if __name__ == "__main__":
    main()
