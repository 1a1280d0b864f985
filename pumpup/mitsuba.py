"""Mitsuba 3 bridge: pumpup's BRDFs as a Mitsuba BSDF plugin, and Mitsuba's BSDFs as pumpup BRDFs.

Imported only explicitly (``import pumpup.mitsuba``); ``import pumpup`` never imports Mitsuba.
Needs the ``render`` extra: ``pip install -e ".[render]"`` (mitsuba >= 3.5 with drjit).

Plugin API (a contract for scripts and renderers that use it)
-------------------------------------------------------------
``variant = register(variant=None)``
    Choose a Mitsuba variant, ``mi.set_variant`` it, and register the BSDF plugin ``"pumpup"``
    for that variant (call it again after switching variants).  ``variant=None`` keeps the
    variant already set, else prefers ``llvm_ad_rgb``.  A JIT (``llvm_*``) variant is first
    *probed in a subprocess* (:func:`probe`): with a libLLVM older than 17, Dr.Jit 1.5 aborts
    the process (SIGABRT, "Cannot select: fmaximum") at the first kernel, which no Python code
    can catch; if the probe fails, ``scalar_rgb`` is used instead and one line on stderr says
    why and how to get the fast variant (``apt-get install libllvm19``, or
    ``DRJIT_LIBLLVM_PATH``).  Returns the variant in use.
``mi.load_dict({"type": "pumpup", "spec": SPEC})``
    SPEC is a pumpup spec as a JSON string (``json.dumps(spec)``, or :func:`bsdf_dict`), a
    short spec (``"phong:n=20"``), or a JSON list of three specs (one per RGB channel, rgb
    variants only: e.g. ``metal`` with per-channel indices).  Mitsuba's ``load_dict`` reads
    a nested dict with a ``"type"`` as a Mitsuba object, so a *dict* spec is passed through
    :func:`bsdf_dict` / :func:`load_dict`, which turn it into JSON.  Flat parameters work too:
    ``{"type": "pumpup", "model": "phong", "n": 20}``.  A spec the plugin cannot translate
    raises ``SpecError`` naming the type (Mitsuba wraps it in a RuntimeError).
``bsdf_dict(spec) -> dict``, ``load_dict(scene_dict)``
    ``{"type": "pumpup", "spec": "<json>"}``; ``mi.load_dict`` of a scene dict in which every
    ``{"type": "pumpup", "spec": {...}}`` has been converted that way.
The BSDF
    Front side only (0 where either cosine <= 0), one component, flags ``GlossyReflection``
    (``DiffuseReflection`` for ``lambert``).  Directions are in Mitsuba's local shading frame
    (z = normal, x = the frame's tangent ``si.sh_frame.s``, which is the x axis of anisotropic
    models such as ``ward_aniso``).  Mitsuba's ``si.wi`` points to the viewer (pumpup's ``wo``)
    and its ``wo`` to the light (pumpup's ``wi``):

    * ``eval(ctx, si, wo)`` = f_r(wi=wo, wo=si.wi) * cos(theta) of Mitsuba's wo (Mitsuba's
      convention: the cosine is included), per channel;
    * ``pdf(ctx, si, wo)`` = pumpup's sampling density (:func:`pumpup.sampling.pdf`);
    * ``sample(ctx, si, s1, s2)`` draws with pumpup's strategy (:func:`pumpup.sampling.strategy`:
      the Phong lobe of 000 eq. 19-22 around the mirror direction, half-vector lobes for Blinn
      (cos^n), Beckmann and GGX, the cosine-weighted hemisphere otherwise, and mixtures for sums,
      the component chosen with ``s1``); a lobe direction below the horizon is a rejected draw:
      weight 0, ``pdf`` 0 (000 after eq. 22), which keeps estimators unbiased.  The returned
      weight is eval / pdf at the returned (float32) direction, and ``bs.pdf`` equals
      ``pdf(ctx, si, bs.wo)``;
    * ``eval_pdf`` returns (eval, pdf).

    Everything is computed in Dr.Jit operations on Float64 (the float32 inputs converted exactly,
    the result rounded once to Mitsuba's float32; only the sampler's azimuth sine and cosine are float32, of the
    float32 sample), so in ``llvm_*`` variants it is traced into Mitsuba's kernels; in ``scalar_*`` variants the
    same code runs on Python floats.  A pumped model divides by the same upper bounds of the albedo tables as
    pumpup's compiled kernel (spline + margin, capped at 1; :class:`pumpup.operators.pumping._Lookup`): from quartics
    in fixed cells of the cosine, each at least the bound and within 1e-13 of it (:class:`_CellG`, its cell and the
    position in it from the cosine's bits, no search; a cell with a kink split there; below the levels' tables, where
    the bounds are power laws, coarser cells down to float32's smallest subnormal where they fit; finer cells from
    where features crowd up to 1), with pairs in the few cells that still miss and below the cells level by level;
    the levels whose bounds a fixed grid does not fit from refined cells of their own (a coarse cell cut into finer
    ones), else from a level table of those levels;
    else (no level fits, or the product of a chain whose bounds all increase does not) through pumpup's table of all
    levels: the product table G(m) where every level's bound increases
    (:class:`pumpup.operators.pumping._Product`, m = max(N.wi, N.wo)), else the level table
    (:class:`pumpup.operators.pumping._LevelTable`: every level's bound on one set of pieces, one piece per cosine
    for all levels), else level by level.  A piece is found from the float64 bits of the cosine with one read of a
    cell (its first piece and the next starts) and its row is read in 64-byte packets (:class:`_Cells`,
    :class:`_Rows`); below a level table's start the levels' power laws are computed without a branch, below a product
    table's the level-by-level path runs in a conditional.  The value is rounded down before the cast to float32
    (x (1 - 2^-23)), so the exported BSDF is pointwise at most the double-precision one and keeps its proof of energy
    conservation (001 eq. 18).
``from_mitsuba(bsdf_dict, channel=0, variant=None) -> pumpup BRDF``
    A Mitsuba BSDF as a pumpup BRDF: f_r(wi, wo) = eval(si.wi = wo, wo = wi)[channel] / N.wi,
    front side, so that ``albedo``, ``tabulate``, ``check_reciprocity``, ``pump`` and
    ``compensate`` work on it.  Evaluated by Mitsuba in float32: its relative accuracy is about
    1e-7 per value (see docs/user-guide/mitsuba.md for what this limits).

Supported pumpup types: lambert, phong, stretched_phong, retro, phong_shader, blinn,
stretched_blinn, phong_blinn, ward, modified_ward, ward_aniso, schlick, cook_torrance,
beckmann, ggx (with ``ior`` or ``eta``/``k`` Fresnel, separable or correlated Smith, exact or
Walter G1), metal, plastic, and ``pumped`` over any of them (g1 or g2, any number of levels), and
``fresnel`` (F(Theta_min) x one of these, pumped or not: the colour-keeping pumped metal's channel).

Examples
--------
>>> import pumpup.mitsuba as pm
>>> variant = pm.register("scalar_rgb")
>>> import mitsuba as mi
>>> b = pm.load_dict({"type": "pumpup", "spec": {"type": "lambert", "albedo": 0.5}})
>>> si = mi.SurfaceInteraction3f(); si.wi = mi.Vector3f(0, 0, 1)
>>> round(b.eval(mi.BSDFContext(), si, mi.Vector3f(0, 0.6, 0.8))[0] * 3.141592653589793 / 0.4, 6)
1.0
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
from typing import Any

import numpy as np

from . import sampling as _sampling
from ._extras import require
from .core import BRDF, SpecError, from_function, load

mi = require("mitsuba", "pumpup.mitsuba (Mitsuba 3)")
dr = require("drjit", "pumpup.mitsuba (Mitsuba 3)")

__all__ = ["register", "probe", "choose_variant", "bsdf_dict", "load_dict", "from_mitsuba", "SUPPORTED",
           "DEFAULT_VARIANT", "FALLBACK_VARIANT"]

DEFAULT_VARIANT = "llvm_ad_rgb"
FALLBACK_VARIANT = "scalar_rgb"

_INV_PI = 1.0 / math.pi
_INV_2PI = 0.5 / math.pi
_SQRT_PI = math.sqrt(math.pi)
_TWO_PI_F32 = float(np.float32(2.0 * math.pi))

# ----------------------------------------------------------------------------------------
# The subprocess probe of a JIT variant
# ----------------------------------------------------------------------------------------

#: the probe: set the variant, run a BSDF kernel with fmaximum (the instruction libLLVM 15
#: cannot select) and a Float64 kernel, print a marker
_PROBE_CODE = r"""
import sys
import drjit as dr, mitsuba as mi
mi.set_variant(sys.argv[1])
b = mi.load_dict({"type": "roughconductor", "alpha": 0.2})
si = dr.zeros(mi.SurfaceInteraction3f, 16)
si.wi = mi.Vector3f(0.0, 0.6, 0.8)
v = b.eval(mi.BSDFContext(), si, mi.Vector3f(0.0, -0.6, 0.8))
x = dr.maximum(mi.Float64(v[0]), dr.sqrt(mi.Float64(dr.arange(mi.Float, 16))))
dr.eval(v, x)
print("pumpup-probe-ok", float(dr.sum(x)[0]) > 0)
"""

_PROBES: dict[tuple, tuple[bool, str]] = {}


def probe(variant: str = DEFAULT_VARIANT, timeout: float = 180.0) -> tuple[bool, str]:
    """Test in a subprocess whether ``variant`` runs a BSDF kernel here without aborting.

    Parameters
    ----------
    variant : str
        A Mitsuba variant name (``mi.variants()``).
    timeout : float
        Seconds before the probe counts as failed.

    Returns
    -------
    (ok, reason)
        ``reason`` is "" when ok, else one line (the signal, the exit status or the last line
        of the probe's stderr).  Cached per (variant, DRJIT_LIBLLVM_PATH) for the session.
    """
    key = (variant, os.environ.get("DRJIT_LIBLLVM_PATH"))
    if key in _PROBES:
        return _PROBES[key]
    if variant not in mi.variants():
        res = (False, f"this Mitsuba build has no variant {variant!r} (it has {', '.join(mi.variants())})")
    elif variant.startswith("scalar"):
        res = (True, "")
    else:
        try:
            r = subprocess.run([sys.executable, "-c", _PROBE_CODE, variant], capture_output=True, text=True,
                               timeout=timeout, env=dict(os.environ))
        except subprocess.TimeoutExpired:
            res = (False, f"the probe of {variant} did not finish in {timeout:g} s")
        else:
            if r.returncode == 0 and "pumpup-probe-ok True" in r.stdout:
                res = (True, "")
            else:
                lines = [ln for ln in (r.stderr or "").strip().splitlines() if ln.strip()]
                tail = lines[-1].strip()[:160] if lines else "no message"
                if r.returncode < 0:
                    try:
                        sig = signal.Signals(-r.returncode).name
                    except ValueError:
                        sig = f"signal {-r.returncode}"
                    res = (False, f"the probe process was killed by {sig} ({tail})")
                else:
                    res = (False, f"the probe exited with status {r.returncode} ({tail})")
    _PROBES[key] = res
    return res


def choose_variant(prefer: str = DEFAULT_VARIANT, quiet: bool = False) -> str:
    """``prefer`` if :func:`probe` passes, else ``scalar_rgb`` (with one line on stderr)."""
    ok, reason = probe(prefer)
    if ok:
        return prefer
    if not quiet:
        print(f"pumpup.mitsuba: {prefer} is unusable here ({reason}); using {FALLBACK_VARIANT} (slow). "
              "For the fast variant install libLLVM >= 17 (Debian: apt-get install libllvm19) or point "
              "DRJIT_LIBLLVM_PATH at one.", file=sys.stderr)
    return FALLBACK_VARIANT


# ----------------------------------------------------------------------------------------
# Array helpers: the same code runs on Dr.Jit arrays (JIT variants) and Python floats (scalar)
# ----------------------------------------------------------------------------------------


def _jit() -> bool:
    return dr.is_jit_v(mi.Float)


def _f64(x):
    """An exact Float64 copy of a Mitsuba Float (float32 in JIT variants; a Python float in scalar)."""
    return mi.Float64(x) if _jit() else float(x)


def _div(a, b):
    """The quotient a / b that never raises (Python floats raise on / 0; lanes with b = 0 are masked by the caller)."""
    return a * dr.rcp(b)


class _Table:
    """A float64 table for ``dr.gather`` (a Float64 array in JIT variants, a numpy array in scalar)."""

    def __init__(self, values):
        self.np = np.ascontiguousarray(np.asarray(values, dtype=np.float64).ravel())
        self.dr = mi.Float64(self.np) if _jit() else None

    def __getitem__(self, idx):
        if self.dr is None:
            return float(self.np[int(idx)])
        return dr.gather(mi.Float64, self.dr, idx)


def _int(v):
    return mi.UInt32(v) if _jit() else int(v)


# ----------------------------------------------------------------------------------------
# Dr.Jit versions of the models: k(wl, v, *brdf.kernel_args()) with wl = wi, v = wo as
# (x, y, z) tuples of Float64, beside the numba kernels they mirror (same formulas, same order)
# ----------------------------------------------------------------------------------------


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _tan2_half(wl, v):
    """tan^2 delta from S = L + V (pumpup.models._half.tan2_half)."""
    sz = wl[2] + v[2]
    qx = _div(wl[0] + v[0], sz)
    qy = _div(wl[1] + v[1], sz)
    return qx * qx + qy * qy


def _pow_pos(x, n):
    """x^n for x > 0 (0 elsewhere: every caller masks x <= 0); an integer n up to 2^16 by repeated squaring (at most
    32 products, each rounded once: a few 1e-16 relative, no logarithm and exponential).
    """
    if float(n) == int(n) and 0 < n <= 2**16:
        k, sq, out = int(n), x, None
        while k:
            if k & 1:
                out = sq if out is None else out * sq
            k >>= 1
            if k:
                sq = sq * sq
        return dr.select(x > 0, out, 0.0)
    return dr.select(x > 0, dr.power(dr.maximum(x, 1e-300), n), 0.0)


def _fresnel_dielectric(c, n):
    """pumpup.models.cook_torrance._fresnel (002 sec. 3.2); callers use it only for n > 0."""
    g = dr.sqrt(dr.maximum(n * n + c * c - 1.0, 0.0))
    a = _div(g - c, g + c)
    q = _div(c * (g + c) - 1.0, c * (g - c) + 1.0)
    return 0.5 * a * a * (1.0 + q * q)


def _fresnel_conductor(c, eta, k):
    """pumpup.models.metal._fresnel_real: the exact conductor Fresnel factor without cancellation."""
    s2 = (1.0 - c) * (1.0 + c)
    t0 = (eta - 1.0) * (eta + 1.0) - k * k + c * c  # eta^2 - k^2 - s^2 without cancellation near eta = 1, c = 0
    big = dr.sqrt(t0 * t0 + (2.0 * eta * k) ** 2)  # a^2 + b^2
    ra = dr.sqrt(dr.maximum(0.5 * (big + t0), 0.0))
    rb = dr.sqrt(dr.maximum(0.5 * (big - t0), 0.0))
    pos = t0 >= 0.0
    a = dr.select(pos, ra, _div(eta * k, dr.maximum(rb, 1e-300)))
    b = dr.select(pos, _div(eta * k, dr.maximum(ra, 1e-300)), rb)
    a = dr.select(big == 0.0, 0.0, a)
    b = dr.select(big == 0.0, 0.0, b)
    e21 = (eta - 1.0) * (eta + 1.0) - k * k
    plus = (a + c) ** 2 + b * b
    rs = dr.select(plus > 0.0, _div(e21 * e21 + 4.0 * eta * eta * k * k, plus * plus), 0.0)  # |1 - e^2|^2 / |c + A|^4
    rp = rs * _div((a * c - s2) ** 2 + b * b * c * c, (a * c + s2) ** 2 + b * b * c * c)
    return 0.5 * (rs + rp)


def _mirror_cos(wl, v):
    """R.V with R the mirror of wl about the normal, 2 (N.wl)(N.v) - wl.v (000 eq. 9)."""
    return 2.0 * wl[2] * v[2] - _dot(wl, v)


def _dr_lambert(wl, v, albedo):
    return albedo * _INV_PI + 0.0 * wl[2]


def _dr_phong(wl, v, n, c):
    rv = _mirror_cos(wl, v)  # 000 eq. 9
    return dr.select(rv > 0, c * _pow_pos(rv, n), 0.0)  # 000 eq. 5


def _den_p(mx, p):
    return mx if p == 1.0 else (1.0 + 0.0 * mx if p == 0.0 else dr.power(mx, p))


def _dr_stretched_phong(wl, v, n, p, c):
    rv = _mirror_cos(wl, v)  # 000 eq. 9
    mx = dr.maximum(wl[2], v[2])
    return dr.select(rv > 0, _div(c * _pow_pos(rv, n), _den_p(mx, p)), 0.0)  # 000 eq. 10, 12


def _dr_retro(wl, v, n, p, c):
    lv = _dot(wl, v)
    mx = dr.maximum(wl[2], v[2])
    return dr.select(lv > 0, _div(c * _pow_pos(lv, n), dr.power(mx, p)), 0.0)  # 000 eq. 13


def _dr_phong_shader(wl, v, n, ks, kd):
    rv = _mirror_cos(wl, v)
    return kd + dr.select(rv > 0, _div(ks * _pow_pos(rv, n), wl[2]), 0.0)  # 002 eq. 5, 8


def _dr_blinn(wl, v, n, c):
    cos2 = dr.rcp(1.0 + _tan2_half(wl, v))  # (N.H)^2
    return c * _pow_pos(cos2, 0.5 * n)  # 000 eq. 31


def _dr_stretched_blinn(wl, v, n, c):
    cos2 = dr.rcp(1.0 + _tan2_half(wl, v))
    return _div(c * _pow_pos(cos2, 0.5 * n), dr.maximum(wl[2], v[2]))  # 000 eq. 32


def _dr_phong_blinn(wl, v, n, ks, kd):
    cos2 = dr.rcp(1.0 + _tan2_half(wl, v))
    return kd + ks * _pow_pos(cos2, 0.5 * n)  # 002 eq. 24, 6


def _dr_ward(wl, v, m, c):
    t2 = _tan2_half(wl, v)
    den = 4.0 * math.pi * m * m * (dr.sqrt(dr.maximum(wl[2], 0.0)) * dr.sqrt(dr.maximum(v[2], 0.0)))
    return _div(c * dr.exp(-t2 / (m * m)), den)  # 000 eq. 34, 001 eq. 8


def _dr_modified_ward(wl, v, m, c):
    t2 = _tan2_half(wl, v)
    return _div(c * dr.exp(-t2 / (m * m)), 4.0 * math.pi * m * m * dr.maximum(wl[2], v[2]))  # 000 eq. 35


def _dr_ward_aniso(wl, v, ax, ay, c):
    sz = wl[2] + v[2]
    qx = _div(wl[0] + v[0], sz)  # h_x / h_z
    qy = _div(wl[1] + v[1], sz)  # h_y / h_z
    e = (qx / ax) ** 2 + (qy / ay) ** 2
    den = 4.0 * math.pi * ax * ay * (dr.sqrt(dr.maximum(wl[2], 0.0)) * dr.sqrt(dr.maximum(v[2], 0.0)))
    return _div(c * dr.exp(-e), den)  # Ward 1992 (isotropic: 000 eq. 34)


def _dr_schlick(wl, v, r, c):
    t = _tan2_half(wl, v)
    cos2 = dr.rcp(1.0 + t)
    sin2 = dr.select(t <= 1.0, t * cos2, 1.0 - cos2)
    d = r + (1.0 - r) * sin2  # 1 - (1 - r)(N.H)^2
    gl = r + (1.0 - r) * wl[2]
    gv = r + (1.0 - r) * v[2]
    return c / (4.0 * math.pi) * _div(_div(r, d * d), gl * gv)  # 000 eq. 36


def _dr_cook_torrance(wl, v, m, ior):
    s = (wl[0] + v[0], wl[1] + v[1], wl[2] + v[2])
    t = _tan2_half(wl, v)
    e = dr.exp(-t / (m * m))
    d = e * ((1.0 + t) * (1.0 + t)) / (4.0 * math.pi * m * m)  # 001 eq. 9
    g = dr.minimum(1.0, _div(4.0 * dr.minimum(wl[2], v[2]), s[2] * (1.0 + t)))  # 001 eq. 10
    c = 0.5 * dr.sqrt(_dot(s, s))  # V.H
    f = _fresnel_dielectric(c, ior) if ior > 0 else 1.0
    return _div(f * d * g, wl[2] * v[2])  # 001 eq. 9


def _projected(w, dist, g1, alpha):
    """pumpup.physics.microfacet.projected: P = z (1 + Lambda) = z / G1 (Walter et al. 2007)."""
    x, y, z = w
    if dist == 1:
        return 0.5 * (z + dr.sqrt(z * z + alpha * alpha * (x * x + y * y)))  # Walter eq. 34
    s = dr.sqrt(x * x + y * y)
    a = _div(z, alpha * s)
    if g1 == 0:
        p = 0.5 * (z * (1.0 + dr.erf(a)) + alpha * s * dr.exp(-a * a) / _SQRT_PI)  # Walter eq. 27 (exact)
    else:
        p = dr.select(a >= 1.6, z, _div(alpha * s * (1.0 + 2.276 * a + 2.577 * a * a), 3.535 + 2.181 * a))
    return dr.select(s == 0.0, z, p)


def _dr_microfacet(wl, v, dist, alpha, shadowing, g1, ior, eta, k):
    """D F G / (4 N.wi N.wo) with the half-vector terms written in S = wi + wo (|S|^2 = n2, S_z^2 = sz2, S_x^2 + S_y^2
    = sxy2: cos^2 theta_h = sz2 / n2, tan^2 theta_h = sxy2 / sz2), one division for the whole quotient.
    """
    sx, sy, sz = wl[0] + v[0], wl[1] + v[1], wl[2] + v[2]
    sxy2, sz2 = sx * sx + sy * sy, sz * sz
    n2 = sxy2 + sz2
    a2 = alpha * alpha
    if dist == 0:
        r = dr.rcp(sz2)
        num = dr.exp(-(sxy2 * r) / a2) * ((n2 * r) * (n2 * r))  # Walter eq. 25: exp(-tan^2 / a2) / cos^4 ...
        den = math.pi * a2  # ... / (pi a2)
    else:
        q = a2 * sz2 + sxy2
        num, den = a2 * (n2 * n2), math.pi * (q * q)  # Walter eq. 33: a2 / (pi cos^4 (a2 + tan^2)^2)
    if eta > 0.0:
        num = num * _fresnel_conductor(0.5 * dr.sqrt(n2), eta, k)  # at wi.h = |S| / 2
    elif ior > 0.0:
        num = num * _fresnel_dielectric(0.5 * dr.sqrt(n2), ior)
    pl = _projected(wl, dist, g1, alpha)
    pv = _projected(v, dist, g1, alpha)
    if shadowing == 0:
        return _div(num, den * (4.0 * pl * pv))  # Walter eq. 20, separable Smith
    return _div(num, den * (4.0 * (v[2] * pl + wl[2] * pv - wl[2] * v[2])))  # Heitz 2014, height-correlated


def _dr_metal(wl, v, n, eta, k, c):
    rv = _mirror_cos(wl, v)  # 000 eq. 9
    mx = dr.maximum(wl[2], v[2])
    return dr.select(rv > 0, _div(c * _pow_pos(rv, n), mx) * _fresnel_conductor(mx, eta, k), 0.0)  # 000 eq. 28


def _dr_plastic(wl, v, n, ad, a_s, eta):
    rv = _mirror_cos(wl, v)
    mx = dr.maximum(wl[2], v[2])
    fr = _fresnel_conductor(mx, eta, 0.0) if eta > 0.0 else 1.0  # 000 eq. 30
    spec = _div(a_s * (n + 2.0) / (2.0 * math.pi) * _pow_pos(rv, n), mx) * fr  # 000 eq. 29
    return ad / math.pi + dr.select(rv > 0, spec, 0.0)


_KERNELS = {
    "lambert": _dr_lambert, "phong": _dr_phong, "stretched_phong": _dr_stretched_phong, "retro": _dr_retro,
    "phong_shader": _dr_phong_shader, "blinn": _dr_blinn, "stretched_blinn": _dr_stretched_blinn,
    "phong_blinn": _dr_phong_blinn, "ward": _dr_ward, "modified_ward": _dr_modified_ward,
    "ward_aniso": _dr_ward_aniso, "schlick": _dr_schlick, "cook_torrance": _dr_cook_torrance,
    "beckmann": _dr_microfacet, "ggx": _dr_microfacet, "metal": _dr_metal, "plastic": _dr_plastic,
}

#: the pumpup model types the plugin translates
SUPPORTED = tuple(sorted(set(_KERNELS) | {"pumped", "fresnel"}))


class _Level:
    """One pumping level in Dr.Jit: the upper bound u(mu) of :func:`pumpup.physics.lookups.upper_scalar` on
    the same arrays (:class:`pumpup.operators.pumping._Lookup`), found by a binary search of fixed length.
    """

    def __init__(self, lookup, controlled: bool):
        lk = lookup
        self.logx = _Table(lk.logx)
        self.n = len(lk.logx)
        self.deg = lk.coef.shape[0]
        self.coef = _Table(lk.coef)  # row r at r * (n - 1) + i
        self.logx0 = float(lk.logx[0])
        self.v0, self.slope0 = float(lk.v0), float(lk.slope0)
        self.margin_lo, self.margin, self.cap = float(lk.margin_lo), float(lk.margin), float(lk.cap)
        self.controlled = controlled
        self.steps = []
        s = 1
        while s < self.n:
            s *= 2
        while s >= 1:
            self.steps.append(s)
            s //= 2

    def upper(self, mu):
        lm = dr.log(mu)
        lo = _int(0)
        for step in self.steps:  # the largest lo in [0, n - 2] with logx[lo] <= lm
            cand = lo + step
            ok = cand <= self.n - 2
            safe = dr.select(ok, cand, lo) if _jit() else (cand if ok else lo)
            take = ok & (self.logx[safe] <= lm)
            lo = dr.select(take, safe, lo) if _jit() else (safe if take else lo)
        d = lm - self.logx[lo]
        m1 = self.n - 1
        val = self.coef[lo]
        for r in range(1, self.deg):  # Horner: the spline piece in d = log(mu) - logx[lo]
            val = val * d + self.coef[lo + r * m1]
        below = self.v0 * dr.exp(self.slope0 * (lm - self.logx0)) + self.margin_lo  # power law below the table
        u = dr.select(lm < self.logx0, below, val + self.margin)  # (as pumpup.physics.lookups.upper_log)
        return dr.minimum(u, self.cap) if math.isfinite(self.cap) else u

    def g(self, mi_, mo):
        g = dr.maximum(self.upper(mi_), self.upper(mo))  # 001 eq. 20
        if self.controlled:
            g = dr.maximum(g, dr.maximum(mi_, mo))  # 001 eq. 21
        return g


class _Rows:
    """Rows of float64 numbers, one per piece, for one gather per piece: in JIT variants padded to a multiple of 8
    and read as packets of 8 consecutive values (a 64-byte line each, ``dr.gather`` of an ``ArrayXf64``), in scalar
    variants a numpy array.
    """

    PACKET = 8

    def __init__(self, rows):
        rows = np.asarray(rows, dtype=np.float64)
        self.width = rows.shape[1]
        self.packets = -(-self.width // self.PACKET)
        padded = np.zeros((rows.shape[0], self.packets * self.PACKET))
        padded[:, :self.width] = rows
        self.np = padded
        self.dr = _aligned_f64(padded) if _jit() else None

    def __call__(self, s) -> list:
        """Row ``s`` (a UInt32 array, or an int in scalar variants) as a list of its ``width`` values."""
        if self.dr is None:
            return [float(x) for x in self.np[int(s)][:self.width]]
        packet = _array_xf64()
        out = []
        for j in range(self.packets):
            idx = s * self.packets + j if self.packets > 1 else s
            p = dr.gather(packet, self.dr, idx, shape=(self.PACKET, dr.width(s)))
            out.extend(p[i] for i in range(self.PACKET))
        return out[:self.width]


def _aligned_f64(values, align: int = 64):
    """A Float64 array of ``values`` whose storage starts on an ``align``-byte boundary: Dr.Jit maps a numpy array's
    memory (no copy; it holds a reference to the array) and reads packets from it only when it is so aligned, else it
    gathers each value alone (the same numbers, slower).
    """
    values = np.ascontiguousarray(values, dtype=np.float64).ravel()
    buf = np.empty(values.size + align // 8)
    off = (-buf.ctypes.data % align) // 8
    host = buf[off:off + values.size]
    host[:] = values
    return mi.Float64(host)


def _array_xf64():
    """The dynamic array of Float64 arrays of the current JIT variant (what ``dr.gather`` reads packets into)."""
    import importlib

    return importlib.import_module(mi.Float64.__module__).ArrayXf64


class _Cells:
    """The piece of a table in m (pieces [lo[s], lo[s + 1]), ``lo`` ending with an inf sentinel) that holds m > mlo,
    found from the float64 bits of m as :meth:`pumpup.operators.pumping._LevelTable.piece` finds it, without a branch:
    cell c = (bits(m) >> ``shift``) - ``cbase`` holds a packet (s0, b_1, ..., b_(w-1)), s0 the piece where the cell
    starts and b_i the start of piece s0 + i where it lies inside the cell (else inf); the piece is s0 + the number of
    b_i <= m, read with one gather.  2^bits cells per octave and w in {2, 4}: the fewest bits from CELL_BITS to
    ``MAX_BITS`` at which no cell holds more than 3 piece starts.

    Where even ``MAX_BITS`` leaves more than 3 starts in some cell (the pieces crowd about a few points, as a 3-level
    pumped GGX's level table does near m = 0.97), the cells are two-level (``fine``): a coarse cell at CELL_BITS holds
    e_c and the index of its first fine cell (one UInt32, ``(index << 5) | e_c``), e_c the fewest extra bits that
    leave at most 3 starts in each of its 2^e_c fine cells; the fine cells are packets of width 4 as above.  Two small
    dependent gathers, where one level of cells would need a large table of wide packets.
    """

    MAX_BITS = 12
    #: the most extra bits of a fine cell (two-level cells)
    MAX_FINE_BITS = 26

    def __init__(self, lo, mlo: float):
        from .physics.lookups import CELL_BITS, float_bits_reference

        self._bits = float_bits_reference
        self.lo_np = np.asarray(lo, dtype=np.float64)
        starts = self.lo_np[:-1]
        b0 = int(float_bits_reference(mlo))
        top = int(float_bits_reference(1.0))
        for bits in range(CELL_BITS, self.MAX_BITS + 1):
            most = self._most(starts, self._edges(b0, top, 52 - bits))
            if most <= 3:
                break
        self.shift = shift = 52 - (bits if most <= 3 else CELL_BITS)
        self.cbase = b0 >> shift
        edges = self._edges(b0, top, shift)
        self.ncell = len(edges) - 1
        self.fine = None
        if most <= 3:
            self.width = 2 if most <= 1 else 4
            self.np = self._packets(starts, edges[:-1], edges[1:])
        else:
            self.width = 4
            e = np.zeros(self.ncell, dtype=np.int64)  # each coarse cell's extra bits: 0 where it holds <= 3 starts
            for c in np.nonzero(self._inside(starts, edges) > 3)[0]:
                while self._most(starts, edges[c] + (np.arange(2 ** e[c] + 1, dtype=np.int64) << (shift - e[c]))) > 3:
                    e[c] += 1
                    if e[c] > self.MAX_FINE_BITS:
                        raise ValueError("pumpup.mitsuba: a table's pieces are too crowded for its cells")
            nfine = 2**e
            first = np.concatenate([[0], np.cumsum(nfine)[:-1]])
            # the fine cells' lower edges: cell c's, plus j << (shift - e_c) for its j-th fine cell
            j = np.arange(int(nfine.sum()), dtype=np.int64) - np.repeat(first, nfine)
            step = np.repeat(np.int64(1) << (shift - e), nfine)
            lo_bits = np.repeat(edges[:-1], nfine) + j * step
            self.fine = self._packets(starts, lo_bits, lo_bits + step)
            self.coarse = ((first << 5) | e).astype(np.uint32)
            self.np = self._packets(starts, edges[:-1], edges[1:])  # the scalar path: s0, then a search
        if _jit():
            self.dr = _aligned_f64(self.np if self.fine is None else self.fine)
            if self.fine is not None:
                self.coarse_dr = mi.UInt32(self.coarse)

    @staticmethod
    def _edges(b0, top, shift):
        """The edges (float64 bits) of the cells from the one of bits ``b0`` to the one of ``top``, 2^(52 - shift)
        cells per octave.
        """
        return np.arange(b0 >> shift, (top >> shift) + 2, dtype=np.int64) << shift

    @staticmethod
    def _inside(starts, edges):
        """The piece starts inside each of the cells with these edges (after the cell's first piece's)."""
        bounds = np.asarray(edges, dtype=np.int64).view(np.float64)
        return np.searchsorted(starts, bounds[1:], side="left") - np.searchsorted(starts, bounds[:-1], side="right")

    @classmethod
    def _most(cls, starts, edges):
        """The most piece starts inside one of the cells with these edges."""
        return int(cls._inside(starts, edges).max())

    def _packets(self, starts, lo_bits, hi_bits):
        """The packets (s0, b_1, ..., b_(w-1)) of the cells [lo_bits[i], hi_bits[i]) (float64 bits)."""
        lo_m = np.asarray(lo_bits, dtype=np.int64).view(np.float64)
        hi_m = np.asarray(hi_bits, dtype=np.int64).view(np.float64)
        s0 = np.clip(np.searchsorted(starts, lo_m, side="right") - 1, 0, len(starts) - 1)
        table = np.full((len(s0), self.width), math.inf)
        table[:, 0] = s0
        for i in range(1, self.width):
            nxt = self.lo_np[np.minimum(s0 + i, len(self.lo_np) - 1)]
            table[:, i] = np.where(nxt < hi_m, nxt, math.inf)  # a start inside the cell, else never reached
        return table

    def __call__(self, m):
        """The piece that holds m (m > mlo; other m give some valid piece index)."""
        if not _jit():
            c = min(max((int(self._bits(m)) >> self.shift) - self.cbase, 0), self.ncell - 1)
            s = int(self.np[c, 0])
            while m >= self.lo_np[s + 1]:
                s += 1
            return s
        mb = dr.reinterpret_array(mi.UInt64, m)
        bits = mb >> self.shift
        c = mi.UInt32(dr.minimum(dr.maximum(bits, self.cbase) - self.cbase, self.ncell - 1))
        if self.fine is not None:  # two-level: the coarse cell's entry, then its fine cell (class docstring)
            entry = dr.gather(mi.UInt32, self.coarse_dr, c)
            e = mi.UInt64(entry & 31)
            c = (entry >> 5) + mi.UInt32((mb >> (self.shift - e)) & ((mi.UInt64(1) << e) - 1))
        cell = dr.gather(_array_xf64(), self.dr, c, shape=(self.width, dr.width(c)))
        one, zero = mi.UInt32(1), mi.UInt32(0)
        s = mi.UInt32(cell[0])
        for i in range(1, self.width):
            s = s + dr.select(m >= cell[i], one, zero)
        return s


def _horner(row, a: int, deg: int, t):
    """sum_r row[a + r] t^(deg - r), in the order of :func:`pumpup.physics.lookups.horner` (and the compiled
    kernels).
    """
    v = row[a] * t
    for r in range(1, deg):
        v = (v + row[a + r]) * t
    return v + row[a + deg]


class _ProductG:
    """The product table's G(m) = g_1 ... g_k in Dr.Jit (:class:`pumpup.operators.pumping._Product`, the same pieces
    and coefficients, already scaled up by 1 + epsilon; its numpy reference is ``_Product.__call__``): m = max(N.wi,
    N.wo), one cell gather and one gather of the piece's row (6 coefficients, centre, inverse half-width: 64 bytes).
    """

    def __init__(self, prod):
        self.mlo = float(prod.mlo)
        self.deg = prod.coef.shape[0] - 1
        self.cells = _Cells(prod.lo, self.mlo)
        self.rows = _Rows(np.concatenate([prod.coef, prod.center[None], prod.ihalf[None]]).T)

    def __call__(self, mi_, mo):
        m = dr.maximum(mi_, mo)
        row = self.rows(self.cells(m))
        d = self.deg
        return _horner(row, 0, d, (m - row[d + 1]) * row[d + 2])


class _PairG:
    """The level table's g_1 ... g_k at (N.wi, N.wo) in Dr.Jit (:class:`pumpup.operators.pumping._LevelTable`, the
    compiled :func:`pumpup.physics.lookups.g_pair`; its numpy reference is ``_LevelTable.g``): one piece per cosine
    serves every level, its row (centre, inverse half-width, each level's coefficients) read in packets of 8.

    ``below``: where no float32 lies between the table's mlo and a level's first node (nor above its mu0), a float32
    cosine m <= mlo lies below every level's spline, where pumpup's level-by-level path (:func:`g_levels`) takes the
    power law v0 exp(slope0 (log m - log x0)) + margin_lo (at most the cap): this class then computes it too, without a
    branch (the exponential as a Taylor polynomial where |slope0 (log m - log x0)| <= 1e-3, to 1e-18), and the pair
    needs no level-by-level path at all.  ``power_laws=False``: no power laws (its caller looks those cosines up level
    by level).
    """

    def __init__(self, table, power_laws: bool = True):
        self.mlo = float(table.mlo)
        self.deg = table.coef.shape[1] - 1
        self.controlled = [bool(c) for c in table.controlled]
        self.cells = _Cells(table.lo, self.mlo)
        self.rows = _Rows(table.rows)
        f32 = np.float32(self.mlo)
        if float(f32) > self.mlo:
            f32 = np.nextafter(f32, np.float32(0.0))
        top = float(f32)  # the largest float32 <= mlo
        looks = table.looks
        span = math.log(self.mlo) - math.log(float(np.finfo(np.float32).smallest_subnormal)) + 1.0
        self.below = None
        if power_laws and all(top < math.exp(lk.logx[0]) * (1.0 - 1e-12) and top <= lk.mu0 for lk in looks):
            self.below = []
            for lk in looks:
                ymax = abs(float(lk.slope0)) * span  # |slope0 (log m - log x0)| for every float32 m in (0, mlo]
                terms = next((d for d in range(1, 8) if ymax ** (d + 1) / math.factorial(d + 1) <= 1e-18), None)
                self.below.append((float(lk.v0), float(lk.slope0), float(lk.logx[0]), float(lk.margin_lo),
                                   float(lk.cap), terms if ymax <= 1e-3 else None))
            #: log(m) from the exponent and a float32 logarithm of the mantissa (m is a float32: its mantissa is
            #: exact in float32; the logarithm is off by at most 3e-7) where that moves every slope0 log(m) by at most
            #: 1e-13, else in float64
            self.cheap_log = all(abs(b[1]) * 3e-7 <= 1e-13 for b in self.below)

    @staticmethod
    def _power_law(lm, v0, slope0, logx0, margin_lo, cap, terms):
        """A level's bound below its first node (pumpup.physics.lookups.upper_log), at log(m) = ``lm``."""
        y = slope0 * (lm - logx0)
        if terms is not None:  # exp(y) to ``terms`` + 1 terms of its Taylor series (Horner), error below 1e-18
            e = 1.0 / math.factorial(terms)
            for r in range(terms - 1, -1, -1):
                e = e * y + 1.0 / math.factorial(r)
        else:
            e = dr.exp(y)
        u = v0 * e + margin_lo
        return dr.minimum(u, cap) if math.isfinite(cap) else u

    def _log(self, m):
        if not (self.cheap_log and _jit()):
            return dr.log(dr.maximum(m, 1e-300))
        bits = dr.reinterpret_array(mi.UInt64, m)
        e = mi.Float64(mi.Int32(mi.UInt32(bits >> 52))) - 1023.0  # the exponent (m > 0; others are masked)
        mant = dr.reinterpret_array(mi.Float64, (bits & ((1 << 52) - 1)) | (1023 << 52))  # in [1, 2)
        return e * math.log(2.0) + mi.Float64(dr.log(mi.Float(mant)))

    def __call__(self, mi_, mo):
        ri, ro = self.rows(self.cells(mi_)), self.rows(self.cells(mo))
        ti, to = (mi_ - ri[0]) * ri[1], (mo - ro[0]) * ro[1]
        mmax = dr.maximum(mi_, mo)
        if self.below is not None:
            lmi, lmo = self._log(mi_), self._log(mo)
            low_i, low_o = mi_ <= self.mlo, mo <= self.mlo
        g_all = None
        for j, controlled in enumerate(self.controlled):
            a = 2 + j * (self.deg + 1)
            ui, uo = _horner(ri, a, self.deg, ti), _horner(ro, a, self.deg, to)
            if self.below is not None:  # (power laws below the tables, as g_levels)
                ui = dr.select(low_i, self._power_law(lmi, *self.below[j]), ui)
                uo = dr.select(low_o, self._power_law(lmo, *self.below[j]), uo)
            g = dr.maximum(ui, uo)  # 001 eq. 20
            if controlled:
                g = dr.maximum(g, mmax)  # 001 eq. 21
            g_all = g if g_all is None else g_all * g
        return g_all


class _CellsMiss(ValueError):
    """Raised by :class:`_CellPolynomials` where more than MAX_BAD cells miss or more than MAX_SPLITS are split: the
    plugin leaves levels out of the cells or takes pumpup's tables.
    """


class _CellPolynomials:
    """Functions F_j of the cosine m (a pumped chain's level bounds or the product of its g, :class:`_CellG`) as
    quartics in fixed cells of m.  The fine cells: 2^``bits`` cells per octave from the one holding ``start`` (mlo,
    where every level's spline begins) up to 1, cell c = (bits(m) >> shift) - cbase, t = m's bits below the shift /
    2^shift in [0, 1) (the position in the cell, exact), and a cell of its own holding F_j(1).  With ``low``, below
    mlo, where every level's bound is a power law: 2^low_bits cells per octave down to float32's smallest subnormal
    (:data:`LOW_EXP`), found the same way, where their quartics fit (``nlow`` > 0); then the cells hold every float32
    cosine > 0.  A look-up computes its cell from the bits of m and reads its coefficients, one gather each, with no
    search and no index table: on Mitsuba's llvm variants that costs less than finding a piece of the level table
    (:class:`_PairG`).  Each F_j is taken at most its cap.

    Each cell's quartic interpolates F_j at the Chebyshev points of the cell (of the part of it on its side of mlo)
    and is lifted by three times its largest miss at 65 points there, plus 8 ulps of the sum of its coefficients'
    magnitudes (Horner's rounding): it is at least F_j on the cell, so the plugin divides by at least pumpup's
    levelwise g and never returns more than pumpup.  A cell whose quartic, lifted, may lie more than :data:`LIFT` of
    its smallest value above F_j (a kink or a jump of F_j in it: the lift plus the miss) is split at the kinks where
    the chain knows of them: its first piece keeps the cell's row, each further piece, from kink t_i, has a row of its
    own, a quartic in t - t_i.  Else the cell is ``bad``: the plugin looks pairs with a cosine there up level by level.
    The fewest bits of :data:`BITS` with the fewest bad cells, then the fewest split cells.  Beyond :data:`MAX_BAD` bad
    cells, top cells: from the lowest bad cell up to 1, the fewest 2^top_bits cells per octave of which at most
    :data:`MAX_TOP_BAD` miss (those are bad, not split), found from the bits of m as the fine cells are, with one
    comparison and one select more (``ntop``; a chain whose features crowd near m = 1).  Beyond MAX_BAD bad cells even
    so, or :data:`MAX_SPLITS` split cells, refined cells (``coarse``): 2^REFINE_BITS coarse cells per octave, each cut
    into the fewest 2^e fine cells (e <= MAX_EXTRA_BITS) that all fit, a fine cell that misses even so split at a kink
    where it can be; a look-up reads its coarse cell's entry (first fine cell << 5 | e), then its fine cell's
    coefficients.  Refused (:class:`_CellsMiss`: the plugin then leaves levels out of the cells, or takes pumpup's
    product or level table) beyond MAX_BAD fine cells that miss or MAX_SPLITS split ones.  ``reference`` is the plain
    numpy version of the look-up, the same operations in the same order.
    """

    #: the relative lift a cell may need (the plugin's values may lie this much further below pumpup's, per function)
    LIFT = 1e-13
    #: the cells per octave tried, 2^bits
    BITS = (8, 9, 10)
    #: the quartic (five reads per look-up; quintics fit with fewer cells but cost one more read, 3-5 % of a
    #: sample and an eval of pumped GGX or Phong)
    DEGREE = 4
    #: the most cells that may miss (:attr:`bad`)
    MAX_BAD = 4
    #: the most kinks at which one cell is split, and the most split cells (each costs a few selects per look-up)
    MAX_KINKS = 3
    MAX_SPLITS = 4
    #: the lowest octave of the low cells, as a float64 exponent (biased): 2^-149, float32's smallest subnormal
    LOW_EXP = 1023 - 149
    #: the cells per octave below mlo tried, 2^low_bits
    LOW_BITS = (0, 1, 2, 3)
    #: the float64 bits of 1
    ONE = int(np.float64(1.0).view(np.int64))
    #: top cells, where a fixed grid of :data:`BITS` misses in more than MAX_BAD cells: from the lowest of them up to
    #: 1, 2^top_bits cells per octave, the fewest (at most MAX_TOP_BITS, in at most MAX_TOP_ROWS rows) where at most
    #: MAX_TOP_BAD miss, together at most MAX_TOP_BAD_WIDTH wide; those are not split (splits there measured slower
    #: than cells that miss, so small that few pairs take the level-by-level path).  More than MAX_BAD: 3-level g2
    #: Phong's product has 5 at 2^14, whatever engine built its tables, where 4 at 2^18 needed tables from the default
    MAX_TOP_BITS = 20
    MAX_TOP_ROWS = 2**13
    MAX_TOP_BAD = 8
    MAX_TOP_BAD_WIDTH = 2.0**-12
    #: refined cells, where no fixed grid of :data:`BITS` fits: 2^REFINE_BITS coarse cells per octave, each cut into
    #: 2^e fine cells, e from 0 to MAX_EXTRA_BITS, the fewest where all fit
    REFINE_BITS = 9
    MAX_EXTRA_BITS = 10

    def __init__(self, functions, caps, start: float, kinks=(), low: bool = False, refine: bool = True):
        self.mlo = float(start)
        self.mlo_bits = int(np.float64(start).view(np.int64))
        self.caps = [float(c) for c in caps]
        self.nfun = len(functions)
        kinks = np.sort(np.asarray(kinks, dtype=np.float64))
        best = None
        for bits in self.BITS:  # (the fewest cells that miss, then the fewest split cells, then the fewest bits)
            fit = self._fine(functions, bits, kinks)
            if best is None or (len(fit[2]), len(fit[1])) < (len(best[3]), len(best[2])):
                best = (bits, *fit)
            if len(fit[1]) + len(fit[2]) == 0:
                break
        bits, coef, splits, bad = best
        # top cells: (the bits of their first cell's left edge, their shift, their coefficients with a row for m = 1,
        # those that miss), else None
        top = self._top(functions, bits, bad) if len(bad) > self.MAX_BAD else None
        if top is not None:  # (the fine cells end where the top cells begin)
            coef, splits, bad = coef[:min(bad)], [s for s in splits if s[0] < min(bad)], []
        #: refined cells: each coarse cell's entry (its first fine cell << 5 | its extra bits e), else None
        self.coarse = None
        if (len(bad) > self.MAX_BAD or len(splits) > self.MAX_SPLITS) and refine:
            bits, top = self.REFINE_BITS, None
            coef, self.coarse, splits, bad = self._refined(functions, kinks)
        if len(bad) > self.MAX_BAD or len(splits) > self.MAX_SPLITS:
            raise _CellsMiss(f"pumpup.mitsuba: {len(bad)} cells of a level's bound are not within its lift of "
                             f"quartics and {len(splits)} are split at kinks")
        self.shift = 52 - bits
        self.cbase = self.mlo_bits >> self.shift
        self.nfine = coef.shape[0]
        lows, low_bits = None, 0
        for low_bits in self.LOW_BITS if low else ():
            lows = self._low(functions, kinks, low_bits, self.MAX_SPLITS - len(splits))
            if lows is not None:
                break
        #: the low cells' rows follow the fine cells' (none where they do not fit or were not asked for)
        self.nlow = 0 if lows is None else lows[0].shape[0]
        self.low_shift = 52 - low_bits
        self.low_base = self.LOW_EXP << low_bits
        if lows is not None:
            coef = np.concatenate([coef, lows[0]])
            splits = splits + [(self.nfine + c, *rest) for c, *rest in lows[1]]
        #: the top cells' rows follow the low cells' (none where the fine cells fit up to 1): 2^(52 - top_shift) cells
        #: per octave from the float whose bits are top_bits up to 1, the last holding m = 1
        self.ntop, self.top_bits, self.top_shift = 0, self.ONE + 1, 0
        if top is not None:
            self.top_bits, self.top_shift, top_coef, top_bad = top
            self.ntop = top_coef.shape[0]
            bad = bad + [coef.shape[0] + int(c) for c in top_bad]
            coef = np.concatenate([coef, top_coef])
        self.top_base = self.top_bits >> self.top_shift
        #: the cells split at kinks, (cell, [t of each kink], the row of the piece from the first kink): the further
        #: pieces' rows follow the cells'
        self.splits = []
        rows = [coef]
        for c, own, pieces, tk in splits:
            coef[c] = own
            self.splits.append((int(c), tk, sum(r.shape[0] for r in rows)))
            rows.append(pieces)
        coef = np.concatenate(rows)
        #: the cells whose quartics miss even so: pairs with a cosine there are looked up level by level
        self.bad = [int(c) for c in bad]
        self.np = np.ascontiguousarray(coef.reshape(coef.shape[0], -1))  # row c: F_1's 5 coefficients, F_2's, ...
        self.dr = _aligned_f64(self.np) if _jit() else None
        self.coarse_dr = mi.UInt32(self.coarse) if _jit() and self.coarse is not None else None

    @staticmethod
    def _grid(first: int, last: int, shift: int):
        """(left, width) of the cells ``first`` ... ``last``, cell c holding the floats whose bits >> shift are c."""
        c = np.arange(first, last + 1, dtype=np.int64)
        left = (c << shift).view(np.float64)
        return left, ((c + 1) << shift).view(np.float64) - left

    def _fine(self, functions, bits, kinks):
        """(the fine cells' coefficients (cell, function, 5), highest power first, lifted, and one more row for m = 1;
        the cells split at kinks, as :meth:`_split`; the cells that still miss).
        """
        shift = 52 - bits
        left, width = self._grid(self.mlo_bits >> shift, (self.ONE >> shift) - 1, shift)
        lo_t, hi_t = self._side(left, width, below=False)
        coef, ok = self._fit(functions, left, width, lo_t, hi_t)
        coef = np.concatenate([coef, self._row_of_one(functions)])
        if np.count_nonzero(~ok) > self.MAX_SPLITS + self.MAX_BAD:  # (refused however they split: not tried)
            return coef, [], list(np.nonzero(~ok)[0])
        splits, bad = self._split(functions, left, width, ok, kinks, lo_t, hi_t)
        return coef, splits, bad

    def _refined(self, functions, kinks):
        """(the fine cells' coefficients, in the order of their coarse cells, and one more row for m = 1; the coarse
        cells' entries (first fine cell << 5 | e); the fine cells split at kinks, as :meth:`_split`; the fine cells
        that still miss) of refined cells: each coarse cell that misses cut into 2^e fine cells, the fewest with all
        within LIFT, at most 2^MAX_EXTRA_BITS; fine cells that miss even so are split at a kink where they can be (at
        most MAX_SPLITS in all).
        """
        shift = 52 - self.REFINE_BITS
        left, width = self._grid(self.mlo_bits >> shift, (self.ONE >> shift) - 1, shift)
        coef, ok = self._fit(functions, left, width, *self._side(left, width, below=False))

        def cut(i, e):  # the 2^e fine cells of coarse cell i
            n = 2**e
            sub_left, sub_width = left[i] + width[i] * np.arange(n) / n, np.full(n, width[i] / n)  # (exact)
            lo_t, hi_t = self._side(sub_left, sub_width, below=False)
            c, fits = self._fit(functions, sub_left, sub_width, lo_t, hi_t)
            split, miss = self._split(functions, sub_left, sub_width, fits, kinks, lo_t, hi_t)
            return c, split, miss

        rows, entries, splits, bad = [], [], [], []
        first = 0
        for i in range(len(left)):
            e = 0
            c, split, miss = (coef[i:i + 1], [], []) if ok[i] else cut(i, 0)
            while (miss or split) and e < self.MAX_EXTRA_BITS:  # (finer cells cost memory, splits a few selects)
                e += 1
                c, split, miss = cut(i, e)
            if len(splits) + len(split) > self.MAX_SPLITS:  # (the cells to split beyond MAX_SPLITS miss)
                miss, split = miss + [k for k, *_ in split], []
            rows.append(c)
            entries.append((first << 5) | e)
            splits += [(first + k, *rest) for k, *rest in split]
            bad += [first + k for k in miss]
            first += len(c)
        entries.append(first << 5)
        return (np.concatenate(rows + [self._row_of_one(functions)]), np.array(entries, dtype=np.uint32), splits,
                sorted(bad))

    def _top(self, functions, bits: int, bad):
        """(the bits of the left edge of the lowest fine cell of ``bad``, the top cells' shift, their coefficients with
        one more row for m = 1, the top cells that miss) of the fewest top cells per octave from that edge up to 1 of
        which at most MAX_TOP_BAD miss, at most MAX_TOP_BAD_WIDTH wide together, in at most MAX_TOP_ROWS rows; else
        None (and where the lowest is the first fine cell: some fine cell stays below the top cells, so that every
        cosine's fine cell is a row).
        """
        if min(bad) == 0:
            return None
        shift = 52 - bits
        top_bits = ((self.mlo_bits >> shift) + min(bad)) << shift
        for top in range(bits + 1, self.MAX_TOP_BITS + 1):
            top_shift = 52 - top
            first, last = top_bits >> top_shift, (self.ONE >> top_shift) - 1
            if last - first + 2 > self.MAX_TOP_ROWS:
                return None
            left, width = self._grid(first, last, top_shift)
            coef, ok = self._fit(functions, left, width, *self._side(left, width, below=False))
            if np.count_nonzero(~ok) <= self.MAX_TOP_BAD and np.sum(width[~ok]) <= self.MAX_TOP_BAD_WIDTH:
                return top_bits, top_shift, np.concatenate([coef, self._row_of_one(functions)]), np.nonzero(~ok)[0]
        return None

    def _low(self, functions, kinks, bits: int, nsplit: int):
        """(the coefficients of 2^``bits`` cells per octave from 2^(LOW_EXP - 1023) up to mlo, the cells split at
        kinks) where their quartics, split at no more than ``nsplit`` cells, fit every function; else None.
        """
        shift = 52 - bits
        left, width = self._grid(self.LOW_EXP << bits, (self.mlo_bits - 1) >> shift, shift)
        lo_t, hi_t = self._side(left, width, below=True)
        with np.errstate(all="ignore"):
            coef, ok = self._fit(functions, left, width, lo_t, hi_t)
            splits, bad = self._split(functions, left, width, ok, kinks, lo_t, hi_t)
        if bad or len(splits) > nsplit or not np.all(np.isfinite(coef)):
            return None
        return coef, splits

    def _side(self, left, width, below: bool):
        """(lo_t, hi_t): the part in t of each cell [left, left + width) that holds m >= mlo (``below``: m < mlo),
        exact where the cell holds mlo; empty (lo_t = hi_t) where no part does.
        """
        t = np.clip((self.mlo - left) / width, 0.0, 1.0)
        return (np.zeros_like(t), t) if below else (t, np.ones_like(t))

    def _fit(self, functions, left, width, lo_t, hi_t):
        """:meth:`_pieces` of each cell on its part [lo_t, hi_t) (a cell cut at mlo: fitted alone there); a cell with
        no part is never read: fitted whole and taken as fitting.
        """
        empty = lo_t >= hi_t
        coef, ok = self._pieces(functions, left, width, 0.0)
        ok |= empty
        for k in np.nonzero(~empty & ((lo_t > 0.0) | (hi_t < 1.0)))[0]:
            coef[k:k + 1], ok[k:k + 1] = self._pieces(functions, left[k:k + 1], width[k:k + 1], 0.0, lo_t[k],
                                                      hi_t[k])
        return coef, ok

    def _row_of_one(self, functions):
        """The row of the cell of m = 1, (1, function, 5): each function's value there, a constant."""
        row = np.zeros((1, len(functions), self.DEGREE + 1))
        row[0, :, -1] = [float(fn(np.array([1.0]))[0]) for fn in functions]
        return row

    def _split(self, functions, left, width, ok, kinks, lo_t, hi_t):
        """(the cells that miss (``~ok``, each holding t in [lo_t, hi_t)) split at kinks, [(cell, its first piece's
        coefficients, the further pieces', [t of each kink])]; the cells that still miss).  A cell is split at one of
        the ``kinks`` inside it, else at all of them (at most MAX_KINKS), where every piece is within LIFT.
        """
        splits, bad = [], []
        for i in np.nonzero(~ok)[0]:
            x = kinks[(kinks > left[i]) & (kinks < left[i] + width[i])]
            inside = np.unique((x - left[i]) / width[i])  # (t of each kink, exact)
            inside = inside[(inside > lo_t[i]) & (inside < hi_t[i])]
            tries = [inside[k:k + 1] for k in range(len(inside))] + ([inside] if 1 < len(inside) <= self.MAX_KINKS
                                                                     else [])
            for tk in tries:
                ends = np.concatenate([[lo_t[i]], tk, [hi_t[i]]])
                own, fits = self._pieces(functions, left[i:i + 1], width[i:i + 1], 1e-14, ends[0], ends[1])
                pieces = []
                for a, b in zip(ends[1:-1], ends[2:]):  # (a piece from kink a: a quartic in t - a)
                    p, f = self._pieces(functions, left[i:i + 1] + width[i:i + 1] * a, width[i:i + 1], 1e-14, 0.0,
                                        b - a)
                    pieces.append(p)
                    fits = fits & f
                if np.all(fits):
                    splits.append((i, own[0], np.concatenate(pieces), [float(v) for v in tk]))
                    break
            else:
                bad.append(i)
        return splits, bad

    def _pieces(self, functions, left, width, margin, t0: float = 0.0, t1: float = 1.0):
        """(the lifted quartics (piece, function, 5) in t of every function at m = left + width t, t in [t0, t1);
        whether each piece's lift is within LIFT).  ``margin``: a further lift, relative to the function's largest
        value on the piece (a split cell's pieces: the kink's position is known to a few ulps).
        """
        from .physics.lookups import horner

        deg = self.DEGREE
        cheb = 0.5 - 0.5 * np.cos(np.pi * (np.arange(deg + 1) + 0.5) / (deg + 1))
        tk = t0 + (t1 - t0) * cheb
        tt = t0 + (t1 - t0) * np.linspace(0.0, 1.0, 65)
        power = np.arange(deg, -1, -1)
        coef = np.zeros((len(left), len(functions), deg + 1))
        ok = np.ones(len(left), dtype=bool)
        for j, fn in enumerate(functions):
            vk = fn(left[:, None] + width[:, None] * tk[None, :])
            if t0 == 0.0:  # in u = t / t1 on [0, 1], then in t (solve: inverting the matrix first cost 1e-14)
                a = np.linalg.solve(np.vander(cheb, deg + 1), vk.T).T / t1 ** power
            else:
                a = np.linalg.solve(np.vander(tk, deg + 1), vk.T).T
            mt = left[:, None] + width[:, None] * tt[None, :]
            mt[:, -1] = np.nextafter(mt[:, -1], 0.0)  # (a piece holds [t0, t1): a jump at its end)
            vt = fn(mt)
            pt = horner(a.T[:, :, None], (mt - left[:, None]) / width[:, None])  # (at the t of the float m, exact)
            miss = np.max(np.abs(vt - pt), axis=1)
            lift = (3.0 * miss + 8.0 * np.finfo(float).eps * np.sum(np.abs(a), axis=1)
                    + margin * np.max(np.abs(vt), axis=1))
            ok &= lift + miss <= self.LIFT * np.min(vt, axis=1)  # (the most the lifted quartic lies above)
            a[:, -1] += lift
            coef[:, j] = a
        return coef, ok

    @staticmethod
    def _in_grid(bits, shift: int, base: int, n: int | None, xp=np):
        """(cell, t) of float64 bits in a grid of ``n`` cells, cell c holding the floats whose bits >> shift are
        base + c, t the bits below the shift / 2^shift (exact); bits below the grid in its first cell, bits above it in
        its last, but for ``n`` None: the low cells, which end where the comparison that selects them does (a clamp
        there cost 3 % of a 1-level pumped GGX sample, measured).  ``xp``: numpy, or Dr.Jit (bits a UInt64 array).
        """
        if xp is np:
            c = np.maximum(bits >> shift, base) - base
            t = (bits & ((1 << shift) - 1)).astype(np.float64) * 2.0**-shift
            return (c if n is None else np.minimum(c, n - 1)), t
        c = dr.maximum(bits >> shift, base) - base
        t = mi.Float64(bits & ((1 << shift) - 1)) * 2.0**-shift
        return mi.UInt32(c if n is None else dr.minimum(c, n - 1)), t

    def _cell(self, bits):
        """(cell, t) of the float64 bits of m > 0 (numpy): a fine cell from m's bits above the shift, t those below
        it / 2^shift (exact); from the top cells' first edge up, its top cell and t likewise, and below mlo, where the
        low cells hold every float32, its low cell.
        """
        c, t = self._in_grid(bits, self.shift, self.cbase, self.nfine)
        if self.coarse is not None:  # the coarse cell's entry, then its fine cell
            entry = self.coarse[self._in_grid(bits, self.shift, self.cbase, len(self.coarse))[0]].astype(np.int64)
            sub = self.shift - (entry & 31)
            c = (entry >> 5) + ((bits >> sub) & ((1 << (entry & 31)) - 1))
            t = (bits & ((1 << sub) - 1)).astype(np.float64) * np.ldexp(1.0, -sub)
        if self.ntop:
            top = bits >= self.top_bits
            ct, tt = self._in_grid(bits, self.top_shift, self.top_base, self.ntop)
            c, t = np.where(top, ct + (self.nfine + self.nlow), c), np.where(top, tt, t)
        if self.nlow:
            low = bits < self.mlo_bits
            cl, tl = self._in_grid(bits, self.low_shift, self.low_base, None)
            c, t = np.where(low, cl + self.nfine, c), np.where(low, tl, t)
        return c, t

    def _halves(self, c, t, select):
        """(row, t) after the splits: in a split cell, from its kink t_i on, the row of the piece from t_i and t - t_i
        (``select``: numpy's where or Dr.Jit's select).
        """
        row, start = c, t * 0.0
        for cell, kinks, first in self.splits:
            hit = c == cell
            for i, tk in enumerate(kinks):
                right = hit & (t >= tk)
                row = select(right, first + i, row)
                start = select(right, tk, start)
        return row, t - start

    def in_bad(self, m):
        """Whether m >= mlo lies in a cell of :attr:`bad` (numpy, Dr.Jit or a float)."""
        if isinstance(m, (np.ndarray, float)):  # (numpy's float64 is a float)
            c = self._cell(np.asarray(m, dtype=np.float64).view(np.int64))[0]
            return np.isin(c, self.bad) if isinstance(m, np.ndarray) else bool(np.isin(c, self.bad))
        c = self._cell_dr(m)[0]
        out = dr.full(mi.Bool, False, dr.width(m))
        for b in self.bad:
            out |= c == b
        return out

    def _cell_dr(self, m):
        """:meth:`_cell` in Dr.Jit, of the Float64 cosines m (m <= 0: some valid cell)."""
        mb = dr.reinterpret_array(mi.UInt64, m)
        if self.coarse is not None:  # the coarse cell's entry, then its fine cell
            coarse_cell = self._in_grid(mb, self.shift, self.cbase, len(self.coarse), xp=dr)[0]
            entry = dr.gather(mi.UInt32, self.coarse_dr, coarse_cell)
            e = mi.UInt64(entry & 31)
            sub = self.shift - e
            c = (entry >> 5) + mi.UInt32((mb >> sub) & ((mi.UInt64(1) << e) - 1))
            t = mi.Float64(mb & ((mi.UInt64(1) << sub) - 1)) * dr.reinterpret_array(mi.Float64, (1023 - sub) << 52)
        else:
            c, t = self._in_grid(mb, self.shift, self.cbase, self.nfine, xp=dr)
        if self.ntop:
            top = mb >= self.top_bits
            ct, tt = self._in_grid(mb, self.top_shift, self.top_base, self.ntop, xp=dr)
            c, t = dr.select(top, ct + (self.nfine + self.nlow), c), dr.select(top, tt, t)
        if self.nlow:
            low = mb < self.mlo_bits
            cl, tl = self._in_grid(mb, self.low_shift, self.low_base, None, xp=dr)
            c, t = dr.select(low, cl + self.nfine, c), dr.select(low, tl, t)
        return c, t

    def reference(self, m):
        """[F_1(m), ..., F_k(m)], each at most its cap, as the Dr.Jit look-up computes them (numpy; m >= mlo, or
        m > 0 where the low cells hold every float32).
        """
        m = np.asarray(m, dtype=np.float64)
        c, t = self._halves(*self._cell(m.view(np.int64)), np.where)
        rows = self.np[c]
        deg = self.DEGREE
        out = []
        for j, cap in enumerate(self.caps):
            u = _horner([rows[..., j * (deg + 1) + r] for r in range(deg + 1)], 0, deg, t)
            out.append(np.minimum(u, cap) if math.isfinite(cap) else u)
        return out

    def __call__(self, m):
        """:meth:`reference` in Dr.Jit (Float64 cosines; below mlo some valid cell's values; scalar variants call
        :meth:`reference`).
        """
        c, t = self._halves(*self._cell_dr(m), dr.select)
        deg = self.DEGREE
        base = c * (self.nfun * (deg + 1))
        out = []
        for j, cap in enumerate(self.caps):
            row = [dr.gather(mi.Float64, self.dr, base + (j * (deg + 1) + r)) for r in range(deg + 1)]
            u = _horner(row, 0, deg, t)
            out.append(dr.minimum(u, cap) if math.isfinite(cap) else u)
        return out


class _CellG:
    """g_1 ... g_k of a pumped chain from :class:`_CellPolynomials`.  Where every level's bound increases, one function
    of m = max(N.wi, N.wo): G(m) = prod_j max(min(U_j(m), cap_j), m where controlled) (001 eq. 20, 21; pumpup's product
    table), looked up once per pair.  Else each level's uncapped bound U_j, looked up at both cosines, and g_j =
    max(min(U_j, cap_j) at N.wi, at N.wo), at least max(N.wi, N.wo) where controlled; where some levels' bounds do not
    fit a fixed grid (crowded features), only the others, times those levels' g from refined cells of their own
    (``rest_cells``: a refined look-up's coarse read delays only those levels' reads), else from a level table of
    their own (:class:`_PairG`: one piece per cosine).  Both cosines above ``mlo`` (any cosine > 0 where ``whole``),
    and not in a cell whose quartics miss (:meth:`in_bad`); the plugin looks the others up level by level.
    """

    def __init__(self, looks, controlled):
        self.increasing = all(lk.increasing for lk in looks)
        # the fine cells' start: where every level's spline has begun (below it a level's bound is a power law, with a
        # jump of its margin), and for the product, above every level's mu0 (pumpup's product table's mlo)
        start = max(self._spline_start(float(lk.logx[0])) for lk in looks)
        if self.increasing:
            start = max([start] + [float(lk.mu0) for lk in looks])
        self.controlled = [bool(c) for c in controlled]
        kinks = self._kinks(looks, start)
        #: the levels that are not in the fixed cells, and their refined cells or level table (None: none)
        self.rest, self.rest_cells, self.rest_table = [], None, None
        self.rest_controlled = []
        if self.increasing:
            self.cells = _CellPolynomials([self._product_of(looks)], [math.inf], start, kinks, refine=False)  # (refined
            # cells of the product measured no faster than pumpup's product table: 3-level g2 Phong 1.67 x against 1.62)
        else:  # (each level's bound at both cosines, as pumpup's level-by-level path: the low cells serve)
            try:
                self.cells = self._levels_in_cells(looks, range(len(looks)), start, kinks, refine=False)
            except _CellsMiss:
                fit = [j for j in range(len(looks)) if self._fits(looks[j], start, kinks)]
                if not fit:  # (refined cells of every level, else pumpup's tables)
                    self.cells = self._levels_in_cells(looks, range(len(looks)), start, kinks)
                else:
                    self.cells = self._levels_in_cells(looks, fit, start, kinks, refine=False)
                    self.rest = [j for j in range(len(looks)) if j not in fit]
                    try:
                        self.rest_cells = self._levels_in_cells(looks, self.rest, start, kinks)
                    except _CellsMiss:
                        self._rest_pair(looks)
            self.rest_controlled = [self.controlled[j] for j in self.rest]
            self.controlled = [self.controlled[j] for j in range(len(looks)) if j not in self.rest]
        #: pairs with a cosine at or below mlo go level by level, unless the cells hold every float32 cosine > 0
        #: (``whole``: the low cells fit, and no level is in a level table); then only pairs in a cell that misses do
        self.mlo = self.cells.mlo if self.rest_table is None else max(self.cells.mlo, self.rest_table.mlo)
        self.whole = (bool(self.cells.nlow) and self.rest_table is None
                      and (self.rest_cells is None or bool(self.rest_cells.nlow)))
        #: the cells whose quartics miss, of the fixed cells and of the refined ones
        self.bad = self.cells.bad + ([] if self.rest_cells is None else self.rest_cells.bad)

    @staticmethod
    def _levels_in_cells(looks, levels, start, kinks, refine: bool = True, low: bool = True):
        """The cells of the uncapped bounds of ``levels``, with low cells where ``low`` and they fit, refined where
        ``refine`` and a fixed grid does not fit (:class:`_CellsMiss` where the cells do not fit).
        """
        return _CellPolynomials([lambda m, lk=looks[j]: lk.upper(m, capped=False) for j in levels],
                                [looks[j].cap for j in levels], start, kinks, low=low, refine=refine)

    def _fits(self, lk, start, kinks) -> bool:
        """Whether a fixed grid of cells fits the bound of look-up ``lk`` alone."""
        try:
            self._levels_in_cells([lk], [0], start, kinks, refine=False, low=False)
        except _CellsMiss:
            return False
        return True

    def _rest_pair(self, looks):
        """The level table of the levels not in the cells (:class:`_CellsMiss` where it cannot be built)."""
        from .operators.pumping import _LevelTable, _ProductError

        try:
            self.rest_table = _LevelTable([looks[j] for j in self.rest], [self.controlled[j] for j in self.rest])
        except _ProductError as e:
            raise _CellsMiss(f"pumpup.mitsuba: no level table of the levels beyond the cells: {e}") from None
        self.rest_g = _PairG(self.rest_table, power_laws=False)  # (cosines below its mlo go level by level)

    def _kinks(self, looks, start):
        """Where a function of the cells may have a kink: the levels' spline breakpoints (pumpup's albedo kinks among
        them) and flat pieces' ends, where a bound crosses its cap, and, for the product, where a controlled level's
        bound meets m (001 eq. 21).
        """
        from .operators.pumping import _level_breaks, _meet_kinks

        br = _level_breaks(looks, start)  # (the knots, every eighth of an octave and the cap crossings)
        flats = [x for lk in looks for a, b, _ in lk.flats for x in (a, b)]
        flats += [self._spline_start(float(lk.logx[0])) for lk in looks]  # (a jump of its margin: low cells)
        meets = _meet_kinks([lk for lk, c in zip(looks, self.controlled) if c], br) if self.increasing else []
        return np.concatenate([br, flats, meets])

    @staticmethod
    def _spline_start(logx0: float) -> float:
        """The smallest float m with log(m) >= logx0: where a level's bound leaves its power law for its spline (a
        jump of its margins; pumpup.physics.lookups.upper_log tests log(m) < logx0 in the same libm logarithm).
        """
        m = math.exp(logx0)
        while math.log(m) >= logx0:
            m = math.nextafter(m, 0.0)
        while math.log(m) < logx0:
            m = math.nextafter(m, math.inf)
        return m

    def _product_of(self, looks):
        """G(m), the product of every level's g at N.wi = N.wo = m, from the levels' look-ups."""
        def product(m):
            g = np.ones_like(m)
            for lk, controlled in zip(looks, self.controlled):
                g = g * (np.maximum(lk.upper(m), m) if controlled else lk.upper(m))  # 001 eq. 20, 21
            return g
        return product

    @staticmethod
    def _levels(ui, uo, mmax, maximum, controlled_levels):
        g_all = None
        for j, controlled in enumerate(controlled_levels):
            g = maximum(ui[j], uo[j])  # 001 eq. 20
            if controlled:
                g = maximum(g, mmax)  # 001 eq. 21
            g_all = g if g_all is None else g_all * g
        return g_all

    def in_bad(self, mi_, mo):
        """Whether the pair looks a cosine up in a cell whose quartics miss (:attr:`_CellPolynomials.bad`)."""
        if self.increasing:
            return self.cells.in_bad(dr.maximum(mi_, mo) if isinstance(mi_, mi.Float64) else np.maximum(mi_, mo))
        out = self.cells.in_bad(mi_) | self.cells.in_bad(mo)
        return out if self.rest_cells is None else out | self.rest_cells.in_bad(mi_) | self.rest_cells.in_bad(mo)

    def reference(self, mi_, mo):
        """The plain numpy version (both cosines >= mlo)."""
        mi_, mo = np.asarray(mi_, dtype=np.float64), np.asarray(mo, dtype=np.float64)
        mmax = np.maximum(mi_, mo)
        if self.increasing:
            return self.cells.reference(mmax)[0]
        g = self._levels(self.cells.reference(mi_), self.cells.reference(mo), mmax, np.maximum, self.controlled)
        if self.rest_cells is not None:
            return g * self._levels(self.rest_cells.reference(mi_), self.rest_cells.reference(mo), mmax, np.maximum,
                                    self.rest_controlled)
        return g if self.rest_table is None else g * self.rest_table.g(mi_, mo)

    def __call__(self, mi_, mo):
        if not _jit():
            return float(self.reference(mi_, mo))
        mmax = dr.maximum(mi_, mo)
        if self.increasing:
            return self.cells(mmax)[0]
        g = self._levels(self.cells(mi_), self.cells(mo), mmax, dr.maximum, self.controlled)
        if self.rest_cells is not None:
            return g * self._levels(self.rest_cells(mi_), self.rest_cells(mo), mmax, dr.maximum,
                                    self.rest_controlled)
        return g if self.rest_table is None else g * self.rest_g(mi_, mo)


#: the largest float32, the type Mitsuba's JIT variants evaluate in
FLOAT32_MAX = float(np.finfo(np.float32).max)


def _check_float32(brdf: BRDF) -> None:
    """A SpecError unless every number of ``brdf``'s spec and its value at normal incidence and at a 45-degree
    mirror pair fit float32: beyond it, Mitsuba would get inf without a word.
    """
    stack = [("", brdf.spec)]
    while stack:
        name, v = stack.pop()
        if isinstance(v, dict):
            stack.extend((k if not name else f"{name}.{k}", x) for k, x in v.items())
        elif isinstance(v, list):
            stack.extend((f"{name}[{i}]", x) for i, x in enumerate(v))
        elif isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) > FLOAT32_MAX:
            raise SpecError(f"pumpup.mitsuba: parameter {name!r} = {v:g} is beyond float32's range (|x| <= 3.4e38), "
                            "in which Mitsuba evaluates: the BSDF would return inf")
    s = math.sqrt(0.5)
    peak = np.asarray(brdf.eval(np.array([[0.0, 0.0, 1.0], [s, 0.0, s]]), np.array([[0.0, 0.0, 1.0], [-s, 0.0, s]])))
    if not np.all(np.abs(peak) <= FLOAT32_MAX):
        raise SpecError(f"pumpup.mitsuba: {json.dumps(brdf.spec)} evaluates to {float(np.max(np.abs(peak))):g} at its "
                        "peak, beyond float32's range (3.4e38) in which Mitsuba evaluates")


