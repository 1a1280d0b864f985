"""pumpup.shader: the GLSL runs on Mesa's llvmpipe (moderngl, EGL) and is compared with pumpup's eval.

- closed-form models: |shader - pumpup| <= B pumpup, B the model's stated float32 bound (the shader's own
  ``pumpup_base(wi, wo).y``), on 1e5 random, near-mirror and grazing pairs where pumpup >= 1e-30 (float32's range);
- pumped (1 and 3 levels, g1 and g2) and compensated models: the shader is never above pumpup, and below it by at most
  3 B + table_error (the base within B of pumpup, times 1 - 2 B, and the tables' float32 margins);
- a furnace integral summed in the shader matches pumpup.albedo within the quadrature's error;
- every target compiles (glslangValidator), HLSL and MSL come out of spirv-cross, BRDF Explorer files parse with a
  parser of its grammar and run.
"""

from __future__ import annotations

import json
import os
import re
import subprocess

import numpy as np
import pytest
from glsl_harness import directions, furnace, furnace_reference, gl_context, need_tool, run

import pumpup
from pumpup.core import SpecError
from pumpup.shaders import TARGETS, shader, table_error, uniforms

BASES = [
    "phong:n=20", {"type": "phong", "n": 1000}, {"type": "stretched_phong", "n": 50, "p": 0.5},
    {"type": "stretched_phong", "n": 50, "p": 1}, "blinn:n=100", {"type": "stretched_blinn", "n": 1000},
    "ward:m=0.2", "modified_ward:m=0.05", {"type": "cook_torrance", "m": 0.3, "ior": 1.5},
    {"type": "cook_torrance", "m": 0.1}, "schlick:r=0.1", "lambert:albedo=0.5",
    {"type": "ggx", "alpha": 0.3, "eta": 0.2, "k": 3.0, "shadowing": "correlated"},
    {"type": "ggx", "alpha": 0.05, "ior": 1.5}, {"type": "beckmann", "alpha": 0.3, "ior": 1.5},
    {"type": "beckmann", "alpha": 0.3, "g1": "walter"}, {"type": "retro", "n": 20},
    {"type": "retro", "n": 50, "p": 0.5}, {"type": "metal", "n": 20, "eta": 0.2, "k": 3.0},
    {"type": "plastic", "n": 30, "ad": 0.4, "a_s": 0.5, "eta": 1.5}, {"type": "plastic", "n": 30},
    {"type": "minnaert", "k": 0.7}, {"type": "minnaert", "k": 3.0}, {"type": "lacquer", "s": 0.1},
    {"type": "phong_shader", "n": 5, "kd": 0.1, "ks": 0.3}, {"type": "phong_blinn", "n": 300, "kd": 0.2, "ks": 0.5},
    {"type": "fresnel", "base": {"type": "phong", "n": 20}, "eta": 0.2, "k": 3.0},
    {"type": "lafortune", "n": 50, "cx": -0.8, "cy": -0.8, "cz": 1.0, "p": 0.5},
    {"type": "torrance_sparrow", "d": "D1", "s": 20}, {"type": "torrance_sparrow", "d": "D2", "s": 5.0, "ior": 1.5},
    {"type": "torrance_sparrow", "d": "D3", "s": 0.3}, {"type": "torrance_sparrow", "d": "D3", "s": 2.0, "b": 0.5},
    {"type": "torrance_sparrow", "d": "D4", "s": 0.1}, {"type": "torrance_sparrow", "d": "D4", "s": 0.4, "ior": 1.33},
    {"type": "lewis_phong", "n": 20}, {"type": "lewis_phong", "n": 1, "k_rho": 0.8, "k_sigma": 0.5},
    {"type": "lewis_phong", "n": 500, "k_sigma": 0.9}, {"type": "lewis_phong", "n": 0},
    {"type": "oren_nayar"}, {"type": "oren_nayar", "albedo": 0.7, "sigma": 0.5}, {"type": "oren_nayar", "sigma": 1.2},
    {"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rs": 1.0},
    {"type": "ashikhmin_shirley", "nu": 100, "nv": 100, "rs": 0.05, "rd": 0.8},
    {"type": "ashikhmin_shirley", "nu": 10, "nv": 1000, "rs": 0.5},
    {"type": "ashikhmin_shirley", "nu": 0, "nv": 0, "rs": 0.2, "rd": 0.5},
    {"type": "ashikhmin_shirley", "nu": 5000, "nv": 200, "rs": 0.9, "rd": 0.1},
]

