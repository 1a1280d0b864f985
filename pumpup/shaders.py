"""Shader code for pumpup's BRDFs: GLSL, GLSL ES, HLSL, Metal and Disney's BRDF Explorer, with the tables baked in.

``pumpup.shader(spec, target="glsl")`` turns a closed-form model, a ``pumped`` chain of it (g1 or g2, any number of
levels) or a compensated one (``kulla_conty``, ``scaled``) into source code.  The pumped levels' albedo bounds and the
compensation's bound U >= E go in as constant arrays of polynomial pieces in the cosine m, fitted for float32
(:data:`FIT_TOL`): where every level's bound increases, the product G(m) of all levels' g at m = max(N.wi, N.wo) (as
pumpup's product table, :class:`pumpup.operators.pumping._Product`); otherwise every level's bound on one shared set of
pieces (as pumpup's level table, :class:`pumpup.operators.pumping._LevelTable`), so that one piece search per cosine
serves every level (:class:`_Pieces`); below the tables' lower end (1e-8) the bounds' largest values there.  The code
has no branches on the cosines: a software rasteriser runs every branch of a group of pixels.

Conventions of the ``glsl`` and ``glsl-es`` targets (a library snippet: a header comment, no ``#version`` line, no
``precision`` line, no ``main``; every global name starts with ``pumpup_``)::

    float pumpup_brdf(vec3 wi, vec3 wo)

in the local frame N = (0, 0, 1), ``wi`` towards the light, ``wo`` towards the viewer, f_r in 1/sr *without* the cosine
factor, 0 below the horizon: :meth:`pumpup.core.BRDF.eval`.  A model's parameters are ``uniform float pumpup_<name>;``
(:func:`uniforms` gives their values); a pumped or compensated model bakes every parameter, since each one changes the
tables, and the header says so.

The bound survives the cast
---------------------------
The shader evaluates in float32.  Every model's code computes, beside its value, a bound B of its relative float32
error (first-order propagation of the roundings with the accuracy GLSL specifies for its built-ins: + - * correctly
rounded, / 2.5 ULP, exp and exp2 (3 + 2|x|) ULP, log and log2 an absolute 2^-21 inside [0.5, 2] and 3 ULP outside,
inversesqrt 2 ULP; the float32 rounding of the parameters included).  A pumped or compensated model multiplies its base
value by 1 - 2 B and reads table pieces whose constant terms were raised, in double precision before the rounding to
float32, by twice the fit's largest miss, pumpup's own table's epsilon and twice the worst float32 error of the piece
(Horner's rule, the rounding of the coefficients and of the variable), so that every bound it divides by is at least
pumpup's, and the result is rounded down once more for the
final products and quotient: the shader's value is never above pumpup's double-precision value at the same
(float32) directions, and the exported BRDF keeps its albedo <= 1 (001 eq. 18), as the Mitsuba plugin does
(:mod:`pumpup.mitsuba`).

The ``hlsl`` and ``msl`` targets are translated by ``glslangValidator`` (GLSL -> SPIR-V) and ``spirv-cross``
(SPIR-V -> HLSL / MSL) from a standalone compute shader that wraps the GLSL library; ``brdf-explorer`` writes a
``.brdf`` file for Disney's BRDF Explorer (a parameter block and ``vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)``,
which works in the frame it is given).

This module is over 1,000 lines because every model's GLSL source stands beside its float32 error bound and the
baking of the pumped and compensated tables that the bound protects: a model's shader and its bound are read and
changed together.
"""

from __future__ import annotations

import json
import math
import os
import shlex
import shutil
import subprocess
import tempfile
from typing import Any

import numpy as np

from ._version import __version__
from .core import BRDF, SpecError, load

__all__ = ["shader", "uniforms", "table_error", "TARGETS", "SUPPORTED", "write_shader", "error_bound_text"]

#: the targets :func:`shader` writes
TARGETS = ("glsl", "glsl-es", "hlsl", "msl", "brdf-explorer")

#: float32's unit roundoff
U = 2.0**-24
_LN2 = math.log(2.0)

# ----------------------------------------------------------------------------------------
# float32 helpers: literals and directed rounding
# ----------------------------------------------------------------------------------------


def _f32(x: float) -> np.float32:
    return np.float32(x)


def _up32(x: float) -> np.float32:
    """The smallest float32 >= x."""
    y = np.float32(x)
    if float(y) < x:
        y = np.nextafter(y, np.float32(np.inf))
    return y


def _down32(x: float) -> np.float32:
    """The largest float32 <= x."""
    y = np.float32(x)
    if float(y) > x:
        y = np.nextafter(y, np.float32(-np.inf))
    return y


def _up32_array(x: np.ndarray) -> np.ndarray:
    y = np.asarray(x, dtype=np.float64).astype(np.float32)
    low = y.astype(np.float64) < x
    y[low] = np.nextafter(y[low], np.float32(np.inf))
    return y


def _lit(x: Any) -> str:
    """A GLSL float literal of the float32 value of ``x`` (the shortest decimal that reads back to it)."""
    v = np.float32(x)
    if not np.isfinite(v):
        raise SpecError(f"pumpup.shader: the value {float(x):g} is beyond float32's range (|x| <= 3.4e38), in which "
                        "the shader evaluates")
    s = repr(float(v))
    if "e" not in s and "." not in s:
        s += ".0"
    return s


def _array(name: str, values, per_line: int = 6) -> str:
    vals = [_lit(v) for v in np.asarray(values).ravel()]
    n = len(vals)
    rows = [", ".join(vals[i:i + per_line]) for i in range(0, n, per_line)]
    body = ",\n    ".join(rows)
    return f"const float {name}[{n}] = float[{n}](\n    {body});\n"


# ----------------------------------------------------------------------------------------
# The GLSL of the models: vec2 pumpup_base(l, v) = (f_r, bound of its relative float32 error), for l.z, v.z > 0
# ----------------------------------------------------------------------------------------

_COMMON = """\
const float pumpup_U = 5.9604645e-08;  // float32's unit roundoff, 2^-24
const float pumpup_PI = 3.14159265;

// tan^2 of the angle between N and H = (L + V) / |L + V|, from S = L + V (relative error <= 20 U)
float pumpup_tan2_half(vec3 l, vec3 v) {
    float sz = l.z + v.z;
    float qx = (l.x + v.x) / sz;
    float qy = (l.y + v.y) / sz;
    return qx * qx + qy * qy;
}

// bound of the absolute error of log2(x) or log(x) = y (GLSL: 2^-21 inside [0.5, 2], 3 ULP outside)
float pumpup_log_err(float y) {
    return 4.7683716e-07 + 6.0 * pumpup_U * abs(y);
}

// bound of the relative error of exp(x) (or exp2(x) with dx in units of ln 2) whose argument has absolute error
// dx: e^dx - 1 plus GLSL's (3 + 2|x|) ULP; 1 where float32 underflows
float pumpup_exp_err(float x, float dx) {
    if (x < -87.0) return 1.0;
    return dx * (1.0 + dx) + (3.0 + 2.0 * abs(x)) * 2.0 * pumpup_U;
}

// ln(1 + x) for x >= 0 and a bound of its absolute error
vec2 pumpup_log1p(float x) {
    if (x < 0.03) {
        float s = x * (1.0 - x * (0.5 - x * (0.33333333 - x * (0.25 - x * 0.2))));
        return vec2(s, 12.0 * pumpup_U * s + x * x * x * x * x * x * 0.17);
    }
    float s = log(1.0 + x);
    return vec2(s, pumpup_log_err(s) + 2.0 * pumpup_U * (1.0 + x));
}
"""

_FRESNEL_DIELECTRIC = """\
// Fresnel factor of a dielectric (002 sec. 3.2) and a bound of its relative error
vec2 pumpup_fresnel_dielectric(float c, float n) {
    float g2 = n * n + c * c - 1.0;
    float g = sqrt(max(g2, 0.0));
    float a = (g - c) / (g + c);
    float q = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    float f = 0.5 * a * a * (1.0 + q * q);
    float eg = 4.0 * pumpup_U * (n * n + c * c) / max(g2, 1e-30) + 12.0 * pumpup_U;
    float err = 40.0 * pumpup_U + 4.0 * (g + c) / max(abs(g - c), 1e-30) * eg
        + 8.0 * pumpup_U * (c * (g + c) + 1.0) + 8.0 * pumpup_U * n * n / max(g2, 1e-30);
    return vec2(f, err);
}
"""

_FRESNEL_CONDUCTOR = """\
// exact Fresnel factor of a conductor (eta + i k) without cancellation, as pumpup.models.metal, and a bound of its
// relative error
vec2 pumpup_fresnel_conductor(float c, float eta, float k) {
    float s2 = (1.0 - c) * (1.0 + c);
    float t0 = (eta - 1.0) * (eta + 1.0) - k * k + c * c;
    float big = sqrt(t0 * t0 + (2.0 * eta * k) * (2.0 * eta * k));
    float ra = sqrt(max(0.5 * (big + t0), 0.0));
    float rb = sqrt(max(0.5 * (big - t0), 0.0));
    float a = t0 >= 0.0 ? ra : eta * k / max(rb, 1e-30);
    float b = t0 >= 0.0 ? eta * k / max(ra, 1e-30) : rb;
    if (big == 0.0) { a = 0.0; b = 0.0; }
    float e21 = (eta - 1.0) * (eta + 1.0) - k * k;
    float plus = (a + c) * (a + c) + b * b;
    float rs = plus > 0.0 ? (e21 * e21 + 4.0 * eta * eta * k * k) / (plus * plus) : 0.0;
    float rp = rs * ((a * c - s2) * (a * c - s2) + b * b * c * c) / ((a * c + s2) * (a * c + s2) + b * b * c * c);
    float err = 256.0 * pumpup_U * (1.0 + (eta * eta + k * k + 1.0) / max(abs(e21) + 2.0 * eta * k, 1e-30));
    return vec2(0.5 * (rs + rp), err);
}
"""

_ERF = """\
// erf(x) for x >= 0 (Abramowitz and Stegun 7.1.26: absolute error <= 1.5e-7)
float pumpup_erf(float x) {
    float t = 1.0 / (1.0 + 0.3275911 * x);
    float p = t * (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
    return 1.0 - p * exp(-x * x);
}
"""


def _phong_code(b: BRDF, stretched: bool) -> str:
    den = ""
    if stretched:
        den = """
    float mx = max(l.z, v.z);
    if (pumpup_p == 1.0) {
        f /= mx;
        e += 5.0 * pumpup_U;
    } else {
        float lm = log2(mx);
        float zp = pumpup_p * lm;
        f /= exp2(zp);  // max(N.L, N.V)^p, 000 eq. 12
        e += pumpup_exp_err(-abs(zp), 0.6931472 * (pumpup_p * pumpup_log_err(lm) + 2.0 * pumpup_U * abs(zp)))
            + 5.0 * pumpup_U;
    }"""
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    float rv = 2.0 * l.z * v.z - dot(l, v);  // R.V, 000 eq. 9 (absolute error <= 8 U)
    if (rv <= 0.0) return vec2(0.0);
    float l2 = log2(rv);
    float z = pumpup_n * l2;
    float f = pumpup_c * exp2(z);  // 000 eq. 5
    float e = pumpup_exp_err(z, 0.6931472 * (pumpup_n * (11.6 * pumpup_U / rv + pumpup_log_err(l2))
        + 2.0 * pumpup_U * abs(z))) + 4.0 * pumpup_U;{den}
    return vec2(f, e);
}}
"""


def _blinn_code(b: BRDF, stretched: bool) -> str:
    tail = "\n    f /= max(l.z, v.z);  // 000 eq. 32\n    e += 5.0 * pumpup_U;" if stretched else ""
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    float t = pumpup_tan2_half(l, v);
    vec2 lp = pumpup_log1p(t);  // -ln (N.H)^2
    float x = -0.5 * pumpup_n * lp.x;
    float f = pumpup_c * exp(x);  // c (N.H)^n, 000 eq. 31
    float dx = 0.5 * pumpup_n * (lp.y + 22.0 * pumpup_U * t / (1.0 + t)) + 2.0 * pumpup_U * abs(x);
    float e = pumpup_exp_err(x, dx) + 4.0 * pumpup_U;{tail}
    return vec2(f, e);
}}
"""