class _DrModel:
    """A pumpup BRDF translated to Dr.Jit: ``f(wl, v)`` in Float64, and its sampling strategy."""

    #: pumped values are multiplied by this before the cast to float32 (rounded down)
    ROUND_DOWN = 1.0 - 2.0**-23

    def __init__(self, brdf: BRDF):
        _check_float32(brdf)
        self.brdf = brdf
        self.levels: list[_Level] = []
        #: (eta, k) of an outer ``fresnel`` model (base x F(Theta_min), pumpup.models.fresnel), else None
        self.fresnel = (brdf.p["eta"], brdf.p["k"]) if brdf.type == "fresnel" else None
        base = brdf.p["base"] if self.fresnel is not None else brdf
        from .operators.pumping import Pumped

        #: one table for all levels where the chain has one: the product table G(max(N.wi, N.wo)) where every level's
        #: bound increases, else the level table (as pumpup's chain kernel chooses); None: level by level
        self.fast: _CellG | _ProductG | _PairG | None = None
        if isinstance(base, Pumped):
            try:  # every level's bound in fixed cells of the cosine, where quartics fit them
                self.fast = _CellG([lev.lookup() for lev in base.chain()], [lev.controlled for lev in base.chain()])
            except _CellsMiss:
                prod = base.product()
                table = base.level_table() if prod is None else None
                self.fast = _ProductG(prod) if prod is not None else (_PairG(table) if table is not None else None)
        while isinstance(base, Pumped):
            self.levels.append(_Level(base.lookup(), base.controlled))
            base = base.base
        self.levels.reverse()
        if base.type not in _KERNELS:
            raise SpecError(f"pumpup.mitsuba: model type {base.type!r} has no Dr.Jit translation; the plugin supports "
                            f"{', '.join(SUPPORTED)}")
        self.base = base
        self.kernel = _KERNELS[base.type]
        self.args = base.kernel_args()
        strat = _sampling.strategy(brdf, 1.0)
        for mu in (0.5, 1e-3):
            if _sampling.strategy(brdf, mu) != strat:
                raise SpecError(f"pumpup.mitsuba: the sampling strategy of {brdf.type!r} depends on the incidence "
                                "angle, which the plugin does not support")
        self.components = strat.components

    def g(self, mi_, mo):
        """The product of all levels' g at cosines (mi_, mo), as pumpup's chain kernel computes it where both are > 0
        (elsewhere a value that the caller masks).
        """
        def by_levels(mi_, mo):
            mi_, mo = dr.maximum(mi_, 1e-300), dr.maximum(mo, 1e-300)
            g = 1.0
            for lev in self.levels:
                g = g * lev.g(mi_, mo)
            return g

        if self.fast is None:
            return by_levels(mi_, mo)
        # the table where both cosines exceed its mlo; level by level where the smaller lies in (0, mlo] (a pair
        # with a cosine <= 0 gives 0 whatever g is: it stays on the table's path, whose lookups stay in range)
        if getattr(self.fast, "below", None) is not None:  # the table holds every float32 cosine > 0
            return self.fast(mi_, mo) if _jit() or dr.minimum(mi_, mo) > 0.0 else 1.0
        mmin = dr.minimum(mi_, mo)
        if isinstance(self.fast, _CellG) and self.fast.whole:  # (every cosine > 0 in the cells)
            if not self.fast.bad:
                return self.fast(mi_, mo) if _jit() or mmin > 0.0 else 1.0
            slow = self.fast.in_bad(mi_, mo) & (mmin > 0.0)
        else:
            slow = (mmin <= self.fast.mlo) & (mmin > 0.0)
            if isinstance(self.fast, _CellG) and self.fast.bad:  # (and where a cell's quartics miss)
                slow = slow | (self.fast.in_bad(mi_, mo) & (mmin > self.fast.mlo))
        if not _jit():
            return by_levels(mi_, mo) if (slow or mmin <= 0.0) else self.fast(mi_, mo)
        # the table's value outside the conditional, so that Dr.Jit shares it between sample() and eval() at the same
        # pair; the conditional runs the level-by-level path only where some lane of a packet needs it
        g = self.fast(mi_, mo)
        return dr.if_stmt((mi_, mo, g), slow, lambda a, b, g: by_levels(a, b), lambda a, b, g: g)

    def f(self, wl, v):
        val = self.kernel(wl, v, *self.args)
        if self.fresnel is not None:  # 000 eq. 28's factor F(Theta_min), before the rounding down below
            val = val * _fresnel_conductor(dr.maximum(wl[2], v[2]), *self.fresnel)
        if self.levels:
            val = _div(val, self.g(wl[2], v[2])) * self.ROUND_DOWN  # 001 eq. 16, all levels
        return dr.select((wl[2] > 0) & (v[2] > 0), val, 0.0)


