"""Exact images of a sphere: Lewis's shader test (002 Fig. 2) and the white furnace.

No renderer is involved: every pixel is a closed-form function of the model.

Geometry
--------
An orthographic camera looks at a unit sphere centred at the origin along -z; the
image plane is the square [-1, 1]^2 of world x (to the right) and y (up), so the sphere
touches the four edges of the image.  Pixel (i, j) of a ``size x size`` image (row i
from the top, column j from the left) has its centre at

    x = -1 + (2 j + 1) / size,    y = 1 - (2 i + 1) / size,

and lies on the sphere if x^2 + y^2 < 1; there the world normal is
N = (x, y, sqrt(1 - x^2 - y^2)) and the direction towards the viewer is V = (0, 0, 1)
for every pixel.  Pixels off the sphere hold radiance 0 and ``mask`` False.

Local shading frame (pumpup's convention: the normal is the local z axis)
-------------------------------------------------------------------------
The tangent T is the direction of the parallels of a globe whose poles are at the top
and bottom of the image (the world y axis): T = (y_w x N) / |y_w x N| = (N_z, 0, -N_x) /
sqrt(N_x^2 + N_z^2), and the bitangent is B = N x T (it runs along the meridians,
towards the top pole).  A world direction w has the local coordinates (w.T, w.B, w.N).
At the centre of the image T, B, N are the world x, y, z axes.  The tangent only
matters for anisotropic models (``ward_aniso``, ``lafortune`` with cx != cy): their
local x axis (a_x of Ward) runs horizontally around the sphere.  T is defined at every
pixel centre, because N_z > 0 there.

Directional light (002 Fig. 2)
------------------------------
One directional source at angle Phi_L from the viewing direction, seen from the centre of
the sphere (Lewis's test configuration; no ambient light), in the plane of the view and
the image's horizontal axis: L = (sin Phi_L cos psi, sin Phi_L sin psi, cos Phi_L) with
the azimuth psi = 0 (light to the right) by default.  Phi_L in [0, 180) degrees; beyond
90 the light is behind the sphere and lights a crescent.  The radiance towards the
viewer is (002 eq. 7 with L_a = 0; 001 eq. 3)

    L_r = E f_r(L, V) (N.L)_+,

with E the irradiance the source gives a surface facing it (default 1) and f_r the
model's whole BRDF: a shader's diffuse term (``kd``, ``k_sigma`` < 1) is part of it.

Furnace
-------
Under a uniform white sky of radiance 1 a convex object sees only the sky, so its
radiance towards V is integral f_r(L, V) (N.L) d omega_L over the hemisphere: for a
reciprocal BRDF exactly the directional albedo a(mu_V) at mu_V = N.V (000 eq. 2), which
pumpup's engine computes.  :func:`furnace` tabulates a(mu) once per session
(``pumpup.tabulate``, adaptive grid down to mu = 1e-8; for a reciprocal model at the default
tolerances it is the pumping operator's own table, ``pumpup.operators.pumping.base_table``) and looks
every pixel up in the table; ``Image.error`` is the table's stated bound (twice the measured interpolation
error plus the largest quadrature error, as in ``AlbedoTable.upper``).  A non-reciprocal
model is integrated over the incidence direction instead (its albedo with the roles of
wi and wo exchanged); an anisotropic one is refused (its furnace radiance depends on the
azimuth of V, which one table in mu cannot give).

Output
------
:func:`write_exr` writes linear radiance (32-bit float, channel ``Y``, the sphere mask in
``A``) with the model and geometry in the header; :func:`tone_map` and :func:`write_png`
make a display image with a stated tone map: radiance x 2^exposure, the sRGB transfer
function (IEC 61966-2-1), values above 1 clipped and **marked magenta**, the background
slate blue.  :func:`grid_figure` assembles labelled grids (matplotlib).
"""

from __future__ import annotations

import json
import math
import os
import textwrap
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from .core import BRDF

__all__ = [
    "Image",
    "SphereGeometry",
    "geometry",
    "light_direction",
    "sphere",
    "furnace",
    "tone_map",
    "write_exr",
    "read_exr",
    "write_png",
    "grid_figure",
    "label",
    "lewis_exponent",
    "check_size",
    "check_light",
    "MIN_SIZE",
    "MAX_SIZE",
]

