"""Lafortune's anisotropic generalisation of Phong, single lobe and multi-lobe sum.

The lobe is a power of the "special dot product" (R.V)_M = R^T M V with a diagonal
M = diag(Cx, Cy, Cz) and R = 2 (N.L) N - L the mirror direction of L (000 eq. 8, 14).
With N = (0, 0, 1), R = (-Lx, -Ly, Lz), so

    (R.V)_M = -Cx Lx Vx - Cy Ly Vy + Cz Lz Vz,

which is symmetric in L and V: the models are reciprocal.  Cx = Cy = Cz = 1 gives back
(R.V), i.e. Phong (p = 0) and stretched Phong (p = 1).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, vectorize

from ..core import BRDF, MAX_EXPONENT, Lobe, Param, SpecError, register


def _rv_m(wi, wo, cx, cy, cz):
    """(R.V)_M = Cx Rx Vx + Cy Ry Vy + Cz Rz Vz with R = (-Lx, -Ly, Lz) (000 eq. 14).

    The products Lx Vx are formed first so that the value is bitwise symmetric in L, V.
    """
    return cz * (wi[..., 2] * wo[..., 2]) - cx * (wi[..., 0] * wo[..., 0]) - cy * (wi[..., 1] * wo[..., 1])


def _up(wi, wo):
    return (wi[..., 2] > 0) & (wo[..., 2] > 0)


# --- one lobe ---------------------------------------------------------------------------

#: the largest peak value c max(|cx|, |cy|, |cz|)^n [1/sr] a lobe may have: (R.V)_M <= max |C| for unit
#: L and V, so f <= c max|C|^n; beyond this the values overflow in the kernel's arithmetic or the
#: albedo (up to pi x the peak) is not a reflectance any more, and the cubature ran for minutes
MAX_PEAK = 1e100


def _check_peak(model, n, cx, cy, cz, c, where=""):
    big = max(abs(cx), abs(cy), abs(cz))
    if c > 0 and big > 0:
        log_peak = math.log10(c) + n * math.log10(big)
        if log_peak > math.log10(MAX_PEAK):
            raise SpecError(
                f"{model}: the lobe's peak c max(|cx|, |cy|, |cz|)^n{where} = 10^{log_peak:.4g} exceeds {MAX_PEAK:g} "
                f"[1/sr]; reduce parameter 'c', 'n' or the coefficients 'cx', 'cy', 'cz'"
            )



@vectorize(cache=True)
def _kernel(lx, ly, lz, vx, vy, vz, n, cx, cy, cz, p, c):  # pragma: no cover - compiled
    if lz <= 0.0 or vz <= 0.0:
        return 0.0
    rv = cz * (lz * vz) - cx * (lx * vx) - cy * (ly * vy)  # 000 eq. 14, R = (-Lx, -Ly, Lz)
    if rv <= 0.0:
        return 0.0
    return c * rv**n / max(lz, vz) ** p  # 000 eq. 15


def _reference(wi, wo, n, cx, cy, cz, p, c):
    rv = np.maximum(_rv_m(wi, wo, cx, cy, cz), 0.0)
    mx = np.maximum(wi[..., 2], wo[..., 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        f = c * rv**n / mx**p  # 000 eq. 15 (eq. 14 when p = 0)
    return np.where(_up(wi, wo) & (rv > 0), f, 0.0)


def _isotropic_lobe(n, cx, cy, cz, p, mu):
    """The quadrature hint of one lobe (shared by the single lobe and the sum)."""
    levels = (mu,) if p > 0 else ()
    if cx == cy == cz and cx > 0:
        # (R.V)_M = Cx (R.V): a Phong power lobe around the mirror direction
        return Lobe(axis="mirror", radial="power", sharpness=n, levels=levels, symmetric=True)
    # anisotropic: no lobe knowledge; even in wo_y when wi is in the xz-plane.  The lobe's zero set (R.V)_M = cz mu
    # cos(alpha) - cx s sin(alpha) cos(beta) = 0 is a kink (a jump of the n-th derivative) that meets the horizon at
    # beta = pi/2, a boundary of the engines' dyadic pieces: unmarked, the thin sliver of lobe between it and pi/2 fell
    # between the last node and the boundary (n = 2, cx = 3, cz = 0.3 at mu = 0.2: 1.0e-7 missed with an estimate of
    # 2e-11).  With wi turned out of the xz-plane the
    # zero set is cos(beta - beta*) = ..., which this form does not hold: there the cut is an extra one, not the kink's
    return Lobe(axis="normal", radial="cosine", levels=levels, kinks=_zero_set_kinks(cx, cz), symmetric=True)


_KINKS: dict = {}


def _zero_set_kinks(cx, cz):
    """kinks(mu, s, cos_a, sin_a) -> [(a, b)] of the zero set a + b cos(beta) = 0 of (R.V)_M for wi in the xz-plane
    (one callable per (cx, cz), so that the hints of all mu group together).
    """
    key = (float(cx), float(cz))
    if key not in _KINKS:
        def kinks(mu, s, ca, sa, cx=key[0], cz=key[1]):
            return [(cz * mu * ca, -cx * s * sa)]
        _KINKS[key] = kinks
    return _KINKS[key]


@register("lafortune")
class Lafortune(BRDF):
    """Anisotropic Lafortune lobe, f_r = c [(R.V)_M]_+^n / max(N.L, N.V)^p [1/sr].

    (R.V)_M = Cx Rx Vx + Cy Ry Vy + Cz Rz Vz with R = 2 (N.L) N - L = (-Lx, -Ly, Lz)
    (000 eq. 14); p > 0 is the stretched form of 000 eq. 15.  Reciprocal, since
    (R.V)_M = -Cx Lx Vx - Cy Ly Vy + Cz Lz Vz is symmetric in L and V.

    Parameters
    ----------
    n : float, >= 0
        Exponent.
    cx, cy, cz : float, default 1
        Diagonal of M (dimensionless, any sign).  cx = cy = cz = 1 is Phong (p = 0) or
        stretched Phong (p = 1); cx != cy makes the lobe anisotropic; cx = cy < cz moves
        it towards the normal ("off-specular"), negative cx = cy towards the light.
    p : float, in [0, 1], default 0
        Stretch power (000 eq. 15); p = 0 is Lafortune's original lobe (000 eq. 14).
    c : float, >= 0, default 1
        Scale C_max [1/sr].

    Notes
    -----
    An anisotropic lobe's albedo depends on the azimuth of ``wi``, not only on mu:
    ``pumpup.albedo(f, mu, phi=...)`` (phi = 0 puts ``wi`` in the xz-plane).

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "lafortune", "n": 10, "cx": 0.8, "cy": 1.2, "cz": 1.1})
    >>> round(float(f.eval([0, 0, 1], [0, 0, 1])) / 1.1**10, 12)  # wi = wo = N: c cz^n
    1.0
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, doc="exponent"),
        "cx": Param(1.0, doc="M_xx (dimensionless)"),
        "cy": Param(1.0, doc="M_yy (dimensionless)"),
        "cz": Param(1.0, doc="M_zz (dimensionless)"),
        "p": Param(0.0, lo=0.0, hi=1.0, doc="stretch power"),
        "c": Param(1.0, lo=0.0, doc="scale [1/sr]"),
    }
    examples = [
        {"n": 20},
        {"n": 10, "cx": 0.8, "cy": 1.2, "cz": 1.1},
        {"n": 30, "cx": 1.0, "cy": 0.5, "cz": 1.0, "p": 1.0},
        {"n": 4.5, "cx": -1.0, "cy": -1.0, "cz": 1.0, "p": 0.5, "c": 0.3},
    ]
    kernel = staticmethod(_kernel)
    reference_fn = staticmethod(_reference)

    def _validate(self) -> None:
        q = self.p
        _check_peak(self.type, q["n"], q["cx"], q["cy"], q["cz"], q["c"])

    def lobe(self, mu):
        """The Lobe hint: a power lobe about the mirror direction where cx = cy = cz > 0, else the cosine map about the
        normal.
        """
        q = self.p
        return _isotropic_lobe(q["n"], q["cx"], q["cy"], q["cz"], q["p"], mu)

    def azimuth_hint(self):
        """The closed-form-azimuth hint (pumpup.engine.polar) where the lobe is isotropic:
        cx = cy = cz = C > 0 gives (R.V)_M = C (R.V) (stretched Phong), cx = cy = -cz, cz = C > 0
        gives C (L.V) (the retro-reflective lobe); the scale is c C^n (000 eq. 14, 15).
        """
        from ..core.hints import AzimuthHint, PowerLobe

        q = self.p
        C = q["cz"]
        if not C > 0 or q["cx"] != q["cy"] or abs(q["cx"]) != C:
            return None
        with np.errstate(over="ignore"):
            scale = float(q["c"] * np.float64(C) ** q["n"])
        return AzimuthHint(PowerLobe(n=q["n"], p=float(q["p"])), scale=lambda mu: np.full(np.shape(mu), scale))

    def lobe_axis(self, mu, phi):
        """For p = 0 (000 eq. 14): (R.V)_M = v.wo with v = (-cx Lx, -cy Ly, cz Lz), so f = c |v|^n (v^.wo)_+^n, a
        Phong power lobe about v^ at elevation nu = cz mu / |v|, scaled by c |v|^n (the
        1-D path about v^ at every azimuth of wi, :func:`pumpup.engine.polar.axis_albedo`).  None for p > 0
        (max(N.L, N.V) depends on mu itself), for cz <= 0 (v^ on or below the horizon), where :meth:`polar` applies, and
        where nu or the scale is not a positive finite number.  With cx = cy, |v| is taken without phi
        (the albedo is isotropic).
        """
        q = self.p
        if q["p"] != 0.0 or not q["cz"] > 0.0 or self.azimuth_hint() is not None:
            return None
        mu = np.asarray(mu, dtype=np.float64)
        s2 = (1.0 - mu) * (1.0 + mu)
        if q["cx"] == q["cy"]:
            side = q["cx"] * q["cx"] * s2
        else:
            phi = np.asarray(phi, dtype=np.float64)
            side = s2 * ((q["cx"] * np.cos(phi)) ** 2 + (q["cy"] * np.sin(phi)) ** 2)
        vz = q["cz"] * mu
        norm = np.sqrt(side + vz * vz)
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            nu = np.minimum(vz / norm, 1.0)
            scale = q["c"] * norm ** q["n"]
        if not (np.all(nu > 0.0) and np.all(np.isfinite(scale)) and np.all(scale > 0.0)):
            return None
        return float(q["n"]), nu, scale

    def azimuth_range(self):
        """None when cx = cy, else pi / 2 (the albedo is even in x and in y)."""
        # (R.V)_M is unchanged by x -> -x and by y -> -y of both L and V: a(phi) = a(-phi) = a(pi - phi)
        return None if self.p["cx"] == self.p["cy"] else np.pi / 2


