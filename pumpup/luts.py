"""Renderer look-up tables of the directional albedo E(mu, alpha), in the renderers' own conventions.

Production renderers ship a small table of the albedo of their microfacet model, made by
Monte Carlo and read by bilinear interpolation.  :func:`lut` makes such a table exactly (every
node by pumpup's deterministic quadrature, with its error), in a renderer's axes, layout,
clamping and storage, and measures three errors: the quadrature error at the nodes, the
quantisation error of the storage format, and the error of the renderer's own look-up (its
bilinear interpolation at its coordinates, clamping included) against the true E between the
nodes.  :func:`audit` reads a shipped table and grades it against pumpup's truth.

Definitions: E(mu) = integral of f_r cos(theta_o) d omega_o (000 eq. 2) with F = 1;
E_avg = 2 integral_0^1 E(mu) mu dmu (000 eq. 33); the split-sum pair (Karis 2013, Filament's
DFG) A = integral (1 - Fc) f_r cos d omega_o and B = integral Fc f_r cos d omega_o with
Fc = (1 - wi.h)^5 (Schlick), so that E = A + B for F0 = 1 and a Schlick-Fresnel albedo is
F0 A + B.

The presets are one data table, :data:`PRESETS`; what each renderer's convention is, and how
it was established, is in the entry's ``source``.  The roughness r of every preset is the
renderer's "perceptual" roughness, alpha = r^2.

This module is over 1,000 lines because the renderer presets, the writers of each table format and the audit of
shipped tables share one description of a table's axes and conventions.
"""

from __future__ import annotations

import json
import os
import re
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .core import BRDF, SpecError, load
from .core.budget import time_budget

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["PRESETS", "Preset", "LutError", "lut", "audit", "read_table", "write_lut", "lookup", "AuditResult", "grade"]


class LutError(ValueError):
    """A table that cannot be read, has the wrong size, or fails a requested tolerance."""


# --------------------------------------------------------------------------------------------
# The presets: one row per renderer
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Preset:
    """A renderer's table convention.

    Axes (index i = 0 .. n-1; "rows" are mu unless ``layout`` says otherwise):

    * ``"node"``: u = i / (n - 1) (nodes on the ends; Cycles, appleseed);
    * ``"square"``: u = (i / (n - 1))^2 (BSDL's mu axis);
    * ``"texel"``: u = (i + 0.5) / n (texel centres; GPU textures, Mitsuba's Texture2f);
    * ``"filament"``: u = min((i + 1.5) / n, 1) for GL row i (what Filament's generator
      computes, one texel above the centre its shader reads; see ``source``).

    The value at a node is computed at max(u, floor); the renderer looks it up at its own
    coordinate (``lookup``: "node" = saturate(x) (n - 1), "square" = sqrt(saturate(x)) (n - 1),
    "texel" = x n - 0.5 clamped to the edge texels), bilinearly.
    """

    name: str
    renderer: str
    n_mu: int
    n_rough: int
    mu_axis: str
    rough_axis: str
    mu_floor: float
    rough_floor: float
    shadowing: str
    storage: str  # "text6" (printf %f of a float), "half", "float32", "float64"
    stores: str  # "E" or "1-E"
    eavg: bool
    split: bool
    fmt: str  # "c", "filament", "npy", "netcdf", "exr"
    names: tuple = ()
    lookup_mu_min: float = 1e-4
    lookup_rough_min: float = 1e-2
    source: str = ""
    #: default quadrature tolerance of the nodes: 1e-8, or 1e-6 for half floats (whose rounding is 2.4e-4)
    rtol: float = 1e-8
    #: which axis the rows of a C array run over ("mu": data[i_mu * n_rough + j]; "rough": data[j * n_mu + i])
    rows: str = "mu"
    #: the renderer defines E = 1 at the nodes with mu = 0 or rough = 0 (appleseed's special cases)
    edge_one: bool = False
    #: E_avg follows E in the same C array (appleseed)
    eavg_in_array: bool = False
    #: values per line of a C array (0: one table row per line)
    per_line: int = 0

    @property
    def mu_lookup(self) -> str:
        """How the renderer reads the mu axis: ``texel`` for a texel-centred axis (Filament's too), else the axis kind
        itself.
        """
        return "texel" if self.mu_axis in ("texel", "filament") else self.mu_axis

    @property
    def rough_lookup(self) -> str:
        """How the renderer reads the roughness axis: ``texel`` for a texel-centred axis (Filament's too), else the axis
        kind itself.
        """
        return "texel" if self.rough_axis in ("texel", "filament") else self.rough_axis


PRESETS: dict[str, Preset] = {p.name: p for p in [
    Preset("cycles", "Blender Cycles", 32, 32, "node", "node", 1e-4, 1e-4, "correlated", "text6", "E", True, False,
           "c", ("table_ggx_E", "table_ggx_Eavg"),
           source="cycles_precompute.cpp (shared/peer-tables): rows y -> mu = clamp(y/31, 1e-4, 1), columns x -> "
                  "rough = clamp(x/31, 1e-4, 1), alpha = rough^2, GGX with Cycles' height-correlated Smith G, F = 1; "
                  "data[y*32 + x] printed by std::to_string (%f of the float) after saturatef; table_ggx_Eavg "
                  "over the same rough axis; verified against the shipped numbers (pumpup.audit)"),
    Preset("filament", "Google Filament", 128, 128, "texel", "filament", 0.0, 0.0, "correlated", "half", "E", False,
           True, "filament", ("DFG_LUT",), lookup_rough_min=0.045, rtol=1e-6,
           source="Filament libs/ibl/src/CubemapIBL.cpp CubemapIBL::DFG with DFV_Multiscatter (cmgen "
                  "--ibl-dfg-multiscatter, as filament/CMakeLists.txt builds dfg.inc): NoV = (x + 0.5)/128, "
                  "coord = saturate((128 - y + 0.5)/128) for image row y, a = coord^2 is GGX alpha, height-"
                  "correlated Smith visibility; cmgen writes rows in GL order (row size-1-y first) as half floats, "
                  "two per texel: (B, E) = (integral Fc V..., integral V...); the shader reads "
                  "textureLod(dfg, vec2(NoV, perceptualRoughness)), so GL row t holds roughness (t + 1.5)/128 "
                  "where it is read at (t + 0.5)/128; lookup_rough_min = Filament's MIN_PERCEPTUAL_ROUGHNESS"),
    Preset("filament-centred", "Google Filament (texel-centred rows)", 128, 128, "texel", "texel", 0.0, 0.0,
           "correlated", "half", "E", False, True, "filament", ("DFG_LUT",), lookup_rough_min=0.045, rtol=1e-6,
           source="as 'filament', with each row computed at the texel centre the shader reads, (t + 0.5)/128"),
    Preset("appleseed", "appleseed", 32, 32, "node", "node", 1e-4, 1e-4, "separable", "text6", "E", True, False,
           "c", ("g_glossy_ggx_albedo_table",), rows="rough", edge_one=True, eavg_in_array=True, per_line=4,
           source="appleseed src/appleseed/renderer/modeling/bsdf/microfacethelper.cpp MDFAlbedoTable and "
                  "energycompensation.cpp AlbedoTable2D: row y -> roughness y/31, alpha = roughness^2, column x -> "
                  "cos_theta x/31, data[y*32 + x], E = 1 where cos_theta = 0 or alpha = 0 (special cases), 512 "
                  "Hammersley samples, min(E, 1); E_avg (appleseed: min(2 sum_i E_i cos_i / 32, 1)) follows in the "
                  "same 1056-float array g_glossy_ggx_albedo_table, printed std::fixed with 6 decimals, 4 per line; "
                  "look-up x = cos_theta 31, y = roughness 31, bilinear; the separable Smith G is not checked "
                  "against appleseed's MDF code"),
    Preset("bsdl", "OSL BSDL", 16, 16, "square", "node", 1e-6, 1e-4, "correlated", "float32", "1-E", False, False,
           "c", ("ggx_one_minus_E",),
           source="16 x 16, mu = (i/15)^2 floored at 1e-6, stores 1 - E (issue 16); roughness floor, Smith G and "
                  "array name not checked against BSDL's source"),
    Preset("mitsuba", "Mitsuba 3", 32, 32, "texel", "texel", 0.0, 0.0, "separable", "float32", "E", True, False,
           "npy", (),
           source="an .npy array of shape (n_rough, n_mu, 2) float32 for mi.Texture2f(mi.TensorXf(...)): u = mu, "
                  "v = rough at texel centres, channel 0 = E, channel 1 = E_avg(rough) repeated along u; G separable "
                  "as Mitsuba's roughconductor"),
    Preset("netcdf", "pumpup", 32, 32, "node", "node", 1e-4, 1e-4, "correlated", "float64", "E", True, True,
           "netcdf", (), source="pumpup's own: CF metadata, every error and convention as attributes"),
    Preset("exr", "OpenEXR", 32, 32, "node", "node", 1e-4, 1e-4, "correlated", "float32", "E", True, True, "exr",
           ("E", "E_avg", "A", "B"),
           source="float32 channels, x = mu node, y = rough node; E_avg repeated along x"),
]}

