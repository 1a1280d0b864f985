"""Run pumpup's GLSL on Mesa's llvmpipe (moderngl, EGL): direction pairs in float32 textures, values out of float32
render targets.  Many libraries share one draw: each one's ``pumpup_`` names get their own prefix.
"""

from __future__ import annotations

import os
import re

import numpy as np
import pytest

WIDTH = 1024


def need_tool(name: str):
    """Skip when a system tool is missing, fail instead when CI is "true"."""
    import shutil

    path = shutil.which(name)
    if path is None:
        msg = f"{name} is not installed (Debian: glslang-tools / spirv-cross)"
        if os.environ.get("CI") == "true":
            pytest.fail(msg)
        pytest.skip(msg)
    return path


def gl_context():
    """A standalone OpenGL 4.5 context on EGL (llvmpipe), or skip (fail under CI)."""
    try:
        import moderngl

        return moderngl.create_standalone_context(backend="egl", require=430)
    except Exception as exc:  # no moderngl, no EGL, no Mesa driver
        msg = f"no OpenGL context through moderngl + EGL ({type(exc).__name__}: {exc})"
        if os.environ.get("CI") == "true":
            pytest.fail(msg)
        pytest.skip(msg)


def renamed(src: str, k: int) -> str:
    """The library with every ``pumpup_`` name made ``pumpup<k>_`` (several libraries in one program)."""
    return re.sub(r"\bpumpup_", f"pumpup{k}_", src)


def directions(rng, n: int) -> tuple[np.ndarray, np.ndarray]:
    """n pairs (wi, wo) as float32 unit vectors: a third uniform on the hemisphere, a third near the mirror direction
    (within 1e-4 .. 0.3 rad), a third grazing (a cosine in [1e-6, 0.02])."""
    def hemi(m):
        z = rng.uniform(0.0, 1.0, m)
        phi = rng.uniform(0.0, 2 * np.pi, m)
        s = np.sqrt(1 - z * z)
        return np.stack([s * np.cos(phi), s * np.sin(phi), z], -1)

    a = n // 3
    b = n // 3
    c = n - a - b
    wi1, wo1 = hemi(a), hemi(a)
    wi2 = hemi(b)
    mirror = wi2 * np.array([-1.0, -1.0, 1.0])
    pert = rng.normal(size=(b, 3)) * 10.0 ** rng.uniform(-4, -0.5, b)[:, None]
    wo2 = mirror + pert
    wo2[:, 2] = np.abs(wo2[:, 2])
    wo2 /= np.linalg.norm(wo2, axis=-1, keepdims=True)
    zg = 10.0 ** rng.uniform(-6, np.log10(0.02), c)
    phi = rng.uniform(0.0, 2 * np.pi, c)
    sg = np.sqrt(1 - zg * zg)
    wi3 = np.stack([sg * np.cos(phi), sg * np.sin(phi), zg], -1)
    wo3 = hemi(c)
    swap = rng.uniform(size=c) < 0.5
    wi3[swap], wo3[swap] = wo3[swap].copy(), wi3[swap].copy()
    wi = np.concatenate([wi1, wi2, wi3]).astype(np.float32)
    wo = np.concatenate([wo1, wo2, wo3]).astype(np.float32)
    return wi, wo


_VS_430 = "#version 430 core\nin vec2 pumpup_pos;\nvoid main() { gl_Position = vec4(pumpup_pos, 0.0, 1.0); }\n"
_VS_ES = "#version 300 es\nin vec2 pumpup_pos;\nvoid main() { gl_Position = vec4(pumpup_pos, 0.0, 1.0); }\n"