#: smallest and largest image accepted (pixels per side; 4096^2 pixels take about 2 GB of geometry)
MIN_SIZE = 8
MAX_SIZE = 4096
#: display colour of clipped pixels (radiance x 2^exposure > 1), and of the background, in sRGB [0, 1]
CLIP_COLOUR = (1.0, 0.0, 1.0)
BACKGROUND = (0.20, 0.24, 0.36)


# --------------------------------------------------------------------------------------------
# Input checks (one clear line each, before any work)
# --------------------------------------------------------------------------------------------


def check_size(size) -> int:
    """``size`` as an int in [:data:`MIN_SIZE`, :data:`MAX_SIZE`], or a ValueError naming it."""
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) and not (
            isinstance(size, (float, np.floating)) and float(size).is_integer()):
        raise ValueError(f"size must be an integer number of pixels >= {MIN_SIZE}, got {size!r}")
    if not MIN_SIZE <= int(size) <= MAX_SIZE:
        raise ValueError(f"size must be an integer number of pixels >= {MIN_SIZE} and <= {MAX_SIZE}, got {int(size)}")
    return int(size)


def check_light(light_deg, from_text: bool = False) -> float:
    """``light_deg`` (Phi_L, degrees) as a float in [0, 180), or a ValueError naming it; a string only
    ``from_text`` (the command line's).
    """
    if not from_text and (isinstance(light_deg, (str, bytes, bool, np.bool_))):
        raise ValueError(f"light angle Phi_L must be a number of degrees in [0, 180), got {light_deg!r}")
    try:
        v = float(light_deg)
    except (TypeError, ValueError):
        raise ValueError(f"light angle Phi_L must be a number of degrees in [0, 180), got {light_deg!r}") from None
    if not (0.0 <= v < 180.0):  # also rejects nan
        raise ValueError(f"light angle Phi_L must be in [0, 180) degrees, got {light_deg!r}")
    return v


def _load(f):
    from .core import load

    return f if isinstance(f, BRDF) else load(f)


# --------------------------------------------------------------------------------------------
# Geometry
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class SphereGeometry:
    """Per-pixel geometry of the orthographic unit sphere (see the module docstring).

    ``mask`` (size, size) is True on the sphere; ``normal``, ``tangent``, ``bitangent`` are
    the world vectors N, T, B of the pixels on the sphere, shape (count, 3), in row-major
    pixel order; ``view`` = (V.T, V.B, V.N) is the local view direction of those pixels.
    """

    size: int
    mask: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    bitangent: np.ndarray
    view: np.ndarray

    def to_local(self, w) -> np.ndarray:
        """A world direction (3,) or per-pixel directions (count, 3) in each pixel's local frame."""
        w = np.asarray(w, dtype=np.float64)
        return np.stack([np.sum(w * self.tangent, axis=-1), np.sum(w * self.bitangent, axis=-1),
                         np.sum(w * self.normal, axis=-1)], axis=-1)


_GEOMETRY: dict = {}


def geometry(size: int) -> SphereGeometry:
    """The :class:`SphereGeometry` of a ``size x size`` image (cached per size)."""
    size = check_size(size)
    if size not in _GEOMETRY:
        c = -1.0 + (2.0 * np.arange(size) + 1.0) / size  # pixel centres, left to right
        x = c[None, :]
        y = -c[:, None]  # row 0 at the top: y = 1 - (2 i + 1) / size
        r2 = x * x + y * y
        mask = r2 < 1.0
        xs = np.broadcast_to(x, mask.shape)[mask]
        ys = np.broadcast_to(y, mask.shape)[mask]
        zs = np.sqrt(1.0 - r2[mask])
        n = np.stack([xs, ys, zs], axis=-1)
        h = np.sqrt(xs * xs + zs * zs)  # > 0: zs > 0 at every pixel centre on the sphere
        t = np.stack([zs / h, np.zeros_like(xs), -xs / h], axis=-1)  # T = y_w x N / |y_w x N|
        b = np.cross(n, t)  # B = N x T
        view = np.stack([t[:, 2], b[:, 2], n[:, 2]], axis=-1)  # V = (0, 0, 1) in the local frame
        for a in (mask, n, t, b, view):
            a.setflags(write=False)
        _GEOMETRY.clear()  # keep one size: a 2048^2 geometry is 400 MB
        _GEOMETRY[size] = SphereGeometry(size, mask, n, t, b, view)
    return _GEOMETRY[size]