#: the roughness-like parameter of a model family (alpha = r^2 of the preset's r)
ROUGH_PARAM = {"ggx": "alpha", "beckmann": "alpha", "ward": "m", "modified_ward": "m", "cook_torrance": "m"}

#: worst-case rounding of a value in [0, 1] by each storage (absolute)
STORAGE_BOUND = {"text6": 5e-7 + 2.0 ** -25, "half": 2.0 ** -12, "float32": 2.0 ** -25, "float64": 2.0 ** -54}


def _preset(preset) -> Preset:
    if isinstance(preset, Preset):
        return preset
    if preset not in PRESETS:
        raise SpecError(f"preset must be one of {', '.join(PRESETS)}; got {preset!r}")
    return PRESETS[preset]


def _power(kind: str) -> float:
    """The exponent p of a warped node axis u = (i / (n - 1))^p ("node": 1, "square": 2, "power:p")."""
    if kind == "node":
        return 1.0
    if kind == "square":
        return 2.0
    if kind.startswith("power:"):
        try:
            p = float(kind[6:])
        except ValueError:
            p = float("nan")
        if not (0.1 <= p <= 10):
            raise SpecError(f"axis {kind!r}: the exponent must be a number in [0.1, 10]")
        return p
    raise SpecError(f"unknown axis kind {kind!r}")


def axis_values(kind: str, n: int) -> np.ndarray:
    """The coordinate u of the n nodes of an axis kind (see :class:`Preset`)."""
    i = np.arange(n, dtype=np.float64)
    if kind in ("node", "square") or kind.startswith("power:"):
        return (i / (n - 1)) ** _power(kind)
    if kind == "texel":
        return (i + 0.5) / n
    if kind == "filament":
        return np.minimum((i + 1.5) / n, 1.0)
    raise SpecError(f"unknown axis kind {kind!r}")


def nodes(preset) -> tuple[np.ndarray, np.ndarray]:
    """(mu, rough) at which the preset's nodes are computed (floors applied)."""
    p = _preset(preset)
    mu = np.maximum(axis_values(p.mu_axis, p.n_mu), p.mu_floor)
    rough = np.maximum(axis_values(p.rough_axis, p.n_rough), p.rough_floor)
    return np.minimum(mu, 1.0), np.minimum(rough, 1.0)


def _edge_rule(tr: dict, p: Preset) -> dict:
    """Apply a renderer's definition E = 1 at the mu = 0 and rough = 0 nodes (``edge_one``)."""
    if not p.edge_one:
        return tr
    edge = (axis_values(p.mu_axis, p.n_mu) == 0)[:, None] | (axis_values(p.rough_axis, p.n_rough) == 0)[None, :]
    tr["E"] = np.where(edge, 1.0, tr["E"])
    tr["E_error"] = np.where(edge, 0.0, tr["E_error"])
    for k in ("A", "B"):
        if k in tr:
            tr[k] = np.where(edge, np.nan, tr[k])
    return tr


# --------------------------------------------------------------------------------------------
# The renderer's look-up
# --------------------------------------------------------------------------------------------