def _draw(ctx, fragment: str, es: bool, outputs: int, uniforms, first: int, samplers: dict, size: tuple, vbo):
    """Compile ``fragment`` (with ``outputs`` float outputs), set each library's uniforms (``uniforms[k]`` for library
    ``first + k``, renamed as :func:`renamed` renames them) and the samplers (name -> texture, units in order), draw the
    full-screen triangle into ``size`` float textures and read them back: one (pixels, 4) array per output.
    """
    import moderngl

    prog = ctx.program(vertex_shader=_VS_ES if es else _VS_430, fragment_shader=fragment)
    for k, values in enumerate(uniforms):
        for name, val in values.items():
            key = name.replace("pumpup_", f"pumpup{first + k}_", 1)
            if key in prog:
                prog[key].value = float(np.float32(val))
    for unit, (name, texture) in enumerate(samplers.items()):
        prog[name].value = unit
        texture.use(unit)
    outs = [ctx.texture(size, 4, dtype="f4") for _ in range(outputs)]
    fbo = ctx.framebuffer(outs)
    fbo.use()
    vao = ctx.vertex_array(prog, [(vbo, "2f", "pumpup_pos")])
    vao.render(moderngl.TRIANGLES)
    got = [np.frombuffer(fbo.read(components=4, dtype="f4", attachment=k), "f4").reshape(-1, 4)
           for k in range(outputs)]
    for o in outs:
        o.release()
    fbo.release()
    vao.release()
    prog.release()
    return got


def run(ctx, libraries: list[str], wi: np.ndarray, wo: np.ndarray, es: bool = False, uniforms=None,
        with_error: bool = True, group: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Evaluate ``pumpup_brdf`` of every library at the pairs (one draw for up to ``group`` <= 8 libraries): (values,
    error bounds), each (libraries, n) float64.  The error bound is ``pumpup_base(wi, wo).y`` (0 below the horizon).
    Libraries with tables compile much faster one per program (llvmpipe's compile time grows faster than the size)."""
    import moderngl

    n = wi.shape[0]
    h = -(-n // WIDTH)
    pad = h * WIDTH - n

    def tex(a):
        a4 = np.zeros((h * WIDTH, 4), np.float32)
        a4[:n, :3] = a
        a4[n:, 2] = 1.0
        t = ctx.texture((WIDTH, h), 4, a4.tobytes(), dtype="f4")
        t.filter = (moderngl.NEAREST, moderngl.NEAREST)
        return t

    twi, two = tex(wi), tex(wo)
    vbo = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], "f4").tobytes())
    values, errors = [], []
    size = group
    for s in range(0, len(libraries), size):
        group = libraries[s:s + size]
        head = "#version 300 es\nprecision highp float;\n" if es else "#version 430 core\n"
        src = [head]
        for k, lib in enumerate(group):
            src.append(renamed(lib, s + k))
        src.append("uniform highp sampler2D pumpup_test_wi;\nuniform highp sampler2D pumpup_test_wo;\n")
        for k in range(len(group)):
            src.append(f"layout(location = {k}) out vec4 pumpup_test_out{k};\n")
        src.append("void main() {\n    ivec2 p = ivec2(gl_FragCoord.xy);\n"
                   "    vec3 a = texelFetch(pumpup_test_wi, p, 0).xyz;\n"
                   "    vec3 b = texelFetch(pumpup_test_wo, p, 0).xyz;\n"
                   "    bool up = a.z > 0.0 && b.z > 0.0;\n")
        for k in range(len(group)):
            j = s + k
            err = f"up ? pumpup{j}_base(a, b).y : 0.0" if with_error else "0.0"
            src.append(f"    pumpup_test_out{k} = vec4(pumpup{j}_brdf(a, b), {err}, 0.0, 1.0);\n")
        src.append("}\n")
        for r in _draw(ctx, "".join(src), es, len(group), (uniforms or [])[s:s + size], s,
                       {"pumpup_test_wi": twi, "pumpup_test_wo": two}, (WIDTH, h), vbo):
            values.append(r[:n, 0].astype(np.float64))
            errors.append(r[:n, 1].astype(np.float64))
    twi.release()
    two.release()
    vbo.release()
    del pad
    return np.array(values), np.array(errors)