# ----------------------------------------------------------------------------------------
# Sampling in Dr.Jit (pumpup.sampling's components)
# ----------------------------------------------------------------------------------------


def _frame(a):
    """pumpup.sampling._frame: an orthonormal basis perpendicular to a (Duff et al. 2017)."""
    ax, ay, az = a
    sign = dr.select(az >= 0.0, 1.0, -1.0)
    c = -dr.rcp(sign + az)
    b = ax * ay * c
    return (1.0 + sign * ax * ax * c, sign * b, -sign * ax), (b, sign + ay * ay * c, -ay)


def _comp_sample(kind, k, v, u1, u2):
    """One component of pumpup.sampling._sample_kernel: (wi (x, y, z), ok)."""
    C = _sampling
    sp, cp = dr.sincos(mi.Float(u2) * _TWO_PI_F32)  # in float32 (u2 is one): a direction's last bits are float32's
    sp, cp = _f64(sp), _f64(cp)
    if kind == C.COSINE:
        r = dr.sqrt(u1)
        z = dr.sqrt(dr.maximum(1.0 - u1, 0.0))
        return (r * cp, r * sp, z), z > 0.0
    if kind in (C.MIRROR, C.RETRO):
        t = _div(dr.log(u1), k + 1.0)
        ca = dr.exp(t)  # 000 eq. 20
        sa = dr.sqrt(dr.maximum((1.0 - ca) * (1.0 + ca), 0.0))
        e1, e2 = _frame(v)
        r = tuple(ca * v[i] + sa * (cp * e1[i] + sp * e2[i]) for i in range(3))  # 000 eq. 22
        ok = (r[2] > 0.0) & (u1 > 0.0)
        if kind == C.MIRROR:
            r = (-r[0], -r[1], r[2])  # L = 2 (N.R) N - R (000 after eq. 22)
        return r, ok
    if kind == C.HALF_POWER:
        t = _div(dr.log(u1), k + 1.0)
        ch = dr.exp(t)
        sh = dr.sqrt(dr.maximum((1.0 - ch) * (1.0 + ch), 0.0))
    else:
        if kind == C.HALF_BECKMANN:
            t2 = -k * k * dr.log(dr.maximum(1.0 - u1, 1e-300))  # tan^2 = -m^2 ln(1 - u)
        else:
            t2 = _div(k * u1, dr.maximum(1.0 - u1, 1e-300))  # tan^2 = r u / (1 - u)
        ch = dr.rsqrt(1.0 + t2)
        sh = dr.sqrt(t2) * ch
    h = (sh * cp, sh * sp, ch)
    d = _dot(v, h)
    w = (2.0 * d * h[0] - v[0], 2.0 * d * h[1] - v[1], 2.0 * d * h[2] - v[2])
    return w, (d > 0.0) & (w[2] > 0.0) & (u1 > 0.0)