def _ward_code(b: BRDF, modified: bool) -> str:
    if modified:
        den = "4.0 * pumpup_PI * m2 * max(l.z, v.z)"
        cite = "000 eq. 35"
    else:
        den = "4.0 * pumpup_PI * m2 * (sqrt(l.z) * sqrt(v.z))"
        cite = "000 eq. 34, 001 eq. 8"
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    float m2 = pumpup_m * pumpup_m;
    float x = pumpup_tan2_half(l, v) / m2;
    float f = pumpup_c * exp(-x) / ({den});  // {cite}
    return vec2(f, pumpup_exp_err(-x, 31.0 * pumpup_U * x) + 48.0 * pumpup_U);
}}
"""


def _cook_torrance_code(b: BRDF) -> str:
    ior = b.p["ior"]
    fres = ("vec2 fr = pumpup_fresnel_dielectric(c, pumpup_ior);  // 002 sec. 3.2" if ior is not None
            else "vec2 fr = vec2(1.0, 0.0);")
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    vec3 s = l + v;
    float t = pumpup_tan2_half(l, v);
    float m2 = pumpup_m * pumpup_m;
    float x = t / m2;
    float d = exp(-x) * ((1.0 + t) * (1.0 + t)) / (4.0 * pumpup_PI * m2);  // 001 eq. 9
    float g = min(1.0, 4.0 * min(l.z, v.z) / (s.z * (1.0 + t)));  // 001 eq. 10
    float c = 0.5 * sqrt(dot(s, s));  // V.H
    {fres}
    float f = fr.x * d * g / (l.z * v.z);  // 001 eq. 9
    return vec2(f, pumpup_exp_err(-x, 31.0 * pumpup_U * x) + fr.y + 96.0 * pumpup_U);
}}
"""


def _schlick_code(b: BRDF) -> str:
    return """\
vec2 pumpup_base(vec3 l, vec3 v) {
    float t = pumpup_tan2_half(l, v);
    float cos2 = 1.0 / (1.0 + t);
    float sin2 = t <= 1.0 ? t * cos2 : 1.0 - cos2;
    float r = pumpup_r;
    float d = r + (1.0 - r) * sin2;  // 1 - (1 - r)(N.H)^2
    float gl = r + (1.0 - r) * l.z;
    float gv = r + (1.0 - r) * v.z;
    float f = pumpup_c / (4.0 * pumpup_PI) * (r / d / d) / (gl * gv);  // 000 eq. 36
    return vec2(f, 192.0 * pumpup_U);
}
"""


def _lambert_code(b: BRDF) -> str:
    return """\
vec2 pumpup_base(vec3 l, vec3 v) {
    return vec2(pumpup_albedo * 0.318309886, 6.0 * pumpup_U);
}
"""


def _microfacet_code(b: BRDF) -> str:
    dist, _alpha, shadowing, g1, ior, eta, _k = b.kernel_args()
    parts = []
    if dist == 0:  # Beckmann
        parts.append("""\
    float x = t / a2;
    float d = exp(-x) * ((1.0 + t) * (1.0 + t)) / (pumpup_PI * a2);  // Walter eq. 25
    float e = pumpup_exp_err(-x, 31.0 * pumpup_U * x) + 64.0 * pumpup_U;""")
        if g1 == 0:
            proj = """\
float pumpup_projected(vec3 w) {  // z (1 + Lambda) = z / G1, Walter eq. 27 (exact)
    float s = sqrt(w.x * w.x + w.y * w.y);
    if (s == 0.0) return w.z;
    float a = w.z / (pumpup_alpha * s);
    return 0.5 * (w.z * (1.0 + pumpup_erf(a)) + pumpup_alpha * s * exp(-a * a) * 0.564189584);
}
const float pumpup_projected_err = 3.2e-6;
"""
        else:
            proj = """\
float pumpup_projected(vec3 w) {  // z / G1 with Walter's rational G1 (Walter eq. 27)
    float s = sqrt(w.x * w.x + w.y * w.y);
    if (s == 0.0) return w.z;
    float a = w.z / (pumpup_alpha * s);
    if (a >= 1.6) return w.z;
    return pumpup_alpha * s * (1.0 + 2.276 * a + 2.577 * a * a) / (3.535 + 2.181 * a);
}
float pumpup_projected_jump(vec3 w) {  // Walter's G1 jumps by 5.7e-5 at a = 1.6: a bound where a may round across
    float s = sqrt(w.x * w.x + w.y * w.y);
    float a = w.z / (pumpup_alpha * s);
    return abs(a - 1.6) < 1e-5 ? 1.2e-4 : 0.0;
}
const float pumpup_projected_err = 1.9e-6;
"""
    else:  # GGX
        parts.append("""\
    float cos2 = 1.0 / (1.0 + t);
    float sin2 = t <= 1.0 ? t * cos2 : 1.0 - cos2;
    float q = a2 * cos2 + sin2;
    float d = a2 / (pumpup_PI * q * q);  // Walter eq. 33
    float e = 128.0 * pumpup_U;""")
        proj = """\
float pumpup_projected(vec3 w) {  // z (1 + Lambda) = z / G1, Walter eq. 34
    float s2 = w.x * w.x + w.y * w.y;
    return 0.5 * (w.z + sqrt(w.z * w.z + pumpup_alpha * pumpup_alpha * s2));
}
const float pumpup_projected_err = 1.5e-6;
"""
    if eta > 0.0:
        fres = "vec2 fr = pumpup_fresnel_conductor(c, pumpup_eta, pumpup_k);"
    elif ior > 0.0:
        fres = "vec2 fr = pumpup_fresnel_dielectric(c, pumpup_ior);"
    else:
        fres = "vec2 fr = vec2(1.0, 0.0);"
    if shadowing == 0:
        tail = "float f = d * fr.x / (4.0 * pl * pv);  // Walter eq. 20, separable Smith"
    else:
        tail = "float f = d * fr.x / (4.0 * (v.z * pl + l.z * pv - l.z * v.z));  // Heitz 2014, height-correlated"
    jump = " + pumpup_projected_jump(l) + pumpup_projected_jump(v)" if (dist == 0 and g1 == 1) else ""
    body = "\n".join(parts)
    return proj + f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    vec3 s = l + v;
    float t = pumpup_tan2_half(l, v);
    float a2 = pumpup_alpha * pumpup_alpha;
{body}
    float c = 0.5 * sqrt(dot(s, s));  // wi.h
    {fres}
    float pl = pumpup_projected(l);
    float pv = pumpup_projected(v);
    {tail}
    return vec2(f, e + fr.y + 2.0 * pumpup_projected_err + 24.0 * pumpup_U{jump});
}}
"""


def _power_lines(var: str, err_abs: str, n: str) -> str:
    """GLSL lines: ``float pw = var^n`` as exp2(n log2 var) and ``float pe``, a bound of its relative error, for
    ``var`` > 0 with absolute error ``err_abs``.
    """
    return f"""\
    float l2 = log2({var});
    float z = {n} * l2;
    float pw = exp2(z);
    float pe = pumpup_exp_err(z, 0.6931472 * ({n} * ({err_abs} / ({var} * 0.6931472) + pumpup_log_err(l2))
        + 2.0 * pumpup_U * abs(z)));
"""


def _retro_code(b: BRDF) -> str:
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    float lv = dot(l, v);  // L.V (absolute error <= 6 U)
    if (lv <= 0.0) return vec2(0.0);
{_power_lines("lv", "6.0 * pumpup_U", "pumpup_n")}    float mx = max(l.z, v.z);
    float f = pumpup_c * pw;
    float e = pe + 4.0 * pumpup_U;
    if (pumpup_p == 1.0) {{
        f /= mx;
        e += 5.0 * pumpup_U;
    }} else {{
        float lm = log2(mx);
        float zp = pumpup_p * lm;
        f /= exp2(zp);
        e += pumpup_exp_err(-abs(zp), 0.6931472 * (pumpup_p * pumpup_log_err(lm) + 2.0 * pumpup_U * abs(zp)))
            + 5.0 * pumpup_U;
    }}
    return vec2(f, e);  // c (L.V)^n / max(N.L, N.V)^p, 000 eq. 13
}}
"""


def _metal_code(b: BRDF) -> str:
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    float rv = 2.0 * l.z * v.z - dot(l, v);  // R.V, 000 eq. 9 (absolute error <= 8 U)
    if (rv <= 0.0) return vec2(0.0);
{_power_lines("rv", "11.6 * pumpup_U", "pumpup_n")}    float mx = max(l.z, v.z);  // cos(Theta_min)
    vec2 fr = pumpup_fresnel_conductor(mx, pumpup_eta, pumpup_k);
    return vec2(pumpup_c * pw / mx * fr.x, pe + fr.y + 10.0 * pumpup_U);  // 000 eq. 28
}}
"""


def _plastic_code(b: BRDF) -> str:
    fres = ("vec2 fr = pumpup_fresnel_conductor(mx, pumpup_eta, 0.0);  // 000 eq. 30" if b.p["eta"] is not None
            else "vec2 fr = vec2(1.0, 0.0);")
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    float f = pumpup_ad * 0.318309886;
    float rv = 2.0 * l.z * v.z - dot(l, v);  // R.V, 000 eq. 9 (absolute error <= 8 U)
    if (rv <= 0.0) return vec2(f, 6.0 * pumpup_U);
{_power_lines("rv", "11.6 * pumpup_U", "pumpup_n")}    float mx = max(l.z, v.z);  // cos(Theta_min)
    {fres}
    float spec = pumpup_a_s * (pumpup_n + 2.0) / (2.0 * pumpup_PI) * pw / mx * fr.x;  // 000 eq. 29
    return vec2(f + spec, max(6.0 * pumpup_U, pe + fr.y + 14.0 * pumpup_U) + 2.0 * pumpup_U);
}}
"""


def _minnaert_code(b: BRDF) -> str:
    return """\
vec2 pumpup_base(vec3 l, vec3 v) {
    float k1 = pumpup_k - 1.0;
    float al = log2(l.z);
    float av = log2(v.z);
    float zl = k1 * al;
    float zv = k1 * av;
    float f = pumpup_b * exp2(zl) * exp2(zv);  // b ((N.S)(N.V))^(k - 1), 002 sec. 3.4
    float el = pumpup_exp_err(zl, 0.6931472 * (abs(k1) * pumpup_log_err(al) + 2.0 * pumpup_U * abs(zl)
        + pumpup_U * pumpup_k * abs(al)));
    float ev = pumpup_exp_err(zv, 0.6931472 * (abs(k1) * pumpup_log_err(av) + 2.0 * pumpup_U * abs(zv)
        + pumpup_U * pumpup_k * abs(av)));
    return vec2(f, el + ev + 4.0 * pumpup_U);
}
"""


def _lacquer_code(b: BRDF) -> str:
    return """\
vec2 pumpup_base(vec3 l, vec3 v) {
    float x = pumpup_s / l.z + pumpup_s / v.z;
    return vec2(pumpup_c * exp(-x), pumpup_exp_err(-x, 8.0 * pumpup_U * x) + 4.0 * pumpup_U);  // 002 sec. 3.3
}
"""


def _phong_shader_code(b: BRDF) -> str:
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    float rv = 2.0 * l.z * v.z - dot(l, v);  // R.V (absolute error <= 8 U)
    if (rv <= 0.0) return vec2(pumpup_kd, pumpup_U);
{_power_lines("rv", "11.6 * pumpup_U", "pumpup_n")}    float spec = pumpup_ks * pw / l.z;  // 002 eq. 5, 8
    return vec2(pumpup_kd + spec, max(pumpup_U, pe + 9.0 * pumpup_U) + 2.0 * pumpup_U);
}}
"""


def _phong_blinn_code(b: BRDF) -> str:
    return """\
vec2 pumpup_base(vec3 l, vec3 v) {
    float t = pumpup_tan2_half(l, v);
    vec2 lp = pumpup_log1p(t);  // -ln (N.H)^2
    float x = -0.5 * pumpup_n * lp.x;
    float spec = pumpup_ks * exp(x);  // 002 eq. 24, 6
    float dx = 0.5 * pumpup_n * (lp.y + 22.0 * pumpup_U * t / (1.0 + t)) + 2.0 * pumpup_U * abs(x);
    return vec2(pumpup_kd + spec, max(pumpup_U, pumpup_exp_err(x, dx) + 4.0 * pumpup_U) + 2.0 * pumpup_U);
}
"""


def _lafortune_code(b: BRDF) -> str:
    err = "8.0 * pumpup_U * (abs(pumpup_cx) + abs(pumpup_cy) + abs(pumpup_cz))"
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    float rv = pumpup_cz * (l.z * v.z) - pumpup_cx * (l.x * v.x) - pumpup_cy * (l.y * v.y);  // 000 eq. 14
    if (rv <= 0.0) return vec2(0.0);
{_power_lines("rv", err, "pumpup_n")}    float f = pumpup_c * pw;
    float e = pe + 4.0 * pumpup_U;
    if (pumpup_p == 1.0) {{
        f /= max(l.z, v.z);
        e += 5.0 * pumpup_U;
    }} else if (pumpup_p != 0.0) {{
        float lm = log2(max(l.z, v.z));
        float zp = pumpup_p * lm;
        f /= exp2(zp);  // max(N.L, N.V)^p, 000 eq. 15
        e += pumpup_exp_err(-abs(zp), 0.6931472 * (pumpup_p * pumpup_log_err(lm) + 2.0 * pumpup_U * abs(zp)))
            + 5.0 * pumpup_U;
    }}
    return vec2(f, e);
}}
"""