def light_direction(light_deg: float, azimuth_deg: float = 0.0) -> np.ndarray:
    """The world direction towards the light at Phi_L = ``light_deg`` from the view (0, 0, 1).

    ``azimuth_deg`` turns it about the view axis: 0 puts the light to the right of the
    image, 90 above it.
    """
    p = math.radians(check_light(light_deg))
    if not math.isfinite(float(azimuth_deg)):
        raise ValueError(f"light azimuth must be a finite number of degrees, got {azimuth_deg!r}")
    a = math.radians(float(azimuth_deg))
    return np.array([math.sin(p) * math.cos(a), math.sin(p) * math.sin(a), math.cos(p)])


# --------------------------------------------------------------------------------------------
# Images
# --------------------------------------------------------------------------------------------


@dataclass
class Image:
    """An exact image of the sphere.

    Attributes
    ----------
    radiance : ndarray, (size, size) or (size, size, channels)
        Linear radiance [W / (m^2 sr) for unit irradiance or sky radiance]; 0 off the sphere.
    mask : ndarray of bool, (size, size)
        Pixel centre on the sphere.
    kind : {"sphere", "furnace"}
    spec : dict
        The model.
    error : float or None
        For a furnace image, a bound on |radiance - a(mu_V)| over the image (the albedo
        table's stated bound); None for a directional-light image, which is f_r x cosine to
        rounding (no approximation beyond the model's own evaluation).
    params : dict
        light_deg, azimuth_deg, irradiance (sphere) or the table's tolerances (furnace), size.
    """

    radiance: np.ndarray
    mask: np.ndarray
    kind: str
    spec: dict
    error: float | None = None
    params: dict = field(default_factory=dict)

    @property
    def size(self) -> int:
        """The image's width and height in pixels."""
        return int(self.mask.shape[0])

    def header(self) -> dict:
        """Plain-text metadata (for the EXR header and the PNG text chunks)."""
        out = {"pumpup_kind": f"pumpup {self.kind} image", "pumpup_spec": json.dumps(self.spec, sort_keys=True),
               "pumpup_params": json.dumps(self.params, sort_keys=True)}
        if self.error is not None:
            out["pumpup_error_bound"] = repr(float(self.error))
        from ._version import __version__

        out["pumpup_version"] = __version__
        return out