def _comp_pdf(kind, k, wl, v):
    """pumpup.sampling._pdf_kernel: density [1/sr] of wi = wl given wo = v for one component."""
    C = _sampling
    if kind == C.COSINE:
        p = wl[2] * _INV_PI
    elif kind in (C.MIRROR, C.RETRO):
        rx, ry = (-wl[0], -wl[1]) if kind == C.MIRROR else (wl[0], wl[1])
        dx, dy, dz = rx - v[0], ry - v[1], wl[2] - v[2]
        h = 0.5 * (dx * dx + dy * dy + dz * dz)  # 1 - R.V without cancellation (and as pumpup.sampling for float32
        # directions a few 1e-8 off unit length, where R.V itself differs from it by that much)
        p = dr.select(h < 1.0, (k + 1.0) * _INV_2PI * _pow_pos(1.0 - h, k), 0.0)
    else:  # p(h) / (4 wo.h) in S = wi + wo, as in _dr_microfacet (|S| = 2 wo.h, cos theta_h = S_z / |S|)
        sx, sy, sz = wl[0] + v[0], wl[1] + v[1], wl[2] + v[2]
        sxy2, sz2 = sx * sx + sy * sy, sz * sz
        n2 = sxy2 + sz2
        if kind == C.HALF_POWER:
            n = dr.sqrt(n2)
            ph = (k + 1.0) * _INV_2PI * _pow_pos(_div(sz, n), k) if k > 0 else _INV_2PI + 0.0 * n
            p = _div(ph, 2.0 * n)
        elif kind == C.HALF_BECKMANN:
            r = dr.rcp(sz2)
            # exp(-tan^2 / k^2) / (pi k^2 ch^3) / (2 |S|)
            p = _div(dr.exp(-(sxy2 * r) / (k * k)) * n2 * r, (2.0 * math.pi * k * k) * sz)
        else:
            q = k * sz2 + sxy2
            p = _div(k * n2 * sz, (2.0 * math.pi) * (q * q))  # k / (pi ch^3 (k + tan^2)^2) / (2|S|)
        p = dr.select(n2 > 0.0, p, 0.0)
    return dr.select((wl[2] > 0.0) & (v[2] > 0.0), p, 0.0)