# --- a sum of lobes -----------------------------------------------------------------------


@njit(cache=True)
def _sum_kernel(lx, ly, lz, vx, vy, vz, n, cx, cy, cz, p, c):  # pragma: no cover - compiled
    out = np.zeros(lx.size)
    for j in range(lx.size):
        if lz[j] <= 0.0 or vz[j] <= 0.0:
            continue
        mx = max(lz[j], vz[j])
        acc = 0.0
        for i in range(n.size):
            rv = cz[i] * (lz[j] * vz[j]) - cx[i] * (lx[j] * vx[j]) - cy[i] * (ly[j] * vy[j])  # 000 eq. 14
            if rv > 0.0:
                acc += c[i] * rv ** n[i] / mx ** p[i]  # 000 eq. 16
        out[j] = acc
    return out


def _sum_reference(wi, wo, n, cx, cy, cz, p, c):
    f = np.zeros(np.broadcast_shapes(wi.shape, wo.shape)[:-1])
    for ni, cxi, cyi, czi, pi_, ci in zip(n, cx, cy, cz, p, c):
        f = f + _reference(wi, wo, ni, cxi, cyi, czi, pi_, ci)  # 000 eq. 16: sum of eq. 15 lobes
    return f


def _ones_like_n(q):
    return [1.0] * len(q["n"])