def _index(kind: str, x: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i0, i1, t) of a 1-D linear look-up at coordinate x."""
    x = np.asarray(x, dtype=np.float64)
    if kind != "texel":
        s = np.clip(x, 0.0, 1.0)
        p = _power(kind)
        c = (s if p == 1.0 else s ** (1.0 / p)) * (n - 1)  # Cycles lookup_table_read: saturatef(x) (size - 1)
        i0 = np.minimum(np.floor(c).astype(np.int64), n - 1)
        t = c - i0
    else:
        c = np.clip(x * n - 0.5, 0.0, n - 1.0)  # bilinear texture filtering, clamp to edge
        i0 = np.minimum(np.floor(c).astype(np.int64), n - 1)
        t = c - i0
    i1 = np.minimum(i0 + 1, n - 1)
    return i0, i1, t


def lookup(table: np.ndarray, mu, rough, preset) -> np.ndarray:
    """The renderer's bilinear look-up of ``table`` (shape (n_mu, n_rough), values of E) at (mu, rough).

    The coordinates broadcast; each axis is mapped by the preset's look-up kind and clamped
    as the renderer clamps (see :class:`Preset`).
    """
    p = _preset(preset)
    table = np.asarray(table, dtype=np.float64)
    mu, rough = np.broadcast_arrays(np.asarray(mu, float), np.asarray(rough, float))
    a0, a1, s = _index(p.mu_lookup, mu, table.shape[0])
    b0, b1, t = _index(p.rough_lookup, rough, table.shape[1])
    return ((1 - s) * ((1 - t) * table[a0, b0] + t * table[a0, b1])
            + s * ((1 - t) * table[a1, b0] + t * table[a1, b1]))


# --------------------------------------------------------------------------------------------
# Truth: E, E_avg and the split-sum pair by pumpup's quadrature
# --------------------------------------------------------------------------------------------


class _SchlickWeighted(BRDF):
    """f_r (1 - wi.h)^5: the Fc-weighted lobe of the split sum (not registered; same Lobe hint)."""

    type = "schlick_fc_weighted"
    params: dict = {}
    constant = None

    def __init__(self, base: BRDF) -> None:  # noqa: D107 - bypasses the registry's parameter parsing
        self.base = base
        self.p = {}
        self.reciprocal = base.reciprocal

    @property
    def spec(self) -> dict:
        return {"type": self.type, "base": self.base.spec}

    def _eval(self, wi, wo):
        f = self.base._eval(wi, wo)
        s = wi + wo
        c = 0.5 * np.sqrt(np.sum(s * s, axis=-1))  # wi.h = |wi + wo| / 2
        return f * np.clip(1.0 - c, 0.0, 1.0) ** 5  # Schlick's Fc (Karis 2013; Filament DFV_Multiscatter)

    def lobe(self, mu):
        return self.base.lobe(mu)

    def azimuth_hint(self):
        """The base's Smith hint with Schlick's Fc as its Fresnel factor at wi.h (the 1-D half-vector route), where the
        base is a Smith model with F = 1; else None (the nested quadrature of :meth:`_eval`).
        """
        from dataclasses import replace

        from .core.hints import Fresnel, SmithLobe

        hint = self.base.azimuth_hint()
        if hint is None or hint.factors or not isinstance(hint.family, SmithLobe) or hint.family.fresnel is not None:
            return None
        return replace(hint, family=replace(hint.family, fresnel=Fresnel(schlick=0.0)))  # Fc = (1 - wi.h)^5


class _NestedSchlickWeighted(_SchlickWeighted):
    """:class:`_SchlickWeighted` without its hint: B by the nested quadrature of ``eval`` alone (the independent second
    route of the tests, and the baseline of scripts/bench/bench_lut.py).
    """

    def azimuth_hint(self):
        return None


def model_spec(model, preset=None) -> tuple[dict, str]:
    """(base spec without the roughness parameter, name of that parameter) for a model argument."""
    if isinstance(model, BRDF):
        spec = dict(model.spec)
    elif isinstance(model, dict):
        spec = dict(model)
    elif isinstance(model, str):
        from .core import parse_spec

        spec = parse_spec(model)
    else:
        raise TypeError(f"model must be a name, a spec dict or a BRDF, got {type(model).__name__}")
    kind = spec.get("type")
    if kind not in ROUGH_PARAM:
        raise SpecError(f"model {kind!r} has no roughness-like parameter pumpup knows; lut supports "
                        f"{', '.join(ROUGH_PARAM)}")
    param = ROUGH_PARAM[kind]
    if param in spec and not isinstance(model, BRDF):  # (a BRDF always carries it: its value is replaced alike)
        raise SpecError(f"the table's axis sets {kind}'s {param!r} (alpha = rough^2 at every node); remove "
                        f"{param}={spec[param]!r} from the model")
    spec.pop(param, None)
    if preset is not None and kind in ("ggx", "beckmann") and "shadowing" not in spec:
        spec["shadowing"] = _preset(preset).shadowing
    load({**spec, param: 0.5})  # validate now, before long work
    return spec, param


def _brdf(spec: dict, param: str, rough: float) -> BRDF:
    return load({**spec, param: float(rough) ** 2})  # alpha = r^2 (every preset)


def _albedo(f: BRDF, mu, rtol: float, max_regions: int, atol: float = 1e-14):
    from .engine.cubature import AlbedoWarning, albedo

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AlbedoWarning)  # the error estimate says it; counted by the caller
        return albedo(f, mu, return_error=True, rtol=rtol, atol=atol, max_regions=max_regions)


def _map_columns(fn, n: int, threads: int | None):
    """[fn(j) for j in range(n)] on threads (the compiled kernels release the GIL); fn(0) first, alone."""
    from .tables import THREADS, _cores

    threads = max(1, min(threads or THREADS or _cores(), n))
    out = [None] * n
    out[0] = fn(0)  # compiles whatever the kernels still need on this thread
    if threads == 1:
        for j in range(1, n):
            out[j] = fn(j)
        return out
    import contextvars
    from concurrent.futures import ThreadPoolExecutor

    from .core import budget

    def column(j):  # (in a copy of the caller's context: its route choice and time budget hold on the threads)
        budget.check(f"computing column {j} of {n}")
        return fn(j)

    context = contextvars.copy_context()
    with ThreadPoolExecutor(threads) as pool:
        for j, r in zip(range(1, n), pool.map(lambda j: context.copy().run(column, j), range(1, n))):
            out[j] = r
    return out


def truth_grid(spec: dict, param: str, mu, rough, *, rtol: float = 1e-8, split: bool = False,
               max_regions: int = 200, threads: int | None = None, _weighted=_SchlickWeighted) -> dict:
    """E (and with ``split`` A, B) on the product grid mu x rough, each with its error estimate.

    Returns a dict of arrays of shape (len(mu), len(rough)): ``E``, ``E_error`` (and ``A``,
    ``B``, ``A_error``, ``B_error``), plus ``over_tolerance``: the number of nodes whose
    error estimate exceeds rtol * E (the engine stopped at ``max_regions``; their estimate is
    still an honest bound, only larger).  B of a Smith model with F = 1 takes the engine's 1-D routes, with Schlick's Fc
    as the Fresnel factor at wi.h (:class:`_SchlickWeighted`); of other models, the nested quadrature.
    """
    mu = np.asarray(mu, dtype=np.float64)
    rough = np.asarray(rough, dtype=np.float64)

    def column(j):
        f = _brdf(spec, param, rough[j])
        e, ee = _albedo(f, mu, rtol, max_regions)
        if not split:
            return e, ee
        # B is small where Fc is (near normal incidence): its tolerance is relative to E, not to B
        b, be = _albedo(_weighted(f), mu, rtol, max_regions, atol=rtol * float(np.min(e)))
        return e, ee, b, be

    cols = _map_columns(column, len(rough), threads)
    out = {"E": np.stack([c[0] for c in cols], axis=1), "E_error": np.stack([c[1] for c in cols], axis=1)}
    if split:
        out["B"] = np.stack([c[2] for c in cols], axis=1)
        out["B_error"] = np.stack([c[3] for c in cols], axis=1)
        out["A"] = out["E"] - out["B"]
        out["A_error"] = out["E_error"] + out["B_error"]
    out["over_tolerance"] = int(np.count_nonzero(out["E_error"] > rtol * np.abs(out["E"]) + 1e-14))
    return out


def mean_albedo_grid(spec: dict, param: str, rough, *, rtol: float = 1e-8, max_regions: int = 200,
                     threads: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """E_avg(rough) = 2 integral_0^1 E(mu) mu dmu (000 eq. 33), with its error, for each rough.

    Adaptive Gauss-Kronrod (7/15) over tau with mu = tau^2 (3 - 2 tau) (as
    :func:`pumpup.mean_albedo`), starting from 6 panels graded towards grazing; the error adds
    |K - G| and the propagated albedo errors.
    """
    from .engine.cubature import NODES, WG, WK

    rough = np.asarray(rough, dtype=np.float64)

    def one(j):
        f = _brdf(spec, param, rough[j])
        edges = np.array([0.0, 1 / 32, 1 / 8, 1 / 4, 1 / 2, 3 / 4, 1.0])  # graded towards grazing
        a, b = edges[:-1], edges[1:]
        total = 0.0
        err = 0.0
        est = None
        for _ in range(12):
            tau = a[:, None] + (b - a)[:, None] * NODES[None, :]
            m = tau * tau * (3 - 2 * tau)
            w = 6 * tau * (1 - tau) * (b - a)[:, None]
            v, e = _albedo(f, np.maximum(m, 1e-300).ravel(), rtol / 2, max_regions)
            v = v.reshape(m.shape)
            e = e.reshape(m.shape)
            fv = 2 * v * m * w
            k = fv @ WK
            g = np.abs(k - fv @ WG)
            pe = (2 * e * m * w) @ WK
            if est is None:
                est = max(float(np.abs(k).sum()), 1e-3)  # the whole integral, for the panels' share of rtol
            good = g <= rtol * est * (b - a)
            total += float(k[good].sum())
            err += float(g[good].sum() + pe[good].sum())
            if good.all():
                break
            mid = 0.5 * (a[~good] + b[~good])
            a, b = np.concatenate([a[~good], mid]), np.concatenate([mid, b[~good]])
        else:
            total += float(k[~good].sum())
            err += float(g[~good].sum() + pe[~good].sum())
        return total, err

    res = _map_columns(one, len(rough), threads)
    return np.array([r[0] for r in res]), np.array([r[1] for r in res])


# --------------------------------------------------------------------------------------------
# Storage
# --------------------------------------------------------------------------------------------


def quantise(values, storage: str) -> np.ndarray:
    """The value a renderer reads back after storing ``values`` in ``storage`` (as float64)."""
    v = np.asarray(values, dtype=np.float64)
    if storage == "text6":
        f = np.clip(v, 0.0, 1.0).astype(np.float32)  # saturatef, then std::to_string (printf "%f")
        return np.array([float(np.float32(float(f"{float(x):f}"))) for x in f.ravel()]).reshape(v.shape)
    if storage == "half":
        return v.astype(np.float32).astype(np.float16).astype(np.float64)
    if storage == "float32":
        return v.astype(np.float32).astype(np.float64)
    if storage == "float64":
        return v.copy()
    raise SpecError(f"unknown storage {storage!r}")


# --------------------------------------------------------------------------------------------
# Look-up error against the truth between the nodes
# --------------------------------------------------------------------------------------------


def _dense_axis(kind: str, n: int, lo: float, per_cell: int, stride: int) -> np.ndarray:
    """Physical coordinates between the look-up nodes: per_cell points per cell (every
    ``stride``-th cell), plus the domain ends (the clamped regions).
    """
    if kind == "texel":
        c = np.arange(0, n - 1, stride)[:, None] + (np.arange(per_cell) + 0.5)[None, :] / per_cell
        u = (c.ravel() + 0.5) / n
    else:
        c = (np.arange(0, n - 1, stride)[:, None] + (np.arange(per_cell) + 0.5)[None, :] / per_cell).ravel() / (n - 1)
        u = c ** _power(kind)
    u = np.concatenate([[lo], u, [1.0]])
    return np.unique(np.clip(u, lo, 1.0))


def lookup_error(table, spec: dict, param: str, preset, *, per_cell: int = 1, stride: int = 1,
                 rtol: float = 1e-7, refine: int = 3, threads: int | None = None, max_regions: int = 200) -> dict:
    """Error of the renderer's look-up of ``table`` against the true E between the nodes.

    The truth is computed on a dense grid (``per_cell`` points per cell and axis, cell
    centres for 1, every ``stride``-th cell, plus the ends of the domain
    [lookup_mu_min, 1] x [lookup_rough_min, 1]); from the ``refine`` worst points a bounded
    Nelder-Mead search maximises |look-up - E| within the surrounding cells.

    Returns a dict: ``max_abs`` and ``where`` (mu, rough) over everything evaluated,
    ``grid_max_abs`` / ``grid_where`` on the dense grid, ``rms`` on the grid, ``points``,
    ``truth_error`` (largest quadrature error of the truth values used), and ``grid`` (mu, rough,
    error array) for maps and tests.
    """
    p = _preset(preset)
    table = np.asarray(table, dtype=np.float64)
    n_mu, n_r = table.shape
    mu = _dense_axis(p.mu_lookup, n_mu, p.lookup_mu_min, per_cell, stride)
    rough = _dense_axis(p.rough_lookup, n_r, p.lookup_rough_min, per_cell, stride)
    return lookup_error_on(lambda m, r: lookup(table, m, r, p), spec, param, mu, rough, rtol=rtol, refine=refine,
                           threads=threads, max_regions=max_regions)


def lookup_error_on(look, spec: dict, param: str, mu: np.ndarray, rough: np.ndarray, *, rtol: float = 1e-7,
                    refine: int = 3, threads: int | None = None, max_regions: int = 200) -> dict:
    """:func:`lookup_error` for any look-up ``look(mu, rough)`` (broadcasting) on the dense axes ``mu`` x ``rough``
    (the model parameter is rough^2), refined around the ``refine`` worst points.
    """
    tr = truth_grid(spec, param, mu, rough, rtol=rtol, threads=threads, max_regions=max_regions)
    err = look(mu[:, None], rough[None, :]) - tr["E"]
    i, j = np.unravel_index(np.argmax(np.abs(err)), err.shape)
    out = {"grid_max_abs": float(abs(err[i, j])), "grid_where": (float(mu[i]), float(rough[j])),
           "rms": float(np.sqrt(np.mean(err ** 2))), "points": int(err.size),
           "truth_error": float(tr["E_error"].max()), "grid": (mu, rough, err)}
    best, where = out["grid_max_abs"], out["grid_where"]
    if refine:
        from scipy.optimize import minimize

        order = np.argsort(np.abs(err), axis=None)[::-1][:refine]
        for flat in order:
            a, b = np.unravel_index(flat, err.shape)
            lo = np.array([mu[max(a - 1, 0)], rough[max(b - 1, 0)]])
            hi = np.array([mu[min(a + 1, len(mu) - 1)], rough[min(b + 1, len(rough) - 1)]])
            truth_err = [0.0]

            def neg(x):
                m, r = np.clip(x, lo, hi)
                v, e = _albedo(_brdf(spec, param, r), m, rtol, max_regions)
                truth_err[0] = max(truth_err[0], float(e))
                return -abs(float(look(m, r)) - float(v))

            res = minimize(neg, np.array([mu[a], rough[b]]), method="Nelder-Mead", bounds=list(zip(lo, hi)),
                           options={"maxfev": 60, "xatol": 1e-6, "fatol": 1e-10})
            out["truth_error"] = max(out["truth_error"], truth_err[0])
            if -res.fun > best:
                best = float(-res.fun)
                where = tuple(float(x) for x in np.clip(res.x, lo, hi))
    out["max_abs"] = best
    out["where"] = where
    return out


# --------------------------------------------------------------------------------------------
# lut: make a table
# --------------------------------------------------------------------------------------------


def lut(model: str | dict | BRDF = "ggx", preset: str = "cycles", *, rtol: float | None = None,
        eavg: bool | None = None, split: bool | None = None, lookup_check: bool = True, per_cell: int | None = None,
        stride: int | None = None, max_lookup_error: float | None = None, threads: int | None = None,
        max_regions: int = 200, max_seconds: float | None = None) -> xr.Dataset:
    """A renderer's albedo table of ``model``, computed exactly, with its errors.

    Parameters
    ----------
    model : str, dict or BRDF
        ``"ggx"``, ``"beckmann"``, a spec (``"ggx:shadowing=separable"``, ``{"type": "ward"}``)
        of a model with a roughness-like parameter (:data:`ROUGH_PARAM`); that parameter is set
        to r^2 at every node.  GGX and Beckmann get the preset's Smith shadowing unless the
        spec gives one.
    preset : str
        A key of :data:`PRESETS` (cycles, filament, filament-centred, appleseed, bsdl, mitsuba,
        netcdf, exr).
    rtol : float, optional
        Relative tolerance of every node (and of E_avg); default the preset's (1e-8; 1e-6 for
        half-float tables, whose storage rounds by up to 2.4e-4).
    eavg, split : bool, optional
        Compute E_avg(rough) / the split-sum pair A, B (default: what the preset stores).
    lookup_check : bool
        Measure the look-up error between the nodes (:func:`lookup_error`).
    per_cell, stride : int, optional
        Density of the look-up check (default 1 point per cell, every cell; every 4th cell
        for tables over 64 a side).
    max_lookup_error : float, optional
        Raise :class:`LutError`, saying where, if the measured look-up error exceeds this.
    threads : int, optional
        Threads for the columns (default: one per core).
    max_seconds : float, optional
        A time budget: past it, the work stops with :class:`pumpup.core.budget.BudgetExceeded` (a TimeoutError)
        instead of running on.  None: no bound.

    Returns
    -------
    xarray.Dataset
        ``E`` (mu, rough) with ``E_error`` and ``E_stored`` (what the format holds, as E),
        ``E_avg`` / ``E_avg_error`` (rough), ``A``, ``B`` (with errors) where computed;
        coordinates ``mu``, ``rough`` (where each node was computed) and ``alpha``; attributes
        with the preset, the model spec, ``quadrature_error``, ``quantisation_error`` (measured)
        and ``quantisation_bound``, ``lookup_error`` and where, and every convention.

    Examples
    --------
    >>> import pumpup
    >>> ds = pumpup.lut("ggx", preset="bsdl", lookup_check=False)
    >>> ds["E"].shape
    (16, 16)
    """
    if max_seconds is not None:  # (a time budget: past it, pumpup.core.budget.BudgetExceeded, a TimeoutError)
        with time_budget("lut", max_seconds):
            return lut(model, preset, rtol=rtol, eavg=eavg, split=split, lookup_check=lookup_check,
                       per_cell=per_cell, stride=stride, max_lookup_error=max_lookup_error, threads=threads,
                       max_regions=max_regions)
    import xarray as xr

    from ._version import __version__

    p = _preset(preset)
    rtol = p.rtol if rtol is None else rtol
    if not (isinstance(rtol, float | int) and 1e-13 <= rtol <= 1e-2):
        raise SpecError(f"rtol must be in [1e-13, 1e-2], got {rtol!r}")
    if max_lookup_error is not None and not max_lookup_error > 0:
        raise SpecError(f"max_lookup_error must be > 0, got {max_lookup_error!r}")
    spec, param = model_spec(model, p)
    eavg = p.eavg if eavg is None else bool(eavg)
    split = p.split if split is None else bool(split)
    mu, rough = nodes(p)
    tr = _edge_rule(truth_grid(spec, param, mu, rough, rtol=rtol, split=split, threads=threads,
                               max_regions=max_regions), p)
    stored = quantise(tr["E"] if p.stores == "E" else 1.0 - tr["E"], p.storage)
    stored_E = stored if p.stores == "E" else 1.0 - stored
    qerr = float(np.max(np.abs(stored_E - tr["E"])))
    data = {
        "E": (("mu", "rough"), tr["E"], {"long_name": "directional albedo E(mu, alpha) (000 eq. 2), F = 1",
                                          "units": "1"}),
        "E_error": (("mu", "rough"), tr["E_error"], {"long_name": "quadrature error estimate of E", "units": "1"}),
        "E_stored": (("mu", "rough"), stored_E, {"long_name": f"E as the {p.storage} storage holds it", "units": "1"}),
    }
    if split:
        for k, text in (("A", "integral (1 - Fc) f_r cos d omega_o, Fc = (1 - wi.h)^5"),
                        ("B", "integral Fc f_r cos d omega_o (E = A + B)")):
            data[k] = (("mu", "rough"), tr[k], {"long_name": text, "units": "1"})
            data[k + "_error"] = (("mu", "rough"), tr[k + "_error"], {"long_name": f"error estimate of {k}"})
    attrs = {
        "pumpup_kind": "pumpup.lut",
        "preset": p.name,
        "renderer": p.renderer,
        "conventions": p.source,
        "mu_axis": p.mu_axis, "rough_axis": p.rough_axis, "mu_floor": p.mu_floor, "rough_floor": p.rough_floor,
        "alpha": "alpha = rough^2",
        "storage": p.storage, "stores": p.stores,
        "spec": json.dumps(spec), "rough_parameter": param,
        "rtol": float(rtol),
        "quadrature_error": float(tr["E_error"].max()),
        "nodes_over_tolerance": tr["over_tolerance"],
        "quantisation_error": qerr,
        "quantisation_bound": STORAGE_BOUND[p.storage],
        "Conventions": "CF-1.8",
        "pumpup_version": __version__,
    }
    if eavg:
        ea, eae = mean_albedo_grid(spec, param, rough, rtol=rtol, threads=threads, max_regions=max_regions)
        data["E_avg"] = (("rough",), ea, {"long_name": "E_avg = 2 integral E mu dmu (000 eq. 33)", "units": "1"})
        data["E_avg_error"] = (("rough",), eae, {"long_name": "error estimate of E_avg", "units": "1"})
        data["E_avg_stored"] = (("rough",), quantise(ea, p.storage), {"long_name": "E_avg as stored"})
        attrs["E_avg_error"] = float(eae.max())
    ds = xr.Dataset(
        data,
        coords={"mu": ("mu", mu, {"long_name": "cos(theta_i) at which each row was computed", "units": "1"}),
                "rough": ("rough", rough, {"long_name": "perceptual roughness r at which each column was computed",
                                           "units": "1"}),
                "alpha": ("rough", rough ** 2, {"long_name": f"model parameter {param} = r^2", "units": "1"})},
        attrs=attrs,
    )
    if lookup_check:
        big = max(p.n_mu, p.n_rough) > 64
        le = lookup_error(stored_E, spec, param, p, per_cell=per_cell or 1, stride=stride or (4 if big else 1),
                          threads=threads, max_regions=max_regions)
        ds.attrs.update({"lookup_error": le["max_abs"], "lookup_error_mu": le["where"][0],
                         "lookup_error_rough": le["where"][1], "lookup_error_rms": le["rms"],
                         "lookup_points": le["points"], "lookup_truth_error": le["truth_error"],
                         "lookup_domain": f"mu in [{p.lookup_mu_min:g}, 1], rough in [{p.lookup_rough_min:g}, 1]"})
        if max_lookup_error is not None and le["max_abs"] > max_lookup_error:
            raise LutError(f"{p.name} table of {spec['type']}: look-up error {le['max_abs']:.3g} exceeds "
                           f"max_lookup_error={max_lookup_error:g} at mu = {le['where'][0]:.6g}, "
                           f"rough = {le['where'][1]:.6g}")
    return ds


# --------------------------------------------------------------------------------------------
# Writers and readers
# --------------------------------------------------------------------------------------------


def _c_array(name: str, values: np.ndarray, storage: str, per_line: int, qualifier: str = "static") -> str:
    flat = np.asarray(values, dtype=np.float64).ravel()
    if storage == "text6":
        items = [f"{float(np.float32(x)):f}f" for x in np.clip(flat, 0, 1)]
    else:
        items = [f"{float(np.float32(x)):.9g}f" for x in flat]
    lines = []
    for a in range(0, len(items), per_line):
        lines.append("  " + ", ".join(items[a:a + per_line]))
    return f"{qualifier} const float {name}[{len(items)}] = {{\n" + ",\n".join(lines) + "\n};\n"


def write_lut(ds, path, preset=None) -> str:
    """Write a :func:`lut` dataset in its preset's format (or ``preset``'s, a :class:`Preset`), atomically."""
    from .tables import atomic_path, write_table

    p = _preset(ds.attrs["preset"] if preset is None else preset)
    E = ds["E"].values
    raw = E if p.stores == "E" else 1.0 - E
    if p.fmt == "netcdf":
        return write_table(ds, path)
    with atomic_path(path) as tmp:
        if p.fmt == "c":
            head = (f"/* {p.renderer} albedo table written by pumpup {ds.attrs['pumpup_version']} from "
                    f"{ds.attrs['spec']}; preset {p.name}: {p.source}.  Rows: {p.rows}.  Quadrature error "
                    f"{ds.attrs['quadrature_error']:.2g}, quantisation error {ds.attrs['quantisation_error']:.2g}"
                    + (f", look-up error {ds.attrs['lookup_error']:.3g}" if "lookup_error" in ds.attrs else "")
                    + ". */\n\n")
            grid = raw if p.rows == "mu" else raw.T  # C order: rows of the preset's row axis
            per = p.per_line or grid.shape[1]
            if p.eavg_in_array:
                if "E_avg" not in ds:
                    raise LutError(f"preset {p.name} stores E_avg in the same array: lut(..., eavg=True)")
                text = head + _c_array(p.names[0], np.concatenate([grid.ravel(), ds["E_avg"].values]), p.storage,
                                       per, "extern")
            else:
                text = head + _c_array(p.names[0], grid, p.storage, per)
                if "E_avg" in ds and len(p.names) > 1:
                    text += "\n" + _c_array(p.names[1], ds["E_avg"].values, p.storage, per)
            with open(tmp, "w") as fh:
                fh.write(text)
        elif p.fmt == "filament":
            if "B" not in ds:
                raise LutError("the filament layout needs the split-sum pair: lut(..., split=True)")
            half = np.stack([ds["B"].values, E], axis=-1).astype(np.float32).astype(np.float16)  # (mu=x, rough=t, 2)
            words = half.transpose(1, 0, 2).reshape(-1).view(np.uint16)  # GL row t (rough) major, x (NoV) minor
            lines = [f"// generated by pumpup {ds.attrs['pumpup_version']} in the layout of cmgen --ibl-dfg "
                     f"--ibl-dfg-multiscatter ({p.name})",
                     "// DFG LUT stored as an RG16F texture, in GL order"]
            per = 8  # 4 texels of 2 halves per line, as cmgen
            for a in range(0, len(words), per):
                lines.append("    " + " ".join(f"0x{w:04x}," for w in words[a:a + per]))
            with open(tmp, "w") as fh:
                fh.write("\n".join(lines) + "\n")
        elif p.fmt == "npy":
            arr = np.zeros((p.n_rough, p.n_mu, 2), np.float32)
            arr[..., 0] = E.T
            arr[..., 1] = ds["E_avg"].values[:, None] if "E_avg" in ds else np.nan
            with open(tmp, "wb") as fh:
                np.save(fh, arr)
        elif p.fmt == "exr":
            import OpenEXR

            chans = {"E": E.T.astype(np.float32)}
            if "E_avg" in ds:
                chans["E_avg"] = np.repeat(ds["E_avg"].values[:, None], p.n_mu, axis=1).astype(np.float32)
            for k in ("A", "B"):
                if k in ds:
                    chans[k] = ds[k].values.T.astype(np.float32)
            header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
                      "pumpup_spec": ds.attrs["spec"], "pumpup_preset": p.name,
                      "pumpup_conventions": "x = mu node i/(n-1) (floor 1e-4), y = rough node, alpha = rough^2"}
            for k in ("quadrature_error", "quantisation_error", "lookup_error", "lookup_error_mu",
                      "lookup_error_rough"):
                if k in ds.attrs:
                    header["pumpup_" + k] = f"{float(ds.attrs[k]):.6g}"
            with OpenEXR.File(header, {k: np.ascontiguousarray(v) for k, v in chans.items()}) as f:
                f.write(tmp)
        else:  # pragma: no cover - every preset has a writer
            raise LutError(f"no writer for format {p.fmt!r}")
    return os.fspath(path)


_C_ARRAY = re.compile(r"(?:static\s+|extern\s+)?const\s+float\s+(\w+)\s*\[\s*(\d+)\s*\]\s*=\s*\{([^}]*)\}", re.S)


def _read_c(path: str, p: Preset) -> dict:
    with open(path, errors="replace") as fh:
        text = fh.read()
    arrays = {m.group(1): (int(m.group(2)), m.group(3)) for m in _C_ARRAY.finditer(text)}
    if p.names[0] not in arrays:
        known = ", ".join(arrays) or "none"
        raise LutError(f"{path!r}: no array named {p.names[0]!r} for preset {p.name} (arrays found: {known})")
    out = {}
    n_e = p.n_mu * p.n_rough + (p.n_rough if p.eavg_in_array else 0)
    for key, name, size in (("E", p.names[0], n_e), ("E_avg", p.names[1] if len(p.names) > 1 else None, p.n_rough)):
        if name is None or name not in arrays:
            continue
        declared, body = arrays[name]
        try:
            vals = np.array([float(t.strip().rstrip("fF")) for t in body.split(",") if t.strip()], dtype=np.float64)
        except ValueError as exc:
            raise LutError(f"{path!r}: array {name} holds a value that is not a number ({exc})") from None
        if declared != size or len(vals) != size:
            raise LutError(f"{path!r}: array {name} has {len(vals)} values (declared {declared}); preset {p.name} "
                           f"needs {size}")
        out[key] = vals.astype(np.float32).astype(np.float64)
    if p.eavg_in_array:
        out["E_avg"] = out["E"][p.n_mu * p.n_rough:]
        out["E"] = out["E"][:p.n_mu * p.n_rough]
    if p.rows == "mu":
        out["E"] = out["E"].reshape(p.n_mu, p.n_rough)  # Cycles: data[y * nx + x], rows mu, columns rough
    else:
        out["E"] = out["E"].reshape(p.n_rough, p.n_mu).T  # appleseed: data[y * 32 + x], y roughness, x cos_theta
    if p.stores == "1-E":
        out["E"] = 1.0 - out["E"]
    return out


def _read_filament(path: str, p: Preset) -> dict:
    with open(path, errors="replace") as fh:
        text = re.sub(r"//[^\n]*", "", fh.read())
    words = re.findall(r"0x([0-9a-fA-F]{1,4})", text)
    n = p.n_mu * p.n_rough
    if len(words) not in (2 * n, 3 * n):
        raise LutError(f"{path!r}: {len(words)} half floats; preset {p.name} needs {2 * n} (RG16F) or {3 * n} "
                       f"(RGB16F with cloth) for {p.n_rough} x {p.n_mu} texels")
    ch = len(words) // n
    half = np.array([int(w, 16) for w in words], dtype=np.uint16).view(np.float16).astype(np.float64)
    half = half.reshape(p.n_rough, p.n_mu, ch)  # GL row t (rough), x (NoV), channels
    return {"E": half[..., 1].T.copy(), "B": half[..., 0].T.copy()}


#: the largest text table (a C array, Filament's header) :func:`read_table` scans: the time to read it is bounded by
#: the size, and renderers ship a few hundred kB (Cycles' shader tables, 287 kB)
MAX_TEXT_BYTES = 8 * 2**20


def npy_header(path: str):
    """(shape, dtype, offset of the data) from a .npy file's header, the array not read; a LutError if the file is no
    readable .npy file.
    """
    try:
        with open(path, "rb") as fh:
            version = np.lib.format.read_magic(fh)
            fmt = np.lib.format
            read_header = fmt.read_array_header_1_0 if version == (1, 0) else fmt.read_array_header_2_0
            shape, _, dtype = read_header(fh)
            offset = fh.tell()
    except (ValueError, OSError, EOFError, SyntaxError) as exc:
        raise LutError(f"{path!r} is not a readable .npy file: {exc}") from None
    return tuple(shape), dtype, offset


def exr_channels(path: str) -> dict:
    """The channels of an OpenEXR file as float64 arrays (name -> array); a LutError if the file is no readable EXR."""
    import OpenEXR

    try:
        with OpenEXR.File(path) as f:
            return {name: np.asarray(v.pixels, dtype=np.float64) for name, v in f.channels().items()}
    except Exception as exc:  # the binding raises several types for damaged files
        raise LutError(f"{path!r} is not a readable OpenEXR file: {exc}") from None


def check_npy_size(path: str, shape: tuple, dtype, offset: int) -> None:
    """A LutError unless the file holds the bytes its .npy header declares: checked before any array is allocated (a
    damaged header may declare terabytes).
    """
    need = offset + int(np.prod(shape)) * dtype.itemsize
    if os.path.getsize(path) < need:
        raise LutError(f"{path!r} is truncated: its header declares {need} bytes, the file holds "
                       f"{os.path.getsize(path)}")


def _check_npy_header(path: str, p: Preset) -> None:
    """A LutError unless the .npy file's header declares a (n_rough, n_mu, 1 or 2) array whose bytes the file holds."""
    shape, dtype, offset = npy_header(path)
    if len(shape) != 3 or tuple(shape[:2]) != (p.n_rough, p.n_mu) or shape[2] not in (1, 2):
        raise LutError(f"{path!r}: array of shape {shape}; preset {p.name} needs ({p.n_rough}, {p.n_mu}, 1 or 2)")
    check_npy_size(path, shape, dtype, offset)