_ATAN = """\
// atan(x) for x >= 0 (Abramowitz and Stegun 4.4.49 on [0, 1]: relative error <= 2e-8; pi/2 - atan(1/x) above)
float pumpup_atan(float x) {
    float y = x <= 1.0 ? x : 1.0 / x;
    float y2 = y * y;
    float p = 1.0 + y2 * (-0.3333314528 + y2 * (0.1999355085 + y2 * (-0.1420889944 + y2 * (0.1065626393
        + y2 * (-0.0752896400 + y2 * (0.0429096138 + y2 * (-0.0161657367 + y2 * 0.0028662257)))))));
    float a = y * p;
    return x <= 1.0 ? a : 1.57079633 - a;
}
"""


def _torrance_sparrow_code(b: BRDF) -> str:
    d = b.p["d"]
    fres = ("vec2 fr = pumpup_fresnel_dielectric(c, pumpup_ior);  // 002 sec. 3.2" if b.p["ior"] is not None
            else "vec2 fr = vec2(1.0, 0.0);")
    if d == "D1":
        dist = """\
    vec2 lp = pumpup_log1p(t);  // -ln cos^2 alpha
    float x = -0.5 * pumpup_s * lp.x;
    float dist = pumpup_b * exp(x);  // D1 = b cos^e alpha, 002 sec. 3.2
    float ed = pumpup_exp_err(x, 0.5 * pumpup_s * (lp.y + 22.0 * pumpup_U * t / (1.0 + t)) + 2.0 * pumpup_U * abs(x))
        + 2.0 * pumpup_U;"""
    elif d == "D2":
        dist = """\
    float al = pumpup_atan(sqrt(t));  // alpha (relative error <= 2e-8 + 48 U)
    float y = pumpup_s * al;
    float x = y * y;
    float dist = pumpup_b * exp(-x);  // D2 = b exp(-(c2 alpha)^2), 002 sec. 3.2
    float ed = pumpup_exp_err(-x, x * (4.0e-8 + 110.0 * pumpup_U)) + 2.0 * pumpup_U;"""
    elif d == "D3":
        dist = """\
    float cos2 = 1.0 / (1.0 + t);
    float sin2 = t <= 1.0 ? t * cos2 : 1.0 - cos2;
    float s2 = pumpup_s * pumpup_s;
    float q = s2 / (s2 * cos2 + sin2);
    float dist = pumpup_b * q * q;  // D3, 002 sec. 3.2
    float ed = 128.0 * pumpup_U;"""
    else:
        dist = """\
    float s2 = pumpup_s * pumpup_s;
    float x = t / s2;
    float dist = exp(-x) * ((1.0 + t) * (1.0 + t)) / (4.0 * s2);  // D4 (Beckmann), 002 sec. 3.2
    float ed = pumpup_exp_err(-x, 31.0 * pumpup_U * x) + 64.0 * pumpup_U;"""
    return f"""\
vec2 pumpup_base(vec3 l, vec3 v) {{
    vec3 s = l + v;
    float t = pumpup_tan2_half(l, v);  // tan^2 alpha
{dist}
    float g = min(1.0, 4.0 * min(l.z, v.z) / (s.z * (1.0 + t)));  // G, 002 sec. 3.2 (001 eq. 10)
    float c = 0.5 * sqrt(dot(s, s));  // V.H
    {fres}
    float f = fr.x * g * dist / (pumpup_PI * (l.z * v.z));  // 002 eq. 10
    return vec2(f, ed + fr.y + 96.0 * pumpup_U);
}}
"""


def _oren_nayar_code(b: BRDF) -> str:
    return """\
vec2 pumpup_base(vec3 l, vec3 v) {
    float s2 = pumpup_sigma * pumpup_sigma;
    float a = 1.0 - 0.5 * s2 / (s2 + 0.33);  // Oren & Nayar 1994, qualitative model
    float bb = 0.45 * s2 / (s2 + 0.09);
    // max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta) = max(0, Lx Vx + Ly Vy) / max(N.L, N.V)
    float t = max(l.x * v.x + l.y * v.y, 0.0);
    float mx = max(l.z, v.z);
    float r = bb * t / mx;
    float f = pumpup_albedo * 0.318309886 * (a + r);  // Oren & Nayar 1994, qualitative model
    float e = (16.0 * pumpup_U * a + 24.0 * pumpup_U * r + 3.0 * pumpup_U * bb * (abs(l.x * v.x) + abs(l.y * v.y)) / mx)
        / (a + r) + 8.0 * pumpup_U;
    return vec2(f, e);
}
"""


def _ashikhmin_shirley_code(b: BRDF) -> str:
    return """\
vec2 pumpup_base(vec3 l, vec3 v) {
    vec3 s = l + v;
    float hk = 0.5 * sqrt(dot(s, s));  // h.k = |k1 + k2| / 2
    vec3 dd = l - v;
    float q = dot(dd, dd) / (4.0 * (1.0 + hk));  // 1 - h.k
    float q2 = q * q;
    float q5 = q2 * q2 * q;
    float rs = pumpup_rs;
    float fres = rs + (1.0 - rs) * q5;  // AS 2000 eq. 5 (Schlick's F(h.k))
    float ef = (2.0 * pumpup_U * rs + 2.0 * pumpup_U * q5 + 140.0 * pumpup_U * (1.0 - rs) * q5) / max(fres, 1e-30)
        + pumpup_U;
    float t = pumpup_tan2_half(l, v);  // tan^2 theta_h = (S_x^2 + S_y^2) / S_z^2
    float d = 1.0;
    float ed = 0.0;
    if (t > 0.0) {
        float qx = s.x / s.z;
        float qy = s.y / s.z;
        float e = (pumpup_nu * (qx * qx) + pumpup_nv * (qy * qy)) / t;  // nu cos^2 phi_h + nv sin^2 phi_h
        vec2 lp = pumpup_log1p(t);  // -2 ln(N.h)
        float x = -0.5 * e * lp.x;
        d = exp(x);  // (N.h)^e, AS 2000 eq. 4
        ed = pumpup_exp_err(x, 0.5 * e * (lp.y + 22.0 * pumpup_U * t / (1.0 + t)) + 48.0 * pumpup_U * abs(x));
    }
    float norm = sqrt((pumpup_nu + 1.0) * (pumpup_nv + 1.0)) * 0.0397887358;  // / (8 pi)
    float spec = norm * d * fres / hk / max(l.z, v.z);  // AS 2000 eq. 4
    float kd = 0.387507297 * pumpup_rd * (1.0 - rs);  // 28 rd / (23 pi) (1 - rs), AS 2000 eq. 5
    float xi = 0.5 * l.z;
    float xo = 0.5 * v.z;
    // 1 - (1 - x)^5 = x (5 - 10 x + 10 x^2 - 5 x^3 + x^4), x = N.k / 2 (relative error <= 64 U)
    float gi = xi * (5.0 + xi * (-10.0 + xi * (10.0 + xi * (-5.0 + xi))));
    float go = xo * (5.0 + xo * (-10.0 + xo * (10.0 + xo * (-5.0 + xo))));
    float diff = kd * (gi * go);  // AS 2000 eq. 5
    float f = spec + diff;
    float abs_err = spec * (ed + ef + 48.0 * pumpup_U) + diff * 136.0 * pumpup_U
        + 0.387507297 * pumpup_rd * (8.0 * pumpup_U * (1.0 - rs) + 2.0 * pumpup_U) * (gi * go);
    return vec2(f, abs_err / max(f, 1e-37) + pumpup_U);
}
"""


class _HsTable:
    """Lewis's normalisation H_s(mu) (:func:`pumpup.models.lewis.phong_hs`) for one exponent, as polynomial pieces of
    degree 5 in mu (:func:`pumpup.operators.pumping.fit_pieces`, to 1e-10 relative at its test points, checked at 2000
    more) and a bound of the relative error of its float32 evaluation, ``rel`` (fit, Horner's rule, the rounding of
    the coefficients and of mu).
    """

    TOL = 1e-10

    def __init__(self, n: float):
        from .models.lewis import phong_hs
        from .operators.pumping import fit_pieces

        def hs(m):
            return phong_hs(m, n)

        br = np.concatenate([[0.0], 2.0 ** np.arange(-24.0, 0.0, 0.5), [1.0]])
        (coef,), lo, hi, center, half, worst = fit_pieces([hs], br[:-1], br[1:], self.TOL, "H_s table")
        self.lo, self.center, self.ihalf = lo, center, 1.0 / half
        pieces = _Pieces(lo, center, 1.0 / half, [coef], 0.0, "pumpup_hs", raise_=False)
        # the first piece, [0, lo[1]), is found from max(mu, lo[1] / 2): the index then starts there, not at 0
        self.floor = float(np.float32(0.5 * lo[1]))
        pieces.lo32[0] = np.float32(self.floor)
        self.pieces = pieces
        vals = np.min([np.polyval(coef, t) for t in np.linspace(-1.0, 1.0, 9)], axis=0)
        m = np.concatenate([np.geomspace(1e-7, 1.0, 1000), np.linspace(0.0, 1.0, 1000)])
        s = np.clip(np.searchsorted(lo, m, side="right") - 1, 0, len(lo) - 1)
        miss = float(np.max(np.abs(np.polyval(coef[:, s], (m - center[s]) / half[s]) / hs(m) - 1.0)))
        fit = 2.0 * max(float(np.max(worst)), miss)
        #: a bound of the relative error of the shader's H_s
        self.rel = fit + float(np.max(pieces.err / (0.999 * vals))) + 4.0 * U


def _lewis_code(b: BRDF) -> str:
    tab = _HsTable(float(b.p["n"]))
    p = tab.pieces
    hs = p.value(0, "b", "t")
    where = p.locate("", "l.z", f"max(l.z, {_lit(tab.floor)})")
    return p.glsl() + f"""\
const float pumpup_n = {_lit(b.p["n"])};  // baked: H_s's table is made for it
vec2 pumpup_base(vec3 l, vec3 v) {{
    float kd = pumpup_k_rho * (1.0 - pumpup_k_sigma) * 0.318309886;  // 002 eq. 22, the diffuse part
    float ekd = pumpup_k_rho * 0.318309886 * (2.0 * pumpup_U + 5.0 * pumpup_U * (1.0 - pumpup_k_sigma));
    float rv = 2.0 * l.z * v.z - dot(l, v);  // (R_l.V), 000 eq. 9 (absolute error <= 8 U)
    if (rv <= 0.0) return vec2(kd, ekd / max(kd, 1e-37) + pumpup_U);
{_power_lines("rv", "11.6 * pumpup_U", "pumpup_n")}{where}    float hs = {hs};  // H_s(N.S), 002 sec. 4.1
    float spec = pumpup_k_rho * pumpup_k_sigma * pw / hs;  // 002 eq. 22 with F_s = (R_l.V)^n, 002 eq. 5
    float f = kd + spec;
    return vec2(f, (ekd + spec * (pe + {_lit(_up32(tab.rel))} + 6.0 * pumpup_U)) / max(f, 1e-37) + pumpup_U);
}}
"""


#: type -> (the parameters that become uniforms, code generator)
_MODELS = {
    "lambert": (("albedo",), _lambert_code),
    "phong": (("n", "c"), lambda b: _phong_code(b, False)),
    "stretched_phong": (("n", "p", "c"), lambda b: _phong_code(b, True)),
    "blinn": (("n", "c"), lambda b: _blinn_code(b, False)),
    "stretched_blinn": (("n", "c"), lambda b: _blinn_code(b, True)),
    "ward": (("m", "c"), lambda b: _ward_code(b, False)),
    "modified_ward": (("m", "c"), lambda b: _ward_code(b, True)),
    "cook_torrance": (("m", "ior"), _cook_torrance_code),
    "schlick": (("r", "c"), _schlick_code),
    "ggx": (("alpha", "ior", "eta", "k"), _microfacet_code),
    "beckmann": (("alpha", "ior", "eta", "k"), _microfacet_code),
    "retro": (("n", "p", "c"), _retro_code),
    "metal": (("n", "eta", "k", "c"), _metal_code),
    "plastic": (("n", "ad", "a_s", "eta"), _plastic_code),
    "minnaert": (("k", "b"), _minnaert_code),
    "lacquer": (("c", "s"), _lacquer_code),
    "phong_shader": (("n", "ks", "kd"), _phong_shader_code),
    "phong_blinn": (("n", "ks", "kd"), _phong_blinn_code),
    "lafortune": (("n", "cx", "cy", "cz", "p", "c"), _lafortune_code),
    "torrance_sparrow": (("s", "b", "ior"), _torrance_sparrow_code),
    "oren_nayar": (("albedo", "sigma"), _oren_nayar_code),
    "ashikhmin_shirley": (("nu", "nv", "rs", "rd"), _ashikhmin_shirley_code),
    "lewis_phong": (("k_rho", "k_sigma"), _lewis_code),
}

