"""A renderer's albedo table described as plain data: read it, write it, look it up as the renderer does, audit it.

A *conventions* description (a TOML or JSON file, or a dict with the same keys; never code) says what a shipped
table holds and how the renderer reads it::

    model = "ggx:shadowing=correlated"   # a pumpup spec without the roughness parameter
    quantity = "E"                       # "E", "1-E", "E_avg" or "1-E_avg"
    format = "c-array"                   # "c-array" (with array = "name"), "text", "npy", "exr" (with channel),
                                         # "netcdf" (with variable)
    array = "table_ggx_E"
    storage = "text-decimals-6"          # "float32", "float16", "float64", "unorm8", "unorm16", "text-decimals-N"
    shape = [32, 32]                     # in storage order: the slow axis first
    roughness_to_alpha = "square"        # alpha = roughness^2 ("square") or alpha = roughness ("identity")
    lookup = "bilinear-clamped"          # "bilinear-clamped", "bilinear" (edge cells extended) or "nearest"

    [[axes]]                             # one per axis, in storage order
    axis = "mu"                          # "mu", "roughness" or "alpha"
    nodes = "edges"                      # "edges": u_i = i / (n - 1); "centres": u_i = (i + 0.5) / n
    map = "linear"                       # u = t ("linear"), t^2 ("square"), sqrt(t) ("sqrt"), t^exponent ("pow")
    range = [0.0, 1.0]                   # t = (x - range[0]) / (range[1] - range[0]) for the axis quantity x
    clamp = [[0, 1e-4]]                  # [node index, the x at which that node is evaluated]

Optional keys: ``channels`` (the names of values interleaved per cell, fastest, in text, C arrays and .npy
arrays), ``channel`` (the one holding the quantity), ``variable`` (netCDF), ``[e_avg]`` (where the table of
E_avg over roughness is: ``array``, ``follows = true`` for the values after the table in the same array,
``channel`` repeated along mu, or ``variable``), ``name``, ``renderer``, ``source`` (free text); per axis
``exponent`` (for ``map = "pow"``), ``offset`` (centres: node i is evaluated at u = (i + 0.5 + offset) / n,
clipped to [0, 1]), ``fixed`` ([node index, the E the renderer defines there]) and ``lookup_range`` (the domain of
the look-up-error check).

In text formats, integers are the codes of a ``unorm`` storage (value = code / (2^bits - 1)) and hexadecimal words
are the bits of a ``float16``; other numbers are values.

The presets of :mod:`pumpup.luts` ship as such files (:func:`preset_conventions`), and
:func:`audit_conventions` grades any described table as :func:`pumpup.luts.audit` grades a preset's.

This module is over 1,000 lines because the description's checks, the reader and writer of each format and
storage, and the renderer's look-up all follow the one description, field by field, and are tested as one.
"""

from __future__ import annotations

import json
import math
import os
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .core import SpecError
from .luts import (
    AuditResult,
    LutError,
    check_npy_size,
    eavg_grades,
    exr_channels,
    grade,
    lookup_error_on,
    mean_albedo_grid,
    model_spec,
    npy_header,
    truth_grid,
)

__all__ = ["Axis", "Conventions", "ConventionsError", "load_conventions", "preset_conventions", "audit_conventions",
           "quantise", "storage_bound", "PRESET_FILES"]


class ConventionsError(SpecError):
    """A conventions description that is wrong or incomplete; the message names the field."""


#: the conventions files of the presets of :mod:`pumpup.luts`, shipped in the package
PRESET_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "conventions")
PRESET_FILES = {"cycles": "cycles.toml", "filament": "filament.toml", "filament-centred": "filament-centred.toml",
                "appleseed": "appleseed.toml", "bsdl": "bsdl.toml", "mitsuba": "mitsuba.toml",
                "netcdf": "netcdf.toml", "exr": "exr.toml"}

QUANTITIES = ("E", "1-E", "E_avg", "1-E_avg")
FORMATS = ("c-array", "text", "npy", "exr", "netcdf")
LOOKUPS = ("bilinear-clamped", "bilinear", "nearest")
AXES = ("mu", "roughness", "alpha")
MAPS = ("linear", "square", "sqrt", "pow")
TOP_FIELDS = {"model", "quantity", "format", "array", "channel", "channels", "variable", "storage", "shape",
              "roughness_to_alpha", "lookup", "axes", "e_avg", "name", "renderer", "source"}
AXIS_FIELDS = {"axis", "nodes", "map", "exponent", "range", "clamp", "fixed", "offset", "lookup_range"}
EAVG_FIELDS = {"array", "follows", "channel", "variable"}
#: the largest text table read (renderers ship a few hundred kB)
MAX_TEXT_BYTES = 8 * 2**20
_TEXT_DECIMALS = re.compile(r"text-decimals-(\d+)$")


# --------------------------------------------------------------------------------------------
# Storage
# --------------------------------------------------------------------------------------------


def _check_storage(storage: Any) -> str:
    if not isinstance(storage, str) or not (storage in ("float32", "float16", "float64", "unorm8", "unorm16")
                                            or (_TEXT_DECIMALS.match(storage)
                                                and 1 <= int(_TEXT_DECIMALS.match(storage).group(1)) <= 17)):
        raise ConventionsError(f"conventions: field 'storage' must be float32, float16, float64, unorm8, unorm16 or "
                               f"text-decimals-N (N in 1..17); got {storage!r}")
    return storage


def storage_bound(storage: str) -> float:
    """The worst rounding of a value in [0, 1] by ``storage`` (absolute)."""
    _check_storage(storage)
    m = _TEXT_DECIMALS.match(storage)
    if m:
        return 0.5 * 10.0 ** -int(m.group(1)) + 2.0 ** -25  # printed decimals, read back as a C float
    return {"float32": 2.0 ** -25, "float16": 2.0 ** -12, "float64": 2.0 ** -54, "unorm8": 0.5 / 255,
            "unorm16": 0.5 / 65535}[storage]


def _unorm_max(storage: str) -> int:
    return 255 if storage == "unorm8" else 65535