def read_table(path, preset) -> dict:
    """Read a table file in a preset's format: a dict with ``E`` (n_mu, n_rough) as E values
    (1 - E tables converted), and ``E_avg`` (n_rough,) / ``B`` where the file has them.

    Raises
    ------
    LutError
        Unreadable file, wrong size for the preset, or no array of the preset's name.
    """
    p = _preset(preset)
    path = os.fspath(path)
    if not os.path.exists(path):
        raise LutError(f"no such file: {path!r}")
    if not os.path.isfile(path):  # (a FIFO would block the reader forever)
        raise LutError(f"{path!r} is not a regular file (a directory, a FIFO or a device): tables are read from files")
    if p.fmt in ("c", "filament") and os.path.getsize(path) > MAX_TEXT_BYTES:
        raise LutError(f"{path!r} holds {os.path.getsize(path)} bytes; a text table of preset {p.name} is read up to "
                       f"{MAX_TEXT_BYTES} (renderers ship a few hundred kB: Cycles' shader tables, 287 kB)")
    try:
        if p.fmt == "c":
            return _read_c(path, p)
        if p.fmt == "filament":
            return _read_filament(path, p)
        if p.fmt == "npy":
            _check_npy_header(path, p)
            try:
                arr = np.load(path, allow_pickle=False)
            except (ValueError, OSError, EOFError) as exc:
                raise LutError(f"{path!r} is not a readable .npy file: {exc}") from None
            if arr.ndim != 3 or arr.shape[:2] != (p.n_rough, p.n_mu) or arr.shape[2] < 1:
                raise LutError(f"{path!r}: array of shape {arr.shape}; preset {p.name} needs "
                               f"({p.n_rough}, {p.n_mu}, 1 or 2)")
            out = {"E": arr[..., 0].T.astype(np.float64)}
            if arr.shape[2] > 1 and np.all(np.isfinite(arr[..., 1])):
                out["E_avg"] = arr[:, 0, 1].astype(np.float64)
            return out
        if p.fmt == "netcdf":
            from .tables import open_table

            try:
                ds = open_table(path)
            except (ValueError, FileNotFoundError) as exc:
                raise LutError(str(exc)) from None
            if "E" not in ds or ds["E"].shape != (p.n_mu, p.n_rough):
                raise LutError(f"{path!r}: no E of shape ({p.n_mu}, {p.n_rough}) for preset {p.name}")
            out = {"E": ds["E_stored"].values if "E_stored" in ds else ds["E"].values}
            if "E_avg" in ds:
                out["E_avg"] = ds["E_avg"].values
            if "B" in ds:
                out["B"] = ds["B"].values
            return out
        if p.fmt == "exr":
            ch = exr_channels(path)
            if "E" not in ch or ch["E"].shape != (p.n_rough, p.n_mu):
                shape = ch["E"].shape if "E" in ch else None
                raise LutError(f"{path!r}: channel E of shape {shape}; preset {p.name} needs ({p.n_rough}, {p.n_mu})")
            out = {"E": ch["E"].T}
            if "E_avg" in ch:
                out["E_avg"] = ch["E_avg"][:, 0]
            if "B" in ch:
                out["B"] = ch["B"].T
            return out
    except UnicodeDecodeError as exc:  # pragma: no cover - errors="replace" above
        raise LutError(f"{path!r} is not a text table: {exc}") from None
    raise LutError(f"no reader for format {p.fmt!r}")  # pragma: no cover