GGX = {"type": "ggx", "alpha": 0.3}
PHONG = {"type": "phong", "n": 20}
#: pumped and compensated models of the default run (their tables take seconds); the slow test runs the full matrix
OPERATED = [
    {"type": "pumped", "base": PHONG, "g": "g1", "levels": 1},
    {"type": "pumped", "base": PHONG, "g": "g2", "levels": 3},
    {"type": "pumped", "base": GGX, "g": "g1", "levels": 3},
    {"type": "pumped", "base": GGX, "g": "g2", "levels": 1},
    {"type": "kulla_conty", "base": GGX},
    {"type": "scaled", "base": GGX},
    {"type": "pumped", "base": {"type": "oren_nayar", "sigma": 0.3}, "g": "g1", "levels": 1},
]
FULL_BASES = [PHONG, {"type": "blinn", "n": 50}, {"type": "ward", "m": 0.2}, {"type": "cook_torrance", "m": 0.3}, GGX]

N_PAIRS = 100_000


@pytest.fixture(scope="module")
def sources():
    """Every model's BRDF, GLSL and GLSL ES source, made before the GL context exists."""
    out = {}
    for spec in BASES + OPERATED + [GGX]:
        f = pumpup.load(spec)
        out[json.dumps(f.spec, sort_keys=True)] = (f, shader(f, target="glsl"), shader(f, target="glsl-es"),
                                                   uniforms(f))
    return out


@pytest.fixture(scope="module")
def ctx(sources):
    return gl_context()


@pytest.fixture(scope="module")
def pairs():
    return directions(np.random.default_rng(20261206), N_PAIRS)


def _pumpup(f, wi, wo):
    return np.asarray(f.eval(wi.astype(np.float64), wo.astype(np.float64)), dtype=np.float64)


# --- the library's shape: the explorer's contract ---------------------------------------------------------------------


def test_library_contract():
    src = shader("phong:n=20", target="glsl-es")
    assert not re.search(r"^\s*(#version|precision\b)", src, flags=re.M) and "void main" not in src
    assert "float pumpup_brdf(vec3 wi, vec3 wo)" in src
    names = re.findall(r"^(?:const\s+)?(?:uniform\s+)?(?:float|vec2|vec3|int)\s+(\w+)", src, flags=re.M)
    assert names and all(n.startswith("pumpup_") for n in names), names
    assert uniforms("phong:n=20") == {"pumpup_n": 20.0, "pumpup_c": pytest.approx(22 / (2 * np.pi))}
    for name in uniforms("phong:n=20"):
        assert f"uniform float {name};" in src
    pumped = shader({"type": "pumped", "base": PHONG, "levels": 1}, target="glsl")
    assert "uniform" not in pumped.split("\n// table:")[-1] and uniforms({"type": "pumped", "base": PHONG}) == {}
    head = [ln for ln in pumped.splitlines() if ln.startswith("//")][:20]
    text = "\n".join(head)
    for what in ("spec:", "pumpup version:", "made by:", "conventions:", "baked", "table: level 1"):
        assert what in text, what


def test_unsupported_models_name_what_is_missing():
    with pytest.raises(SpecError, match="'function'"):
        shader(pumpup.from_function(lambda wi, wo: 0.1 + 0 * wi[..., 2], name="mine"))
    with pytest.raises(SpecError, match="he_torrance"):
        shader({"type": "he_torrance", "sigma_0": 0.1, "tau": 1.0, "n": 1.5})
    with pytest.raises(SpecError, match="ward_aniso"):
        shader({"type": "ward_aniso", "ax": 0.2, "ay": 0.4}, target="glsl-es")
    with pytest.raises(SpecError, match="inside 'fresnel'"):
        shader({"type": "fresnel", "base": {"type": "kulla_conty", "base": GGX}, "eta": 0.2, "k": 3.0})
    with pytest.raises(ValueError, match="target must be one of"):
        shader("phong:n=20", target="vulkan")