def quantise(values, storage: str) -> np.ndarray:
    """The value a renderer reads back after storing ``values`` in ``storage`` (as float64; unorm clips to [0, 1])."""
    _check_storage(storage)
    v = np.asarray(values, dtype=np.float64)
    m = _TEXT_DECIMALS.match(storage)
    if m:
        n = int(m.group(1))
        f = v.astype(np.float32)
        return np.array([float(np.float32(float(f"{float(x):.{n}f}"))) for x in f.ravel()]).reshape(v.shape)
    if storage.startswith("unorm"):
        q = _unorm_max(storage)
        return np.round(np.clip(v, 0.0, 1.0) * q) / q
    return v.astype(storage).astype(np.float64)


# --------------------------------------------------------------------------------------------
# The description
# --------------------------------------------------------------------------------------------


def _number(v: Any, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
        raise ConventionsError(f"conventions: {what} must be a finite number; got {v!r}")
    return float(v)


@dataclass(frozen=True)
class Axis:
    """One axis of a table: what it holds, where its nodes are, how the renderer maps a coordinate to it."""

    axis: str
    n: int
    nodes: str = "edges"
    map: str = "linear"
    exponent: float = 1.0
    range: tuple = (0.0, 1.0)
    clamp: tuple = ()
    fixed: tuple = ()
    offset: float = 0.0
    lookup_range: tuple = (0.0, 1.0)

    @property
    def power(self) -> float:
        """P of the map u = t^p (linear 1, square 2, sqrt 1/2, pow its exponent)."""
        return {"linear": 1.0, "square": 2.0, "sqrt": 0.5}.get(self.map, self.exponent)

    def u_nodes(self) -> np.ndarray:
        """The table coordinate u of each node (before clamping)."""
        i = np.arange(self.n, dtype=np.float64)
        if self.nodes == "edges":
            return i / (self.n - 1)
        return np.clip((i + 0.5 + self.offset) / self.n, 0.0, 1.0)

    def x_of_u(self, u) -> np.ndarray:
        """The axis quantity x at table coordinate u: x = lo + (hi - lo) u^(1/p)."""
        lo, hi = self.range
        u = np.asarray(u, dtype=np.float64)
        return lo + (hi - lo) * (u ** (1.0 / self.power))

    def x_nodes(self) -> np.ndarray:
        """The x at which each node is evaluated (``clamp`` applied)."""
        x = self.x_of_u(self.u_nodes())
        for i, v in self.clamp:
            x[i] = v
        return x

    def coordinate(self, x) -> np.ndarray:
        """The renderer's continuous index c of x (node i at c = i)."""
        lo, hi = self.range
        t = np.clip((np.asarray(x, dtype=np.float64) - lo) / (hi - lo), 0.0, 1.0)
        u = t if self.power == 1.0 else t ** self.power
        if self.nodes == "edges":
            return u * (self.n - 1)  # Cycles' lookup_table_read: saturatef(x) (size - 1)
        return u * self.n - 0.5  # a texture's texel centres

    def index(self, x, lookup: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(i0, i1, w) of the renderer's 1-D look-up at x: value = (1 - w) v[i0] + w v[i1]."""
        n = self.n
        c = self.coordinate(x)
        if lookup == "bilinear":  # the edge cells extended
            i0 = np.clip(np.floor(c), 0, max(n - 2, 0)).astype(np.int64)
            return i0, np.minimum(i0 + 1, n - 1), c - i0
        c = np.clip(c, 0.0, n - 1.0)
        if lookup == "nearest":
            i0 = np.clip(np.floor(c + 0.5), 0, n - 1).astype(np.int64)
            return i0, i0, np.zeros_like(c)
        i0 = np.minimum(np.floor(c).astype(np.int64), n - 1)
        return i0, np.minimum(i0 + 1, n - 1), c - i0

    def dense(self, per_cell: int, stride: int) -> np.ndarray:
        """X between the nodes for the look-up check: per_cell points per cell, every stride-th cell, plus the ends
        of ``lookup_range``.
        """
        c = (np.arange(0, self.n - 1, stride)[:, None] + (np.arange(per_cell) + 0.5)[None, :] / per_cell).ravel()
        u = c / (self.n - 1) if self.nodes == "edges" else (c + 0.5) / self.n
        lo, hi = self.lookup_range
        x = np.concatenate([[lo], self.x_of_u(u), [hi]])
        return np.unique(np.clip(x, lo, hi))


@dataclass(frozen=True)
class Conventions:
    """A table's conventions (see the module docstring); build one with :func:`load_conventions`."""

    model: str
    quantity: str
    format: str
    storage: str
    shape: tuple
    axes: tuple
    roughness_to_alpha: str = "square"
    lookup: str = "bilinear-clamped"
    array: str | None = None
    channel: str | None = None
    channels: tuple = ()
    variable: str | None = None
    e_avg: dict = field(default_factory=dict)
    name: str = "described"
    renderer: str = ""
    source: str = ""

    # ---- axes ----
    @property
    def average(self) -> bool:
        """The table holds E_avg(roughness) (one axis) rather than E(mu, roughness)."""
        return self.quantity in ("E_avg", "1-E_avg")

    @property
    def stores(self) -> str:
        """"E" or "1-E"."""
        return "1-E" if self.quantity.startswith("1-") else "E"

    def _pos(self, kind: str) -> int:
        names = [a.axis for a in self.axes]
        if kind == "mu":
            return names.index("mu")
        return names.index("roughness") if "roughness" in names else names.index("alpha")

    @property
    def mu_axis(self) -> Axis:
        """The mu axis."""
        return self.axes[self._pos("mu")]

    @property
    def rough_axis(self) -> Axis:
        """The roughness (or alpha) axis."""
        return self.axes[self._pos("rough")]

    def rough_of(self, x) -> np.ndarray:
        """R with alpha = r^2 (pumpup's tables' argument) of the roughness axis quantity x."""
        x = np.asarray(x, dtype=np.float64)
        if self.rough_axis.axis == "roughness" and self.roughness_to_alpha == "square":
            return x
        return np.sqrt(np.maximum(x, 0.0))  # x is alpha

    def x_of_rough(self, r) -> np.ndarray:
        """The roughness axis quantity of r (alpha = r^2)."""
        r = np.asarray(r, dtype=np.float64)
        if self.rough_axis.axis == "roughness" and self.roughness_to_alpha == "square":
            return r
        return r * r

    def alpha_of(self, x) -> np.ndarray:
        """The model's alpha at the roughness axis quantity x."""
        x = np.asarray(x, dtype=np.float64)
        return x * x if self.rough_axis.axis == "roughness" and self.roughness_to_alpha == "square" else x

    def nodes(self) -> tuple[np.ndarray | None, np.ndarray]:
        """(mu, x): where the nodes are evaluated, in table orientation (mu first; mu is None for E_avg tables)."""
        return (None if self.average else self.mu_axis.x_nodes()), self.rough_axis.x_nodes()

    def fixed_mask(self) -> tuple[np.ndarray, np.ndarray]:
        """(mask, value) in table orientation: the nodes whose E the renderer defines (``fixed``)."""
        if self.average:
            ax = self.rough_axis
            mask = np.zeros(ax.n, bool)
            val = np.zeros(ax.n)
            for i, v in ax.fixed:
                mask[i], val[i] = True, v
            return mask, val
        mu_ax, r_ax = self.mu_axis, self.rough_axis
        mask = np.zeros((mu_ax.n, r_ax.n), bool)
        val = np.zeros((mu_ax.n, r_ax.n))
        for i, v in mu_ax.fixed:
            mask[i, :], val[i, :] = True, v
        for j, v in r_ax.fixed:
            mask[:, j], val[:, j] = True, v
        return mask, val

    def to_table(self, stored: np.ndarray) -> np.ndarray:
        """An array in storage order -> table orientation (mu, roughness)."""
        if self.average or self._pos("mu") == 0:
            return stored
        return stored.T

    def to_storage(self, table: np.ndarray) -> np.ndarray:
        """Table orientation (mu, roughness) -> storage order."""
        return self.to_table(table)

    def cell(self, i: int, j: int) -> str:
        """A node (table orientation i over mu, j over roughness) in the file's own indices."""
        idx = (i, j) if self._pos("mu") == 0 else (j, i)
        flat = idx[0] * self.shape[1] + idx[1]
        k = len(self.channels) or 1
        where = f" (item {flat * k + (self.channels.index(self.channel) if self.channels else 0)})" \
            if self.format in ("c-array", "text") else ""
        return f"[{idx[0]}, {idx[1]}]{where}"

    # ---- look-up ----
    def look_up(self, table, mu, x) -> np.ndarray:
        """The renderer's look-up of ``table`` (values of E in table orientation) at (mu, x); broadcasts."""
        table = np.asarray(table, dtype=np.float64)
        mu, x = np.broadcast_arrays(np.asarray(mu, float), np.asarray(x, float))
        a0, a1, s = self.mu_axis.index(mu, self.lookup)
        b0, b1, t = self.rough_axis.index(x, self.lookup)
        return ((1 - s) * ((1 - t) * table[a0, b0] + t * table[a0, b1])
                + s * ((1 - t) * table[a1, b0] + t * table[a1, b1]))

    def look_up_average(self, e_avg, x) -> np.ndarray:
        """The renderer's 1-D look-up of a table of E_avg over the roughness axis at x."""
        b0, b1, t = self.rough_axis.index(np.asarray(x, float), self.lookup)
        e_avg = np.asarray(e_avg, dtype=np.float64)
        return (1 - t) * e_avg[b0] + t * e_avg[b1]

    def own_average(self, table) -> np.ndarray:
        """2 integral_0^1 E(mu) mu dmu (000 eq. 33) of the renderer's look-up of ``table`` along mu, per column
        (Gauss-Legendre, 8 points per cell of the look-up, in its own coordinate).
        """
        ax = self.mu_axis
        x, w = np.polynomial.legendre.leggauss(8)
        u = ax.u_nodes()
        if ax.nodes == "centres":
            u = np.concatenate([[0.0], u, [1.0]])
        sa, sb = u[:-1], u[1:]
        keep = sb > sa
        sa, sb = sa[keep], sb[keep]
        s = (0.5 * (sb - sa))[:, None] * x[None, :] + (0.5 * (sa + sb))[:, None]
        q = 1.0 / ax.power
        lo, hi = ax.range
        m = lo + (hi - lo) * s ** q
        wt = (0.5 * (sb - sa))[:, None] * w[None, :] * (hi - lo) * q * s ** (q - 1)
        m, wt = m.ravel(), wt.ravel()
        for a, b in ((0.0, lo), (hi, 1.0)):  # outside the axis range the look-up holds the edge value
            if b > a:
                m = np.concatenate([m, 0.5 * (b - a) * x + 0.5 * (a + b)])
                wt = np.concatenate([wt, 0.5 * (b - a) * w])
        i0, i1, t = ax.index(m, self.lookup)
        table = np.asarray(table, dtype=np.float64)
        col = (1 - t)[:, None] * table[i0] + t[:, None] * table[i1]
        return np.sum(2 * col * (m * wt)[:, None], axis=0)

    # ---- files ----
    def read(self, path) -> dict:
        """Read a table file as described: ``E`` in table orientation as values of E (or ``E_avg`` for an E_avg
        table), and ``E_avg`` where the description says where it is.

        Raises
        ------
        LutError
            One line naming what differs from the description (size, array, channel, values out of range).
        """
        return _read(self, os.fspath(path))

    def write(self, E, path, e_avg=None) -> str:
        """Write ``E`` (values of E in table orientation, or of E_avg for an E_avg table) as described (quantised by
        the storage), with ``e_avg`` where the description puts it; atomically.
        """
        return _write(self, E, os.fspath(path), e_avg)


# --------------------------------------------------------------------------------------------
# Parsing and validation
# --------------------------------------------------------------------------------------------


def _choice(d: dict, key: str, allowed, where: str = "", default: Any = None) -> Any:
    if key not in d:
        if default is not None:
            return default
        raise ConventionsError(f"conventions: field {where}{key!r} is missing (one of {', '.join(allowed)})")
    v = d[key]
    if v not in allowed:
        raise ConventionsError(f"conventions: field {where}{key!r} must be one of {', '.join(allowed)}; got {v!r}")
    return v


def _pairs(v: Any, what: str, n: int, lo: float, hi: float) -> tuple:
    if not isinstance(v, list) or not all(isinstance(p, list) and len(p) == 2 for p in v):
        raise ConventionsError(f"conventions: {what} must be a list of [node index, value] pairs; got {v!r}")
    out = []
    for i, x in v:
        if isinstance(i, bool) or not isinstance(i, int) or not -n <= i < n:
            raise ConventionsError(f"conventions: {what}: node index must be an integer in [{-n}, {n - 1}]; "
                                   f"got {i!r}")
        x = _number(x, f"{what} value")
        if not lo <= x <= hi:
            raise ConventionsError(f"conventions: {what}: value must be in [{lo:g}, {hi:g}]; got {x!r}")
        out.append((i % n, x))
    return tuple(out)


def _range(v: Any, what: str) -> tuple:
    if not isinstance(v, list) or len(v) != 2:
        raise ConventionsError(f"conventions: {what} must be [low, high]; got {v!r}")
    lo, hi = _number(v[0], what), _number(v[1], what)
    if not 0.0 <= lo < hi <= 1.0:
        raise ConventionsError(f"conventions: {what} must satisfy 0 <= low < high <= 1; got {v!r}")
    return lo, hi


def _no_unknown_fields(d: dict, known, where: str = "") -> None:
    """One line naming the first field of ``d`` (a table at ``where``, e.g. "axes[0].") that is not ``known``."""
    unknown = set(d) - set(known)
    if unknown:
        raise ConventionsError(f"conventions: unknown field '{where}{sorted(unknown)[0]}' (known: "
                               f"{', '.join(sorted(known))})")


def _axis(d: Any, k: int, n: int) -> Axis:
    where = f"axes[{k}]."
    if not isinstance(d, dict):
        raise ConventionsError(f"conventions: axes[{k}] must be a table of axis, nodes, map, range; got {d!r}")
    _no_unknown_fields(d, AXIS_FIELDS, where)
    if d.get("axis") == "f0" or d.get("axis") == "eta":
        raise ConventionsError(f"conventions: field {where}'axis' = {d['axis']!r}: tables over a Fresnel parameter "
                               f"are not supported yet (axes: mu, roughness, alpha)")
    axis = _choice(d, "axis", AXES, where)
    nodes = _choice(d, "nodes", ("edges", "centres"), where, "edges")
    mp = _choice(d, "map", MAPS, where, "linear")
    exponent = 1.0
    if mp == "pow":
        if "exponent" not in d:
            raise ConventionsError(f"conventions: field {where}'exponent' is missing (map = \"pow\" needs it)")
        exponent = _number(d["exponent"], f"field {where}'exponent'")
        if not 0.1 <= exponent <= 10:
            raise ConventionsError(f"conventions: field {where}'exponent' must be in [0.1, 10]; got {exponent!r}")
    elif "exponent" in d:
        raise ConventionsError(f"conventions: field {where}'exponent' is only for map = \"pow\" (map is {mp!r})")
    rng = _range(d.get("range", [0.0, 1.0]), f"field {where}'range'")
    offset = _number(d.get("offset", 0.0), f"field {where}'offset'")
    if offset and nodes != "centres":
        raise ConventionsError(f"conventions: field {where}'offset' is only for nodes = \"centres\"")
    clamp = _pairs(d.get("clamp", []), f"field {where}'clamp'", n, *rng)
    fixed = _pairs(d.get("fixed", []), f"field {where}'fixed'", n, 0.0, 1.0)
    default_lo = {"mu": 1e-4, "roughness": 1e-2, "alpha": 1e-4}[axis]
    lrng = _range(d["lookup_range"], f"field {where}'lookup_range'") if "lookup_range" in d \
        else (max(rng[0], default_lo), rng[1])
    return Axis(axis=axis, n=n, nodes=nodes, map=mp, exponent=exponent, range=rng, clamp=clamp, fixed=fixed,
                offset=offset, lookup_range=lrng)


def _parse(d: dict) -> Conventions:
    if not isinstance(d, dict):
        raise ConventionsError(f"conventions must be a table of fields; got {type(d).__name__}")
    _no_unknown_fields(d, TOP_FIELDS)
    if "model" not in d:
        raise ConventionsError("conventions: field 'model' is missing (a pumpup spec such as "
                               "\"ggx:shadowing=correlated\")")
    model = d["model"]
    if not isinstance(model, str | dict):
        raise ConventionsError(f"conventions: field 'model' must be a spec string or table; got {model!r}")
    try:
        model_spec(model)
    except (SpecError, TypeError, ValueError) as exc:
        raise ConventionsError(f"conventions: field 'model': {exc}") from None
    quantity = _choice(d, "quantity", QUANTITIES)
    fmt = _choice(d, "format", FORMATS)
    if "storage" not in d:
        raise ConventionsError("conventions: field 'storage' is missing (float32, float16, float64, unorm8, unorm16 "
                               "or text-decimals-N)")
    storage = _check_storage(d["storage"])
    shape = d.get("shape")
    if shape is None:
        raise ConventionsError("conventions: field 'shape' is missing (the number of nodes per axis, storage order)")
    ndim = 1 if quantity in ("E_avg", "1-E_avg") else 2
    if (not isinstance(shape, list) or len(shape) != ndim
            or not all(isinstance(n, int) and not isinstance(n, bool) and 2 <= n <= 4096 for n in shape)):
        raise ConventionsError(f"conventions: field 'shape' must be a list of {ndim} integer(s) in [2, 4096] for "
                               f"quantity {quantity!r}; got {shape!r}")
    axes = d.get("axes")
    if not isinstance(axes, list) or len(axes) != ndim:
        got = len(axes) if isinstance(axes, list) else axes
        raise ConventionsError(f"conventions: field 'axes' must list {ndim} axis table(s) ([[axes]]) in storage "
                               f"order for quantity {quantity!r}; got {got!r}")
    axes = tuple(_axis(a, k, shape[k]) for k, a in enumerate(axes))
    kinds = [a.axis for a in axes]
    want = ["roughness|alpha"] if ndim == 1 else ["mu", "roughness|alpha"]
    if kinds.count("mu") != ndim - 1 or len([k for k in kinds if k != "mu"]) != 1:
        raise ConventionsError(f"conventions: field 'axes' must be {' and '.join(want)} (in storage order); got "
                               f"{', '.join(kinds)}")
    r2a = _choice(d, "roughness_to_alpha", ("square", "identity"), default="square")
    lookup = _choice(d, "lookup", LOOKUPS, default="bilinear-clamped")
    channels = d.get("channels", [])
    if not isinstance(channels, list) or not all(isinstance(c, str) for c in channels) or \
            len(set(channels)) != len(channels):
        raise ConventionsError(f"conventions: field 'channels' must be a list of distinct names; got {channels!r}")
    channel = d.get("channel")
    if channels and fmt in ("exr", "netcdf"):
        raise ConventionsError(f"conventions: field 'channels' is for text, c-array and npy; format {fmt!r} names "
                               "its 'channel' or 'variable'")
    if channels:
        channel = channel if channel is not None else ("E" if "E" in channels else channels[0])
        if channel not in channels:
            raise ConventionsError(f"conventions: field 'channel' must be one of channels {channels}; got {channel!r}")
    if fmt == "exr" and not isinstance(channel, str):
        raise ConventionsError("conventions: field 'channel' is missing (format \"exr\" reads one named channel)")
    if fmt == "c-array" and not isinstance(d.get("array"), str):
        raise ConventionsError("conventions: field 'array' is missing (format \"c-array\" reads the array of that "
                               "name)")
    if fmt == "netcdf" and not isinstance(d.get("variable"), str):
        raise ConventionsError("conventions: field 'variable' is missing (format \"netcdf\" reads that variable)")
    if fmt in ("npy", "exr", "netcdf") and storage.startswith("text"):
        raise ConventionsError(f"conventions: field 'storage' {storage!r} is for text formats (format is {fmt!r})")
    if fmt == "netcdf" and storage == "float16":
        raise ConventionsError("conventions: field 'storage' float16 does not exist in netCDF (float32, float64, "
                               "unorm8, unorm16)")
    if fmt == "exr" and storage not in ("float32", "float16"):
        raise ConventionsError(f"conventions: field 'storage' of an EXR channel is float32 or float16; got "
                               f"{storage!r}")
    for key in ("array", "variable"):
        if key in d and {"array": "c-array", "variable": "netcdf"}[key] != fmt:
            raise ConventionsError(f"conventions: field {key!r} does not apply to format {fmt!r}")
    e_avg = d.get("e_avg", {})
    if not isinstance(e_avg, dict):
        raise ConventionsError(f"conventions: field 'e_avg' must be a table; got {e_avg!r}")
    _no_unknown_fields(e_avg, EAVG_FIELDS, "e_avg.")
    if len(e_avg) > 1:
        raise ConventionsError(f"conventions: field 'e_avg' takes one of array, follows, channel, variable; got "
                               f"{', '.join(e_avg)}")
    if e_avg:
        if ndim == 1:
            raise ConventionsError("conventions: field 'e_avg' is for E tables (this one holds E_avg)")
        (k, v), = e_avg.items()
        ok = {"array": fmt == "c-array", "follows": fmt in ("c-array", "text") and v is True,
              "channel": (fmt == "exr") or v in channels, "variable": fmt == "netcdf"}[k]
        if not ok:
            raise ConventionsError(f"conventions: field 'e_avg.{k}' = {v!r} does not apply to format {fmt!r}"
                                   + (f" with channels {channels}" if k == "channel" else ""))
    for key in ("name", "renderer", "source"):
        if key in d and not isinstance(d[key], str):
            raise ConventionsError(f"conventions: field {key!r} must be a string")
    return Conventions(model=model if isinstance(model, str) else json.dumps(model), quantity=quantity, format=fmt,
                       storage=storage, shape=tuple(shape), axes=axes, roughness_to_alpha=r2a, lookup=lookup,
                       array=d.get("array"), channel=channel, channels=tuple(channels), variable=d.get("variable"),
                       e_avg=dict(e_avg), name=d.get("name", "described"), renderer=d.get("renderer", ""),
                       source=d.get("source", ""))


def load_conventions(conventions) -> Conventions:
    """A :class:`Conventions` from a path to a ``.toml`` / ``.json`` file, a dict of the same fields, a preset name
    of :mod:`pumpup.luts` or a :class:`Conventions`.

    Raises
    ------
    ConventionsError
        One line naming the field that is wrong or missing.

    Examples
    --------
    >>> from pumpup.conventions import load_conventions
    >>> c = load_conventions("cycles")
    >>> c.shape, c.quantity, c.mu_axis.x_nodes()[:2].round(4).tolist()
    ((32, 32), 'E', [0.0001, 0.0323])
    """
    if isinstance(conventions, Conventions):
        return conventions
    if isinstance(conventions, dict):
        return _parse(conventions)
    if isinstance(conventions, str) and conventions in PRESET_FILES and not os.path.exists(conventions):
        return preset_conventions(conventions)
    if not isinstance(conventions, str | os.PathLike):
        raise ConventionsError(f"conventions must be a path to a .toml or .json file, a dict or a preset name; got "
                               f"{type(conventions).__name__}")
    path = os.fspath(conventions)
    if not os.path.isfile(path):
        raise ConventionsError(f"conventions: no such file: {path!r}")
    ext = os.path.splitext(path)[1].lower()
    if ext not in (".toml", ".json"):
        raise ConventionsError(f"conventions: {path!r} must be a .toml or .json file")
    if os.path.getsize(path) > 2**20:
        raise ConventionsError(f"conventions: {path!r} is over 1 MB; a description is a few lines")
    try:
        if ext == ".toml":
            try:
                import tomllib
            except ImportError:  # Python 3.10
                raise ConventionsError("conventions: TOML files need Python 3.11 or later; give the same fields as "
                                       "JSON") from None

            with open(path, "rb") as fh:
                d = tomllib.load(fh)
        else:
            with open(path) as fh:
                d = json.load(fh)
    except (ValueError, UnicodeDecodeError) as exc:
        raise ConventionsError(f"conventions: {path!r} is not valid {ext[1:].upper()}: {exc}") from None
    return _parse(d)


def preset_conventions(name: str) -> Conventions:
    """The conventions file shipped for a preset of :mod:`pumpup.luts` (``pumpup/data/conventions/<name>.toml``)."""
    if name not in PRESET_FILES:
        raise ConventionsError(f"preset must be one of {', '.join(PRESET_FILES)}; got {name!r}")
    c = load_conventions(os.path.join(PRESET_DIR, PRESET_FILES[name]))
    return c


# --------------------------------------------------------------------------------------------
# Reading
# --------------------------------------------------------------------------------------------

_NUMBER = re.compile(r"0[xX][0-9a-fA-F]+[uUlL]*|[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?[fFlLuU]*")


def _strip_comments(text: str) -> str:
    return re.sub(r"//[^\n]*", "", re.sub(r"/\*.*?\*/", " ", text, flags=re.S))


def _tokens(body: str) -> list[str]:
    return _NUMBER.findall(body)


def _values(tokens: list[str], c: Conventions, path: str, what: str) -> np.ndarray:
    """Text tokens -> stored values (unorm codes scaled, float16 bits decoded)."""
    st = c.storage
    hexes = [t for t in tokens if t[:2] in ("0x", "0X")]
    if st.startswith("unorm"):
        try:
            codes = np.array([int(t.rstrip("uUlL"), 0) for t in tokens], dtype=np.int64)
        except ValueError:
            bad = next(t for t in tokens if not re.fullmatch(r"(0[xX][0-9a-fA-F]+|\d+)[uUlL]*", t))
            raise LutError(f"{path!r}: {what} holds {bad!r}; storage {st} is read as integer codes") from None
        q = _unorm_max(st)
        if codes.size and (codes.min() < 0 or codes.max() > q):
            k = int(np.argmax((codes < 0) | (codes > q)))
            raise LutError(f"{path!r}: {what}: code {codes[k]} at item {k} is outside [0, {q}] for storage {st}")
        return codes / q
    if hexes:
        if st != "float16":
            raise LutError(f"{path!r}: {what} holds hexadecimal words ({hexes[0]}); only storage float16 reads "
                           "them (as half-float bits)")
        if len(hexes) != len(tokens):
            raise LutError(f"{path!r}: {what} mixes hexadecimal words and decimal numbers")
        words = np.array([int(t.rstrip("uUlL"), 16) for t in tokens], dtype=np.int64)
        if words.max() > 0xFFFF:
            raise LutError(f"{path!r}: {what}: word {hex(int(words.max()))} is wider than a half float")
        return words.astype(np.uint16).view(np.float16).astype(np.float64)
    vals = np.array([float(t.rstrip("fFlLuU")) for t in tokens], dtype=np.float64)
    if st in ("float32", "float16") or st.startswith("text"):
        vals = vals.astype(np.float32).astype(np.float64)  # what the compiler stores
    return vals


def _c_body(text: str, name: str, path: str) -> tuple[str, int | None]:
    m = re.search(r"\b" + re.escape(name) + r"\s*((?:\[[^\]]*\]\s*)*)=\s*\{", text)
    if not m:
        found = re.findall(r"(\w+)\s*(?:\[[^\]]*\]\s*)+=\s*\{", text)
        raise LutError(f"{path!r}: no array named {name!r} (arrays found: {', '.join(found) or 'none'})")
    declared = None
    dims = re.findall(r"\[([^\]]*)\]", m.group(1))
    if dims and all(re.fullmatch(r"\s*\d+\s*", d) for d in dims):
        declared = int(np.prod([int(d) for d in dims]))
    depth, k = 1, m.end()
    while depth and k < len(text):
        depth += {"{": 1, "}": -1}.get(text[k], 0)
        k += 1
    if depth:
        raise LutError(f"{path!r}: the initializer of {name!r} does not end (no closing brace)")
    return text[m.end():k - 1], declared


def _check_size(vals: np.ndarray, need: int, path: str, what: str, declared: int | None = None) -> None:
    if len(vals) != need or (declared is not None and declared != need):
        dec = f" (declared {declared})" if declared is not None else ""
        raise LutError(f"{path!r}: {what} has {len(vals)} values{dec}; the conventions need {need}")


def _split_channels(vals: np.ndarray, c: Conventions) -> dict:
    k = len(c.channels) or 1
    grid = vals.reshape(*c.shape, k)
    names = c.channels or (c.channel or "value",)
    return {n: grid[..., i] for i, n in enumerate(names)}


def _npy(path: str, c: Conventions) -> np.ndarray:
    shape, dtype, offset = npy_header(path)
    want = tuple(c.shape) + ((len(c.channels),) if c.channels else ())
    if shape != want:
        raise LutError(f"{path!r}: array of shape {shape}; the conventions need {want}")
    if dtype.kind not in "fu":
        raise LutError(f"{path!r}: array of dtype {dtype}; tables are floats or unsigned integer codes")
    check_npy_size(path, shape, dtype, offset)
    arr = np.load(path, allow_pickle=False)
    if dtype.kind == "u":
        if not c.storage.startswith("unorm"):
            raise LutError(f"{path!r}: integer array ({dtype}) for storage {c.storage}; integers are unorm codes")
        return arr.astype(np.float64) / _unorm_max(c.storage)
    return arr.astype(np.float64)


def _read(c: Conventions, path: str) -> dict:
    if not os.path.exists(path):
        raise LutError(f"no such file: {path!r}")
    if not os.path.isfile(path):
        raise LutError(f"{path!r} is not a regular file (a directory, a FIFO or a device): tables are read from files")
    n = int(np.prod(c.shape))
    k = len(c.channels) or 1
    key = "E_avg" if c.average else "E"
    out: dict = {}
    avg = None
    if c.format in ("c-array", "text"):
        if os.path.getsize(path) > MAX_TEXT_BYTES:
            raise LutError(f"{path!r} holds {os.path.getsize(path)} bytes; a text table is read up to "
                           f"{MAX_TEXT_BYTES}")
        with open(path, errors="replace") as fh:
            text = _strip_comments(fh.read())
        if c.format == "c-array":
            body, declared = _c_body(text, c.array, path)
            what = f"array {c.array}"
        else:
            body, declared, what = text, None, "the file"
        vals = _values(_tokens(body), c, path, what)
        follows = bool(c.e_avg.get("follows"))
        need = n * k + (c.rough_axis.n if follows else 0)
        _check_size(vals, need, path, what, declared)
        chans = _split_channels(vals[:n * k], c)
        if follows:
            avg = vals[n * k:]
        elif "array" in c.e_avg:
            try:
                body2, dec2 = _c_body(text, c.e_avg["array"], path)
            except LutError:
                body2 = None
            if body2 is not None:
                v2 = _values(_tokens(body2), c, path, f"array {c.e_avg['array']}")
                _check_size(v2, c.rough_axis.n, path, f"array {c.e_avg['array']}", dec2)
                avg = v2
        main = chans[c.channel or "value"] if c.channels else chans[next(iter(chans))]
    elif c.format == "npy":
        arr = _npy(path, c)
        if c.channels:
            chans = {nm: arr[..., i] for i, nm in enumerate(c.channels)}
            main = chans[c.channel]
        else:
            chans, main = {}, arr
    elif c.format == "exr":
        chans = exr_channels(path)
        if c.channel not in chans:
            raise LutError(f"{path!r}: no channel {c.channel!r} (channels: {', '.join(chans) or 'none'})")
        main = chans[c.channel]
        if main.shape != tuple(c.shape):
            raise LutError(f"{path!r}: channel {c.channel} of shape {main.shape}; the conventions need "
                           f"{tuple(c.shape)} (rows first)")
    else:  # netcdf
        import xarray as xr

        try:
            with xr.open_dataset(path) as ds:
                ds.load()
        except Exception as exc:  # netCDF4 and xarray raise several types for damaged files
            raise LutError(f"{path!r} is not a readable netCDF file: {exc}") from None
        if c.variable not in ds:
            raise LutError(f"{path!r}: no variable {c.variable!r} (variables: {', '.join(map(str, ds.data_vars))})")
        main = np.asarray(ds[c.variable].values, dtype=np.float64)
        if main.shape != tuple(c.shape):
            raise LutError(f"{path!r}: variable {c.variable} of shape {main.shape}; the conventions need "
                           f"{tuple(c.shape)}")
        chans = {nm: np.asarray(ds[nm].values, dtype=np.float64) for nm in ds.data_vars}
        if c.storage.startswith("unorm") and np.issubdtype(ds[c.variable].dtype, np.integer):
            main = main / _unorm_max(c.storage)
    if avg is None and c.format in ("npy", "exr", "netcdf") and c.e_avg:
        nm = c.e_avg.get("channel") or c.e_avg.get("variable")
        if nm in chans:
            a = np.asarray(chans[nm], dtype=np.float64)
            if a.shape == tuple(c.shape):  # repeated along mu: the values at the first mu node
                a = c.to_table(a)[0, :]
            if a.shape == (c.rough_axis.n,) and np.all(np.isfinite(a)):
                avg = a
    _check_range(main, c, path, key)
    table = c.to_table(main)
    sign = c.stores == "1-E"
    out[key] = 1.0 - table if sign else table.copy()
    if avg is not None:
        _check_range(avg, c, path, "E_avg")
        out["E_avg"] = 1.0 - avg if sign else np.asarray(avg, dtype=np.float64)
    return out


def _check_range(v: np.ndarray, c: Conventions, path: str, what: str) -> None:
    bad = ~np.isfinite(v) | (v < -0.5) | (v > 1.5)
    if bad.any():
        idx = tuple(int(i) for i in np.unravel_index(int(np.argmax(bad)), v.shape))
        q = c.quantity if what != "E_avg" else ("1-E_avg" if c.stores == "1-E" else "E_avg")
        raise LutError(f"{path!r}: {what} value {float(v[idx]):g} at {list(idx)} is out of range: a stored {q} lies in "
                       "[0, 1] (wrong storage or quantity?)")


# --------------------------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------------------------


def _text_items(stored: np.ndarray, storage: str, c_suffix: bool) -> list[str]:
    m = _TEXT_DECIMALS.match(storage)
    f = "f" if c_suffix else ""
    if m:
        nd = int(m.group(1))
        return [f"{float(np.float32(x)):.{nd}f}{f}" for x in stored]
    if storage.startswith("unorm"):
        q = _unorm_max(storage)
        return [str(int(v)) for v in np.round(np.clip(stored, 0, 1) * q)]
    if storage == "float16":
        return [f"0x{int(w):04x}" for w in stored.astype(np.float16).view(np.uint16)]
    if storage == "float64":
        return [repr(float(x)) for x in stored]
    return [f"{float(np.float32(x)):.9g}{f}" for x in stored]


def _write(c: Conventions, E, path: str, e_avg) -> str:
    from .tables import atomic_path

    E = np.asarray(E, dtype=np.float64)
    want = (c.rough_axis.n,) if c.average else (c.mu_axis.n, c.rough_axis.n)
    if E.shape != want:
        raise LutError(f"values of shape {E.shape}; the conventions need {want} (mu, roughness)")
    sign = c.stores == "1-E"
    stored = c.to_storage(1.0 - E if sign else E)
    avg = None
    if e_avg is not None and c.e_avg:
        avg = np.asarray(e_avg, dtype=np.float64)
        avg = 1.0 - avg if sign else avg
    k = len(c.channels) or 1
    grid = np.zeros((*c.shape, k))
    ci = c.channels.index(c.channel) if c.channels else 0
    grid[..., ci] = stored
    for i, nm in enumerate(c.channels):
        if nm == c.e_avg.get("channel") and avg is not None:
            grid[..., i] = c.to_storage(np.broadcast_to(avg[None, :], (c.mu_axis.n, c.rough_axis.n)))
    with atomic_path(path) as tmp:
        if c.format in ("c-array", "text"):
            flat = grid.ravel()
            if c.e_avg.get("follows") and avg is not None:
                flat = np.concatenate([flat, avg])
            ctype = {"unorm8": "unsigned char", "unorm16": "unsigned short", "float16": "unsigned short",
                     "float64": "double"}.get(c.storage, "float")
            items = _text_items(flat, c.storage, c.format == "c-array" and ctype == "float")
            per = c.shape[-1] * k
            lines = ["  " + ", ".join(items[a:a + per]) for a in range(0, len(items), per)]
            if c.format == "text":
                text = ",\n".join(lines) + "\n"
            else:
                text = f"static const {ctype} {c.array}[{len(items)}] = {{\n" + ",\n".join(lines) + "\n};\n"
                if "array" in c.e_avg and avg is not None:
                    it = _text_items(avg, c.storage, ctype == "float")
                    text += f"\nstatic const {ctype} {c.e_avg['array']}[{len(it)}] = {{\n  " + ", ".join(it) + "\n};\n"
            with open(tmp, "w") as fh:
                fh.write(f"/* {c.renderer or c.name} albedo table of {c.model}, {c.quantity}, storage {c.storage} */\n"
                         + text if c.format == "c-array" else text)
        elif c.format == "npy":
            if c.storage.startswith("unorm"):
                arr = np.round(np.clip(grid, 0, 1) * _unorm_max(c.storage)).astype(
                    np.uint8 if c.storage == "unorm8" else np.uint16)
            else:
                arr = grid.astype(c.storage)
            if not c.channels:
                arr = arr[..., 0]
            with open(tmp, "wb") as fh:
                np.save(fh, arr)
        elif c.format == "exr":
            import OpenEXR

            if c.storage not in ("float32", "float16"):
                raise LutError(f"an EXR channel holds float32 or float16, not {c.storage}")
            chans = {c.channel: np.ascontiguousarray(stored.astype(c.storage))}
            if avg is not None and "channel" in c.e_avg:
                rep = c.to_storage(np.broadcast_to(avg[None, :], (c.mu_axis.n, c.rough_axis.n)))
                chans[c.e_avg["channel"]] = np.ascontiguousarray(rep.astype(c.storage))
            header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
            with OpenEXR.File(header, chans) as f:
                f.write(tmp)
        else:
            import xarray as xr

            dims = tuple(f"{a.axis}_node" for a in c.axes)
            if c.storage.startswith("unorm"):
                data = np.round(np.clip(stored, 0, 1) * _unorm_max(c.storage)).astype(
                    np.uint8 if c.storage == "unorm8" else np.uint16)
            else:
                data = stored.astype(c.storage)
            ds = xr.Dataset({c.variable: (dims, data)})
            if avg is not None and "variable" in c.e_avg:
                ds[c.e_avg["variable"]] = ((f"{c.rough_axis.axis}_node",), avg)
            ds.to_netcdf(tmp, format="NETCDF4")
    return path


# --------------------------------------------------------------------------------------------
# Audit
# --------------------------------------------------------------------------------------------


def _spec(c: Conventions, model=None) -> tuple[dict, str]:
    return model_spec(c.model if model is None else model)


def audit_conventions(path, conventions, *, model=None, rtol: float = 1e-7, lookup_check: bool = True,
                      eavg: bool = True, per_cell: int = 1, stride: int | None = None, png: str | None = None,
                      threads: int | None = None, max_regions: int = 200) -> AuditResult:
    """Grade the table at ``path`` against pumpup's truth, read and looked up as ``conventions`` describe.

    The description is checked before the file is read, and the file against the description before any
    quadrature.  The report gives the node errors relative to E and to the stored quantity, the worst nodes in
    the file's own indices and axes, E > 1, monotonicity violations beyond the storage's rounding (and those
    within it), the renderer's look-up error between the nodes, and E_avg against the table's own E and the truth.

    Examples
    --------
    A 3 x 3 table of 1 - E as unorm16 codes, written from pumpup's values and audited back:

    >>> import os, tempfile, pumpup
    >>> from pumpup.luts import truth_grid
    >>> d = {"model": "ggx:shadowing=separable", "quantity": "1-E", "format": "text", "storage": "unorm16",
    ...      "shape": [3, 3], "axes": [{"axis": "mu", "clamp": [[0, 0.1]]}, {"axis": "alpha", "clamp": [[0, 0.1]]}]}
    >>> c = load_conventions(d)
    >>> mu, alpha = c.nodes()
    >>> E = truth_grid({"type": "ggx", "shadowing": "separable"}, "alpha", mu, c.rough_of(alpha))["E"]
    >>> path = c.write(E, os.path.join(tempfile.mkdtemp(), "t.txt"))
    >>> r = pumpup.audit(path, conventions=d, lookup_check=False)
    >>> r.max_abs <= 0.5 / 65535 + 1e-9
    True
    """
    c = load_conventions(conventions)
    spec, param = _spec(c, model)
    tab = c.read(path)
    mu, x = c.nodes()
    r = c.rough_of(x)
    bound = storage_bound(c.storage)
    mask, val = c.fixed_mask()
    a_label = c.rough_axis.axis
    shown = {**spec, param: "roughness^2" if c.alpha_of(2.0) == 4.0 else a_label}
    if c.average:
        true_avg, err = mean_albedo_grid(spec, param, r, rtol=rtol, threads=threads, max_regions=max_regions)
        true_avg = np.where(mask, val, true_avg)
        err = np.where(mask, 0.0, err)
        res = grade(tab["E_avg"][None, :], true_avg[None, :], err[None, :], bound, c.stores,
                    np.array([float("nan")]), x, name=c.name, spec=shown,
                    labels=("-", a_label), cell=lambda i, j: f"[{j}]")
    else:
        tr = truth_grid(spec, param, mu, r, rtol=rtol, threads=threads, max_regions=max_regions)
        truth = np.where(mask, val, tr["E"])
        terr = np.where(mask, 0.0, tr["E_error"])
        res = grade(tab["E"], truth, terr, bound, c.stores, mu, x, name=c.name,
                    spec=shown, labels=("mu", a_label), cell=c.cell)
        if eavg and "E_avg" in tab:
            own = c.own_average(tab["E"])
            true_avg, true_err = mean_albedo_grid(spec, param, r, rtol=rtol, threads=threads,
                                                  max_regions=max_regions)
            res.eavg = eavg_grades(tab["E_avg"], own, true_avg, true_err, x)
        if lookup_check:
            big = max(c.shape) > 64
            st = stride or (4 if big else 1)
            E = tab["E"]
            mu_d = c.mu_axis.dense(per_cell, st)
            r_d = c.rough_of(c.rough_axis.dense(per_cell, st))
            le = lookup_error_on(lambda m, rr: c.look_up(E, m, c.x_of_rough(rr)), spec, param, mu_d, r_d,
                                 threads=threads, max_regions=max_regions)
            le["where"] = (le["where"][0], float(c.x_of_rough(le["where"][1])))
            le["grid_where"] = (le["grid_where"][0], float(c.x_of_rough(le["grid_where"][1])))
            g = le["grid"]
            le["grid"] = (g[0], c.x_of_rough(g[1]), g[2])
            res.lookup = le
    if png:
        from .luts import error_map_png

        error_map_png(res, png)
    return res