# --------------------------------------------------------------------------------------------
# audit: grade a shipped table
# --------------------------------------------------------------------------------------------


@dataclass
class AuditResult:
    """What :func:`audit` found.  Errors are table - truth (absolute, in units of E)."""

    preset: str
    spec: dict
    n_nodes: int
    max_abs: float
    where_abs: tuple
    max_rel: float
    where_rel: tuple
    truth_error: float
    quantisation_bound: float
    #: nodes where E exceeds 1 by more than the format's rounding plus the truth's error (less is rounding, not a
    #: violation of energy conservation)
    above_one: int
    monotonicity: list = field(default_factory=list)
    lookup: dict | None = None
    eavg: dict | None = None
    #: adjacent pairs stepping the other way than E within two rounding bounds of the storage (rounding, not errors)
    monotonicity_rounding: int = 0
    #: the quantity the file stores ("E" or "1-E"), and the largest error relative to it (over the nodes where it
    #: exceeds ten rounding bounds; ``small_stored`` nodes are smaller) and where
    stores: str = "E"
    max_rel_stored: float = float("nan")
    where_rel_stored: tuple = ()
    small_stored: int = 0
    #: the worst nodes, one line each, indexed and located in the renderer's own axes
    worst: list = field(default_factory=list)
    #: the names of the coordinates in ``where_*``, ``mu`` and ``rough`` (the renderer's axes)
    labels: tuple = ("mu", "rough")
    error_map: np.ndarray | None = None
    truth: np.ndarray | None = None
    table: np.ndarray | None = None
    mu: np.ndarray | None = None
    rough: np.ndarray | None = None

    def ok(self, tol: float | None = None, max_lookup_error: float | None = None) -> bool:
        """Within the user's tolerances (``tol`` on the nodes, ``max_lookup_error`` between them)."""
        good = tol is None or self.max_abs <= tol
        if max_lookup_error is not None and self.lookup is not None:
            good = good and self.lookup["max_abs"] <= max_lookup_error
        return bool(good)

    def report(self) -> str:
        """The audit for people, a few lines: the worst errors at the nodes, the truth's quadrature error and the
        format's rounding, E > 1 and monotonicity violations, and the look-up and E_avg checks where they ran.
        """
        a, b = self.labels

        def at(w):
            return f"{a} = {w[0]:.6g}, {b} = {w[1]:.6g}"

        lines = [f"audit of a {self.preset} table ({self.n_nodes} nodes) against pumpup's {json.dumps(self.spec)}",
                 f"  nodes: max |table - E| = {self.max_abs:.3g} at {at(self.where_abs)}; max relative to E "
                 f"{self.max_rel:.3g} at {at(self.where_rel)}"]
        if self.stores != "E":
            rel = (f"max {self.max_rel_stored:.3g} at {at(self.where_rel_stored)}" if self.where_rel_stored
                   else "no node above ten rounding bounds")
            lines.append(f"  relative to the stored {self.stores}: {rel} (over the nodes where {self.stores} exceeds "
                         f"ten rounding bounds; {self.small_stored} smaller)")
        if self.worst:
            lines.append("  worst nodes (the file's own indices and axes):")
            lines.extend(f"    {w}" for w in self.worst[:5])
        lines += [f"  truth: quadrature error <= {self.truth_error:.2g}; the format rounds by <= "
                  f"{self.quantisation_bound:.2g}",
                  f"  E > 1 at {self.above_one} node(s); {len(self.monotonicity)} monotonicity violation(s) beyond two "
                  f"rounding bounds ({self.monotonicity_rounding} within rounding)"]
        for m in self.monotonicity[:5]:
            lines.append(f"    {m}")
        if self.lookup is not None:
            lk = self.lookup
            lines.append(f"  look-up (the renderer's interpolation) against E: max {lk['max_abs']:.3g} at "
                         f"{at(lk['where'])} (rms {lk['rms']:.2g} over {lk['points']} points)")
        if self.eavg is not None:
            e = self.eavg
            lines.append(f"  E_avg: max |stored - 2 int E mu dmu of the table's own E| = {e['vs_own']:.3g} "
                         f"({b} = {e['vs_own_where']:.6g}); max |stored - true E_avg| = {e['vs_truth']:.3g} "
                         f"({b} = {e['vs_truth_where']:.6g})")
        return "\n".join(lines)