#: parameters that are baked into a model's code whatever the spec (they choose the code or change a table in it)
_BAKED = {"torrance_sparrow": ("d",), "lewis_phong": ("n",)}

#: the model types :func:`shader` translates (and the operators over them)
SUPPORTED = tuple(sorted(_MODELS)) + ("pumped", "kulla_conty", "scaled", "fresnel")


def error_bound_text() -> dict[str, str]:
    """The relative float32 error bound B of each model's shader code, in words (the docs' table)."""
    return {
        "lambert": "6 U",
        "phong": "(exp) + n (11.6 U / R.V + 2^-21 + 6 U |log2 R.V|) ln 2 + 2 U |n log2 R.V| + 4 U",
        "blinn": "(exp) + n/2 (error of ln(1 + tan^2) + 22 U) + 4 U",
        "ward": "(exp) + 31 U tan^2/m^2 + 48 U",
        "cook_torrance": "(exp) + 31 U tan^2/m^2 + Fresnel + 96 U",
        "schlick": "192 U",
        "ggx": "128 U + Fresnel + 2 x 1.5e-6 (Smith) + 24 U",
        "beckmann": "(exp) + 31 U tan^2/alpha^2 + 64 U + Fresnel + 2 x 3.2e-6 (Smith with erf) + 24 U",
        "retro": "as phong with L.V (absolute error 6 U) and the max(N.L, N.V)^p term",
        "metal": "as phong + conductor Fresnel + 10 U",
        "plastic": "max(6 U, phong's + Fresnel + 14 U) + 2 U",
        "minnaert": "two exp2 terms e(z, |k - 1| (2^-21 + 6 U |log2 mu|) + 2 U |z| + U k |log2 mu|) + 4 U",
        "lacquer": "e(-x, 8 U x) + 4 U, x = s (1/N.L + 1/N.V)",
        "phong_shader": "max(U, phong's + 9 U) + 2 U",
        "phong_blinn": "max(U, blinn's) + 2 U",
        "lafortune": "as phong with the lobe's absolute error 8 U (|cx| + |cy| + |cz|) and the max(N.L, N.V)^p term",
        "torrance_sparrow": "D's + Fresnel + 96 U; D1 e(x, s/2 (error of ln(1 + tan^2) + 22 U tan^2/(1 + tan^2)) "
                            "+ 2 U |x|) + 2 U, D2 e(-x, x (4e-8 + 110 U)) + 2 U (an atan of relative error 2e-8), "
                            "D3 128 U, D4 e(-x, 31 U x) + 64 U",
        "oren_nayar": "(16 U A + 24 U r + 3 U B (|Lx Vx| + |Ly Vy|) / max(N.L, N.V)) / (A + r) + 8 U, "
                      "r = B max(0, Lx Vx + Ly Vy) / max(N.L, N.V)",
        "ashikhmin_shirley": "(the lobe x (e(x, e/2 (error of ln(1 + tan^2) + 22 U tan^2/(1 + tan^2)) + 48 U |x|) + "
                             "Schlick's (2 U rs + 2 U q^5 + 140 U (1 - rs) q^5) / F + U + 48 U) + the diffuse term x "
                             "136 U + its factor's rounding) / f + U",
        "lewis_phong": "(the diffuse part's 0.32 k_rho (2 U + 5 U (1 - k_sigma)) + the lobe x (phong's power + H_s's "
                       "table error + 6 U)) / f + U",
    }


# ----------------------------------------------------------------------------------------
# What a spec becomes: the base, its levels or compensation, and the parameters
# ----------------------------------------------------------------------------------------


def _unsupported(b: BRDF, where: str = "") -> SpecError:
    what = f"model type {b.type!r}" + (f" ({where})" if where else "")
    return SpecError(f"pumpup.shader: {what} has no shader translation; supported: {', '.join(SUPPORTED)} "
                     "(pumped and compensated over the closed-form ones)")


class _Plan:
    """A BRDF taken apart for the shader: ``base`` (a closed-form model), ``levels`` (pumped, innermost first) or
    ``comp`` (a compensated model), and whether its parameters are baked.
    """

    def __init__(self, brdf: BRDF):
        from .operators.compensate import KullaConty, Scaled
        from .operators.pumping import Pumped

        self.brdf = brdf
        self.levels: list = []
        self.comp = None
        b = brdf
        #: (eta, k) of an outer ``fresnel`` model (base x F(Theta_min), 000 eq. 28), else None
        self.fresnel = None
        if b.type == "fresnel" and np.ndim(b.p["eta"]) == 0 and np.ndim(b.p["k"]) == 0:
            self.fresnel = (float(b.p["eta"]), float(b.p["k"]))
            b = b.p["base"]
            if isinstance(b, (KullaConty, Scaled)):
                raise _unsupported(b, "inside 'fresnel': F(Theta_min) over a compensation")
        if isinstance(b, (KullaConty, Scaled)):
            self.comp = b
            b = b.base
        elif isinstance(b, Pumped):
            self.levels = b.chain()
            b = self.levels[0].base
        if isinstance(b, (Pumped, KullaConty, Scaled)):
            raise _unsupported(b, f"inside {brdf.type!r}: one operator over a closed-form model is supported")
        if b.type not in _MODELS or not isinstance(b, BRDF) or getattr(b, "fn", None) is not None:
            raise _unsupported(b)
        # (1, 3) arrays, not single vectors: the model's row kernel, which is loaded anyway, rather than its
        # broadcasting ufunc, whose first call builds a wrapper (0.15 s)
        if np.shape(b.eval(np.array([[0.0, 0.0, 1.0]]), np.array([[0.0, 0.0, 1.0]]))) != (1,):
            raise _unsupported(b, "spectral or multi-channel")
        self.base = b
        self.baked = bool(self.levels) or self.comp is not None
        names = _MODELS[b.type][0]
        self.params = {k: float(b.p[k]) for k in names if b.p.get(k) is not None}
        if self.fresnel is not None:
            self.params["fresnel_eta"], self.params["fresnel_k"] = self.fresnel
        s = math.sqrt(0.5)
        peak = np.asarray(brdf.eval(np.array([[0.0, 0.0, 1.0], [s, 0.0, s]]),
                                    np.array([[0.0, 0.0, 1.0], [-s, 0.0, s]])))
        for k, v in self.params.items():
            if not abs(v) <= float(np.finfo(np.float32).max):
                raise SpecError(f"pumpup.shader: parameter {k!r} = {v:g} is beyond float32's range (|x| <= 3.4e38), "
                                "in which the shader evaluates")
        if not np.all(np.abs(peak) <= float(np.finfo(np.float32).max)):
            raise SpecError(f"pumpup.shader: {json.dumps(brdf.spec)} evaluates to {float(np.max(np.abs(peak))):g} "
                            "at its peak, beyond float32's range (3.4e38) in which the shader evaluates")


def uniforms(spec: Any) -> dict[str, float]:
    """The uniforms of :func:`shader`'s GLSL for ``spec``: name -> value (empty when every parameter is baked).

    Parameters
    ----------
    spec : dict, str or BRDF
        As :func:`pumpup.load`.

    Returns
    -------
    dict
        ``{"pumpup_n": 20.0, "pumpup_c": 3.18...}``: set each ``uniform float`` to its value.

    Examples
    --------
    >>> uniforms("phong:n=20")["pumpup_n"]
    20.0
    """
    plan = _Plan(spec if isinstance(spec, BRDF) else load(spec))
    if plan.baked:
        return {}
    return {f"pumpup_{k}": v for k, v in plan.params.items()}


# ----------------------------------------------------------------------------------------
# Tables: a level's spline pieces in ln(mu), a product table's polynomial pieces in m
# ----------------------------------------------------------------------------------------

_GAMMA = 12.0 * U  # Horner's rule of degree 5 in float32 (2 x 5 roundings), with the coefficients' own