# --- closed-form models: equal to float32 rounding --------------------------------------------------------------------


@pytest.mark.parametrize("es", [False, True], ids=["glsl", "glsl-es"])
def test_models_match_pumpup_within_their_float32_bound(sources, ctx, pairs, es):
    wi, wo = pairs
    items = [sources[json.dumps(pumpup.load(s).spec, sort_keys=True)] for s in BASES]
    libs = [it[2] if es else it[1] for it in items]
    vals, bounds = run(ctx, libs, wi, wo, es=es, uniforms=[it[3] for it in items], group=4)
    for (f, *_), v, b in zip(items, vals, bounds):
        p = _pumpup(f, wi, wo)
        assert np.all(v[p == 0] == 0), f.spec
        ok = p >= 1e-30
        assert ok.sum() > N_PAIRS // 3, f.spec
        rel = np.abs(v[ok] - p[ok]) / p[ok]
        worst = np.argmax(rel / np.maximum(b[ok], 1e-300))
        assert np.all(rel <= b[ok]), (f.spec, rel[worst], b[ok][worst])


# --- pumped and compensated: never above ------------------------------------------------------------------------------


def _check_never_above(items, vals, bounds, wi, wo):
    """Never above pumpup; below it by at most the base's 2 B and the tables' float32 margins (table_error)."""
    for (f, *_), v, b in zip(items, vals, bounds):
        p = _pumpup(f, wi, wo)
        above = v > p
        assert not above.any(), (f.spec, int(above.sum()), v[above][:3], p[above][:3])
        tol = table_error(f)
        assert tol["relative"] < 1e-3, (f.spec, tol)
        kc = f.type == "kulla_conty"
        lobe = 2.0 * tol["absolute"] * f.scale if kc else 0.0
        ok = p >= 1e-30  # (float32's normal range)
        # below the tables' lower end (a cosine under 1e-8) the shader divides by the bounds' largest value there
        low = (wi[:, 2] < tol["below"]) | (wo[:, 2] < tol["below"])
        rel = tol["relative"] + np.where(low, 0.0 if kc else tol["below_relative"], 0.0)
        lobe = lobe + np.where(low, 2.0 * tol["below_relative"] * f.scale if kc else 0.0, 0.0)
        gap = (p - v - (3.0 * b + rel) * p - lobe)[ok]  # base within B of pumpup, x (1 - 2 B)
        assert np.all(gap <= 0.0), (f.spec, float(np.max(gap)), tol)


def _with_low_cosines(pairs):
    """The pairs and 300 more with N.wi or N.wo of 1e-9 to 1e-7 (around the tables' lower end, 1e-8)."""
    wi, wo = pairs
    rng = np.random.default_rng(11)
    lw, lo = directions(rng, 300)
    z = (10.0 ** rng.uniform(-9, -7, 300)).astype(np.float32)
    r = np.sqrt(1.0 - z.astype(np.float64) ** 2) / np.linalg.norm(lw[:, :2].astype(np.float64), axis=1)
    lw[:, :2] = (lw[:, :2] * r[:, None]).astype(np.float32)
    lw[:, 2] = z
    swap = rng.uniform(size=300) < 0.5
    lw[swap], lo[swap] = lo[swap].copy(), lw[swap].copy()
    return np.concatenate([wi, lw]), np.concatenate([wo, lo])


def test_pumped_and_compensated_never_above(sources, ctx, pairs):
    wi, wo = _with_low_cosines(pairs)
    items = [sources[json.dumps(pumpup.load(s).spec, sort_keys=True)] for s in OPERATED]
    vals, bounds = run(ctx, [it[1] for it in items], wi, wo, group=1)
    _check_never_above(items, vals, bounds, wi, wo)


