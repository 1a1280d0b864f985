"""Spectral metals: one 000 eq. 28 BRDF per wavelength, their albedo tables and their colour.

000 sec. 5 evaluates the metallic BRDF "at 8 discrete wavelengths" with measured complex
indices and converts the result to XYZ and RGB.  :class:`SpectralMetal` holds one
:class:`pumpup.models.metal.Metal` per wavelength (a shared exponent n and scale c, the index
n + i k of that wavelength from :mod:`pumpup.spectral.optical` or given per channel) and evaluates them
all at once on a trailing wavelength axis.

The albedo engine (:func:`pumpup.albedo`, :func:`pumpup.tabulate`) integrates one scalar
BRDF, so a spectral metal is not a registered model type: :meth:`SpectralMetal.albedo` and
:meth:`SpectralMetal.tabulate` run the engine once per wavelength and stack the results on a
trailing ``wavelength`` axis / dimension, each value with its own error estimate.
:func:`pumpup.load` builds these objects from spectral specs, and :func:`pumpup.albedo`,
``tabulate``, ``mean_albedo``, ``pump``, ``compensate`` and ``save_pumped`` hand them to their
methods (the ``is_spectral`` marker); plastics are in :mod:`pumpup.spectral.plastic`, energy
compensation and saved files in :mod:`pumpup.spectral.ops`.

Colour (:func:`to_xyz`, :func:`to_srgb`) uses colour-science with the CIE 1931 2-degree
observer and illuminant D65: a spectrum of reflectances or albedos is read as the reflectance
of a surface lit by D65, so a perfect white reflector has Y = 1 and linear sRGB (1, 1, 1).

Examples
--------
>>> from pumpup import spectral
>>> gold = spectral.SpectralMetal("Au", n=20)
>>> gold.eval([0, 0, 1], [0, 0, 1]).shape  # one value per default wavelength
(8,)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numba import njit, vectorize

from ..core import BRDF, SpecError
from ..core import load as _load_scalar
from ..physics.fresnel import conductor_scalar as _fresnel_real
from . import optical

__all__ = ["load", "Spectral", "SpectralMetal", "SpectralPumped", "to_xyz", "to_srgb", "RGB_WAVELENGTHS"]

#: Three representative wavelengths [nm] of the sRGB primaries' channels (red, green, blue).
RGB_WAVELENGTHS: tuple[float, float, float] = (630.0, 532.0, 465.0)


@vectorize(cache=True)
def _fresnel_vec(c, eta, k):  # pragma: no cover - compiled
    return _fresnel_real(c, eta, k)


#: Intervals of the tabulated Fresnel factor (000 eq. 28: "g(Theta_min) can be tabulated for the
#: considered wavelengths"), uniform in cos(Theta_min) on [0, 1].
FRESNEL_TABLE_SIZE = 16384


@njit(cache=True)
def _eval_table_kernel(wi, wo, n, c, table, out):  # pragma: no cover - compiled
    m = table.shape[1] - 1
    for p in range(wi.shape[0]):
        lz = wi[p, 2]
        vz = wo[p, 2]
        if lz <= 0.0 or vz <= 0.0:
            continue
        rv = 2.0 * lz * vz - (wi[p, 0] * wo[p, 0] + wi[p, 1] * wo[p, 1] + lz * vz)  # cos(alpha), 000 eq. 9
        if rv <= 0.0:
            continue
        mx = min(max(lz, vz), 1.0)  # cos(Theta_min)
        lobe = c * rv**n / mx
        x = mx * m
        i = min(int(x), m - 1)
        t = x - i
        for j in range(table.shape[0]):
            out[p, j] = lobe * (table[j, i] + t * (table[j, i + 1] - table[j, i]))  # 000 eq. 28, F tabulated


def _eval_table_reference(wi, wo, n, c, table):
    """Plain numpy twin of ``_eval_table_kernel``."""
    m = table.shape[1] - 1
    lz, vz = wi[..., 2], wo[..., 2]
    rv = 2.0 * lz * vz - (wi[..., 0] * wo[..., 0] + wi[..., 1] * wo[..., 1] + lz * vz)
    mx = np.minimum(np.maximum(lz, vz), 1.0)
    ok = (lz > 0) & (vz > 0) & (rv > 0)
    x = np.where(ok, mx, 1.0) * m
    i = np.minimum(x.astype(np.int64), m - 1)
    t = x - i
    f = table[:, i] + t * (table[:, i + 1] - table[:, i])  # (wavelength, ...)
    with np.errstate(divide="ignore", invalid="ignore"):
        lobe = np.where(ok, c * np.where(ok, rv, 0.0) ** n / np.where(ok, mx, 1.0), 0.0)
    return lobe[..., None] * np.moveaxis(f, 0, -1)


#: long names of the per-wavelength parameters :meth:`Spectral.tabulate` stores beside the albedo
_VARIABLE_NAMES = {"eta": "refractive index, real part", "k": "extinction coefficient",
                   "ad": "diffuse albedo (000 eq. 29)", "a_s": "specular weight (000 eq. 29)"}


class Spectral:
    """One scalar BRDF per wavelength (``models``, ``wavelengths`` [nm]), stacked on a trailing axis.

    The base of :class:`SpectralMetal` and of its pumped form (:meth:`SpectralMetal.pump`).
    """

    models: list
    wavelengths: np.ndarray
    material: str | None = None
    #: marks a spectral object for the generic functions (pumpup.load, albedo, tabulate, mean_albedo,
    #: pump, compensate, save_pumped), which hand it to its own methods
    is_spectral = True
    #: the model family, for table titles ("metal" or "plastic")
    kind = "metal"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Spectral) and self.spec == other.spec

    def __hash__(self) -> int:
        import json

        return hash(json.dumps(self.spec, sort_keys=True))

    def innermost(self) -> Spectral:
        """The spectral model under every pumping / compensation (``self`` for a metal or plastic)."""
        cur = self
        while isinstance(getattr(cur, "base", None), Spectral):
            cur = cur.base
        return cur

    def _eval(self, wi, wo):
        """Refused: the functions that call ``_eval`` (check_reciprocity, render, sample, ...) take a
        single-channel BRDF; a clear TypeError instead of an AttributeError deep inside them.
        """
        raise TypeError(f"{self!r} is spectral: this function takes a single-channel BRDF; use its .eval() "
                        "(a trailing wavelength axis) or one wavelength's model, .models[j]")

    def wavelength_variables(self) -> dict:
        """The per-wavelength parameters of the innermost model (``eta``, ``k``, ``ad``, ``a_s``)
        that :meth:`tabulate` stores beside the albedo, name -> array.
        """
        root = self.innermost()
        out = {}
        for name in ("eta", "k", "ad", "a_s"):
            v = getattr(root, name, None)
            if v is not None:
                out[name] = np.asarray(v, dtype=np.float64)
        return out

    def eval(self, wi, wo) -> np.ndarray:
        """f_r(wi, wo) [1/sr] of every wavelength's model: shape broadcast(wi, wo)[:-1] + (len(wavelengths),)."""
        return np.stack([m.eval(wi, wo) for m in self.models], axis=-1)

    # --- albedo ----------------------------------------------------------------------------

    def albedo(self, mu, return_error: bool = False, threads: int | None = None, **kw):
        """Directional albedo per wavelength: shape mu.shape + (len(wavelengths),).

        :func:`pumpup.albedo` of each wavelength's model (keyword arguments passed on); with
        ``return_error`` also its error estimate, same shape.  The (wavelength, chunk of mu)
        integrals are spread over ``threads`` threads (default :data:`pumpup.tables.THREADS`,
        one per core); a value does not depend on the others computed with it, so the result
        does not depend on ``threads``.
        """
        from ..engine.cubature import check_mu

        m = np.asarray(mu, dtype=np.float64)
        flat = np.ascontiguousarray(m.reshape(-1))
        check_mu(flat)  # pumpup.albedo's message, before any thread starts
        v, e = _spread(self, flat, threads, **kw)
        v = v.reshape(m.shape + (len(self.models),))
        e = e.reshape(v.shape)
        return (v, e) if return_error else v

    def mean_albedo(self, return_error: bool = False, **kw):
        """Mean (cosine-weighted hemispherical) albedo per wavelength, :func:`pumpup.mean_albedo` (000 eq. 33)."""
        from ..tables import mean_albedo

        out = [mean_albedo(m, return_error=True, **kw) for m in self.models]
        v = np.array([o[0] for o in out])
        e = np.array([o[1] for o in out])
        return (v, e) if return_error else v

    def tabulate(self, mu=None, *, rtol: float | None = None, atol: float | None = None, interp_tol: float = 1e-7,
                 mu_min: float = 1e-8, max_points: int = 2049, threads: int | None = None, progress=None,
                 phi=None):
        """Albedo tables of every wavelength as one xarray.Dataset with dims (``mu``, ``wavelength``).

        Every value is :func:`pumpup.albedo` of that wavelength's model at that mu, with its own
        error estimate.  With ``mu`` given, every wavelength is computed on it.  Without, one
        adaptive grid is shared by all wavelengths (the :func:`pumpup.tabulate` algorithm run
        on all of them at once): it starts from :func:`pumpup.tables.default_grid` and bisects
        (in log mu) every interval where the interpolant of any wavelength misses the albedo
        computed at the midpoint by more than ``interp_tol``; ``interpolation_error`` (per
        wavelength) is the largest miss of that wavelength over the accepted intervals.  The
        values of a round (all wavelengths x all new mu) are spread over ``threads`` threads
        (default :data:`pumpup.tables.THREADS`, one per core), so the short late rounds of the
        adaptive loop keep every core busy; the table does not depend on ``threads``.

        Parameters as :func:`pumpup.tabulate` (``phi`` must be None: the metals are isotropic;
        ``progress`` is accepted and ignored).
        """
        import json

        import xarray as xr

        from ..core import check_count, check_open_unit, check_tolerance
        from ..engine.cubature import DEFAULT_ATOL, DEFAULT_RTOL, check_mu
        from ..tables import MAX_POINTS_LIMIT, _dataset, adaptive_grid, built_on_tables, default_grid
        from ..tables import reuse as _reuse

        if phi is not None:
            raise SpecError("Spectral.tabulate: parameter 'phi' must be None (the spectral models are isotropic)")
        if threads is not None and (isinstance(threads, bool) or not isinstance(threads, (int, np.integer))
                                    or threads < 1):
            raise ValueError(f"Spectral.tabulate: threads must be an integer >= 1, got {threads!r}")
        rtol = check_tolerance("tabulate", "rtol", DEFAULT_RTOL if rtol is None else rtol)
        atol = check_tolerance("tabulate", "atol", DEFAULT_ATOL if atol is None else atol, hi=np.inf, zero=True)
        interp_tol = check_tolerance("tabulate", "interp_tol", interp_tol, hi=np.inf)
        mu_min = check_open_unit("tabulate", "mu_min", mu_min)
        max_points = check_count("tabulate", "max_points", max_points, 2, MAX_POINTS_LIMIT)
        nw = len(self.models)

        def values(mus):
            """(albedo, error) of shape (len(mus), nw), every (wavelength, chunk of mu) a task."""
            return _spread(self, mus, threads, rtol=rtol, atol=atol)

        if mu is not None:
            grid = np.unique(check_mu(np.atleast_1d(np.asarray(mu, dtype=np.float64))).ravel())
            vals, errs = values(grid)
            interp = np.zeros(nw)
            kind = "given"
        else:
            check_mu(mu_min)
            grid = default_grid(mu_min=mu_min)
            vals, errs = values(grid)
            # one grid for every wavelength: an interval fails if any wavelength misses (pumpup.tables.adaptive_grid)
            grid, vals, errs, interp = adaptive_grid(grid, vals, errs, values, interp_tol, max_points,
                                                     off_grid=built_on_tables(self.spec))
            kind = "adaptive"
        for j, m in enumerate(self.models):  # mean_albedo / max_albedo of a model may reuse its column
            _reuse.remember(m, grid, vals[:, j], errs[:, j], rtol)
        template = _dataset(self.models[0], grid, vals[:, 0], errs[:, 0], rtol, atol, 0.0, kind)
        ds = xr.Dataset(
            {
                "albedo": (("mu", "wavelength"), vals, template["albedo"].attrs),
                "albedo_error": (("mu", "wavelength"), errs, template["albedo_error"].attrs),
                "interpolation_error": ("wavelength", interp, {
                    "long_name": "largest interpolation miss found at the checked points", "units": "1"}),
                **{name: ("wavelength", v, {"long_name": _VARIABLE_NAMES[name], "units": "1"})
                   for name, v in self.wavelength_variables().items()},
            },
            coords={"mu": ("mu", grid, template["mu"].attrs), "theta": ("mu", np.degrees(np.arccos(grid))),
                    "wavelength": self.wavelengths},
            attrs={k: v for k, v in template.attrs.items() if k not in ("spec", "interpolation_error")},
        )
        ds.attrs["interp_tol"] = float(interp_tol)
        ds["wavelength"].attrs["units"] = "nm"
        ds["theta"].attrs["units"] = "degree"
        ds.attrs["spec"] = json.dumps(self.spec, sort_keys=True)
        ds.attrs["title"] = (f"Spectral directional albedo of {self.innermost().kind} "
                             f"({self.material or 'explicit index'})")
        if getattr(self, "material", None) is not None:
            for key, val in optical.metadata(self.material).items():
                ds.attrs[f"optical_{key}"] = val
        return ds