def _zeros_like_n(q):
    return [0.0] * len(q["n"])


@register("lafortune_sum")
class LafortuneSum(BRDF):
    """A sum of Lafortune lobes, f_r = sum_i c_i [(R.V)_M_i]_+^n_i / max(N.L, N.V)^p_i [1/sr].

    000 eq. 16 (each term as in 000 eq. 15; see :class:`Lafortune`).  Every parameter is
    a list with one entry per lobe; all lists have the same length.

    Parameters
    ----------
    n : list of float, each >= 0
        Exponents.
    cx, cy, cz : list of float, default all 1
        Diagonals of the M_i (dimensionless).
    p : list of float, each in [0, 1], default all 0
        Stretch powers.
    c : list of float, each >= 0, default all 1
        Scales C_i [1/sr].

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "lafortune_sum", "n": [5, 50], "c": [0.2, 3.0]})
    >>> g = pumpup.load({"type": "lafortune", "n": 5, "c": 0.2})
    >>> h = pumpup.load({"type": "lafortune", "n": 50, "c": 3.0})
    >>> wi, wo = [0.6, 0, 0.8], [-0.5, 0.1, 0.86023252670426]
    >>> bool(abs(f.eval(wi, wo) - g.eval(wi, wo) - h.eval(wi, wo)) < 1e-12)
    True
    """

    params = {
        "n": Param(lo=0.0, hi=MAX_EXPONENT, kind="floats", doc="exponents"),
        "cx": Param(_ones_like_n, kind="floats", doc="M_xx per lobe"),
        "cy": Param(_ones_like_n, kind="floats", doc="M_yy per lobe"),
        "cz": Param(_ones_like_n, kind="floats", doc="M_zz per lobe"),
        "p": Param(_zeros_like_n, lo=0.0, hi=1.0, kind="floats", doc="stretch powers"),
        "c": Param(_ones_like_n, lo=0.0, kind="floats", doc="scales [1/sr]"),
    }
    constant = None  # one scale per lobe, no single constant
    examples = [
        {"n": [5.0, 50.0], "c": [0.2, 3.0]},
        {"n": [3.0, 20.0, 200.0], "cx": [-1.0, 0.7, 1.0], "cy": [-1.0, 1.3, 1.0], "cz": [1.0, 1.0, 1.0],
         "p": [0.0, 0.5, 1.0], "c": [0.1, 1.0, 10.0]},
    ]
    reference_fn = staticmethod(_sum_reference)

    def _validate(self) -> None:
        lengths = {k: len(v) for k, v in self.p.items()}
        if len(set(lengths.values())) > 1:
            text = ", ".join(f"{k!r} has {m}" for k, m in lengths.items())
            raise SpecError(f"{self.type}: parameters 'n', 'cx', 'cy', 'cz', 'p', 'c' must be lists of equal length "
                            f"(one entry per lobe); {text}")
        for i, (n, cx, cy, cz, c) in enumerate(zip(*(self.p[k] for k in ("n", "cx", "cy", "cz", "c")))):
            _check_peak(self.type, n, cx, cy, cz, c, where=f" of lobe {i}")

    def kernel_args(self) -> tuple:
        """The parameter lists as float64 arrays, one entry per lobe, for the compiled kernel."""
        return tuple(np.asarray(self.p[k], dtype=np.float64) for k in self.params)

    def _eval(self, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
        wi, wo = np.broadcast_arrays(wi, wo)
        shape = wi.shape[:-1]
        a = np.ascontiguousarray(wi.reshape(-1, 3).T)
        b = np.ascontiguousarray(wo.reshape(-1, 3).T)
        out = _sum_kernel(a[0], a[1], a[2], b[0], b[1], b[2], *self.kernel_args())
        return out.reshape(shape)

    def reference(self, wi, wo) -> np.ndarray:
        """The plain numpy f_r: the sum of the lobes."""
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        return _sum_reference(wi, wo, *(self.p[k] for k in self.params))

    def lobes(self) -> list[BRDF]:
        """The terms as single :class:`Lafortune` lobes (with their scales c_i)."""
        keys = list(self.params)
        return [Lafortune(**dict(zip(keys, vals))) for vals in zip(*(self.p[k] for k in keys))]

    def albedo_terms(self):
        """The lobes as terms of weight 1 (:meth:`lobes`)."""
        return [(1.0, lobe) for lobe in self.lobes()]

    def azimuth_range(self):
        """None when every lobe has cx = cy, else pi / 2."""
        return None if all(x == y for x, y in zip(self.p["cx"], self.p["cy"])) else np.pi / 2

    def lobe(self, mu):
        """The single lobe's hint for one lobe, else the cosine map about the normal (with the kink at N.wo = mu where a
        p > 0).
        """
        q = self.p
        if len(q["n"]) == 1:
            return _isotropic_lobe(q["n"][0], q["cx"][0], q["cy"][0], q["cz"][0], q["p"][0], mu)
        levels = (mu,) if any(v > 0 for v in q["p"]) else ()
        return Lobe(axis="normal", radial="cosine", levels=levels, symmetric=True)