def _scatter(values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    values = np.asarray(values, dtype=np.float64)
    out = np.zeros(mask.shape + values.shape[1:])
    out[mask] = values
    return out


def sphere(f, light_deg: float = 0.0, size: int = 256, *, irradiance: float = 1.0, azimuth_deg: float = 0.0) -> Image:
    """The sphere of 002 Fig. 2 under one directional light: L_r = E f_r(L, V) (N.L)_+.

    Parameters
    ----------
    f : BRDF or spec
        Any pumpup model (its diffuse term, if it has one, is part of f_r).
    light_deg : float, in [0, 180)
        Phi_L, the angle between the light and the view direction [degrees].
    size : int, >= 8
        Pixels per side.
    irradiance : float, > 0
        E, the irradiance on a surface facing the light [W / m^2].
    azimuth_deg : float
        Turns the light about the view axis (0: to the right, 90: above).

    Returns
    -------
    Image
        ``radiance`` = E f_r(L_loc, V_loc) (N.L) per pixel, in each pixel's local frame
        (module docstring), 0 where N.L <= 0 and off the sphere.

    Examples
    --------
    >>> import pumpup.render as R
    >>> im = R.sphere({"type": "lambert", "albedo": 1.0}, light_deg=0, size=8)
    >>> round(float(im.radiance.max()) * 3.141592653589793, 3)   # pi x radiance = N.L next to the centre
    0.984
    """
    light_deg = check_light(light_deg)
    size = check_size(size)
    e = float(irradiance)
    if not (math.isfinite(e) and e > 0):
        raise ValueError(f"irradiance must be a finite number > 0, got {irradiance!r}")
    f = _load(f)
    g = geometry(size)
    lw = light_direction(light_deg, azimuth_deg)
    wi = g.to_local(lw)  # unit to rounding: T, B, N orthonormal
    cos_l = np.maximum(wi[:, 2], 0.0)  # N.L
    fr = np.asarray(f._eval(wi, g.view), dtype=np.float64)
    cos = cos_l.reshape(cos_l.shape + (1,) * (fr.ndim - 1))
    rad = e * fr * cos  # 002 eq. 7 with L_a = 0 (001 eq. 3)
    return Image(_scatter(rad, g.mask), g.mask, "sphere", f.spec, None,
                 {"light_deg": light_deg, "azimuth_deg": float(azimuth_deg), "irradiance": e, "size": size})


class Transposed(BRDF):
    """f_T(wi, wo) = f(wo, wi): its albedo at mu is the furnace radiance of f seen from mu_V = mu.

    For a non-reciprocal f the radiance towards V under a white sky is
    integral f(L, V) (N.L) d omega_L, the albedo of f_T at mu_V.  No quadrature hint (the
    engine's generic cubature finds the lobe); not registered, so its spec does not load.
    """

    params: ClassVar[dict] = {}
    constant = None
    reciprocal = False
    type = "transposed"

    def __init__(self, base: BRDF) -> None:
        super().__init__()
        self.base = base

    @property
    def spec(self) -> dict:
        return {"type": "transposed", "base": self.base.spec}

    def _eval(self, wi, wo):
        return self.base._eval(wo, wi)


def _anisotropy(f) -> float:
    """Largest relative change of f under rotations of both directions about N (measured on 4096 pairs)."""
    from .core import direction_set

    d = direction_set(8, 8)
    # every pair spelled out (arrays of one shape): the model's row kernel, not its broadcasting ufunc, whose first
    # call builds a wrapper (the values are the same)
    wi, wo = (np.ascontiguousarray(a) for a in np.broadcast_arrays(d[:, None, :], d[None, :, :]))
    f0 = np.asarray(f._eval(wi, wo), dtype=np.float64)
    worst = 0.0
    for psi in (0.7, 2.1, 4.0):
        c, s = math.cos(psi), math.sin(psi)
        rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        f1 = np.asarray(f._eval(wi @ rot.T, wo @ rot.T), dtype=np.float64)
        # relative to the pair, but not below 1e-6 of the largest value: at the edge of a lobe
        # ((R.V) ~ 1e-16) rounding flips f between 0 and 1e-300
        scale = np.maximum(np.maximum(np.abs(f0), np.abs(f1)), 1e-6 * float(np.abs(f0).max()))
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = np.where(scale > 0, np.abs(f1 - f0) / scale, 0.0)
        worst = max(worst, float(rel.max()))
    return worst


#: relative change under a rotation about N above which :func:`furnace` calls a model anisotropic
ISOTROPY_TOL = 1e-9


#: furnace tables that the pumping operator's cache does not hold: key -> AlbedoTable
_TABLES: dict = {}
#: model key -> whether its furnace integrates f(wo, wi) (measured once: not reciprocal)
_TRANSPOSED: dict = {}


def _pump_module():
    """The module pumpup.operators.pumping (where the pumping tables are cached)."""
    from .operators import pumping

    return pumping


def furnace_table(f, mu_min: float = 1e-8, *, rtol: float | None = None, interp_tol: float | None = None):
    """The albedo table a furnace image looks up: (AlbedoTable, bound, transposed).

    With the default tolerances (None: ``pumpup.operators.pumping.TABLE_RTOL`` and ``TABLE_INTERP_TOL``, 1e-9
    and 1e-7) the table of a reciprocal model is the pumping operator's (``pumpup.operators.pumping.base_table``,
    down to mu = 1e-8, computed once per session and shared: the furnace of a pumped level is the
    table the next level divides by); other tables are cached here per spec and tolerances.
    ``mu_min`` is the smallest mu the table must reach without extrapolation.  ``bound`` is the
    table's stated error bound (``AlbedoTable.margin``); ``transposed`` is True when f is not
    reciprocal and the table holds the albedo of f(wo, wi).
    """
    from .core import SpecError, check_reciprocity
    from .tables import AlbedoTable, tabulate

    pump = _pump_module()

    f = _load(f)
    fkey = pump._key(f)
    if fkey not in _TRANSPOSED:
        probe = np.asarray(f._eval(np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0])))
        if probe.ndim:
            raise SpecError(f"furnace: {f.type} has {probe.shape} channels; the albedo engine integrates one channel")
        aniso = _anisotropy(f)
        if aniso > ISOTROPY_TOL:
            raise SpecError(f"furnace: {f.type} is anisotropic (f changes by {aniso:.2g} relative under a rotation "
                            "about N), so its furnace radiance depends on the azimuth of V; one table in mu cannot "
                            "give it")
        _TRANSPOSED[fkey] = not (f.reciprocal and check_reciprocity(f).reciprocal)
    transposed = _TRANSPOSED[fkey]
    rtol = pump.TABLE_RTOL if rtol is None else float(rtol)
    interp_tol = pump.TABLE_INTERP_TOL if interp_tol is None else float(interp_tol)
    # a hair below mu_min: the grid's last decade is 10^log10(mu_min), which may round up
    low = min(float(mu_min) * (1.0 - 1e-9), 1e-8)
    if not transposed and (rtol, interp_tol) == (pump.TABLE_RTOL, pump.TABLE_INTERP_TOL) and low >= 1e-8 * (1 - 1e-9):
        table = pump.base_table(f, progress=False)
    else:
        key = (("transposed " if transposed else "") + fkey, rtol, interp_tol, low)
        if key not in _TABLES:
            g = Transposed(f) if transposed else f
            ds = tabulate(g, rtol=rtol, interp_tol=interp_tol, mu_min=low, progress=False)
            _TABLES[key] = AlbedoTable.from_dataset(ds)
        table = _TABLES[key]
    if table.mu[0] > mu_min:  # never: the grids start at or below mu_min
        raise AssertionError("furnace table does not reach the smallest mu of the image")
    return table, float(table.margin), transposed