def _own_eavg(E: np.ndarray, p: Preset) -> np.ndarray:
    """2 integral_0^1 E(mu) mu dmu of the table's own look-up along mu (Gauss-Legendre per cell)."""
    x, w = np.polynomial.legendre.leggauss(8)
    n = E.shape[0]
    if p.mu_lookup == "texel":
        edges = np.concatenate([[0.0], (np.arange(n) + 0.5) / n, [1.0]])
        a, b = edges[:-1], edges[1:]
        m = (0.5 * (b - a))[:, None] * x[None, :] + (0.5 * (a + b))[:, None]
        wt = (0.5 * (b - a))[:, None] * w[None, :]
    else:  # linear in s = mu^(1/p) on each cell: integrate in s, dmu = p s^(p-1) ds
        q = _power(p.mu_lookup)
        c = np.arange(n) / (n - 1)
        sa, sb = c[:-1], c[1:]
        s = (0.5 * (sb - sa))[:, None] * x[None, :] + (0.5 * (sa + sb))[:, None]
        m = s ** q
        wt = (0.5 * (sb - sa))[:, None] * w[None, :] * q * s ** (q - 1)
    m = m.ravel()
    wt = wt.ravel()
    rough_any = np.zeros_like(m)
    out = np.empty(E.shape[1])
    for j in range(E.shape[1]):
        col = np.repeat(E[:, j:j + 1], 2, axis=1)  # a one-column table looked up along mu only
        out[j] = float(np.sum(2 * lookup(col, m, rough_any, p) * m * wt))
    return out