class SpectralPumped(Spectral):
    """A spectral BRDF pumped up wavelength by wavelength (001 sec. 3): each wavelength's model is
    divided by its own correction g (:func:`pumpup.pump` of that wavelength's model).
    """

    def __init__(self, base: Spectral, g: str = "g1", levels: int = 1, force: bool = False):
        from ..operators.pumping import pump

        self.base = base
        self.material = base.material
        self.wavelengths = base.wavelengths
        self.models = [pump(m, g=g, levels=levels, force=force) for m in base.models]
        self.eta, self.k = getattr(base, "eta", None), getattr(base, "k", None)
        self.g = g
        self.levels = levels
        self.force = bool(force)

    @property
    def spec(self) -> dict:
        """The model as a plain-JSON dict: the spectral base, ``g``, ``levels``, and ``force`` where it is set."""
        out = {"type": "pumped", "base": self.base.spec, "g": self.g, "levels": self.levels}
        if self.force:
            out["force"] = True
        return out

    def __repr__(self) -> str:
        return f"SpectralPumped({self.base!r}, g={self.g!r}, levels={self.levels})"


class SpectralMetal(Spectral):
    """A metal of 000 eq. 28 at several wavelengths, f_r(wi, wo, lambda) [1/sr].

    f_r = c cos^n(alpha) / cos(Theta_min) F(n(lambda) + i k(lambda), Theta_min), 000 eq. 28,
    with the exponent n and scale c shared by all wavelengths.

    Parameters
    ----------
    material : str, optional
        A metal of :mod:`pumpup.spectral.optical` (``"Au"``, ``"Ag"``, ``"Cu"``, ``"Al"``, ...); its
        measured index is used at every wavelength.  Omit it to give ``eta`` (and ``k``).
    n : float, >= 0
        Phong exponent (000 eq. 28).
    wavelengths : list of float, optional
        Vacuum wavelengths [nm]; default :data:`pumpup.spectral.optical.DEFAULT_WAVELENGTHS` (eight
        from 400 to 680 nm) with ``material``, required length = len(eta) without it.
        ``"rgb"`` stands for :data:`RGB_WAVELENGTHS`.
    eta, k : list of float, optional
        Explicit per-channel index (instead of ``material``), one value per wavelength.
    c : float, optional
        Scale [1/sr], default (n + 2) / (2 pi) (000 eq. 6).
    """

    def __init__(self, material: str | None = None, n: float = None, wavelengths: Any = None,
                 eta: Any = None, k: Any = None, c: float | None = None):
        if n is None:
            raise SpecError("spectral metal: parameter 'n' (the exponent, >= 0) is required")
        if isinstance(wavelengths, str):
            if wavelengths != "rgb":
                raise SpecError("spectral metal: parameter 'wavelengths' must be a list of nm or 'rgb', got "
                                f"{wavelengths!r}")
            wavelengths = RGB_WAVELENGTHS
        if material is not None:
            if eta is not None or k is not None:
                raise SpecError("spectral metal: give either 'material' or 'eta'/'k', not both")
            w = optical.check_wavelengths(optical.DEFAULT_WAVELENGTHS if wavelengths is None else wavelengths)
            etas, ks = optical.constants(material, w)
        else:
            if eta is None:
                raise SpecError(f"spectral metal: give 'material' (one of {', '.join(optical.MATERIALS)}) "
                                "or a per-wavelength 'eta'")
            etas = np.atleast_1d(np.asarray(eta, dtype=np.float64))
            ks = np.zeros_like(etas) if k is None else np.atleast_1d(np.asarray(k, dtype=np.float64))
            if wavelengths is None:
                raise SpecError("spectral metal: parameter 'wavelengths' is required with an explicit 'eta'")
            w = optical.check_wavelengths(wavelengths)
            if not (len(etas) == len(ks) == len(w)):
                raise SpecError(f"spectral metal: 'eta', 'k' and 'wavelengths' must have equal lengths; got "
                                f"{len(etas)}, {len(ks)}, {len(w)}")
        self.material = material
        self.wavelengths = w
        spec = {"type": "metal", "n": n}
        if c is not None:
            spec["c"] = c
        # one scalar model per wavelength; their validation checks n, c, eta, k
        self.models = [_load_scalar({**spec, "eta": float(e), "k": float(kk)}) for e, kk in zip(etas, ks)]
        self.eta = np.array([m.p["eta"] for m in self.models])
        self.k = np.array([m.p["k"] for m in self.models])
        self.n = self.models[0].p["n"]
        self.c = self.models[0].p["c"]

    def __repr__(self) -> str:
        what = self.material or "explicit index"
        return f"SpectralMetal({what}, n={self.n:g}, wavelengths={self.wavelengths.tolist()})"

    @property
    def spec(self) -> dict:
        """A JSON-able description (the spec form ``{"type": "metal", "material": ..., "n": ...}``)."""
        out: dict[str, Any] = {"type": "metal", "n": self.n, "c": self.c, "wavelengths": self.wavelengths.tolist()}
        if self.material is not None:
            out["material"] = self.material
        else:
            out["eta"] = self.eta.tolist()
            out["k"] = self.k.tolist()
        return out

    # --- evaluation ------------------------------------------------------------------------

    def eval(self, wi, wo) -> np.ndarray:
        """f_r(wi, wo) [1/sr] at every wavelength: shape broadcast(wi, wo)[:-1] + (len(wavelengths),).

        The geometry (cos(alpha), cos(Theta_min), the lobe) is computed once per pair in one
        compiled pass and only the Fresnel factor F(eta + i k, Theta_min) per wavelength
        (000 eq. 27, 28; :func:`pumpup.spectral.kernels.metal_eval_kernel`, whose numpy twin is
        ``metal_eval_reference``).  Equal to the one-wavelength models (``self.models``) to a few
        ulp; 8 wavelengths cost about 2x one ``Metal.eval`` (``scripts/bench/bench_spectral.py``).
        """
        from .kernels import flat_pairs, fresnel_constants, metal_eval_kernel

        a, b, shape = flat_pairs(wi, wo)
        if getattr(self, "_fconst", None) is None:
            self._fconst = fresnel_constants(self.eta, self.k)
        out = np.empty((a.shape[0], self.eta.size))
        metal_eval_kernel(a, b, float(self.n), float(self.c), *self._fconst, out)
        return out.reshape(shape + (self.eta.size,))

    def fresnel_table(self):
        """The tabulated F(cos Theta_min) per wavelength (000 eq. 28) and its measured error.

        Returns ``(table, error)``: ``table`` of shape (len(wavelengths), FRESNEL_TABLE_SIZE + 1) on a
        uniform grid of cos in [0, 1], linearly interpolated by :meth:`eval_tabulated`;
        ``error`` the largest |interpolated - exact| F found at the midpoints and quarter points of
        every interval (where linear interpolation errs most), over all wavelengths.
        """
        if getattr(self, "_table", None) is None:
            m = FRESNEL_TABLE_SIZE
            cos = np.linspace(0.0, 1.0, m + 1)
            table = np.stack([_fresnel_vec(cos, e, kk) for e, kk in zip(self.eta, self.k)])
            err = 0.0
            for frac in (0.25, 0.5, 0.75):
                mid = cos[:-1] + frac / m
                exact = np.stack([_fresnel_vec(mid, e, kk) for e, kk in zip(self.eta, self.k)])
                approx = table[:, :-1] + frac * (table[:, 1:] - table[:, :-1])
                err = max(err, float(np.max(np.abs(approx - exact))))
            self._table = (np.ascontiguousarray(table), err)
        return self._table

    def eval_tabulated(self, wi, wo) -> np.ndarray:
        """:meth:`eval` with F(Theta_min) read from :meth:`fresnel_table` (000 eq. 28's fast path).

        Differs from :meth:`eval` by at most f_r(F = 1) times ``fresnel_table()[1]`` (measured when the table is built;
        from 9e-9 for Au to 4e-8, the largest over the nine metals at the default wavelengths).
        """
        from .kernels import flat_pairs

        a2, b2, shape = flat_pairs(wi, wo)  # every direction checked (unit, finite), as eval
        table, _ = self.fresnel_table()
        out = np.zeros((a2.shape[0], table.shape[0]))
        _eval_table_kernel(a2, b2, float(self.n), float(self.c), table, out)
        return out.reshape(shape + (table.shape[0],))

    def pump(self, g: str = "g1", levels: int = 1) -> SpectralPumped:
        """Pump every wavelength up by its own albedo (:func:`pumpup.pump`, 001 sec. 3)."""
        return SpectralPumped(self, g=g, levels=levels)

    def fresnel_normal(self) -> np.ndarray:
        """F at normal incidence, ((n - 1)^2 + k^2) / ((n + 1)^2 + k^2), per wavelength."""
        return ((self.eta - 1) ** 2 + self.k**2) / ((self.eta + 1) ** 2 + self.k**2)