def furnace(f, size: int = 256, *, rtol: float | None = None, interp_tol: float | None = None) -> Image:
    """The sphere in a white furnace (uniform sky of radiance 1): pixel = a(mu_V), mu_V = N.V.

    Parameters
    ----------
    f : BRDF or spec
        An isotropic one-channel model (a non-reciprocal one is integrated over the
        incidence direction: the radiance it sends towards V).
    size : int, >= 8
        Pixels per side.
    rtol, interp_tol : float, optional
        Quadrature and interpolation tolerances of the albedo table (``pumpup.tabulate``); by default
        those of the pumping operator's tables (1e-9, 1e-7), whose cache it shares
        (:func:`furnace_table`).

    Returns
    -------
    Image
        ``radiance`` = a(mu_V) from one adaptive albedo table (down to mu = 1e-8, computed once per
        session) and a look-up per pixel; ``error`` is the table's stated bound, so
        |radiance - exact| <= error at every pixel.  Lambert with albedo rho gives rho.

    Examples
    --------
    >>> import pumpup.render as R
    >>> im = R.furnace({"type": "lambert", "albedo": 0.7}, size=8)
    >>> bool(abs(im.radiance[im.mask] - 0.7).max() < 1e-12)
    True
    """
    size = check_size(size)
    f = _load(f)
    g = geometry(size)
    mu = g.view[:, 2]  # N.V
    table, bound, transposed = furnace_table(f, float(mu.min()), rtol=rtol, interp_tol=interp_tol)
    rad = table(mu)  # 000 eq. 2 (for f(wo, wi) when transposed), one look-up per pixel
    pump = _pump_module()
    return Image(_scatter(rad, g.mask), g.mask, "furnace", f.spec, bound,
                 {"size": size, "rtol": pump.TABLE_RTOL if rtol is None else float(rtol),
                  "interp_tol": pump.TABLE_INTERP_TOL if interp_tol is None else float(interp_tol),
                  "table_nodes": int(len(table.mu)),
                  "transposed": bool(transposed)})


# --------------------------------------------------------------------------------------------
# Parameters of Lewis's figures
# --------------------------------------------------------------------------------------------