def _monotonicity(table: np.ndarray, truth: np.ndarray, bound: float, truth_error: float, mu, rough,
                  labels: tuple = ("mu", "rough")) -> tuple[list[str], int]:
    """Adjacent pairs where the table steps the other way than the truth does.

    A step of the table is the difference of two rounded values, each off by up to the storage's rounding
    ``bound``: a pair is a violation only where the table's step differs from the truth's by more than two
    bounds (plus twice the truth's error); the others are rounding, counted apart.  Steps of the truth below
    twice its error are no direction.  Returns (one line per violation, the number within rounding).
    """
    found = []
    within = 0
    slack = 2 * bound + 2 * truth_error
    for axis, name in ((0, labels[0]), (1, labels[1])):
        dt = np.diff(table, axis=axis)
        de = np.diff(truth, axis=axis)
        other = (np.sign(dt) != np.sign(de)) & (np.abs(de) > 2 * truth_error)
        bad = other & (np.abs(dt - de) > slack)
        within += int(np.count_nonzero(other & ~bad))
        for i, j in np.argwhere(bad):
            m0, r0 = mu[i], rough[j]
            m1, r1 = (mu[i + 1], r0) if axis == 0 else (m0, rough[j + 1])
            found.append(f"along {name}: table steps {dt[i, j]:+.3g} where E steps {de[i, j]:+.3g} between "
                         f"({labels[0]}, {labels[1]}) = ({m0:.4g}, {r0:.4g}) and ({m1:.4g}, {r1:.4g})")
    return found, within


def grade(E: np.ndarray, truth: np.ndarray, truth_error: np.ndarray, bound: float, stores: str, mu, rough, *,
          name: str, spec: dict, labels: tuple = ("mu", "rough"), cell=None, n_worst: int = 5) -> AuditResult:
    """The node part of an audit: ``E`` (the table, as E) against ``truth`` on the grid ``mu`` x ``rough`` (the
    coordinates reported, named ``labels``), for a storage that rounds by ``bound`` and holds ``stores``
    ("E" or "1-E").  ``cell(i, j)`` names a node in the renderer's own indexing (default "[i, j]").
    """
    diff = E - truth
    i, j = np.unravel_index(np.argmax(np.abs(diff)), diff.shape)
    rel = np.abs(diff) / np.maximum(np.abs(truth), 1e-300)
    k, m = np.unravel_index(np.argmax(rel), rel.shape)
    stored_truth = truth if stores == "E" else 1.0 - truth
    # relative to the stored quantity where it is more than ten rounding bounds (below, rounding alone is 10 %)
    big = np.abs(stored_truth) > 10 * bound
    rel_s = np.where(big, np.abs(diff) / np.maximum(np.abs(stored_truth), 1e-300), -1.0)
    ks, ms = np.unravel_index(np.argmax(rel_s), rel_s.shape)
    terr = float(np.max(truth_error))
    mono, within = _monotonicity(E, truth, bound, terr, mu, rough, labels)
    cell = cell or (lambda a, b: f"[{a}, {b}]")
    worst = []
    for flat in np.argsort(np.abs(diff), axis=None)[::-1][:n_worst]:
        a, b = np.unravel_index(flat, diff.shape)
        worst.append(f"{cell(a, b)} {labels[0]} = {mu[a]:.6g}, {labels[1]} = {rough[b]:.6g}: table {E[a, b]:.7g}, "
                     f"E {truth[a, b]:.7g} ({diff[a, b]:+.3g})")
    return AuditResult(
        preset=name, spec=spec, n_nodes=int(E.size), max_abs=float(abs(diff[i, j])),
        where_abs=(float(mu[i]), float(rough[j])), max_rel=float(rel[k, m]), where_rel=(float(mu[k]), float(rough[m])),
        truth_error=terr, quantisation_bound=float(bound),
        above_one=int(np.count_nonzero(E - 1.0 > bound + terr)), monotonicity=mono, monotonicity_rounding=within,
        stores=stores, max_rel_stored=float(max(rel_s[ks, ms], 0.0)) if big.any() else float("nan"),
        where_rel_stored=(float(mu[ks]), float(rough[ms])), small_stored=int(np.count_nonzero(~big)), worst=worst,
        labels=tuple(labels), error_map=diff, truth=truth, table=E, mu=np.asarray(mu), rough=np.asarray(rough))


