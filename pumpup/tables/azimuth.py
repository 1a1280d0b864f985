"""The azimuth of incidence: albedo tables over (mu, phi) and the supremum over phi.

An anisotropic BRDF's directional albedo depends on the azimuth phi of wi as well as on
mu = cos(theta_i): a(mu, phi) (``pumpup.albedo(f, mu, phi=...)``).  The pumping operator of
001 sec. 3 divides by g >= a(L) for every L (001 eq. 17-18), so for such a base it needs an
upper bound of

    A(mu) = sup over phi of a(mu, phi),

which :func:`sup_albedo` computes and ``pumpup.tabulate(f, phi="sup")`` tabulates.

How the supremum is bounded
---------------------------
a(mu, .) is a smooth periodic function of phi (an integral of f over wo, rotated with wi).
Where the model is symmetric under y -> -y and x -> -x (``BRDF.azimuth_range() == pi / 2``),
a(phi) = a(-phi) = a(pi - phi): it is even about 0 and pi / 2 and all its values lie on
[0, pi / 2]; it is sampled at J + 1 equispaced nodes there and extended evenly to a period
of pi.  Otherwise (``2 pi``: nothing known) it is sampled at 2 J nodes on [0, 2 pi).  The
samples define a trigonometric interpolant (exact for a trigonometric polynomial of degree
below the sampling's Nyquist limit; for a smooth periodic function the error falls
geometrically with J).  Its error is *measured* at the midpoints between the nodes, where
the albedo is computed too, and J is doubled (the midpoints become nodes) until that error
is below the tolerance (or J = :data:`J_MAX`).  The bound is

    A(mu) <= max over phi of the interpolant + SAFETY x (its measured midpoint error)
             + the largest quadrature error of the samples,

with the maximum of the interpolant taken on a grid 32 times finer than the nodes (the
interpolant's own curvature between those points is below 1e-3 of its measured error for
the J used) and never below the largest computed sample.  This is the rule the albedo
tables use in mu (``pumpup.tables.AlbedoTable.upper``: an interpolant plus twice the
interpolation error measured at the midpoints plus the quadrature error), applied in phi;
:data:`SAFETY` is the same factor 2.  The tests check the bound against albedos computed
at random azimuths.
"""

from __future__ import annotations

import math

import numpy as np

from ..core import BRDF
from ..engine.cubature import check_phi

__all__ = ["sup_albedo", "J_START", "J_MAX", "SAFETY"]

#: the first number of intervals on the azimuth range, doubled until the interpolant meets
#: its tolerance (at most J_MAX)
J_START = 4
J_MAX = 128
#: the measured midpoint error of the interpolant is multiplied by this in the bound
SAFETY = 2.0
#: the dense grid on which the interpolant's maximum is found, per node interval
_DENSE = 32


class _NoBar:
    def update(self, n):
        pass