def furnace(ctx, libraries: list[str], mu: np.ndarray, nodes: int = 256, es: bool = False, uniforms=None,
            group: int = 8):
    """The directional albedo of every library at each mu, summed in the shader in float32: Gauss-Legendre of
    ``nodes`` points in cos(theta_o), the trapezoid rule of ``nodes`` points in phi_o (wi at phi = 0).
    (libraries, len(mu)) float64, and the same rule's nodes for a double-precision reference."""
    import moderngl

    x, w = np.polynomial.legendre.leggauss(nodes)
    u = 0.5 * (x + 1.0)
    wu = 0.5 * w
    gl = np.zeros((nodes, 4), np.float32)
    gl[:, 0], gl[:, 1] = u, wu
    tnodes = ctx.texture((nodes, 1), 4, gl.tobytes(), dtype="f4")
    tnodes.filter = (moderngl.NEAREST, moderngl.NEAREST)
    m = len(mu)
    mus = np.zeros((m, 4), np.float32)
    mus[:, 0] = mu
    tmu = ctx.texture((m, 1), 4, mus.tobytes(), dtype="f4")
    tmu.filter = (moderngl.NEAREST, moderngl.NEAREST)
    vbo = ctx.buffer(np.array([-1, -1, 3, -1, -1, 3], "f4").tobytes())
    out = []
    size = group
    for s in range(0, len(libraries), size):
        group = libraries[s:s + size]
        head = "#version 300 es\nprecision highp float;\n" if es else "#version 430 core\n"
        src = [head] + [renamed(lib, s + k) for k, lib in enumerate(group)]
        src.append("uniform highp sampler2D pumpup_test_nodes;\nuniform highp sampler2D pumpup_test_mu;\n")
        for k in range(len(group)):
            src.append(f"layout(location = {k}) out vec4 pumpup_test_out{k};\n")
        src.append("""void main() {
    int p = int(gl_FragCoord.x);
    float mu = texelFetch(pumpup_test_mu, ivec2(p, 0), 0).x;
    vec3 wi = vec3(sqrt(max(0.0, (1.0 - mu) * (1.0 + mu))), 0.0, mu);
""")
        for k in range(len(group)):
            src.append(f"    float sum{k} = 0.0;\n")
        src.append(f"""    for (int j = 0; j < {nodes}; j++) {{
        vec2 nw = texelFetch(pumpup_test_nodes, ivec2(j, 0), 0).xy;
        float z = nw.x;
        float r = sqrt(max(0.0, (1.0 - z) * (1.0 + z)));
""")
        for k in range(len(group)):
            src.append(f"        float row{k} = 0.0;\n")
        src.append(f"""        for (int q = 0; q < {nodes}; q++) {{
            float phi = 6.28318531 * (float(q) + 0.5) / {float(nodes)};
            vec3 wo = vec3(r * cos(phi), r * sin(phi), z);
""")
        for k in range(len(group)):
            src.append(f"            row{k} += pumpup{s + k}_brdf(wi, wo);\n")
        src.append("        }\n")
        for k in range(len(group)):
            src.append(f"        sum{k} += nw.y * z * row{k};\n")
        src.append("    }\n")
        for k in range(len(group)):
            src.append(f"    pumpup_test_out{k} = vec4(sum{k} * 6.28318531 / {float(nodes)}, 0.0, 0.0, 1.0);\n")
        src.append("}\n")
        for r in _draw(ctx, "".join(src), es, len(group), (uniforms or [])[s:s + size], s,
                       {"pumpup_test_nodes": tnodes, "pumpup_test_mu": tmu}, (m, 1), vbo):
            out.append(r[:m, 0].astype(np.float64))
    tnodes.release()
    tmu.release()
    vbo.release()
    return np.array(out)


def furnace_reference(f, mu: np.ndarray, nodes: int) -> np.ndarray:
    """The same rule as :func:`furnace` in double precision on pumpup's eval (the numpy reference of the shader's
    quadrature)."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    u = 0.5 * (x + 1.0)
    wu = 0.5 * w
    phi = 2 * np.pi * (np.arange(nodes) + 0.5) / nodes
    r = np.sqrt((1 - u) * (1 + u))
    wo = np.stack([r[:, None] * np.cos(phi)[None], r[:, None] * np.sin(phi)[None],
                   np.broadcast_to(u[:, None], (nodes, nodes))], -1)
    out = []
    for m in mu:
        wi = np.array([np.sqrt((1 - m) * (1 + m)), 0.0, m])
        vals = f.eval(wi, wo)
        out.append(float(np.sum(wu[:, None] * u[:, None] * vals) * 2 * np.pi / nodes))
    return np.array(out)