def eavg_grades(stored, own, true_avg, true_err, x) -> dict:
    """How a table's stored E_avg column differs from its own average of its E (``own``) and from the true mean
    albedo ``true_avg`` (error ``true_err``), over the roughness axis ``x``: the largest differences and where.
    """
    d_own = np.abs(stored - own)
    d_true = np.abs(stored - true_avg)
    return {"vs_own": float(d_own.max()), "vs_own_where": float(x[np.argmax(d_own)]),
            "vs_truth": float(d_true.max()), "vs_truth_where": float(x[np.argmax(d_true)]),
            "truth_error": float(true_err.max()), "own": own, "true": true_avg, "stored": stored}


def audit(path: str | os.PathLike[str], preset: str | None = None, model: str | dict | BRDF | None = None, *,
          conventions=None, rtol: float = 1e-7, lookup_check: bool = True, eavg: bool = True, per_cell: int = 1,
          stride: int | None = None, png: str | None = None, threads: int | None = None,
          max_regions: int = 200) -> AuditResult:
    """Grade a shipped table against pumpup's truth, in a preset's conventions or any described ones.

    With ``conventions`` (a path to a TOML or JSON file, a dict, or a
    :class:`pumpup.conventions.Conventions`), the table is read and graded as that description says
    (:func:`pumpup.conventions.audit_conventions`; ``model`` then overrides its model).  Otherwise
    ``preset`` names one of :data:`PRESETS` (default ``"cycles"``) and ``model`` defaults to GGX.

    Reads ``path`` (:func:`read_table`), recomputes every node with ``model`` (default GGX with
    the preset's Smith term, F = 1) and reports: max absolute and relative node error and where,
    E > 1 and monotonicity violations, the renderer's look-up error between the nodes
    (:func:`lookup_error`), E_avg against the table's own E and against the true E_avg, and
    (with ``png``) an error-map image.

    Examples
    --------
    >>> import pumpup, tempfile, os
    >>> path = os.path.join(tempfile.mkdtemp(), "t.h")
    >>> _ = pumpup.lut_module.write_lut(pumpup.lut("ggx", preset="bsdl", lookup_check=False), path)
    >>> r = pumpup.audit(path, preset="bsdl", lookup_check=False)
    >>> r.max_abs < 1e-7
    True
    """
    if conventions is not None:
        from .conventions import audit_conventions

        if preset is not None:
            raise SpecError("give either preset or conventions, not both")
        return audit_conventions(path, conventions, model=model, rtol=rtol, lookup_check=lookup_check, eavg=eavg,
                                 per_cell=per_cell, stride=stride, png=png, threads=threads, max_regions=max_regions)
    p = _preset("cycles" if preset is None else preset)
    tab = read_table(path, p)
    spec, param = model_spec("ggx" if model is None else model, p)
    mu, rough = nodes(p)
    tr = _edge_rule(truth_grid(spec, param, mu, rough, rtol=rtol, threads=threads, max_regions=max_regions), p)
    E = tab["E"]
    res = grade(E, tr["E"], tr["E_error"], STORAGE_BOUND[p.storage], p.stores, mu, rough, name=p.name,
                spec={**spec, param: "rough^2"})
    if eavg and "E_avg" in tab:
        own = _own_eavg(E, p)
        true_avg, true_err = mean_albedo_grid(spec, param, rough, rtol=rtol, threads=threads, max_regions=max_regions)
        res.eavg = eavg_grades(tab["E_avg"], own, true_avg, true_err, rough)
    if lookup_check:
        big = max(p.n_mu, p.n_rough) > 64
        res.lookup = lookup_error(E, spec, param, p, per_cell=per_cell, stride=stride or (4 if big else 1),
                                  threads=threads, max_regions=max_regions)
    if png:
        error_map_png(res, png)
    return res


def error_map_png(res: AuditResult, path) -> str:
    """An image of table - truth at the nodes (and of the look-up error, if measured), atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .tables import atomic_path

    panels = [("table - E at the nodes", res.mu, res.rough, res.error_map)]
    if res.lookup is not None:
        g = res.lookup["grid"]
        panels.append(("look-up - E between the nodes", g[0], g[1], g[2]))
    fig, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4.5), squeeze=False)
    for ax, (title, mu, rough, err) in zip(axes[0], panels):
        lim = float(np.max(np.abs(err))) or 1.0
        im = ax.pcolormesh(rough, mu, err, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="nearest")
        ax.set_xlabel("roughness r (alpha = r^2)" if res.labels[1] == "rough" else res.labels[1])
        ax.set_ylabel("mu = cos theta" if res.labels[0] == "mu" else res.labels[0])
        ax.set_title(f"{res.preset}: {title}", fontsize=9)
        fig.colorbar(im, ax=ax)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=100)
    plt.close(fig)
    return os.fspath(path)


# --------------------------------------------------------------------------------------------
# Better tables for the same budget: axis warps
# --------------------------------------------------------------------------------------------


def warp_search(model="ggx", preset="cycles", p_grid=(1.0, 1.5, 2.0, 3.0, 4.0), q_grid=(1.0, 1.5, 2.0, 3.0), *,
                rtol: float = 1e-7, per_cell: int = 1, refine: int = 2, threads: int | None = None,
                max_regions: int = 200) -> list[dict]:
    """The worst look-up error of power-warped node axes for the preset's budget and bilinear look-up.

    Each candidate puts the nodes at mu = (i / (n - 1))^p and rough = (j / (n - 1))^q (the preset's
    floors applied) and is read by the same bilinear interpolation in the warped coordinate
    (index = mu^(1/p) (n - 1); BSDL's mu axis is p = 2).  Its nodes are exact (float64) and its
    worst look-up error over the preset's look-up domain is measured by :func:`lookup_error`.
    p = q = 1 is the uniform grid the renderers use.

    Returns
    -------
    list of dict
        One per (p, q), sorted by ``max_abs``: ``p``, ``q``, ``max_abs``, ``where``, ``rms``.
    """
    base = _preset(preset)
    if base.mu_lookup == "texel" or base.rough_lookup == "texel":
        raise SpecError("warp_search needs a preset with node axes (cycles, appleseed, bsdl, netcdf, exr)")
    spec, param = model_spec(model, base)
    out = []
    for p in p_grid:
        for q in q_grid:
            cand = _dc_replace(base, name=f"{base.name}-warp", mu_axis=f"power:{p:g}", rough_axis=f"power:{q:g}")
            mu, rough = nodes(cand)
            table = truth_grid(spec, param, mu, rough, rtol=rtol, threads=threads, max_regions=max_regions)["E"]
            le = lookup_error(table, spec, param, cand, per_cell=per_cell, refine=refine, rtol=rtol, threads=threads,
                              max_regions=max_regions)
            out.append({"p": float(p), "q": float(q), "max_abs": le["max_abs"], "where": le["where"], "rms": le["rms"],
                        "truth_error": le["truth_error"]})
    return sorted(out, key=lambda d: d["max_abs"])


def _dc_replace(obj, **kw):
    import dataclasses

    return dataclasses.replace(obj, **kw)