def _trig_up(v: np.ndarray, factor: int) -> np.ndarray:
    """The trigonometric interpolant of the periodic samples v (..., N), at N * factor
    equispaced points of the same period (the first at the first sample).
    """
    n = v.shape[-1]
    spec = np.fft.rfft(v, axis=-1)
    if n % 2 == 0:
        spec[..., -1] *= 0.5  # the Nyquist term, split between +-N/2: a cosine
    m = n * factor
    full = np.zeros(v.shape[:-1] + (m // 2 + 1,), dtype=complex)
    full[..., :spec.shape[-1]] = spec
    return np.fft.irfft(full, n=m, axis=-1) * factor


def _period(nodes: np.ndarray, symmetric: bool) -> np.ndarray:
    """Samples on one full period from the nodes (..., J + 1) on [0, P] (even extension) or
    the nodes (..., 2 J) on [0, 2 pi).
    """
    if symmetric:
        return np.concatenate([nodes, nodes[..., -2:0:-1]], axis=-1)
    return nodes


def sup_albedo(brdf: BRDF, mu, *, rtol: float = 1e-10, atol: float = 1e-14, tol: float = 1e-8,
               threads: int | None = None, return_samples: bool = False):
    """An upper bound of the supremum over the azimuth phi of wi of the albedo a(mu, phi).

    Parameters
    ----------
    brdf : BRDF
        Any BRDF; for an isotropic one (``azimuth_range()`` None) this is its albedo.
    mu : array_like
        cos(theta_i), each in (0, 1].
    rtol, atol : float
        Quadrature tolerance of every sample (:func:`pumpup.albedo`).
    tol : float
        The interpolant in phi is refined until its measured midpoint error is below this
        (absolute), or the number of intervals reaches :data:`J_MAX`.
    threads : int, optional
        As in :func:`pumpup.tabulate`.
    return_samples : bool
        Also return the azimuths and the albedos computed (for tests).

    Returns
    -------
    (value, error) : ndarrays of the shape of ``mu``
        ``value + error`` is the upper bound: ``value`` is the interpolant's maximum (at
        least the largest sample) and ``error`` = SAFETY x the measured interpolation error
        + the largest quadrature error of the samples (see the module docstring).
    """
    from ..engine.cubature import check_mu
    from . import _chunked

    m = check_mu(mu)
    flat = m.ravel()
    rng = brdf.azimuth_range()
    if rng is None:
        v, e = _chunked(brdf, flat, rtol, atol, _NoBar(), threads)
        out = (v.reshape(m.shape), e.reshape(m.shape))
        return out + ([(np.zeros(1), v[i:i + 1]) for i in range(len(v))],) if return_samples else out
    symmetric = abs(rng - math.pi / 2) < 1e-15
    if not symmetric and abs(rng - 2 * math.pi) > 1e-15:
        raise ValueError(f"{brdf!r}: azimuth_range() must be None, pi/2 or 2 pi, got {rng!r}")

    def grid(j):  # nodes and midpoints for j intervals
        if symmetric:
            h = rng / j
            return np.arange(j + 1) * h, (np.arange(j) + 0.5) * h
        h = 2 * math.pi / (2 * j)
        return np.arange(2 * j) * h, (np.arange(2 * j) + 0.5) * h

    def compute(mus, phis):
        val = np.empty((len(mus), len(phis)))
        err = np.empty_like(val)
        for k, p in enumerate(phis):
            val[:, k], err[:, k] = _chunked(brdf, mus, rtol, atol, _NoBar(), threads, phi=float(p))
        return val, err

    value = np.empty(len(flat))
    error = np.empty(len(flat))
    samples = {}
    j = J_START
    nodes_phi, mids_phi = grid(j)
    todo = np.arange(len(flat))
    nv, ne = compute(flat, nodes_phi)
    while len(todo):
        mv, me = compute(flat[todo], mids_phi)
        # the interpolant of the nodes at the nodes and midpoints: factor 2 of the period samples
        up2 = _trig_up(_period(nv, symmetric), 2)
        pred = up2[:, 1::2][:, :len(mids_phi)]
        miss = np.max(np.abs(pred - mv), axis=1)
        qerr = np.maximum(ne.max(axis=1), me.max(axis=1))
        done = (miss <= tol) | (2 * j > J_MAX)
        if np.any(done):
            dense = _trig_up(_period(nv[done], symmetric), _DENSE).max(axis=1)
            top = np.maximum(dense, np.maximum(nv[done].max(axis=1), mv[done].max(axis=1)))
            value[todo[done]] = top
            error[todo[done]] = SAFETY * miss[done] + qerr[done]
            if return_samples:
                for i in np.nonzero(done)[0]:
                    samples[todo[i]] = (np.concatenate([nodes_phi, mids_phi]), np.concatenate([nv[i], mv[i]]))
        keep = ~done
        if not keep.any():
            break
        # the midpoints become nodes: interleave them
        j *= 2
        nodes_new, mids_phi = grid(j)
        merged = np.empty((int(keep.sum()), len(nodes_new)))
        merged_e = np.empty_like(merged)
        merged[:, 0::2], merged_e[:, 0::2] = nv[keep], ne[keep]
        merged[:, 1::2], merged_e[:, 1::2] = mv[keep], me[keep]
        nv, ne, nodes_phi, todo = merged, merged_e, nodes_new, todo[keep]
    out = (value.reshape(m.shape), error.reshape(m.shape))
    if return_samples:  # per value of mu: (azimuths, albedos) of the interpolant that gave the bound
        return out + ([samples[i] for i in range(len(flat))],)
    return out


# --- plumbing for pumpup.tabulate -----------------------------------------------------------

def table_values(brdf: BRDF, phi, rtol, atol, threads, interp_tol):
    """For :func:`pumpup.tabulate`: (values(mu, bar) -> (val, err), phis or None, phi_kind or None).

    ``val`` is (n,) for a table over mu, (n, k) for one over (mu, phi); ``phi_kind`` is what
    the attributes of a table over mu of an anisotropic model say: 0.0 or "sup".
    """
    from . import _chunked

    aniso = brdf.azimuth_range() is not None
    if phi is None:
        return (lambda mu, bar: _chunked(brdf, mu, rtol, atol, bar, threads)), None, (0.0 if aniso else None)
    if isinstance(phi, str):
        if phi != "sup":
            raise ValueError(f"tabulate: phi must be None, a number, an array of numbers or 'sup', got {phi!r}")
        if not aniso:
            return (lambda mu, bar: _chunked(brdf, mu, rtol, atol, bar, threads)), None, None

        def sup(mu, bar):
            v, e = sup_albedo(brdf, mu, rtol=rtol, atol=atol, tol=interp_tol, threads=threads)
            bar.update(len(mu))
            return v, e
        return sup, None, "sup"
    phis = np.atleast_1d(check_phi(phi)).astype(np.float64).ravel()
    if not len(phis):
        raise ValueError("tabulate: phi must hold at least one azimuth (radians), got an empty array")
    if len(np.unique(phis)) != len(phis):
        raise ValueError("tabulate: the values of phi must be distinct")

    def grid(mu, bar):
        if not aniso:  # isotropic: one column, the same at every phi
            v, e = _chunked(brdf, mu, rtol, atol, bar, threads)
            return np.repeat(v[:, None], len(phis), axis=1), np.repeat(e[:, None], len(phis), axis=1)
        val = np.empty((len(mu), len(phis)))
        err = np.empty_like(val)
        for k, p in enumerate(phis):
            val[:, k], err[:, k] = _chunked(brdf, mu, rtol, atol, _NoBar(), threads, phi=float(p))
        bar.update(len(mu))
        return val, err
    return grid, phis, None


def phi_dataset(ds1, val, err, phis):
    """The table over (mu, phi) with the coordinates and attributes of the one-column table ds1."""
    out = ds1.drop_vars(["albedo", "albedo_error"])
    out = out.assign_coords(phi=("phi", phis, {"long_name": "azimuth of wi, from the tangent x axis towards y",
                                               "units": "radian"}))
    out["albedo"] = (("mu", "phi"), val, dict(ds1["albedo"].attrs, long_name="directional albedo a(mu, phi)"))
    out["albedo_error"] = (("mu", "phi"), err, ds1["albedo_error"].attrs)
    out.attrs["azimuth"] = "phi is the azimuth of wi = (sin theta_i cos phi, sin theta_i sin phi, cos theta_i)"
    return out


def describe_phi(ds, brdf, kind):
    """Say in the attributes of a table over mu which azimuth of wi it holds."""
    if kind == "sup":
        ds.attrs["azimuth"] = ("sup over phi: albedo + albedo_error bounds the supremum over the azimuth of wi "
                               "of a(mu, phi) (pumpup.tables.azimuth.sup_albedo)")
        ds["albedo"].attrs["long_name"] = "supremum over phi of the directional albedo (centre of the bound)"
    else:
        ds.attrs["azimuth"] = f"phi = {float(kind):g} rad: wi in the xz-plane (the albedo of this model depends on phi)"