def _mixture_pdf(components, wl, v):
    out = 0.0
    for w, kind, k in components:
        out = out + w * _comp_pdf(kind, k, wl, v)
    return out


# ----------------------------------------------------------------------------------------
# The plugin
# ----------------------------------------------------------------------------------------


def _spec_from_props(props) -> Any:
    keys = list(props.keys())
    if "spec" in keys:
        extra = [k for k in keys if k != "spec"]
        if extra:
            raise SpecError(f"pumpup plugin: give either 'spec' or 'model' with flat parameters, not 'spec' and "
                            f"{', '.join(map(repr, extra))}")
        s = props["spec"]
        if not isinstance(s, str):
            raise SpecError(f"pumpup plugin: 'spec' must be a JSON string (use pumpup.mitsuba.bsdf_dict), got "
                            f"{type(s).__name__}")
        s = s.strip()
        if s.startswith("{") or s.startswith("["):
            try:
                return json.loads(s)
            except json.JSONDecodeError as exc:
                raise SpecError(f"pumpup plugin: 'spec' is not valid JSON: {exc}") from None
        from .core import parse_spec

        return parse_spec(s)  # the short form, phong:n=20
    if "model" in keys:
        spec = {"type": props["model"]}
        for k in keys:
            if k != "model":
                spec[k] = props[k]
        return spec
    raise SpecError("pumpup plugin: needs a 'spec' (a JSON string of a pumpup spec) or a 'model' with flat parameters")