def test_pumped_glsl_es_never_above(sources, ctx, pairs):
    wi, wo = pairs
    items = [sources[json.dumps(pumpup.load(s).spec, sort_keys=True)] for s in (OPERATED[0], OPERATED[3])]
    vals, bounds = run(ctx, [it[2] for it in items], wi, wo, es=True, group=1)
    _check_never_above(items, vals, bounds, wi, wo)


@pytest.mark.slow
def test_pumped_matrix_never_above():
    specs = [{"type": "pumped", "base": b, "g": g, "levels": n} for b in FULL_BASES for g in ("g1", "g2")
             for n in (1, 3)]
    specs += [{"type": m, "base": b} for m in ("kulla_conty", "scaled")
              for b in (PHONG, {"type": "cook_torrance", "m": 0.3}, {"type": "ggx", "alpha": 0.5, "ior": 1.5})]
    specs += [{"type": "scaled", "base": GGX, "f0": 0.5},
              {"type": "fresnel", "base": {"type": "pumped", "base": PHONG, "levels": 3}, "eta": 0.2, "k": 3.0}]
    items = []
    for s in specs:
        f = pumpup.load(s)
        items.append((f, shader(f, target="glsl")))
    context = gl_context()
    wi, wo = directions(np.random.default_rng(7), 400_000)
    vals, bounds = run(context, [it[1] for it in items], wi, wo, group=1)
    _check_never_above(items, vals, bounds, wi, wo)


# --- the furnace in the shader ----------------------------------------------------------------------------------------