def load(spec: Any) -> Spectral:
    """A spectral model from the spec ``{"type": "metal", "material": "Au", "n": 20}``.

    Accepts ``material`` (or per-wavelength ``eta``/``k`` lists) with ``n``, optional ``c`` and
    ``wavelengths`` (a list of nm or ``"rgb"``), ``{"type": "plastic", ...}``
    (:class:`pumpup.spectral.plastic.SpectralPlastic`), ``{"type": "pumped", "base": <spectral
    spec>, "g": ..., "levels": ...}`` and ``{"type": "kulla_conty" | "scaled", "base": <spectral
    spec>, ...}`` (:class:`pumpup.spectral.ops.SpectralCompensated`); ``spec`` round-trips.
    :func:`pumpup.load` calls this for every spectral spec (:func:`pumpup.core.is_spectral_spec`).

    Examples
    --------
    >>> from pumpup import spectral
    >>> f = spectral.load({"type": "metal", "material": "Cu", "n": 20, "wavelengths": "rgb"})
    >>> f.eval([0, 0, 1], [0, 0, 1]).shape
    (3,)
    """
    if isinstance(spec, Spectral):
        return spec
    if isinstance(spec, str):
        from ..core import parse_spec

        spec = parse_spec(spec)
    if not isinstance(spec, dict) or "type" not in spec:
        raise SpecError(f"spectral.load: a spec must be a dict with a 'type' key, got {spec!r}")
    kw = {k: v for k, v in spec.items() if k != "type"}
    if spec["type"] == "pumped":
        allowed = {"base", "g", "levels", "force"}
        bad = sorted(set(kw) - allowed)
        if bad or "base" not in kw:
            raise SpecError(f"spectral.load: a pumped spec needs 'base' and allows {', '.join(sorted(allowed))}; "
                            f"got {sorted(kw)}")
        from ..operators.pumping import pump

        return pump(load(kw["base"]), g=kw.get("g", "g1"), levels=kw.get("levels", 1), force=kw.get("force", False))
    if spec["type"] == "pumped_lobe":  # the colour-keeping pumped metal (SpectralPumpedLobe)
        allowed = {"base", "g", "levels"}
        bad = sorted(set(kw) - allowed)
        if bad or "base" not in kw:
            raise SpecError(f"spectral.load: a pumped_lobe spec needs 'base' (a spectral metal) and allows "
                            f"{', '.join(sorted(allowed))}; got {sorted(kw)}")
        base = load(kw["base"])
        if not isinstance(base, SpectralMetal):
            raise SpecError(f"spectral.load: parameter 'base' of pumped_lobe must be a spectral metal, got {base!r}")
        return SpectralPumpedLobe(base, g=kw.get("g", "g1"), levels=kw.get("levels", 1))
    if spec["type"] in ("kulla_conty", "scaled"):
        from .ops import SpectralCompensated

        return SpectralCompensated.from_spec(spec, load)
    if spec["type"] == "plastic":
        from .plastic import SpectralPlastic

        return SpectralPlastic.from_spec(spec)
    if spec["type"] != "metal":
        raise SpecError(f"spectral.load: 'type' must be 'metal', 'plastic', 'pumped', 'pumped_lobe', 'kulla_conty' or "
                        f"'scaled', "
                        f"got {spec['type']!r}")
    allowed = {"material", "n", "wavelengths", "eta", "k", "c"}
    bad = sorted(set(kw) - allowed)
    if bad:
        raise SpecError(f"spectral.load: unknown parameter(s) {', '.join(map(repr, bad))}; allowed: "
                        f"{', '.join(sorted(allowed))}")
    return SpectralMetal(**kw)