def _poly_error(coef: np.ndarray, w: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """Per piece (columns of ``coef``, highest power first): a bound of |P32(x') - P(x)| for |x| <= w, |x' - x| <=
    ``delta``, P32 Horner's rule in float32 on the coefficients rounded to float32.
    """
    deg = coef.shape[0] - 1
    err = np.zeros(coef.shape[1])
    for r in range(deg + 1):
        p = deg - r
        a = np.abs(coef[r])
        err += a * (((w + delta) ** p - w ** p) + _GAMMA * (w + delta) ** p)
    return err


#: cells per octave of the piece index (the float32 bits of the variable, as pumpup's kernel uses the float64 bits):
#: at least 2^_CELL_BITS, more (up to 2^_CELL_BITS_MAX) until no cell holds more than two piece starts
_CELL_BITS = 4
_CELL_BITS_MAX = 10
#: the most cells of one index (4-byte ints in the source)
_CELLS_MAX = 2048


#: the cosine above which the piece index has its finer cells (most cosines, and most pieces, lie above it)
_FINE_FROM = 0.25


def _cells(b: np.ndarray, bits: int, start: float, end: float) -> tuple[int, int, int, np.ndarray, int]:
    """(shift, cbase, ncell, first piece of each cell, most piece starts in a cell) of 2^bits cells per octave from the
    cell of ``start`` up to the cell of ``end``.
    """
    n = len(b)
    shift = 23 - bits
    cbase = int(int(np.array([start], np.float32).view(np.uint32)[0]) >> shift)
    cend = int(int(np.array([end], np.float32).view(np.uint32)[0]) >> shift)
    ncell = max(cend - cbase + 1, 1)
    starts = ((np.arange(ncell, dtype=np.int64) + cbase) << shift).astype(np.uint32).view(np.float32)
    ends = ((np.arange(ncell, dtype=np.int64) + cbase + 1) << shift).astype(np.uint32).view(np.float32)
    starts = np.maximum(starts, np.float32(start))
    ends = np.minimum(ends, np.float32(np.nextafter(np.float32(end), np.float32(np.inf))))
    first = np.clip(np.searchsorted(b, starts, side="right") - 1, 0, n - 1)
    last = np.clip(np.searchsorted(b, ends, side="left") - 1, 0, n - 1)
    return shift, cbase, ncell, first, int(np.max(last - first)) + 1


def _choose_cells(b: np.ndarray, start: float, end: float, most: int, bits: int = _CELL_BITS):
    """:func:`_cells` with ``bits`` and up until no cell holds more than two piece starts, within ``most`` cells."""
    got = _cells(b, bits, start, end)
    while got[4] > 2 and bits < _CELL_BITS_MAX:
        nxt = _cells(b, bits + 1, start, end)
        if nxt[2] > most:
            break
        bits += 1
        got = nxt
    return got


#: the most bits of a crowded cell's sub-cells (:class:`_Index`)
_SUB_BITS_MAX = 8


def _span(b: np.ndarray, lo_bits: np.ndarray, width: int, start: float, end: float) -> tuple[np.ndarray, np.ndarray]:
    """The first and the last piece (lower ends ``b``) that may hold a float32 in each range of bits [lo_bits, lo_bits
    + width) within [``start``, ``end``].
    """
    n = len(b)
    starts = np.maximum(lo_bits.astype(np.uint32).view(np.float32), np.float32(start))
    ends = np.minimum((lo_bits + width).astype(np.uint32).view(np.float32),
                      np.float32(np.nextafter(np.float32(end), np.float32(np.inf))))
    first = np.clip(np.searchsorted(b, starts, side="right") - 1, 0, n - 1)
    last = np.clip(np.searchsorted(b, ends, side="left") - 1, 0, n - 1)
    return first, last


class _Index:
    """How the shader finds the piece of a float32 ``var`` >= the first lower end (``bounds32``, sorted): the largest s
    with ``{nm}_b[s] <= var``, without branches.

    The cell of ``var`` from its float32 bits (2^bits cells per octave, as :func:`pumpup.physics.lookups.g_product`
    finds a piece from the float64 bits; below _FINE_FROM and above it, bits each from _CELL_BITS up until a cell
    holds at most two piece starts, within _CELLS_MAX cells in all) gives ``{nm}_cs[cell]``: the first candidate
    piece, or, for a cell that still holds more than two piece starts (pieces crowd where a bound is barely smooth:
    3-level g2 pumped GGX near m = 0.97), -1 - the offset of its 2^``sub`` sub-cells (the next ``sub`` bits of
    ``var``) in ``{nm}_sub``, each holding its first candidate piece; then a binary search of fixed length over the
    candidates (the bounds array is padded with float32's largest value, so the steps need no range check).  Both
    reads are made for every ``var`` (a GPU runs both sides of a select): two dependent reads and one step instead of
    one read and up to four steps.  :meth:`piece` is the plain numpy reference of the GLSL.
    """

    def __init__(self, bounds32: np.ndarray):
        b = np.asarray(bounds32, dtype=np.float32)
        self.b = b
        lo = float(b[0])
        self.split = float(np.float32(max(_FINE_FROM, lo)))
        regions = [_choose_cells(b, self.split, 1.0, _CELLS_MAX // 2)]
        if lo < self.split:
            regions.insert(0, _choose_cells(b, lo, self.split, _CELLS_MAX // 2, bits=1))  # (few pieces down there)
            self.coarse = regions[0][:3]
        else:
            self.coarse = (19, 0, 0)
        self.fine = regions[-1][:3]
        ends = [(lo, self.split), (self.split, 1.0)][-len(regions):]
        cells, counts = [], []
        for (shift, cbase, ncell, _, _), (a, z) in zip(regions, ends):
            bits = (np.arange(ncell, dtype=np.int64) + cbase) << shift
            first, last = _span(b, bits, 1 << shift, a, z)
            cells.append((shift, bits, first, last, a, z))
            counts.append(last - first + 1)
        count = int(max(int(np.max(c)) for c in counts))
        #: the sub-cells' bits (0: none) and entries
        self.sub, subs = 0, []
        cs = np.concatenate([c[2] for c in cells]).astype(np.int64)
        if count > 2:
            top = min(_SUB_BITS_MAX, min(c[0] for c in cells))
            for k in range(1, top + 1):
                worst, entries = 1, []
                for shift, bits, first, last, a, z in cells:
                    for c in np.nonzero(last - first + 1 > 2)[0]:
                        sb = bits[c] + (np.arange(1 << k, dtype=np.int64) << (shift - k))
                        f2, l2 = _span(b, sb, 1 << (shift - k), a, z)
                        worst = max(worst, int(np.max(l2 - f2)) + 1)
                        entries.append(f2)
                if worst < count and (worst <= 2 or k == top):
                    self.sub, subs, count = k, entries, worst
                    break
            if self.sub:
                off = at = 0
                for shift, bits, first, last, a, z in cells:
                    for c in np.nonzero(last - first + 1 > 2)[0]:
                        cs[at + c] = -1 - off
                        off += 1 << self.sub
                    at += len(bits)
        self.cs = cs
        self.subtable = np.concatenate(subs).astype(np.int64) if subs else np.zeros(0, np.int64)
        k = 1
        while k < count:
            k *= 2
        self.width = k  # candidates per cell (a power of two): steps k/2, k/4, ..., 1

    def piece(self, m) -> np.ndarray:
        """The piece the GLSL finds for float32 values ``m`` (each >= the first lower end): the numpy reference."""
        m = np.asarray(m, dtype=np.float32)
        u = m.view(np.uint32).astype(np.int64)
        fs, fbase, nfine = self.fine
        cs_, cbase, ncoarse = self.coarse
        ncell = len(self.cs)
        fine = np.clip((u >> fs) - (fbase - ncoarse), ncoarse, ncell - 1)
        if ncoarse:
            cell = np.where(m >= np.float32(self.split), fine, np.clip((u >> cs_) - cbase, 0, ncoarse - 1))
        else:
            cell = fine
        i = self.cs[cell]
        if self.sub:
            sh = np.where(m >= np.float32(self.split), fs, cs_) - self.sub if ncoarse else fs - self.sub
            j = np.maximum(-1 - i, 0) + ((u >> sh) & ((1 << self.sub) - 1))
            i = np.where(i >= 0, i, self.subtable[np.minimum(j, len(self.subtable) - 1)])
        bp = np.concatenate([self.b, np.full(self.width, np.finfo(np.float32).max, np.float32)])
        k = self.width // 2
        while k >= 1:
            i = i + np.where(bp[i + k] <= m, k, 0)
            k //= 2
        return i

    def glsl(self, nm: str, var: str) -> tuple[str, str]:
        """(arrays, code) of ``int {nm}_piece(float var)``."""
        pad = np.full(self.width, np.finfo(np.float32).max, dtype=np.float32)
        fs, fbase, nfine = self.fine
        cs_, cbase, ncoarse = self.coarse
        ncell = len(self.cs)
        vals = ", ".join(str(int(x)) for x in self.cs)
        arrays = (_array(f"{nm}_b", np.concatenate([self.b, pad]))
                  + f"const highp int {nm}_cs[{ncell}] = int[{ncell}]({vals});\n")
        fine_c = f"clamp(int(u >> {fs}u) - {fbase - ncoarse}, {ncoarse}, {ncell - 1})"
        split = _lit(self.split)
        cell = (f"{var} >= {split} ? {fine_c} : clamp(int(u >> {cs_}u) - {cbase}, 0, {ncoarse - 1})" if ncoarse
                else fine_c)
        lines = [f"    highp uint u = floatBitsToUint({var});", f"    highp int i = {nm}_cs[{cell}];"]
        if self.sub:
            nsub = len(self.subtable)
            arrays += (f"const highp int {nm}_sub[{nsub}] = int[{nsub}]("
                       + ", ".join(str(int(x)) for x in self.subtable) + ");\n")
            sh = f"({var} >= {split} ? {fs - self.sub}u : {cs_ - self.sub}u)" if ncoarse else f"{fs - self.sub}u"
            lines.append(f"    i = i >= 0 ? i : {nm}_sub[max(-1 - i, 0) + int((u >> {sh}) & {(1 << self.sub) - 1}u)];")
        k = self.width // 2
        while k >= 1:
            lines.append(f"    i += {nm}_b[i + {k}] <= {var} ? {k} : 0;")
            k //= 2
        code = f"highp int {nm}_piece(highp float {var}) {{\n" + "\n".join(lines) + "\n    return i;\n}\n"
        return arrays, code


def _search(bounds32: np.ndarray, nm: str, var: str = "m") -> tuple[str, str]:
    """GLSL of ``int {nm}_piece(float var)`` (:class:`_Index`): (arrays, code)."""
    return _Index(bounds32).glsl(nm, var)


def _range_below(lk, t32: float) -> tuple[float, float]:
    """The smallest and the largest value of a level's bound (``pumpup.operators.pumping._Lookup.upper``) at float32
    cosines in (0, ``t32``): the power law below its first node at its two ends (float32's smallest cosine 2^-149 and
    the node), the spline between the node and ``t32`` on 400 points; lowered and raised by 1e-9 of themselves (that
    stretch is a relative 1e-12 of mu wide: the spline moves by less), at most the cap.
    """
    x0 = math.exp(lk.logx[0])
    lo = math.log(2.0**-149)
    ends = [lk.v0 * math.exp(lk.slope0 * (z - lk.logx[0])) for z in (lo, min(math.log(t32), lk.logx[0]))]
    inf, sup = min(ends) + lk.margin_lo, max(ends) + lk.margin_lo
    if t32 > x0:
        spline = lk.upper(np.geomspace(x0, t32, 400), capped=False)
        inf, sup = min(inf, float(np.min(spline))), max(sup, float(np.max(spline)))
    return min(inf * (1.0 - 1e-9), lk.cap), min(sup * (1.0 + 1e-9), lk.cap)


def _sup_below(lk, t32: float) -> float:
    """The largest value of a level's bound at float32 cosines in (0, ``t32``) (:func:`_range_below`)."""
    return _range_below(lk, t32)[1]


def _inf_below(lk, t32: float) -> float:
    """The smallest value of a level's bound at float32 cosines in (0, ``t32``) (:func:`_range_below`)."""
    return _range_below(lk, t32)[0]


class _LevelTable:
    """One level's upper bound u(mu) (:func:`pumpup.physics.lookups.upper_scalar`), as the shader reads it."""

    def __init__(self, lk, name: str):
        self.name = name
        n = len(lk.logx)
        self.npieces = n - 1
        logx = np.asarray(lk.logx, dtype=np.float64)
        coef = np.array(lk.coef, dtype=np.float64)  # (deg + 1, n - 1), highest power first, in d = ln mu - logx[i]
        self.deg = coef.shape[0] - 1
        hi = np.concatenate([logx[1:-1], [max(logx[-1], 0.0)]])
        w = hi - logx[:-1]
        lmax = np.maximum(np.abs(logx[:-1]), np.abs(hi))
        x32 = logx[:-1].astype(np.float32)
        delta = (2.0**-21 + 6.0 * U * lmax) + np.abs(x32.astype(np.float64) - logx[:-1]) + U * (w + lmax) * 2.0
        err = _poly_error(coef, w, delta)
        vals = np.min([np.polyval(coef, w * f) for f in np.linspace(0.0, 1.0, 9)], axis=0) + lk.margin
        #: the largest relative amount by which a piece was raised (half the piece's smallest sampled value)
        self.rel = float(np.max(2.0 * err / np.maximum(0.5 * np.minimum(vals, lk.cap), 1e-300)))
        coef[-1] += lk.margin + 2.0 * err  # the bound of upper_scalar, raised by twice the float32 error
        self.err = err
        self.coef32 = coef.astype(np.float32)
        self.coef32[-1] = _up32_array(coef[-1])
        self.knots = _up32_array(np.exp(logx[:-1]))  # mu >= knots[i]  <=>  ln mu >= logx[i] (in exact arithmetic)
        self.logx32 = x32
        self.logx0 = float(logx[0])
        self.v0, self.slope0, self.margin_lo = float(lk.v0), float(lk.slope0), float(lk.margin_lo)
        self.cap = float(lk.cap)
        self.increasing = bool(lk.increasing)
        self.mu0 = float(lk.mu0)
        self.margin = float(lk.margin)

    def glsl(self) -> str:
        nm, d = self.name, self.deg
        arrays, search = _search(self.knots, nm, "mu")
        out = [arrays, search, _array(f"{nm}_x", self.logx32), _array(f"{nm}_c", self.coef32.T.ravel())]
        horner = f"{nm}_c[b]"
        for r in range(1, d + 1):
            horner = f"({horner}) * dd + {nm}_c[b + {r}]" if r > 1 else f"{nm}_c[b] * dd + {nm}_c[b + 1]"
        cap = f"min(u, {_lit(self.cap)})" if math.isfinite(self.cap) else "u"
        v0 = _lit(_up32(self.v0))
        mlo = _lit(_up32(self.margin_lo * (1.0 + 4 * U)))
        out.append(f"""\
// the upper bound of the level's albedo at mu in (0, 1] (pumpup.physics.lookups.upper_scalar), lm = log(mu): the
// spline piece in ln(mu) that holds mu, a power law below the first node, at most the cap
float {nm}_u(float mu, float lm) {{
    if (mu < {nm}_b[0]) {{
        float x = {_lit(self.slope0)} * (lm - {_lit(self.logx0)});
        float dx = abs({_lit(self.slope0)})
            * (pumpup_log_err(lm) + 2.0 * pumpup_U * (abs(lm) + {_lit(abs(self.logx0))}))
            + 2.0 * pumpup_U * abs(x);
        float u = {v0} * exp(x) * (1.0 + 2.0 * pumpup_exp_err(x, dx) + 4.0 * pumpup_U) + {mlo};
        return {cap};
    }}
    highp int i = {nm}_piece(mu);
    float dd = lm - {nm}_x[i];
    highp int b = {d + 1} * i;
    float u = {horner};
    return {cap};
}}
""")
        return "".join(out)


class _Pieces:
    """Polynomial pieces in m on one set of pieces, one or more functions per piece, as the shader reads them: a
    product table G(m) (:class:`pumpup.operators.pumping._Product`, one function) or a level table
    (:class:`pumpup.operators.pumping._LevelTable`, every level's bound U_j).  Each polynomial is re-expanded about
    its piece's float32 centre (so that m - centre is exact in float32) and its constant term raised, in double
    precision before the rounding to float32, by twice its float32 error (Horner's rule, the rounding of the
    coefficients and of t) and by ``lift`` times its largest value on the piece.

    The arrays: ``{name}_b`` the pieces' lower ends (rounded up to float32; padded), ``{name}_cs`` the cell index
    (:func:`_search`), ``{name}_cen`` and ``{name}_ih`` each piece's float32 centre and inverse half-width, and
    ``{name}_c`` per piece the functions' coefficients one after the other, highest power first (piece s, function j,
    power r at ``(s * k + j) * (degree + 1) + r``): one piece search per cosine serves every function.

    With ``octave``, the polynomials are in t = (m - centre) 2^-e instead, e the exponent of m (of min(m, 1 - 2^-24),
    so that m = 1 shares the exponent of its piece, which lies in [1/2, 1]), computed from the bits of m: exact,
    since every piece lies within an octave, and one read fewer per look-up (no ``{name}_ih``).  (Not for degree 5:
    t^5's coefficient, (half-width 2^-e)^-5 times the fit's, could leave float32's range on the narrowest pieces.)
    """

    #: GLSL of 2^-e for a float32 m in (0, 1] from its bits (e its exponent; 1 - 2^-24's for m = 1)
    OCTAVE = "uintBitsToFloat(0x7F000000u - (floatBitsToUint(min({m}, 0.99999994)) & 0x7F800000u))"

    @staticmethod
    def octave_scale(m) -> np.ndarray:
        """2^-e of float32 values m in (0, 1] as :attr:`OCTAVE` computes it (float64)."""
        e = np.frexp(np.minimum(np.asarray(m, np.float32), np.float32(1.0 - 2.0**-24)).astype(np.float64))[1] - 1
        return np.ldexp(1.0, -e)

    def __init__(self, lo, center, ihalf, coefs, lift, name: str, raise_: bool = True, octave: bool = False):
        self.name = name
        lo = np.asarray(lo, dtype=np.float64)
        hi = np.minimum(np.concatenate([lo[1:], [1.0]]), 1.0)
        center, ihalf = np.asarray(center, dtype=np.float64), np.asarray(ihalf, dtype=np.float64)
        c32 = center.astype(np.float32)
        ih32 = ihalf.astype(np.float32)
        self.octave = octave
        # the variable the shader computes: (m - c32) times ih32, or times 2^-e (the octave of the piece, exactly)
        lo32 = _up32_array(lo)  # a float32 m is in piece s when lo32[s] <= m < lo32[s + 1]
        scale = self.octave_scale(lo32) if octave else ih32.astype(np.float64)
        if octave:  # (every piece within an octave: the last float32 of each has the exponent of its first)
            top = np.concatenate([np.nextafter(lo32[1:], np.float32(0)), [np.float32(1.0)]])
            held = np.concatenate([lo32[1:] > lo32[:-1], [True]])
            if not np.all((self.octave_scale(top) == scale) | ~held):
                raise ValueError("a piece of the shader's table spans more than an octave")
        alpha = ihalf / scale
        beta = (c32.astype(np.float64) - center) * ihalf
        smax = np.maximum(np.abs(lo - c32), np.abs(hi - c32)) * scale * (1.0 + 4 * U)
        rows, errs, rels = [], [], []
        for coef in coefs:
            coef = np.asarray(coef, dtype=np.float64)  # (deg + 1, pieces), highest power first, t = (m - c) ih
            deg = coef.shape[0] - 1
            # Q(s) = P(alpha s + beta): Horner on the coefficient arrays (low power first), all pieces at once
            q = np.zeros((deg + 1, coef.shape[1]))
            q[0] = coef[0]
            for r in range(1, deg + 1):
                nq = np.zeros_like(q)
                nq[1:] += q[:-1] * alpha
                nq += q * beta
                nq[0] += coef[r]
                q = nq
            qh = q[::-1].copy()  # highest power first
            err = _poly_error(qh, smax, U * smax) + 1e-15 * np.sum(
                np.abs(qh) * smax ** np.arange(deg, -1, -1)[:, None], axis=0)
            samples = np.array([np.polyval(coef, t) for t in np.linspace(-1.0, 1.0, 9)])
            vals, vmax = np.min(samples, axis=0), np.max(np.abs(samples), axis=0)
            raise_by = 2.0 * err + np.asarray(lift) * 1.01 * vmax
            #: the largest relative amount by which a piece was raised (against half its smallest sampled value)
            rels.append(float(np.max(raise_by / np.maximum(0.5 * vals, 1e-300))))
            c32 = qh.astype(np.float32)
            if raise_:
                qh[-1] += raise_by
                c32[-1] = _up32_array(qh[-1])
            rows.append(c32)
            errs.append(err)
        self.deg = rows[0].shape[0] - 1
        self.nfun = len(rows)
        #: (pieces, functions, degree + 1)
        self.coef32 = np.stack(rows).transpose(2, 0, 1)
        self.err = np.max(errs, axis=0)
        self.rel = max(rels)
        self.lo32 = _up32_array(lo)  # m >= lo32[s]  <=>  m >= lo[s], for a float32 m
        self.c32, self.ih32 = center.astype(np.float32), ih32
        self.npieces = len(lo)

    def values(self, m) -> np.ndarray:
        """The plain numpy reference of the shader's look-up at float32 cosines ``m`` (>= the first lower end): every
        function's value, (functions,) + m's shape, from the float32 coefficients in double precision.
        """
        m = np.asarray(m, dtype=np.float32)
        s = np.clip(np.searchsorted(self.lo32, m, side="right") - 1, 0, self.npieces - 1)
        scale = self.octave_scale(m) if self.octave else self.ih32[s].astype(np.float64)
        t = (m.astype(np.float64) - self.c32[s].astype(np.float64)) * scale
        out = []
        for j in range(self.nfun):
            v = np.zeros(m.shape)
            for r in range(self.deg + 1):
                v = v * t + self.coef32[s, j, r].astype(np.float64)
            out.append(v)
        return np.stack(out)

    def glsl(self) -> str:
        """The arrays and ``int {name}_piece(float m)``; :meth:`value` writes a function's value from the piece."""
        nm = self.name
        arrays, search = _search(self.lo32, nm, "m")
        ih = "" if self.octave else _array(f"{nm}_ih", self.ih32)
        return "".join([arrays, _array(f"{nm}_cen", self.c32), ih,
                        _array(f"{nm}_c", self.coef32.ravel()), search])

    def value(self, j: int, base: str, t: str) -> str:
        """GLSL of function j's polynomial at ``t``, Horner's rule, the piece's coefficients from ``{name}_c[base +
        ...]`` (``base`` = piece x functions x (degree + 1)).
        """
        nm, d = self.name, self.deg
        o = j * (d + 1)
        expr = f"{nm}_c[{base} + {o}]"
        for r in range(1, d + 1):
            head = expr if r == 1 else f"({expr})"
            expr = f"{head} * {t} + {nm}_c[{base} + {o + r}]"
        return expr

    def locate(self, var: str, m: str, search: str | None = None) -> str:
        """GLSL lines: the piece of ``m`` (>= the first lower end; found from ``search`` if given), ``t{var}`` and
        ``b{var}`` for :meth:`value`.
        """
        nm = self.name
        scale = self.OCTAVE.format(m=m) if self.octave else f"{nm}_ih[s{var}]"
        return (f"    highp int s{var} = {nm}_piece({search or m});\n"
                f"    float t{var} = ({m} - {nm}_cen[s{var}]) * {scale};\n"
                f"    highp int b{var} = {self.nfun * (self.deg + 1)} * s{var};\n")


#: the relative tolerance of the shader's own tables (:func:`_fit_table`): float32's resolution is 6e-8, so pumpup's
#: tables, fitted to 1e-14 for double precision (hundreds of pieces per level), would only make the shader longer and
#: slower to compile
FIT_TOL = 1e-8


#: the degree of the product tables' polynomials (:class:`_PumpedTables`, :class:`_CompTables`)
PRODUCT_DEGREE = 5
#: the degree of the level table's polynomials (:class:`_PumpedTables`): every level's coefficients are read at both
#: cosines, and on llvmpipe a read from a constant array at a computed index costs several arithmetic operations, so
#: cubics (83 pieces for a 3-level g1 pumped GGX alpha 0.3, 150 for g2, against 48 and 95 quintics) read 24 values per
#: pair instead of 36 (scripts/bench/bench_shader.py)
LEVEL_DEGREE = 3


def _kinks(looks, controlled, br: np.ndarray) -> np.ndarray:
    """Values of m in the range of ``br`` where a level's g switches term (its uncapped bound crosses its cap, or, g2,
    its bound crosses m: 001 eq. 21), from the sign changes on ``br`` and its geometric midpoints (brentq).
    """
    from scipy.optimize import brentq

    grid = np.unique(np.concatenate([br, np.sqrt(br[:-1] * br[1:])]))
    out = []
    for lk, c in zip(looks, controlled):
        fns = [] if not math.isfinite(lk.cap) else [lambda m, lk=lk: lk.upper(m, capped=False) - lk.cap]
        if c:
            fns.append(lambda m, lk=lk: lk.upper(m) - m)
        for fn in fns:
            v = fn(grid)
            for i in np.nonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0)[0]:
                out.append(brentq(lambda m, fn=fn: float(fn(np.array([m]))[0]), grid[i], grid[i + 1], xtol=1e-300,
                                  rtol=1e-15))
    return np.array(out)


def _fit_table(functions, looks, controlled, mlo: float, lift: float, name: str,
               degree: int = PRODUCT_DEGREE, octave: bool = False) -> _Pieces:
    """The shader's table of ``functions`` (each positive on [mlo, 1]) as :class:`_Pieces`: polynomials of ``degree``
    in m on one set of pieces (:func:`pumpup.operators.pumping.fit_pieces`: at most an octave each, split where a
    level's g switches term, bisected until each function is met to :data:`FIT_TOL` at the fit's test points), each
    raised by twice its largest miss, at those points and at 33 more per piece, plus ``lift`` of itself (the amount by
    which pumpup's own table may exceed the function) and its float32 error.
    """
    from .operators.pumping import fit_pieces

    br = np.unique(np.concatenate([[mlo, 1.0], 2.0 ** np.arange(math.floor(math.log2(mlo)), 0.0)]))
    br = br[(br >= mlo) & (br <= 1.0)]
    br = np.unique(np.concatenate([br, _kinks(looks, controlled, br)]))
    coefs, lo, hi, center, half, worst = fit_pieces(functions, br[:-1], br[1:], FIT_TOL, f"shader table {name}",
                                                    degree=degree)
    tt = np.linspace(-1.0, 1.0, 33)
    m = np.clip(center[:, None] + half[:, None] * tt[None, :], lo[:, None], hi[:, None])
    miss = np.array(worst)
    for fn, coef in zip(functions, coefs):
        approx = sum(coef[r][:, None] * tt[None, :] ** (coef.shape[0] - 1 - r) for r in range(coef.shape[0]))
        miss = np.maximum(miss, np.max(np.abs(approx / fn(m) - 1.0), axis=1))
    return _Pieces(lo, center, 1.0 / half, coefs, 2.0 * miss + lift, name, octave=octave)


# ----------------------------------------------------------------------------------------
# Assembling the library
# ----------------------------------------------------------------------------------------


def _param_decls(plan: _Plan) -> str:
    lines = []
    for k, v in plan.params.items():
        if plan.baked:
            lines.append(f"const float pumpup_{k} = {_lit(v)};")
        else:
            lines.append(f"uniform float pumpup_{k};")
    return "\n".join(lines) + ("\n" if lines else "")


class _PumpedTables:
    """What a pumped chain's shader reads: the product table (every level's bound increases: G(m), m = max(N.wi,
    N.wo)), else the level table (every level's bound on one set of pieces in m), else each level's spline in ln mu;
    below the tables' lower end ``t32`` (1e-8 for pumpup's tables), each level's largest bound there (``sup``).
    """

    def __init__(self, plan: _Plan):
        from .operators.pumping import _ProductError

        levels = plan.levels
        self.looks = [lev.lookup() for lev in levels]
        self.controlled = [bool(lev.controlled) for lev in levels]
        prod = levels[-1].product()
        self.product = self.table = self.splines = None
        self.t32 = 0.0
        self.below = 0.0
        self.k = 1.0
        # above it every level is on its spline (as pumpup's tables: pumping._Product, pumping._LevelTable)
        mlo = max(max(lk.mu0, math.exp(lk.logx[0])) for lk in self.looks) * (1.0 + 1e-12)
        try:
            if prod is not None:  # pumpup divides by its product table: G (1 + epsilon), its miss <= epsilon / 2
                self.product = _fit_table([prod.exact], self.looks, self.controlled, prod.mlo,
                                          2.0 * prod.epsilon + 4 * np.finfo(float).eps, "pumpup_product")
                mlo = prod.mlo
            else:  # pumpup divides by its level table (at most each U_j) or level by level (U_j)
                self.table = _fit_table([lk.upper for lk in self.looks], self.looks, self.controlled, mlo, 0.0,
                                        "pumpup_lt", degree=LEVEL_DEGREE, octave=True)
        except _ProductError:
            self.product = self.table = None
        if self.product is None and self.table is None:
            self.splines = [_LevelTable(lk, f"pumpup_level{j + 1}") for j, lk in enumerate(self.looks)]
            self.rel = sum(t.rel for t in self.splines)
            return
        self.t32 = float(_up32(mlo))  # m >= t32  <=>  m >= mlo, for a float32 m
        self.sup = [max(_sup_below(lk, self.t32), self.t32 if c else 0.0)
                    for lk, c in zip(self.looks, self.controlled)]
        inf = [_inf_below(lk, self.t32) for lk in self.looks]
        at = [float(lk.upper(np.array([self.t32]))[0]) for lk in self.looks]
        if self.product is not None:
            # every U_j increases: for N.wi or N.wo below t32, g_j <= max(sup_j, g_j(max(m, t32))) <= K_j g_j(...)
            self.k = math.prod(max(1.0, c / u) for c, u in zip(self.sup, at)) * (1.0 + 1e-9)
            self.rel = self.product.rel
            worst = self.k * max(1.0, math.prod(at) / math.prod(inf))
        else:
            self.rel = len(levels) * self.table.rel
            worst = math.prod(max(c / i, 1.0) for c, i in zip(self.sup, inf))
        #: how much lower than pumpup's value (relative) the constant bounds below t32 may make the shader there
        self.below = worst - 1.0


def _pumped_glsl(plan: _Plan) -> tuple[str, list[str], int]:
    tabs = _PumpedTables(plan)
    out, notes = [], []
    nlev = len(plan.levels)
    for j, lev in enumerate(plan.levels):
        lk = tabs.looks[j]
        notes.append(f"level {j + 1} ({lev.p['g']}): albedo bound of {json.dumps(lev.base.spec)}: table margin "
                     f"{lk.margin:.3g}, cap {lk.cap:g}")
    if tabs.splines is not None:
        body = []
        for j, (t, controlled) in enumerate(zip(tabs.splines, tabs.controlled)):
            out.append(t.glsl())
            notes.append(f"level {j + 1}: {t.npieces} pieces (degree {t.deg} in ln mu), float32 error <= "
                         f"{float(np.max(t.err)):.3g} (added)")
            nm = t.name
            if t.increasing:
                look = (f"mmin > {_lit(_down32(t.mu0))} ? {nm}_u(mmax, lmax) : max({nm}_u(mi, li), {nm}_u(mo, lo))")
            else:
                look = f"max({nm}_u(mi, li), {nm}_u(mo, lo))"
            body.append(f"    float g{j + 1} = {look};  // 001 eq. 20")
            if controlled:
                body.append(f"    g{j + 1} = max(g{j + 1}, mmax);  // 001 eq. 21")
        prod_expr = " * ".join(f"g{j + 1}" for j in range(nlev))
        out.append(f"""\
// the product of all levels' g at the cosines mi, mo > 0 (001 eq. 16, 20, 21), at least pumpup's: each level's
// spline in ln mu
float pumpup_g(float mi, float mo) {{
    float mmax = max(mi, mo);
    float mmin = min(mi, mo);
    float li = log(mi);
    float lo = log(mo);
    float lmax = mi >= mo ? li : lo;
{chr(10).join(body)}
    return {prod_expr};
}}
""")
        return "".join(out), notes, nlev
    t = _lit(tabs.t32)
    if tabs.product is not None:
        p = tabs.product
        out.append(p.glsl())
        notes.append(f"product table G(m) of all levels, m = max(N.wi, N.wo): {p.npieces} pieces (degree {p.deg} in m) "
                     f"for m >= {tabs.t32:.9g}, fitted to {FIT_TOL:g}, raised by twice its fit and float32 errors "
                     f"(<= {p.rel:.3g} relative); where N.wi or N.wo < {tabs.t32:.9g}, times {tabs.k:.9g}")
        out.append(f"""\
// the product of all levels' g at the cosines mi, mo > 0 (001 eq. 16, 20, 21), at least pumpup's: one piece of the
// product table G(m), m = max(mi, mo); where a cosine is below the table's lower end, G times the constant K =
// prod_j max(1, sup_j / U_j(lower end)) (sup_j: the level's largest bound below it)
float pumpup_g(float mi, float mo) {{
    float m = max(max(mi, mo), {t});
{p.locate("", "m")}    float g = {p.value(0, "b", "t")};
    return min(mi, mo) < {t} ? g * {_lit(_up32(tabs.k))} : g;
}}
""")
        return "".join(out), notes, nlev
    q = tabs.table
    out.append(q.glsl())
    notes.append(f"level table: every level's bound U_j(m) on one set of {q.npieces} pieces (degree {q.deg} in m) for "
                 f"m >= {tabs.t32:.9g}, fitted to {FIT_TOL:g}, raised by twice its fit and float32 errors (<= "
                 f"{q.rel:.3g} relative); below it each level's largest bound there: "
                 + ", ".join(f"{c:.9g}" for c in tabs.sup))
    body = []
    for j, controlled in enumerate(tabs.controlled):
        c = _lit(_up32(tabs.sup[j]))
        body.append(f"    float g{j + 1} = max(mi < {t} ? {c} : {q.value(j, 'bi', 'ti')},\n"
                    f"        mo < {t} ? {c} : {q.value(j, 'bo', 'to')});  // 001 eq. 20")
        if controlled:
            body.append(f"    g{j + 1} = max(g{j + 1}, max(mi, mo));  // 001 eq. 21")
    prod_expr = " * ".join(f"g{j + 1}" for j in range(nlev))
    out.append(f"""\
// the product of all levels' g at the cosines mi, mo > 0 (001 eq. 16, 20, 21), at least pumpup's: one piece of the
// level table per cosine, every level's bound U_j read from it; below the table's lower end, the level's largest
// bound there
float pumpup_g(float mi, float mo) {{
{q.locate("i", f"max(mi, {t})")}{q.locate("o", f"max(mo, {t})")}{chr(10).join(body)}
    return {prod_expr};
}}
""")
    return "".join(out), notes, nlev


class _CompTables:
    """What a compensation's shader reads for U >= E: the product table of U in m (:class:`_Pieces`) above its lower
    end ``t32``, U's largest value below it (``sup``); or, without a product table, the spline in ln mu.
    """

    def __init__(self, plan: _Plan):
        bound = plan.comp.bound
        self.lookup = bound.lookup
        self.product = None
        self.spline = None
        self.below = 0.0
        self.t32 = 0.0
        table = None
        if bound.product is not None:
            from .operators.pumping import _ProductError

            try:
                table = _fit_table([bound.product.exact], [self.lookup], [False], bound.product.mlo,
                                   2.0 * bound.product.epsilon + 4 * np.finfo(float).eps, "pumpup_eprod")
            except _ProductError:
                table = None
        if table is not None:
            self.product = table
            self.t32 = float(_up32(bound.product.mlo))
            self.sup = _sup_below(self.lookup, self.t32)
            self.below = self.sup - _inf_below(self.lookup, self.t32)  # (absolute)
            self.err = float(np.max(self.product.err))
            self.rel = self.product.rel
        else:
            self.spline = _LevelTable(self.lookup, "pumpup_e")
            self.err = float(np.max(self.spline.err))
            self.rel = self.spline.rel


def _comp_glsl(plan: _Plan) -> tuple[str, list[str]]:
    c = plan.comp
    tabs = _CompTables(plan)
    lk = tabs.lookup
    notes = [f"compensation bound U >= E of {json.dumps(c.white.spec)}: table margin {lk.margin:.3g}, cap {lk.cap:g}"]
    if tabs.product is not None:
        p = tabs.product
        t = _lit(tabs.t32)
        notes.append(f"table of U in m: {p.npieces} pieces (degree {p.deg}) for m >= {tabs.t32:.9g}, fitted to "
                     f"{FIT_TOL:g}, raised by twice its fit and float32 errors (<= {p.rel:.3g} relative); below it "
                     f"U's largest value there, {tabs.sup:.9g}")
        out = [p.glsl(), f"""\
// U(m) >= E(m), at least pumpup's bound (pumpup.physics.lookups.scale_bound): one piece of the product table; below
// its lower end, U's largest value there
float pumpup_upper(float m) {{
{p.locate("", f"max(m, {t})")}    float u = {p.value(0, "b", "t")};
    return m < {t} ? {_lit(_up32(tabs.sup))} : u;
}}
"""]
        return "".join(out), notes
    lvl = tabs.spline
    notes.append(f"spline of U: {lvl.npieces} pieces (degree {lvl.deg} in ln mu), float32 error <= {tabs.err:.3g} "
                 "(added)")
    out = [lvl.glsl(), """\
// U(m) >= E(m), at least pumpup's bound (pumpup.physics.lookups.scale_bound)
float pumpup_upper(float m) {
    return pumpup_e_u(m, log(m));
}
"""]
    return "".join(out), notes


def table_error(spec: Any) -> dict[str, float]:
    """How far below pumpup's value the shader's tables may take a pumped or compensated BRDF (its base's own float32
    error bound B aside): the float32 error added to the table pieces (twice, in :func:`shader`) and the final rounding
    down.

    Parameters
    ----------
    spec : dict, str or BRDF
        As :func:`shader`.

    Returns
    -------
    dict
        ``{"relative": r, "absolute": a, "below": m, "below_relative": rb}``: where N.wi and N.wo are both at least
        ``m`` (the tables' lower end, 1e-8 for pumpup's tables; 0 without one), a pumped value is at least pumpup's x
        (1 - 3 B - r); a ``scaled`` one too; a ``kulla_conty`` one at least pumpup's base x (1 - 3 B - r) + its lobe -
        scale x 2 a (a: the largest amount by which the shader's U exceeds pumpup's).  Where a cosine is below ``m``
        the shader divides by each level's largest bound below ``m`` (U's largest value below it for a compensation),
        which may take a pumped or scaled value lower by a further relative ``rb`` (``rb`` absolute in U for
        ``kulla_conty``).  All 0 for a closed-form model.
    """
    plan = _Plan(spec if isinstance(spec, BRDF) else load(spec))
    if plan.levels:
        tabs = _PumpedTables(plan)
        return {"relative": tabs.rel + 4.0 * (len(plan.levels) + 9) * U, "absolute": 0.0, "below": tabs.t32,
                "below_relative": tabs.below}
    if plan.comp is not None:
        tabs = _CompTables(plan)
        return {"relative": tabs.rel + 32.0 * U, "absolute": 2.0 * tabs.err + 4.0 * U, "below": tabs.t32,
                "below_relative": tabs.below}
    return {"relative": 0.0, "absolute": 0.0, "below": 0.0, "below_relative": 0.0}


def _library(plan: _Plan) -> tuple[str, list[str]]:
    """(GLSL library body without the header, table notes)."""
    parts = [_COMMON]
    b = plan.base
    code = _MODELS[b.type][1](b)
    if "pumpup_fresnel_dielectric" in code:
        parts.append(_FRESNEL_DIELECTRIC)
    if "pumpup_fresnel_conductor" in code:
        parts.append(_FRESNEL_CONDUCTOR)
    if "pumpup_erf" in code:
        parts.append(_ERF)
    if "pumpup_atan" in code:
        parts.append(_ATAN)
    parts.append(_param_decls(plan))
    parts.append(f"// the base model {b.type}: (f_r, a bound of its relative float32 error) for N.wi, N.wo > 0\n")
    if plan.fresnel is not None:
        if "pumpup_fresnel_conductor" not in code:
            parts.append(_FRESNEL_CONDUCTOR)
        parts.append(code.replace("vec2 pumpup_base(vec3 l, vec3 v)", "vec2 pumpup_base_inner(vec3 l, vec3 v)"))
        parts.append("""\
// the fresnel model: the base times F(eta + i k, Theta_min), cos(Theta_min) = max(N.wi, N.wo) (000 eq. 28)
vec2 pumpup_base(vec3 l, vec3 v) {
    vec2 f = pumpup_base_inner(l, v);
    vec2 fr = pumpup_fresnel_conductor(max(l.z, v.z), pumpup_fresnel_eta, pumpup_fresnel_k);
    return vec2(f.x * fr.x, f.y + fr.y + 2.0 * pumpup_U);
}
""")
    else:
        parts.append(code)
    notes: list[str] = []
    if plan.levels:
        glsl, notes, nlev = _pumped_glsl(plan)
        parts.append(glsl)
        rd = 1.0 - 4.0 * (nlev + 8) * U
        parts.append(f"""\
// the pumped BRDF (001 eq. 16): the base's lower bound over the product of the levels' upper bounds, rounded down
float pumpup_brdf(vec3 wi, vec3 wo) {{
    if (wi.z <= 0.0 || wo.z <= 0.0) return 0.0;
    vec2 f = pumpup_base(wi, wo);
    float lo = max(f.x * (1.0 - 2.0 * f.y), 0.0);
    return lo / pumpup_g(wi.z, wo.z) * {_lit(_down32(rd))};
}}
""")
    elif plan.comp is not None:
        glsl, notes = _comp_glsl(plan)
        parts.append(glsl)
        c = plan.comp
        if c.type == "kulla_conty":
            scale = _lit(_down32(c.scale))
            parts.append(f"""\
// the Kulla-Conty compensation f + F_ms D(mu_i) D(mu_o) / (pi I) (KC eq. 1-2), D = max(0, 1 - U), rounded down
float pumpup_brdf(vec3 wi, vec3 wo) {{
    if (wi.z <= 0.0 || wo.z <= 0.0) return 0.0;
    vec2 f = pumpup_base(wi, wo);
    float lo = max(f.x * (1.0 - 2.0 * f.y), 0.0);
    float di = max(0.0, 1.0 - pumpup_upper(wi.z));
    float dd = max(0.0, 1.0 - pumpup_upper(wo.z));
    return (lo + {scale} * (di * dd) * {_lit(_down32(1.0 - 8.0 * U))}) * {_lit(_down32(1.0 - 8.0 * U))};
}}
""")
        else:
            f0 = float(c.p["f0"])
            if f0 == 1.0:
                expr = f"lo / pumpup_upper(wo.z) * {_lit(_down32(1.0 - 12.0 * U))}"
            else:
                expr = (f"lo * max(0.0, s - 8.0 * pumpup_U * (1.0 + {_lit(f0)} * (r + 1.0)))"
                        f" * {_lit(_down32(1.0 - 8.0 * U))}")
            parts.append(f"""\
// the 1/E scaling f (1 + F0 (1 / U(mu_o) - 1)) (Turquin eq. 6), rounded down
float pumpup_brdf(vec3 wi, vec3 wo) {{
    if (wi.z <= 0.0 || wo.z <= 0.0) return 0.0;
    vec2 f = pumpup_base(wi, wo);
    float lo = max(f.x * (1.0 - 2.0 * f.y), 0.0);
    float r = 1.0 / pumpup_upper(wo.z) * {_lit(_down32(1.0 - 6.0 * U))};
    float s = 1.0 + {_lit(f0)} * (r - 1.0);
    return {expr};
}}
""")
    else:
        parts.append("""\
// f_r [1/sr] without the cosine factor, 0 below the horizon (pumpup's BRDF.eval)
float pumpup_brdf(vec3 wi, vec3 wo) {
    if (wi.z <= 0.0 || wo.z <= 0.0) return 0.0;
    return pumpup_base(wi, wo).x;
}

// a bound of the relative float32 error of pumpup_brdf (the tests compare it with pumpup's double precision)
float pumpup_brdf_error(vec3 wi, vec3 wo) {
    if (wi.z <= 0.0 || wo.z <= 0.0) return 0.0;
    return pumpup_base(wi, wo).y;
}
""")
    return "".join(parts), notes


def _header(plan: _Plan, target: str, notes: list[str], command: str | None, comment: str = "//") -> str:
    spec = json.dumps(plan.brdf.spec, sort_keys=True)
    cmd = command or f"pumpup.shader({spec!r}, target={target!r})"
    lines = [
        f"pumpup shader, target {target}",
        f"spec: {spec}",
        f"pumpup version: {__version__}",
        f"made by: {cmd}",
        "conventions: local frame N = (0, 0, 1); pumpup_brdf(wi, wo) with wi towards the light (L) and wo towards the",
        "  viewer (V), unit vectors; returns f_r in 1/sr WITHOUT the cosine factor, 0 below the horizon",
        "  (pumpup's BRDF.eval); every global name starts with pumpup_.",
    ]
    if plan.baked:
        lines.append("parameters: baked as constants (each one changes the tables): "
                     + ", ".join(f"{k} = {v:.9g}" for k, v in plan.params.items()))
        lines.append("float32: the value is at most pumpup's double-precision value at the same directions (the base's")
        lines.append("  float32 error bound subtracted, every table bound raised by its float32 error, rounded down),")
        lines.append("  so the albedo stays <= 1")
    else:
        lines.append("uniforms: " + (", ".join(f"float pumpup_{k} (= {v:.9g} for this spec)"
                                                for k, v in plan.params.items()) or "none"))
    fixed = [k for k in _BAKED.get(plan.base.type, ()) if plan.base.p.get(k) is not None]
    if fixed:
        lines.append("baked into the code (it chooses the code or changes a table in it): "
                     + ", ".join(f"{k} = {plan.base.p[k]}" for k in fixed))
        lines.append("float32: pumpup_brdf_error(wi, wo) bounds the relative difference from pumpup's double precision")
    for n in notes:
        lines.append("table: " + n)
    return "".join(f"{comment} {ln}\n" for ln in lines)


def _glsl(plan: _Plan, target: str, command: str | None) -> str:
    body, notes = _library(plan)
    return _header(plan, target, notes, command) + body


# ----------------------------------------------------------------------------------------
# Standalone shaders, SPIR-V translation, BRDF Explorer
# ----------------------------------------------------------------------------------------

_COMPUTE_MAIN = """
// standalone: f[i] = pumpup_brdf(dirs[2 i].xyz, dirs[2 i + 1].xyz), one invocation per pair
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer pumpup_In { vec4 pumpup_dirs[]; };
layout(std430, binding = 1) writeonly buffer pumpup_Out { float pumpup_values[]; };
void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= uint(pumpup_values.length())) return;
    pumpup_values[i] = pumpup_brdf(pumpup_dirs[2u * i].xyz, pumpup_dirs[2u * i + 1u].xyz);
}
"""

_FRAGMENT_MAIN_ES = """
// standalone: the BRDF at the uniform directions pumpup_wi, pumpup_wo, written to pumpup_value
uniform vec3 pumpup_wi;
uniform vec3 pumpup_wo;
out vec4 pumpup_value;
void main() {
    pumpup_value = vec4(pumpup_brdf(pumpup_wi, pumpup_wo));
}
"""


def _standalone(lib: str, es: bool) -> str:
    if es:
        return "#version 300 es\nprecision highp float;\nprecision highp int;\n" + lib + _FRAGMENT_MAIN_ES
    return "#version 450\n" + lib + _COMPUTE_MAIN


def _tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        pkg = "glslang-tools" if name == "glslangValidator" else "spirv-cross"
        raise FileNotFoundError(f"pumpup.shader: the hlsl and msl targets need {name} on PATH (Debian/Ubuntu: apt-get "
                           f"install {pkg})")
    return path


def _uniform_block(lib: str) -> str:
    """SPIR-V for Vulkan needs the loose uniforms in a block: ``uniform float pumpup_x;`` -> one std140 block."""
    lines = lib.splitlines()
    names = [ln.split()[2].rstrip(";") for ln in lines if ln.startswith("uniform float ")]
    if not names:
        return lib
    body = "\n".join(ln for ln in lines if not ln.startswith("uniform float "))
    block = ("layout(std140, binding = 2) uniform pumpup_Params {\n"
             + "".join(f"    float {n};\n" for n in names) + "};\n")
    # the block goes before the first use: right after the header comment and the common helpers' first line
    return block + body + "\n"


def _translate(lib: str, target: str) -> str:
    validator, cross = _tool("glslangValidator"), _tool("spirv-cross")
    src = _standalone(_uniform_block(lib), es=False)
    with tempfile.TemporaryDirectory(prefix="pumpup-shader-") as tmp:
        comp = os.path.join(tmp, "pumpup.comp")
        spv = os.path.join(tmp, "pumpup.spv")
        with open(comp, "w") as fh:
            fh.write(src)
        r = subprocess.run([validator, "-V", "--target-env", "vulkan1.1", "-o", spv, comp], capture_output=True,
                           text=True)
        if r.returncode != 0:
            raise RuntimeError(f"pumpup.shader: glslangValidator rejected the GLSL: {(r.stdout + r.stderr).strip()}")
        args = [cross, spv, "--hlsl", "--shader-model", "50"] if target == "hlsl" else [cross, spv, "--msl"]
        r = subprocess.run(args, capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError(f"pumpup.shader: spirv-cross failed: {(r.stdout + r.stderr).strip()}")
        return r.stdout


def _brdf_explorer(plan: _Plan, lib: str, header: str) -> str:
    """A ``.brdf`` file of Disney's BRDF Explorer: the uniforms as its parameters, BRDF(L, V, N, X, Y) in world
    space.
    """
    from .core import registry

    cls = registry()[plan.base.type]
    params = []
    if not plan.baked:
        for k, v in plan.params.items():
            decl = cls.params.get(k)
            lo = decl.lo if decl is not None and math.isfinite(decl.lo) else 0.0
            hi = decl.hi if decl is not None and math.isfinite(decl.hi) else max(2.0 * abs(v), 1.0)
            hi = max(hi, v) if math.isfinite(hi) else max(2.0 * abs(v), 1.0)
            if not math.isfinite(hi) or hi > 1e6:
                hi = max(2.0 * abs(v), 1.0)
            params.append(f"float pumpup_{k} {lo:.9g} {hi:.9g} {v:.9g}")
    body = "\n".join(ln for ln in lib.splitlines() if not ln.startswith("uniform float "))
    hdr = "".join("# " + ln[3:] + "\n" if ln.startswith("// ") else ln + "\n" for ln in header.splitlines())
    return ("analytic\n\n" + hdr
            + "# BRDF Explorer passes world-space L, V and the frame N, X, Y; the shader maps them to the local frame\n"
            "\n::begin parameters\n" + "".join(p + "\n" for p in params) + "::end parameters\n\n"
            "::begin shader\n" + body + """
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
{
    vec3 wi = vec3(dot(L, X), dot(L, Y), dot(L, N));
    vec3 wo = vec3(dot(V, X), dot(V, Y), dot(V, N));
    return vec3(pumpup_brdf(wi, wo));
}

::end shader
""")


# ----------------------------------------------------------------------------------------
# The public functions
# ----------------------------------------------------------------------------------------


def shader(spec: Any, target: str = "glsl", standalone: bool = False, command: str | None = None) -> str:
    """Shader source code of a BRDF with its tables baked in.

    Parameters
    ----------
    spec : dict, str or BRDF
        A closed-form model (:data:`SUPPORTED`), a ``pumped`` chain of one (g1 or g2, any levels) or a ``kulla_conty``
        or ``scaled`` compensation of one.
    target : {"glsl", "glsl-es", "hlsl", "msl", "brdf-explorer"}
        ``glsl`` (GLSL 4.x) and ``glsl-es`` (GLSL ES 3.00, WebGL 2): a library snippet defining ``float
        pumpup_brdf(vec3 wi, vec3 wo)`` (see the module docstring); ``hlsl`` (shader model 5) and ``msl`` (Metal):
        translated through SPIR-V by glslangValidator and spirv-cross from a compute shader that evaluates
        ``pumpup_brdf`` on a buffer of direction pairs; ``brdf-explorer``: a ``.brdf`` file for Disney's BRDF
        Explorer.
    standalone : bool
        For ``glsl`` / ``glsl-es``: add the ``#version`` line and a ``main`` (a compute shader over a buffer of pairs
        for GLSL 4.50, a fragment shader of the uniform directions ``pumpup_wi``, ``pumpup_wo`` for GLSL ES).
    command : str, optional
        The command that made the file, for the header (default: the Python call).

    Returns
    -------
    str
        The source.  A header comment gives the spec, pumpup's version, the conventions, the uniforms or baked
        parameters, the tables' sizes and error bounds and the command.

    Raises
    ------
    SpecError
        For a model without a closed form in the shader (``from_function``, spectral models, ``he_torrance``, ...),
        naming it; ValueError for an unknown target.

    Examples
    --------
    >>> src = shader("phong:n=20", target="glsl-es")
    >>> "float pumpup_brdf(vec3 wi, vec3 wo)" in src and "uniform float pumpup_n;" in src
    True
    """
    if target not in TARGETS:
        raise ValueError(f"target must be one of {', '.join(TARGETS)}; got {target!r}")
    brdf = spec if isinstance(spec, BRDF) else load(spec)
    plan = _Plan(brdf)
    if target in ("glsl", "glsl-es"):
        src = _glsl(plan, target, command)
        if standalone:
            src = _standalone(src, es=target == "glsl-es")
        return src
    lib, notes = _library(plan)
    header = _header(plan, target, notes, command)
    if target == "brdf-explorer":
        return _brdf_explorer(plan, lib, header)
    return header + _translate(lib, target)


def write_shader(spec: Any, target: str, path: str | os.PathLike[str], command: str | None = None) -> str:
    """Write :func:`shader`'s source to ``path`` atomically (a temporary file renamed into place); returns the path."""
    from .tables import atomic_path

    src = shader(spec, target=target, command=command)
    with atomic_path(path) as tmp:
        with open(tmp, "w") as fh:
            fh.write(src)
    return os.fspath(path)


def command_line(spec_text: str, target: str, out: str | None) -> str:
    """The shell command that makes a file (for the header)."""
    cmd = f"pumpup shader {shlex.quote(spec_text)} --target {target}"
    return cmd + (f" --out {shlex.quote(out)}" if out else "")