def lewis_exponent(beta_deg: float) -> float:
    """The exponent whose cos^n falls to 1/2 at the half-angle beta: n = -ln 2 / ln cos(beta) (002 sec. 3.1)."""
    b = math.radians(float(beta_deg))
    if not 0.0 < b < 0.5 * math.pi:
        raise ValueError(f"specular half-angle beta must be in (0, 90) degrees, got {beta_deg!r}")
    return -math.log(2.0) / math.log(math.cos(b))


def label(spec) -> str:
    """A short human label of a spec: ``phong n=20``, ``g2 x2 of blinn n=20``."""
    if not isinstance(spec, dict):
        spec = _load(spec).spec
    if spec.get("type") == "pumped":
        depth, s = 0, spec
        while isinstance(s, dict) and s.get("type") == "pumped":
            depth += int(s.get("levels", 1))
            g = s.get("g", "g1")
            s = s["base"]
        return f"{g} x{depth} of {label(s)}"
    if isinstance(spec.get("base"), dict):
        rest = ", ".join(f"{k}={_fmt(v)}" for k, v in spec.items() if k not in ("type", "base"))
        return f"{spec['type']}{' ' + rest if rest else ''} of {label(spec['base'])}"
    parts = [f"{k}={_fmt(v)}" for k, v in spec.items() if k != "type" and k != "c"]
    return " ".join([spec.get("type", "?")] + parts)


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


# --------------------------------------------------------------------------------------------
# Writers
# --------------------------------------------------------------------------------------------


def _atomic(path):
    from .tables import atomic_path

    return atomic_path(path)


def _openexr():
    try:
        import OpenEXR
    except ImportError:
        raise ImportError("EXR images need the 'openexr' package (a pumpup dependency): pip install openexr") from None
    return OpenEXR


def write_exr(path, image: Image) -> str:
    """Write linear radiance as 32-bit float OpenEXR (channel ``Y``, or ``R``, ``G``, ``B``; mask in ``A``).

    The header holds ``pumpup_spec``, ``pumpup_params``, ``pumpup_kind`` and, for a furnace,
    ``pumpup_error_bound``.  Written atomically.  Needs the ``openexr`` package.
    """
    OpenEXR = _openexr()
    rad = np.asarray(image.radiance)
    if rad.ndim == 2:
        channels = {"Y": rad.astype(np.float32)}
    elif rad.ndim == 3 and rad.shape[2] == 3:
        channels = {k: np.ascontiguousarray(rad[..., i], dtype=np.float32) for i, k in enumerate("RGB")}
    else:
        raise ValueError(f"write_exr: radiance must be (size, size) or (size, size, 3), got {rad.shape}")
    channels["A"] = image.mask.astype(np.float32)
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    header.update(image.header())
    path = os.fspath(path)
    with _atomic(path) as tmp:
        with OpenEXR.File(header, channels) as out:
            out.write(tmp)
    return path


def read_exr(path) -> tuple[np.ndarray, np.ndarray, dict]:
    """Read an EXR written by :func:`write_exr`: (radiance float32, mask bool, pumpup header fields).

    Raises ValueError if the file is not an OpenEXR image, has no ``Y`` (or ``R, G, B``) and
    ``A`` channels, or holds non-finite or negative radiance.
    """
    OpenEXR = _openexr()
    path = os.fspath(path)
    if not os.path.exists(path):
        raise FileNotFoundError(f"no such image: {path!r}")
    try:
        with OpenEXR.File(path, separate_channels=True) as f:
            ch = {k: np.array(v.pixels) for k, v in f.channels().items()}
            header = {k: v for k, v in f.header().items() if k.startswith("pumpup_")}
    except Exception as exc:  # the binding raises RuntimeError or its own types
        raise ValueError(f"{path!r} is not a readable OpenEXR image: {exc}") from None
    if "A" not in ch or not ("Y" in ch or all(k in ch for k in "RGB")):
        raise ValueError(f"{path!r}: expected channels Y (or R, G, B) and A, found {sorted(ch)}")
    rad = ch["Y"] if "Y" in ch else np.stack([ch[k] for k in "RGB"], axis=-1)
    if not np.all(np.isfinite(rad)) or np.any(rad < 0):
        raise ValueError(f"{path!r}: radiance must be finite and >= 0")
    return rad, ch["A"] > 0.5, header


def srgb(v: np.ndarray) -> np.ndarray:
    """The sRGB transfer function (IEC 61966-2-1) of linear values in [0, 1]."""
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1.0 / 2.4) - 0.055)