_CLASSES: dict[str, type] = {}


def _plugin_class():
    """The BSDF class for the current variant (mi.BSDF exists only once a variant is set)."""
    variant = mi.variant()
    if variant in _CLASSES:
        return _CLASSES[variant]

    class PumpupBSDF(mi.BSDF):
        """A pumpup BRDF as a Mitsuba BSDF (see the pumpup.mitsuba docstring)."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            spec = _spec_from_props(props)
            if isinstance(spec, list):
                if len(spec) != 3 or not mi.is_rgb:
                    raise SpecError("pumpup plugin: a list spec needs 3 entries (R, G, B) and an rgb variant, got "
                                    f"{len(spec)} in {mi.variant()}")
                self.brdfs = [load(s) for s in spec]
            else:
                self.brdfs = [load(spec)]
            self.models = [_DrModel(b) for b in self.brdfs]
            self.components = self.models[len(self.models) // 2].components  # sample with the middle (green) one
            inner = self.models[0].base.type
            lobe = mi.BSDFFlags.DiffuseReflection if (inner == "lambert" and not self.models[0].levels) \
                else mi.BSDFFlags.GlossyReflection
            self.m_flags = lobe | mi.BSDFFlags.FrontSide
            self.m_components = [self.m_flags]
            self.spec = spec

        # wl: pumpup's wi (Mitsuba's wo, towards the light); v: pumpup's wo (Mitsuba's si.wi)
        def _values(self, wl, v):
            vals = [m.f(wl, v) for m in self.models]
            return vals

        def _color(self, vals, cos):
            if len(vals) == 1:
                return mi.Spectrum(mi.Float(vals[0] * cos))
            return mi.Color3f(*(mi.Float(x * cos) for x in vals))

        @staticmethod
        def _dirs(si_wi, wo):
            v = (_f64(si_wi.x), _f64(si_wi.y), _f64(si_wi.z))
            wl = (_f64(wo.x), _f64(wo.y), _f64(wo.z))
            return wl, v

        def eval(self, ctx, si, wo, active=True):
            wl, v = self._dirs(si.wi, wo)
            up = (wl[2] > 0) & (v[2] > 0)
            vals = [dr.select(up, x, 0.0) for x in self._values(wl, v)]
            out = self._color(vals, dr.maximum(wl[2], 0.0))  # Mitsuba's eval includes cos(theta_o)
            if not ctx.is_enabled(mi.BSDFFlags.GlossyReflection) and not ctx.is_enabled(mi.BSDFFlags.DiffuseReflection):
                return mi.Spectrum(0.0)
            return dr.select(active, out, 0.0) if _jit() else (out if active else mi.Spectrum(0.0))

        def pdf(self, ctx, si, wo, active=True):
            wl, v = self._dirs(si.wi, wo)
            p = mi.Float(_mixture_pdf(self.components, wl, v))
            return dr.select(active, p, 0.0) if _jit() else (p if active else 0.0)

        def eval_pdf(self, ctx, si, wo, active=True):
            return self.eval(ctx, si, wo, active), self.pdf(ctx, si, wo, active)

        def sample(self, ctx, si, sample1, sample2, active=True):
            v = (_f64(si.wi.x), _f64(si.wi.y), _f64(si.wi.z))
            u0, u1, u2 = _f64(sample1), _f64(sample2.x), _f64(sample2.y)
            wx, wy, wz, ok = 0.0, 0.0, 0.0, False
            acc = 0.0
            for idx, (w, kind, k) in enumerate(self.components):
                d, good = _comp_sample(kind, k, v, u1, u2)
                last = idx == len(self.components) - 1
                pick = (u0 >= acc) if last else ((u0 >= acc) & (u0 < acc + w))
                acc += w
                if _jit():
                    wx, wy, wz = dr.select(pick, d[0], wx), dr.select(pick, d[1], wy), dr.select(pick, d[2], wz)
                    ok = dr.select(pick, good, ok)
                elif pick:
                    wx, wy, wz, ok = d[0], d[1], d[2], good
            ok = ok & (v[2] > 0.0)
            bs = dr.zeros(mi.BSDFSample3f)
            wo = mi.Vector3f(mi.Float(wx), mi.Float(wy), mi.Float(wz))
            if _jit():
                wo = dr.select(ok, dr.normalize(wo), mi.Vector3f(0.0, 0.0, 1.0))
            else:
                wo = dr.normalize(wo) if ok else mi.Vector3f(0.0, 0.0, 1.0)
            wl = (_f64(wo.x), _f64(wo.y), _f64(wo.z))
            ok = ok & (wl[2] > 0.0)
            p = _mixture_pdf(self.components, wl, v)
            ok = ok & (p > 0.0)
            vals = self._values(wl, v)
            weight = self._color([dr.select(ok, _div(x, dr.maximum(p, 1e-300)), 0.0) for x in vals], wl[2])
            bs.wo = wo
            bs.pdf = mi.Float(dr.select(ok, p, 0.0))
            bs.eta = 1.0
            bs.sampled_type = mi.UInt32(+self.m_flags & ~int(mi.BSDFFlags.FrontSide))
            bs.sampled_component = mi.UInt32(0)
            if _jit():
                keep = active & ok
                return bs, dr.select(keep, weight, 0.0)
            return bs, (weight if (active and ok) else mi.Spectrum(0.0))

        def to_string(self):
            return f"PumpupBSDF[spec = {json.dumps(self.spec)}]"

        def traverse(self, callback):
            pass

    _CLASSES[variant] = PumpupBSDF
    return PumpupBSDF


def register(variant: str | None = None) -> str:
    """Set a usable Mitsuba variant and register the BSDF plugin ``"pumpup"`` for it.

    Parameters
    ----------
    variant : str or None
        The variant to use; None keeps the one already set (``mi.variant()``), or prefers
        ``llvm_ad_rgb``.  A JIT variant is probed in a subprocess first (:func:`probe`); if it
        would abort, ``scalar_rgb`` is used and one line on stderr says so.

    Returns
    -------
    str
        The variant in use.
    """
    if variant is None:
        variant = mi.variant() or DEFAULT_VARIANT
    if variant not in mi.variants():
        raise ValueError(f"variant must be one of {', '.join(mi.variants())}; got {variant!r}")
    if not variant.startswith("scalar"):
        ok, _ = probe(variant)
        if not ok:
            variant = choose_variant(variant)
    mi.set_variant(variant)
    cls = _plugin_class()
    mi.register_bsdf("pumpup", lambda props: cls(props))
    return variant


def bsdf_dict(spec: Any) -> dict:
    """``{"type": "pumpup", "spec": "<JSON>"}`` for ``mi.load_dict`` (spec: a dict, a BRDF, a list of
    three per-channel specs, or a string).
    """
    if isinstance(spec, BRDF):
        spec = spec.spec
    if isinstance(spec, list):
        spec = [s.spec if isinstance(s, BRDF) else s for s in spec]
    if isinstance(spec, (dict, list)):
        return {"type": "pumpup", "spec": json.dumps(spec)}
    if isinstance(spec, str):
        return {"type": "pumpup", "spec": spec}
    raise TypeError(f"spec must be a dict, a list of specs, a JSON or short string or a pumpup BRDF, got "
                    f"{type(spec).__name__}")


def _convert(d):
    if isinstance(d, dict):
        if d.get("type") == "pumpup" and isinstance(d.get("spec"), (dict, list, BRDF)):
            out = bsdf_dict(d["spec"])
            out.update({k: v for k, v in d.items() if k not in ("type", "spec")})
            return out
        return {k: _convert(v) for k, v in d.items()}
    return d


def load_dict(scene: dict):
    """``mi.load_dict`` after turning every ``{"type": "pumpup", "spec": {...}}`` into JSON (:func:`bsdf_dict`)."""
    return mi.load_dict(_convert(scene))


# ----------------------------------------------------------------------------------------
# Mitsuba's BSDFs as pumpup BRDFs
# ----------------------------------------------------------------------------------------


def from_mitsuba(bsdf: Any, channel: int = 0, variant: str | None = None, name: str | None = None) -> BRDF:
    """A Mitsuba BSDF as a pumpup BRDF (front side, the cosine divided out, one channel).

    Parameters
    ----------
    bsdf : dict or mitsuba.BSDF
        A ``mi.load_dict`` dict (e.g. ``{"type": "roughconductor", "alpha": 0.2}``) or a loaded BSDF.
    channel : int, in [0, channels)
        Which channel of Mitsuba's spectrum to return (R, G, B = 0, 1, 2 in rgb variants).
    variant : str or None
        As :func:`register` (None keeps the current variant, or prefers a probed ``llvm_ad_rgb``); rgb or
        mono variants only.
    name : str, optional
        The BRDF's name (default: the dict's type).

    Returns
    -------
    BRDF
        f_r(wi, wo) = eval(si.wi = wo, wo = wi)[channel] / N.wi in 1/sr, 0 below the horizon;
        Mitsuba evaluates in float32 (relative rounding about 1e-7 per value).
    """
    variant = register(variant)
    if mi.is_spectral:
        raise ValueError(f"from_mitsuba needs an rgb or mono variant (channel = an RGB channel), got {variant}; "
                         "a chosen wavelength of a spectral variant is not supported")
    if isinstance(bsdf, dict):
        label = name or f"mitsuba {json.dumps(bsdf, sort_keys=True, default=str)} channel {channel}"
        obj = mi.load_dict(_convert(bsdf))
    else:
        label = name or f"mitsuba {obj} channel {channel}"
        obj = bsdf
    if isinstance(channel, bool) or not isinstance(channel, (int, np.integer)):
        raise TypeError(f"channel must be an integer, got {channel!r}")
    nch = 3 if mi.is_rgb else 1
    if not 0 <= channel < nch:
        raise ValueError(f"channel must be in [0, {nch}) for variant {variant}, got {channel}")
    ctx = mi.BSDFContext()
    jit = _jit()

    def fn(wi, wo):
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        a = np.broadcast_to(wi, shape + (3,)).reshape(-1, 3)
        b = np.broadcast_to(wo, shape + (3,)).reshape(-1, 3)
        up = (a[:, 2] > 0) & (b[:, 2] > 0)
        out = np.zeros(a.shape[0])
        idx = np.nonzero(up)[0]
        if idx.size:
            if jit:
                si = dr.zeros(mi.SurfaceInteraction3f, idx.size)
                si.wi = mi.Vector3f(*(mi.Float(b[idx, i].astype(np.float32)) for i in range(3)))
                w = mi.Vector3f(*(mi.Float(a[idx, i].astype(np.float32)) for i in range(3)))
                val = np.asarray(obj.eval(ctx, si, w)[channel] if nch > 1 else obj.eval(ctx, si, w)[0],
                                 dtype=np.float64)
                cos = a[idx, 2].astype(np.float32).astype(np.float64)
                out[idx] = val / cos
            else:
                si = mi.SurfaceInteraction3f()
                for j in idx:
                    si.wi = mi.Vector3f(*b[j])
                    w = mi.Vector3f(*a[j])
                    out[j] = float(obj.eval(ctx, si, w)[channel]) / float(np.float32(a[j, 2]))
        return out.reshape(shape)

    return from_function(fn, name=label)