def test_furnace_in_the_shader_matches_albedo(sources, ctx):
    specs = ["phong:n=20", GGX, OPERATED[2], OPERATED[4]]
    items = [sources[json.dumps(pumpup.load(s).spec, sort_keys=True)] for s in specs]
    mu = np.array([0.2, 0.5, 0.9, 1.0])
    nodes = 192
    got = furnace(ctx, [it[1] for it in items], mu, nodes=nodes, uniforms=[it[3] for it in items], group=1)
    for (f, *_), g in zip(items, got):
        ref = pumpup.albedo(f, mu)
        fine = furnace_reference(f, mu, nodes)  # the same rule in double precision
        coarse = furnace_reference(f, mu, nodes // 2)
        quad_err = np.abs(fine - coarse) + 1e-6  # the rule's error, estimated from half the nodes
        assert np.all(np.abs(fine - ref) <= quad_err), (f.spec, fine, ref, quad_err)
        # the float32 sum in the shader: nodes^2 terms of relative rounding <= (nodes + 2) U each, plus B
        assert np.all(np.abs(g - ref) <= quad_err + 3e-4 * ref), (f.spec, g, ref, quad_err)
        if f.type in ("pumped", "kulla_conty"):
            assert np.all(g <= ref + quad_err), (f.spec, g, ref)


# --- compilers and translators ----------------------------------------------------------------------------------------


def test_every_target_compiles(tmp_path):
    validator = need_tool("glslangValidator")
    specs = ["phong:n=20", GGX, {"type": "beckmann", "alpha": 0.2, "eta": 0.2, "k": 3.0},
             {"type": "pumped", "base": PHONG, "levels": 1}]
    for i, spec in enumerate(specs):
        for target, ext in (("glsl", "comp"), ("glsl-es", "frag")):
            path = tmp_path / f"s{i}.{ext}"
            path.write_text(shader(spec, target=target, standalone=True))
            r = subprocess.run([validator, str(path)], capture_output=True, text=True)
            assert r.returncode == 0, (spec, target, r.stdout + r.stderr)


@pytest.mark.parametrize("target,marker", [("hlsl", "[numthreads(64, 1, 1)]"), ("msl", "kernel void")])
def test_hlsl_and_msl_come_from_spirv_cross(target, marker):
    need_tool("glslangValidator")
    need_tool("spirv-cross")
    src = shader("phong:n=20", target=target)
    assert src.startswith("// pumpup shader, target " + target)
    assert marker in src and "pumpup_brdf" in src
    src = shader({"type": "pumped", "base": PHONG, "levels": 1}, target=target)
    assert "pumpup_product_piece" in src  # (the product table's look-up, translated too)


# --- BRDF Explorer ----------------------------------------------------------------------------------------------------


def parse_brdf_file(text: str) -> dict:
    """A parser of BRDF Explorer's ``.brdf`` grammar (wdas/brdf, BRDFBase::loadBRDF and processParameterLine): the
    first line's first token is "analytic" (or "bparam"); blank lines and lines whose first character (after trimming)
    is '#' are skipped everywhere; ``::begin S`` / ``::end S`` open and close a section (no nesting, the end names the
    open one); a ``parameters`` line is ``float name min max default``, ``bool name value`` or ``color name r g b``;
    other sections collect their lines."""
    lines = text.split("\n")
    kind = lines[0].strip().split(" ")[0]
    if kind not in ("analytic", "bparam"):
        raise ValueError(f"first line must name the BRDF type, got {lines[0]!r}")
    params, sections, current = [], {}, ""
    for line in lines[1:]:
        t = line.strip()
        if not t or t.startswith("#"):
            continue
        tok = t.split()
        if tok[0] == "::begin":
            if current:
                raise ValueError(f"section {tok[1]} opened inside {current}")
            current = tok[1]
            sections[current] = []
        elif tok[0] == "::end":
            if len(tok) < 2 or tok[1] != current:
                raise ValueError(f"::end {tok[1:]} does not close {current!r}")
            current = ""
        elif current == "parameters":
            if tok[0] == "float" and len(tok) == 5:
                lo, hi, val = (float(x) for x in tok[2:])
                params.append(("float", tok[1], lo, hi, val))
            elif tok[0] == "bool" and len(tok) == 3:
                params.append(("bool", tok[1], int(tok[2])))
            elif tok[0] == "color" and len(tok) == 5:
                params.append(("color", tok[1], *(float(x) for x in tok[2:])))
            else:
                raise ValueError(f"bad parameter line {t!r}")
        elif current:
            sections[current].append(line)
        else:
            raise ValueError(f"line outside a section: {t!r}")
    if current:
        raise ValueError(f"section {current} is not closed")
    if "shader" not in sections:
        raise ValueError("no shader section")
    return {"kind": kind, "params": params, "shader": "\n".join(sections["shader"]) + "\n"}


def test_brdf_explorer_files_parse_and_run(ctx, sources):
    rng = np.random.default_rng(3)
    # (the anisotropic Ashikhmin-Shirley lobe turns with the frame: the shader must use the X and Y it is given)
    specs = ["phong:n=20", GGX, OPERATED[2], {"type": "ashikhmin_shirley", "nu": 10, "nv": 1000, "rs": 0.5}]
    for spec in specs:
        f = pumpup.load(spec)
        parsed = parse_brdf_file(shader(f, target="brdf-explorer"))
        assert parsed["kind"] == "analytic"
        assert "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)" in parsed["shader"]
        expected = uniforms(f)
        assert {p[1] for p in parsed["params"]} == set(expected)
        for _, name, lo, hi, val in parsed["params"]:
            assert lo <= val <= hi and val == pytest.approx(expected[name], rel=1e-8)
        # BRDF Explorer's template: the parameters as uniforms, then the shader; run BRDF() in a random frame
        lib = "".join(f"uniform float {p[1]};\n" for p in parsed["params"]) + parsed["shader"]
        lib += ("float pumpup_brdf_frame(vec3 a, vec3 b) {\n"
                "    vec3 n = normalize(vec3(0.3, -0.5, 0.8)); vec3 x = normalize(cross(vec3(0.0, 1.0, 0.0), n));\n"
                "    vec3 y = cross(n, x);\n"
                "    return BRDF(a.x * x + a.y * y + a.z * n, b.x * x + b.y * y + b.z * n, n, x, y).x;\n}\n")
        lib = lib.replace("float pumpup_brdf(", "float pumpup_brdf_local(").replace(
            "pumpup_brdf(wi, wo)", "pumpup_brdf_local(wi, wo)")
        lib = lib.replace("float pumpup_brdf_frame(", "float pumpup_brdf(")
        wi, wo = directions(rng, 3000)
        vals, _ = run(ctx, [lib], wi, wo, uniforms=[{p[1]: p[4] for p in parsed["params"]}], with_error=False)
        ref, _ = run(ctx, [shader(f, target="glsl")], wi, wo, uniforms=[uniforms(f)], with_error=False)
        p = _pumpup(f, wi, wo)
        ok = p > 1e-20
        # the frame's rotation in float32 moves the directions by ~1e-7: compare with the local-frame shader loosely
        assert np.median(np.abs(vals[0][ok] - ref[0][ok]) / p[ok]) < 1e-4, f.spec
        assert np.all((vals[0] == 0) | ok | (p > 0))


def test_targets_listed():
    assert set(TARGETS) == {"glsl", "glsl-es", "hlsl", "msl", "brdf-explorer"}


def test_generation_time_of_a_pumped_ggx():
    import time

    f = pumpup.pump(GGX, g="g2", levels=3)
    f.eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))  # the tables, built once per session
    t = time.perf_counter()
    src = shader(f, target="glsl-es")
    # (scripts/bench/bench_shader.py: < 1 s)
    assert time.perf_counter() - t < 5.0 and "pumpup_lt_c" in src and "table: level 3" in src


