"""What a renderer's white furnace shows, predicted from its albedo table and its look-up.

A white, F = 1 metal in a white environment should vanish: every pixel should read 1.  A renderer that
compensates the energy its microfacet BRDF loses does so with its own table, read by its own look-up, so what it
renders differs from 1 by the table's and the look-up's error.  For a view direction at cos(theta_o) = mu and a
roughness x (the table's axis quantity), with E the true directional albedo (000 eq. 2) and E_l the renderer's
look-up of its table:

* ``"scale"`` (Cycles' Multiscatter GGX, Turquin 2019 with F0 = 1): f / E_l(mu_o), whose furnace is
  E(mu) / E_l(mu) (f is reciprocal, so the furnace toward the viewer is E);
* ``"kulla_conty"``: f + (1 - E_l(mu_i)) (1 - E_l(mu_o)) / (pi (1 - E_avg,l)) (Kulla and Conty 2017), whose
  furnace is E(mu) + (1 - E_l(mu)) (1 - A_l) / (1 - E_avg,l), with A_l = 2 integral E_l mu dmu of the look-up
  and E_avg,l the renderer's look-up of its E_avg table (A_l where it has none);
* ``"none"``: E(mu).
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from .conventions import ConventionsError, load_conventions, quantise
from .luts import mean_albedo_grid, model_spec, truth_grid

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["furnace_prediction", "METHODS"]

METHODS = ("scale", "kulla_conty", "none")


def _grid(v, name: str, lo: float, hi: float) -> np.ndarray:
    a = np.atleast_1d(np.asarray(v, dtype=np.float64))
    if a.ndim != 1 or a.size == 0 or not np.all(np.isfinite(a)) or a.min() < lo or a.max() > hi:
        raise ConventionsError(f"{name} must be a non-empty 1-D array of numbers in [{lo:g}, {hi:g}]")
    return a


def furnace_prediction(conventions, method: str = "scale", *, path: str | os.PathLike | None = None, mu=None,
                       roughness=None, model=None, rtol: float = 1e-7, threads: int | None = None,
                       max_regions: int = 200) -> xr.Dataset:
    """The white-furnace value a renderer that compensates with its table renders, per view cosine and roughness.

    Parameters
    ----------
    conventions : str, path, dict or Conventions
        The renderer's table, described as :mod:`pumpup.conventions` says (a preset name such as ``"cycles"``
        works too); an E table (not an E_avg one).
    method : {"scale", "kulla_conty", "none"}
        How the renderer compensates (see the module docstring).
    path : path, optional
        The shipped table file.  Without it, the table holds pumpup's exact E at the nodes, rounded by the
        storage: what remains is the look-up's error alone.
    mu : array_like, optional
        View cosines in (0, 1] (default 64 cell centres, (k + 0.5) / 64).
    roughness : array_like, optional
        Values of the table's roughness axis quantity (roughness or alpha, as the conventions name it; default 32
        cell centres of its range).
    model : str or dict, optional
        Overrides the conventions' model for the truth.
    rtol : float
        Quadrature tolerance of the true E.

    Returns
    -------
    xarray.Dataset
        Over (``mu``, and ``roughness`` or ``alpha``): ``furnace`` with ``furnace_error`` (from the truth's
        quadrature error), ``E_true``, ``E_lookup`` and, for Kulla-Conty, ``E_avg_lookup`` and ``A_lookup``;
        coordinate ``alpha``; attributes ``method``, ``model``, ``table``, ``lookup``.

    Examples
    --------
    >>> import pumpup
    >>> ds = pumpup.furnace_prediction("cycles", method="scale", mu=[0.5], roughness=[0.5])
    >>> abs(float(ds["furnace"][0, 0]) - 1) < 1e-3
    True
    """
    import xarray as xr

    if method not in METHODS:
        raise ConventionsError(f"method must be one of {', '.join(METHODS)}; got {method!r}")
    c = load_conventions(conventions)
    if c.average:
        raise ConventionsError("conventions: field 'quantity' must be E or 1-E for a furnace prediction (the "
                               "compensation reads E(mu))")
    spec, param = model_spec(c.model if model is None else model)
    ax = c.rough_axis
    lo, hi = ax.range
    mu = _grid((np.arange(64) + 0.5) / 64 if mu is None else mu, "mu", 1e-12, 1.0)
    if mu.min() <= 0:
        raise ConventionsError("mu must be in (0, 1]")
    x = _grid(lo + (hi - lo) * (np.arange(32) + 0.5) / 32 if roughness is None else roughness, ax.axis, lo, hi)
    if path is not None:
        tab = c.read(path)
        table = tab["E"]
        e_avg = tab.get("E_avg")
        source = os.fspath(path)
    else:
        mu_n, x_n = c.nodes()
        tr = truth_grid(spec, param, mu_n, c.rough_of(x_n), rtol=rtol, threads=threads, max_regions=max_regions)
        mask, val = c.fixed_mask()
        exact = np.where(mask, val, tr["E"])
        stored = quantise(exact if c.stores == "E" else 1.0 - exact, c.storage)
        table = stored if c.stores == "E" else 1.0 - stored
        e_avg = None
        if method == "kulla_conty" and c.e_avg:
            ea, _ = mean_albedo_grid(spec, param, c.rough_of(x_n), rtol=rtol, threads=threads,
                                     max_regions=max_regions)
            e_avg = quantise(ea if c.stores == "E" else 1.0 - ea, c.storage)
            e_avg = e_avg if c.stores == "E" else 1.0 - e_avg
        source = f"pumpup's exact E at the nodes, stored as {c.storage}"
    r = c.rough_of(x)
    tr = truth_grid(spec, param, mu, r, rtol=rtol, threads=threads, max_regions=max_regions)
    e_true, e_err = tr["E"], tr["E_error"]
    e_l = c.look_up(table, mu[:, None], x[None, :])
    dims = ("mu", ax.axis)
    data = {"E_true": (dims, e_true, {"long_name": "true directional albedo E(mu) (000 eq. 2)"}),
            "E_lookup": (dims, e_l, {"long_name": "the renderer's look-up of its table"})}
    if method == "scale":
        fur = e_true / e_l  # f / E_l(mu_o): furnace E(mu) / E_l(mu) (Turquin 2019 eq. 6 with F0 = 1)
        ferr = e_err / e_l
    elif method == "none":
        fur, ferr = e_true, e_err
    else:
        a_l = c.look_up_average(c.own_average(table), x)  # 2 int E_l mu dmu, exact for a look-up linear in the columns
        ea_l = a_l if e_avg is None else c.look_up_average(e_avg, x)
        den = 1.0 - ea_l
        ratio = np.where(den > 1e-12, (1.0 - a_l) / np.where(den > 1e-12, den, 1.0), 0.0)
        fur = e_true + (1.0 - e_l) * ratio[None, :]  # E + int f_ms cos d omega_i (Kulla and Conty 2017)
        ferr = e_err
        data["E_avg_lookup"] = ((ax.axis,), ea_l, {"long_name": "the renderer's E_avg at this roughness"})
        data["A_lookup"] = ((ax.axis,), a_l, {"long_name": "2 integral E_lookup mu dmu"})
    data["furnace"] = (dims, fur, {"long_name": f"white furnace toward the viewer, {method} compensation",
                                   "units": "1"})
    data["furnace_error"] = (dims, ferr, {"long_name": "error bound of furnace from the truth's quadrature"})
    return xr.Dataset(data, coords={"mu": ("mu", mu, {"long_name": "cos(theta_o) of the view direction"}),
                                    ax.axis: (ax.axis, x, {"long_name": f"the table's {ax.axis} axis"}),
                                    "alpha": (ax.axis, c.alpha_of(x), {"long_name": f"model parameter {param}"})},
                      attrs={"method": method, "model": c.model if model is None else str(model), "table": source,
                             "lookup": c.lookup, "conventions": c.name})