# --- colour ---------------------------------------------------------------------------------


def _xyz_one(values: np.ndarray, wavelengths: np.ndarray) -> np.ndarray:
    from .._extras import require

    colour = require("colour", "CIE XYZ and sRGB colour of spectra")
    sd = colour.SpectralDistribution(dict(zip(wavelengths.tolist(), values.tolist())))
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    illuminant = colour.SDS_ILLUMINANTS["D65"]
    return np.asarray(colour.sd_to_XYZ(sd, cmfs, illuminant, method="Integration")) / 100.0


def to_xyz(values, wavelengths) -> np.ndarray:
    """CIE 1931 XYZ (Y = 1 for a white reflector) of reflectance / albedo spectra under D65.

    Parameters
    ----------
    values : array_like, shape (..., len(wavelengths))
        Dimensionless reflectances (or albedos) sampled at ``wavelengths``.
    wavelengths : array_like
        Increasing, equally spaced wavelengths [nm] (colour-science interpolates between them and
        holds the end values outside; see ``colour.sd_to_XYZ``).

    Returns
    -------
    ndarray, shape (..., 3)
    """
    import warnings

    w = optical.check_wavelengths(wavelengths)
    v = np.asarray(values, dtype=np.float64)
    if v.shape[-1:] != w.shape:
        raise SpecError(f"to_xyz: 'values' must have a last axis of length {w.size} (the wavelengths), got shape "
                        f"{v.shape}")
    flat = v.reshape(-1, w.size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # colour's notes on interpolating / extrapolating the samples
        out = np.array([_xyz_one(row, w) for row in flat])
    return out.reshape(v.shape[:-1] + (3,))


def to_srgb(values, wavelengths, encoded: bool = False) -> np.ndarray:
    """The sRGB (IEC 61966-2-1, D65 white) of reflectance spectra: linear, or with the sRGB encoding.

    Out-of-gamut values are returned as computed (not clipped).
    """
    from .._extras import require

    colour = require("colour", "CIE XYZ and sRGB colour of spectra")
    xyz = to_xyz(values, wavelengths)
    return np.asarray(colour.XYZ_to_sRGB(xyz, apply_cctf_encoding=encoded))


# --- the colour-keeping pumped metal -----------------------------------------------------------


class _FresnelWeighted(BRDF):
    """One wavelength of :class:`SpectralPumpedLobe`: f_r = f*(wi, wo) F(eta + i k, Theta_min) [1/sr].

    ``lobe`` is the pumped F = 1 lobe (a :class:`pumpup.operators.pumping.Pumped`), shared by all
    wavelengths; the albedo engine integrates this product with the lobe's quadrature hint
    (its lobe and the kinks of g; F(max(N.wi, N.wo)) adds the kink N.wo = mu, already a level
    of the pumped lobe's hint).  Not a registered type: its spec describes it, it does not load.
    """

    type = "fresnel-weighted"
    params = {}
    constant = None

    def __init__(self, lobe: BRDF, eta: float, k: float):
        self.p = {}
        self.lobe_brdf = lobe
        self.eta, self.k = float(eta), float(k)
        self.reciprocal = lobe.reciprocal

    @property
    def spec(self) -> dict:
        return {"type": "fresnel-weighted", "base": self.lobe_brdf.spec, "eta": self.eta, "k": self.k}

    def _eval(self, wi, wo):
        f = np.asarray(self.lobe_brdf._eval(wi, wo), dtype=np.float64)
        mx = np.minimum(np.maximum(wi[..., 2], wo[..., 2]), 1.0)  # cos(Theta_min)
        return np.where(f != 0.0, f * _fresnel_vec(np.maximum(mx, 0.0), self.eta, self.k), 0.0)  # 000 eq. 28

    def reference(self, wi, wo):
        from ..physics.fresnel import fresnel_conductor as fresnel

        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        f = np.asarray(self.lobe_brdf.reference(wi, wo), dtype=np.float64)
        return f * fresnel(np.maximum(wi[..., 2], wo[..., 2]), self.eta, self.k)

    def lobe(self, mu):
        return self.lobe_brdf.lobe(mu)

    def sampling_lobe(self, mu):
        return self.lobe_brdf.sampling_lobe(mu)

    def azimuth_hint(self):
        """The pumped lobe's hint times F(max(N.wi, N.wo)) (000 eq. 28), or None without one."""
        from ..core.hints import FresnelAtMax

        hint = self.lobe_brdf.azimuth_hint()
        return None if hint is None else hint.times(FresnelAtMax(self.eta, self.k))


class SpectralPumpedLobe(Spectral):
    """A colour-keeping pumped metal: the F = 1 lobe pumped once, times F(Theta_min) per wavelength.

    f_r(wi, wo, lambda) = f*(wi, wo) F(n(lambda) + i k(lambda), Theta_min) [1/sr], with f* the
    pumped-up (001 eq. 16, 20 or 21) lobe of 000 eq. 28 without Fresnel,
    L(wi, wo) = c cos^n(alpha) / max(N.L, N.V) (stretched Phong, 000 eq. 7, 12 with p = 1), and
    cos(Theta_min) = max(N.L, N.V).  :class:`SpectralPumped` (``SpectralMetal.pump()``, the
    default, what 001 sec. 3 says) divides every wavelength by its own albedo, which also undoes
    the metal's absorption: every wavelength reaches albedo 1 at normal incidence and pumped gold
    is white.  Here only the lobe's geometric loss (the energy cut off by the horizon) is
    restored; F keeps the colour.

    Plausibility (tested in tests/spectral/test_spectral_speed.py):

    * reciprocal: f* is reciprocal (g is symmetric in wi, wo, 001 eq. 20, 21, and L is
      reciprocal) and F(Theta_min) depends on max(N.L, N.V), symmetric in L and V;
    * energy: 0 <= F <= 1 for a conductor, so for every wavelength and mu
      a_lambda(mu) = int f* F cos(theta_o) d omega_o <= int f* cos(theta_o) d omega_o = a*(mu) <= 1,
      the last because g >= a_L(wi) (001, after eq. 17); so the spectral albedo is bounded by the
      pumped lobe's, which is the pumping bound of a single BRDF;
    * one pumping table instead of one per wavelength: g needs the albedo of L only, which does
      not depend on the wavelength (``pumpup.operators.pumping.base_table`` of L, computed once and shared
      with every other pumping of the same lobe).

    Parameters
    ----------
    base : SpectralMetal
        The metal (its n, c and per-wavelength index are used).
    g : {"g1", "g2"}
        The pumping correction (001 eq. 20 or 21).
    levels : int, >= 1
        Nested pumpings of L (:func:`pumpup.pump`).

    Examples
    --------
    >>> from pumpup import spectral
    >>> gold = spectral.SpectralPumpedLobe(spectral.SpectralMetal("Au", n=20, wavelengths="rgb"))
    >>> f = gold.eval([0, 0, 1], [0, 0, 1])
    >>> bool(f[0] > f[2])  # red above blue: still gold
    True
    """

    def __init__(self, base: SpectralMetal, g: str = "g1", levels: int = 1):
        from ..operators.pumping import pump

        if not isinstance(base, SpectralMetal):
            raise TypeError(f"SpectralPumpedLobe: 'base' must be a SpectralMetal, got {type(base).__name__}")
        self.base = base
        self.material = base.material
        self.wavelengths = base.wavelengths
        self.eta, self.k = base.eta, base.k
        self.g, self.levels = g, levels
        #: the F = 1 lobe of 000 eq. 28, c cos^n(alpha) / max(N.L, N.V)
        self.lobe = _load_scalar({"type": "stretched_phong", "n": base.n, "p": 1.0, "c": base.c})
        #: the pumped lobe f*, one pumping table for all wavelengths
        self.pumped_lobe = pump(self.lobe, g=g, levels=levels)
        self.models = [_FresnelWeighted(self.pumped_lobe, e, kk) for e, kk in zip(self.eta, self.k)]
        self._fconst = None

    @property
    def spec(self) -> dict:
        """The model as a plain-JSON dict: the spectral base, ``g`` and ``levels``."""
        return {"type": "pumped_lobe", "base": self.base.spec, "g": self.g, "levels": self.levels}

    def __repr__(self) -> str:
        return f"SpectralPumpedLobe({self.base!r}, g={self.g!r}, levels={self.levels})"

    def eval(self, wi, wo) -> np.ndarray:
        """f_r [1/sr] at every wavelength, shape broadcast(wi, wo)[:-1] + (len(wavelengths),).

        f* once per pair (the pumped lobe's compiled chain), then F(Theta_min) per wavelength in
        one compiled pass (:func:`pumpup.spectral.kernels.fresnel_scale_kernel`).
        """
        from .kernels import flat_pairs, fresnel_constants, fresnel_scale_kernel

        a, b, shape = flat_pairs(wi, wo)
        if self._fconst is None:
            self._fconst = fresnel_constants(self.eta, self.k)
        f = np.ascontiguousarray(self.pumped_lobe._eval(a, b), dtype=np.float64).reshape(-1)
        out = np.empty((a.shape[0], self.eta.size))
        fresnel_scale_kernel(f, a, b, *self._fconst, out)
        return out.reshape(shape + (self.eta.size,))

    def lobe_albedo(self, mu, return_error: bool = False, **kw):
        """The albedo a*(mu) of the pumped lobe f* (the bound of every wavelength's albedo)."""
        from ..engine.cubature import albedo

        return albedo(self.pumped_lobe, mu, return_error=return_error, **kw)


def _spread(spectral: Spectral, mus: np.ndarray, threads: int | None = None, **kw):
    """:func:`pumpup.albedo` (value, error) of every wavelength's model at ``mus`` (1-D), shape
    (len(mus), len(models)), with the (wavelength, chunk of mu) integrals spread over ``threads``
    threads (default :data:`pumpup.tables.THREADS`, one per core).  Chunk k of a wavelength takes
    every n-th mu, so the dear grazing values are spread over the tasks.
    """
    from concurrent.futures import ThreadPoolExecutor

    from ..engine.cubature import albedo
    from ..tables import THREADS, _cores

    if threads is not None and (isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1):
        raise ValueError(f"threads must be an integer >= 1, got {threads!r}")
    threads = max(1, threads or THREADS or _cores())
    models = spectral.models
    nw = len(models)
    val = np.empty((mus.size, nw))
    err = np.empty_like(val)
    if mus.size == 0:
        return val, err
    chunk = max(1, min(32, -(-mus.size * nw // (4 * threads))))  # >= 4 tasks per thread where possible
    n_chunks = -(-mus.size // chunk)
    tasks = [(j, np.arange(c, mus.size, n_chunks)) for j in range(nw) for c in range(n_chunks)]

    def work(task):
        j, idx = task
        val[idx, j], err[idx, j] = albedo(models[j], mus[idx], return_error=True, **kw)

    if threads == 1 or len(tasks) < 2:
        for t in tasks:
            work(t)
        return val, err
    if not getattr(spectral, "_warm", False):
        # the first value on this thread: it compiles what the kernels still need (two threads
        # compiling one numba ufunc at once race; pumpup.tables._chunked does the same)
        j, idx = tasks[0]
        work((j, idx[:1]))
        spectral._warm = True
    with ThreadPoolExecutor(min(threads, len(tasks))) as pool:
        list(pool.map(work, tasks))
    return val, err


__all__ += ["SpectralPumpedLobe"]


# --- how the core and the operators take spectral models --------------------------------------

from ..core import is_spectral_spec, register_loader  # noqa: E402
from ..operators import compensate as _compensate  # noqa: E402
from ..operators import pumping as _pumping  # noqa: E402

register_loader(is_spectral_spec, load)


@_pumping.pump_model.register(Spectral)
def _pump_spectral(base: Spectral, g: str, levels: int, force) -> SpectralPumped:
    return SpectralPumped(base, g=g, levels=levels, force=bool(force))  # each wavelength divided by its own g


@_pumping.save_pumped.register(Spectral)
def _save_spectral(f: Spectral, path) -> str:
    from .ops import save_spectral_pumped

    return save_spectral_pumped(f, path)  # one file with a wavelength dimension


def _load_spectral(path, root, where):
    from .ops import load_spectral_pumped

    return load_spectral_pumped(path, root, where)


_pumping.FILE_KINDS["pumpup spectral pumped BRDF"] = _load_spectral


@_compensate.furnace.register(Spectral)
def _furnace_spectral(f: Spectral, mu, return_error: bool = False, **kw):
    out = [_compensate.furnace(m, mu, return_error=True, **kw) for m in f.models]  # each wavelength's furnace
    v, e = np.stack([np.asarray(o[0]) for o in out], axis=-1), np.stack([np.asarray(o[1]) for o in out], axis=-1)
    return (v, e) if return_error else v


@_compensate.compensate_model.register(Spectral)
def _compensate_spectral(base: Spectral, method: str, *, f0, f_avg, white, force):
    from .ops import compensate_spectral

    return compensate_spectral(base, method, f0=f0, f_avg=f_avg, white=white, force=bool(force))


from .._lazy import submodules  # noqa: E402

__getattr__ = submodules(__name__)  # the package's modules on first use (pumpup.spectral.<module>)