def test_cli_shader(tmp_path):
    import sys

    out = tmp_path / "phong.glsl"
    env = dict(os.environ)
    r = subprocess.run([sys.executable, "-m", "pumpup.cli", "shader", "phong:n=20", "--target", "glsl-es", "--out",
                        str(out)], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert "float pumpup_brdf(vec3 wi, vec3 wo)" in text
    assert "made by: pumpup shader phong:n=20 --target glsl-es" in text
    r = subprocess.run([sys.executable, "-m", "pumpup.cli", "shader", "phong:n=-1", "--target", "glsl"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    r = subprocess.run([sys.executable, "-m", "pumpup.cli", "shader", "phong:n=20", "--target", "cuda"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr


# --- the tables in m: at least the bounds pumpup divides by (no GL needed) --------------------------------------------


def test_shader_tables_are_at_least_pumpups_bounds():
    from pumpup.shaders import _Plan, _PumpedTables

    rng = np.random.default_rng(2)
    for spec in ({"type": "pumped", "base": GGX, "g": "g2", "levels": 3},
                 {"type": "pumped", "base": PHONG, "g": "g1", "levels": 3}):
        f = pumpup.load(spec)
        tabs = _PumpedTables(_Plan(f))
        m = np.unique(np.concatenate([10.0 ** rng.uniform(np.log10(tabs.t32), 0.0, 20000),
                                      rng.uniform(0.9, 1.0, 20000), [tabs.t32, 1.0]]).astype(np.float32))
        m64 = m.astype(np.float64)
        if tabs.table is not None:  # every level's U_j, which pumpup's level-by-level path divides by
            got, want = tabs.table.values(m), np.stack([lk.upper(m64) for lk in tabs.looks])
            rel = tabs.table.rel
        else:  # pumpup's product table G(m) (scaled up by its epsilon)
            got, want = tabs.product.values(m), f.product()(m64)[None]
            rel = tabs.product.rel
        assert np.all(got >= want), spec
        # (the float32 evaluation may fall below the double-precision polynomial by half the raise)
        assert np.all(got <= want * (1.0 + rel)), (spec, float(np.max(got / want - 1.0)), rel)
        # below the lower end: the constants are at least every bound there
        below = np.float32(tabs.t32) * np.float32(0.5) ** np.arange(1, 120, 7, dtype=np.float32)
        below = below[below > 0]
        for lk, sup in zip(tabs.looks, tabs.sup):
            assert np.all(lk.upper(below.astype(np.float64)) <= sup)


# --- the piece index: the GLSL against its numpy reference, the reference against a search ---------------------------


def _index_cases():
    """(name, _Index, float32 values to look up) for a level table whose pieces crowd (3-level g2 pumped GGX: the
    sub-cells), one whose do not (g1) and a product table (Phong)."""
    from pumpup.shaders import _Index, _Plan, _PumpedTables

    rng = np.random.default_rng(5)
    out = []
    for name, spec in (("g2", {"type": "pumped", "base": GGX, "g": "g2", "levels": 3}),
                       ("g1", {"type": "pumped", "base": GGX, "g": "g1", "levels": 3}),
                       ("phong", {"type": "pumped", "base": PHONG, "g": "g1", "levels": 3})):
        tabs = _PumpedTables(_Plan(pumpup.load(spec)))
        lo = (tabs.table or tabs.product).lo32
        m = np.concatenate([lo, np.nextafter(lo, np.float32(0)), np.nextafter(lo, np.float32(2)),
                            (10.0 ** rng.uniform(np.log10(lo[0]), 0.0, 20000)).astype(np.float32),
                            rng.uniform(0.9, 1.0, 20000).astype(np.float32), [np.float32(1.0)]]).astype(np.float32)
        out.append((name, _Index(lo), np.unique(m[(m >= lo[0]) & (m <= 1.0)])))
    return out


def test_piece_index_reference_is_the_search():
    cases = _index_cases()
    assert cases[0][1].sub > 0 and cases[1][1].sub == 0  # (g2's crowded cells take sub-cells; g1's need none)
    for name, ix, m in cases:
        want = np.clip(np.searchsorted(ix.b, m, side="right") - 1, 0, len(ix.b) - 1)
        assert np.array_equal(ix.piece(m), want), name


@pytest.mark.parametrize("es", [False, True])
def test_piece_index_glsl_matches_its_reference(ctx, es):
    for name, ix, m in _index_cases():
        arrays, code = ix.glsl("pumpup_t", "m")
        # (wo read too, so that the program keeps its sampler)
        lib = arrays + code + ("float pumpup_brdf(vec3 wi, vec3 wo) { return float(pumpup_t_piece(wi.z))"
                               " + min(wo.z, 0.0); }\n")
        wi = np.zeros((len(m), 3), np.float32)
        wi[:, 2] = m
        got, _ = run(ctx, [lib], wi, wi, es=es, with_error=False)
        assert np.array_equal(got[0], ix.piece(m).astype(np.float64)), (name, es)


@pytest.mark.parametrize("es", [False, True])
def test_level_table_glsl_matches_its_reference(ctx, es):
    """Every level's bound as the GLSL computes it (piece, t = (m - centre) 2^-e from the bits of m, Horner) against
    _Pieces.values, the numpy reference (float64 on the float32 coefficients): within the float32 error bound of the
    piece (``err``, which the table's constant terms were raised by twice)."""
    from pumpup.shaders import _Plan, _PumpedTables

    rng = np.random.default_rng(8)
    for g in ("g1", "g2"):
        q = _PumpedTables(_Plan(pumpup.load({"type": "pumped", "base": GGX, "g": g, "levels": 3}))).table
        assert q.octave and "pumpup_lt_ih" not in q.glsl()
        m = np.unique(np.concatenate([q.lo32, np.nextafter(q.lo32, np.float32(2)),
                                      (10.0 ** rng.uniform(np.log10(q.lo32[0]), 0.0, 20000)).astype(np.float32),
                                      [np.float32(1.0)]]).astype(np.float32))
        m = m[(m >= q.lo32[0]) & (m <= 1.0)]
        wi = np.zeros((len(m), 3), np.float32)
        wi[:, 2] = m
        s = np.clip(np.searchsorted(q.lo32, m, side="right") - 1, 0, q.npieces - 1)
        want = q.values(m)
        for j in range(q.nfun):
            lib = (q.glsl() + "float pumpup_brdf(vec3 wi, vec3 wo) {\n" + q.locate("", "wi.z")
                   + f"    return {q.value(j, 'b', 't')} + min(wo.z, 0.0);\n}}\n")
            got, _ = run(ctx, [lib], wi, wi, es=es, with_error=False)
            assert np.all(np.abs(got[0] - want[j]) <= q.err[s] + 1e-300), (g, j, es)