def tone_map(image: Image, exposure: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Display RGB in [0, 1] and the clipped mask: v = radiance x 2^exposure, sRGB transfer.

    Pixels with v > 1 + 1e-9 (any channel; for a furnace image v > 1 + 1e-9 + its error bound x 2^exposure) are
    painted :data:`CLIP_COLOUR` (magenta) and flagged in the returned mask; pixels off the sphere are
    :data:`BACKGROUND`.  Grey images become grey RGB.
    """
    if not math.isfinite(float(exposure)):
        raise ValueError(f"exposure must be a finite number of stops, got {exposure!r}")
    v = np.asarray(image.radiance, dtype=np.float64) * 2.0 ** float(exposure)
    if v.ndim == 2:
        v = v[..., None]
    if v.shape[2] == 1:
        v = np.repeat(v, 3, axis=2)
    if v.shape[2] != 3:
        raise ValueError(f"tone_map: radiance must have 1 or 3 channels, got {v.shape[2]}")
    # a furnace image may exceed 1 by its own error bound without reflecting more than it receives;
    # 1e-9: a light scaled to make the peak 1 gives 1 + 2e-16, which is not clipping
    tol = float(image.error or 0.0) * 2.0 ** float(exposure) + 1e-9
    clipped = image.mask & np.any(v > 1.0 + tol, axis=2)
    rgb = srgb(v)
    rgb[clipped] = CLIP_COLOUR
    rgb[~image.mask] = BACKGROUND
    return rgb, clipped


def tone_text(exposure: float) -> str:
    """The tone map in words, for captions and PNG metadata."""
    return (f"radiance x 2^{float(exposure):g} (exposure {float(exposure):+g} stops), sRGB transfer, "
            "values above 1 clipped and shown magenta")


def write_png(path, image: Image, exposure: float = 0.0) -> str:
    """Write the tone-mapped image (:func:`tone_map`) as an 8-bit sRGB PNG, atomically.

    The PNG's text chunks hold the tone map and the image's metadata.
    """
    import matplotlib.image as mimage

    rgb, clipped = tone_map(image, exposure)
    meta = {"Description": tone_text(exposure), "Software": "pumpup.render"}
    meta.update({k: str(v) for k, v in image.header().items()})
    meta["pumpup_clipped_pixels"] = str(int(clipped.sum()))
    path = os.fspath(path)
    with _atomic(path) as tmp:
        mimage.imsave(tmp, (np.round(rgb * 255.0)).astype(np.uint8), format="png", metadata=meta)
    return path


def grid_figure(images, path, *, row_labels=None, col_labels=None, exposure: float = 0.0, title: str | None = None,
                tile_text=None, tile_inches: float = 1.6) -> str:
    """Assemble images (a list of rows, each a list of :class:`Image` or None) into a labelled PNG.

    Every tile is tone-mapped with the same ``exposure`` (:func:`tone_map`); the tone map is
    stated under the grid.  ``tile_text(image) -> str`` writes a line on each tile (default:
    Phi_L for sphere images, the maximum and the error bound for furnace images).
    """
    from matplotlib.figure import Figure  # no pyplot: the caller's backend and figures are left alone

    rows = [list(r) for r in images]
    n_rows, n_cols = len(rows), max(len(r) for r in rows)
    fig = Figure(figsize=(tile_inches * n_cols + 1.9, tile_inches * n_rows + 0.9))
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    for i, row in enumerate(rows):
        for j in range(n_cols):
            ax = axes[i][j]
            ax.set_xticks([])
            ax.set_yticks([])
            for s in ax.spines.values():
                s.set_visible(False)
            im = row[j] if j < len(row) else None
            if im is None:
                ax.axis("off")
                continue
            rgb, clipped = tone_map(im, exposure)
            ax.imshow(rgb, interpolation="nearest")
            text = tile_text(im) if tile_text else _default_tile_text(im, clipped)
            if text:  # wrapped to the tile's width (6.5 pt characters), so it never runs into the next tile
                width = max(12, int(tile_inches * 72 / (6.5 * 0.62)))
                text = "\n".join(textwrap.fill(line, width) for line in text.splitlines())
                ax.text(0.02, 0.98, text, transform=ax.transAxes, va="top", ha="left", fontsize=6.5, color="white",
                        bbox={"facecolor": "black", "alpha": 0.55, "pad": 1.5, "linewidth": 0})
            if i == 0 and col_labels:
                ax.set_title(col_labels[j], fontsize=8)
            if j == 0 and row_labels:
                ax.set_ylabel(row_labels[i], fontsize=7, rotation=0, ha="right", va="center", labelpad=4)
    if title:
        fig.suptitle(title, fontsize=9)
    fig.text(0.5, 0.005, "tone map: " + tone_text(exposure), ha="center", va="bottom", fontsize=7)
    fig.tight_layout(rect=(0, 0.03, 1, 0.97 if title else 1.0))
    path = os.fspath(path)
    with _atomic(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    return path


def _default_tile_text(im: Image, clipped) -> str:
    vals = im.radiance[im.mask]
    peak = float(vals.max()) if vals.size else 0.0
    if im.kind == "furnace":
        return f"max {peak:.4f}\nmin {float(vals.min()):.3f}"
    return f"max {peak:.3g}" + (f"\n{int(clipped.sum())} clipped" if clipped.any() else "")


# --------------------------------------------------------------------------------------------
# Batches (the command line's ``pumpup render sphere`` and ``pumpup render furnace``)
# --------------------------------------------------------------------------------------------


def _stem(k: int, f) -> str:
    return f"{k:02d}_{f.type}"


def render_spheres(models, lights, size: int, out: str, *, exposure: float = 0.0, irradiance: float = 1.0,
                   report=print) -> list[str]:
    """Render every model at every light angle into ``out``: EXR + PNG per image and a labelled grid.

    ``models`` are loaded BRDFs (or specs), ``lights`` Phi_L in degrees.  Files:
    ``sphere_KK_TYPE_L{Phi_L}.exr/.png`` and ``sphere_grid.png`` (rows: models, columns: Phi_L).
    Returns the paths written.
    """
    lights = [check_light(v) for v in lights]
    size = check_size(size)
    models = [_load(m) for m in models]
    written, rows = [], []
    for k, f in enumerate(models):
        row = []
        for phi in lights:
            im = sphere(f, phi, size, irradiance=irradiance)
            stem = os.path.join(out, f"sphere_{_stem(k, f)}_L{phi:g}")
            written += [write_exr(stem + ".exr", im), write_png(stem + ".png", im, exposure)]
            clipped = int(tone_map(im, exposure)[1].sum())
            report(f"{label(f.spec)}, Phi_L = {phi:g} deg: max radiance {float(im.radiance.max()):.6g}, "
                   f"{clipped} clipped pixels -> {stem}.exr/.png")
            row.append(im)
        rows.append(row)
    grid = os.path.join(out, "sphere_grid.png")
    written.append(grid_figure(rows, grid, row_labels=[label(f.spec) for f in models],
                               col_labels=[f"Phi_L = {v:g} deg" for v in lights], exposure=exposure,
                               title=f"directional light (002 Fig. 2), irradiance {irradiance:g}"))
    report(f"wrote {grid}")
    return written


def render_furnaces(models, size: int, out: str, *, exposure: float = 0.0, report=print) -> list[str]:
    """Furnace images of every model into ``out``: EXR + PNG each (``furnace_KK_TYPE``) and ``furnace_grid.png``."""
    size = check_size(size)
    models = [_load(m) for m in models]
    written, ims = [], []
    for k, f in enumerate(models):
        im = furnace(f, size)
        stem = os.path.join(out, f"furnace_{_stem(k, f)}")
        written += [write_exr(stem + ".exr", im), write_png(stem + ".png", im, exposure)]
        vals = im.radiance[im.mask]
        report(f"{label(f.spec)}: a(mu_V) from {float(vals.min()):.6g} (rim) to {float(vals.max()):.6g}, "
               f"error bound {im.error:.2g} -> {stem}.exr/.png")
        ims.append(im)
    grid = os.path.join(out, "furnace_grid.png")
    written.append(grid_figure([ims], grid, col_labels=[label(f.spec) for f in models], exposure=exposure,
                               title="white furnace: pixel = albedo a(mu_V)"))
    report(f"wrote {grid}")
    return written
