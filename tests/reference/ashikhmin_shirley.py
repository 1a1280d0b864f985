"""An independent Ashikhmin-Shirley BRDF and albedo quadrature, for tests/models/test_ashikhmin_shirley.py.

Written from the paper's formulas (M. Ashikhmin and P. Shirley, "An Anisotropic Phong BRDF Model", Journal of
Graphics Tools 5(2), 2000, eq. 4 and 5) in the most literal way: h is normalised, its azimuth phi_h taken with
arctan2, the exponent nu cos^2 phi_h + nv sin^2 phi_h, (h.n) raised to it, 1 - (1 - x)^5 as written.  It shares
no code with pumpup (it imports numpy and scipy only).

The albedo a(mu, phi) = integral over the hemisphere of f_r(wi, wo) cos(theta_o) d omega_o, two ways:

* method A (:func:`albedo`): a product Gauss-Legendre rule in (theta_o, phi_o) (d omega = sin(theta) d theta d phi:
  smooth at the pole, where a rule in cos(theta) would meet a square root), on panels graded geometrically towards
  the mirror direction of wi (where the lobe peaks and, at theta_o = theta_i, max(N.wi, N.wo) has its kink) and, in
  phi_o, towards the tangent axes (where an anisotropic lobe is a ridge);
* method B (:func:`albedo_cylinder`): cylindrical coordinates about the tangent axis of the larger exponent, in
  which the ridge of a strongly anisotropic lobe (S_axis = 0, S = wi + wo) is a straight line (in (theta, phi) it is
  a curve that a product rule does not resolve), a rule per slice with the kink N.wo = mu as a break.

Each returns the value on 3n/2 nodes per panel with, as its error, the difference from the value on n nodes (plus
1e-14 relative for rounding); the tests check that this estimate holds against a finer resolution and closed forms.
The same rules integrate a sampling density over the hemisphere (:func:`pdf_integral`).
"""

import math

import numpy as np
from numpy.polynomial.legendre import leggauss


def brdf(wi, wo, nu, nv, rs, rd=0.0):
    """f_r(wi, wo) [1/sr] of eq. 4 + 5, literally; wi = k1 (light), wo = k2 (viewer); 0 below the horizon."""
    k1 = np.asarray(wi, dtype=float)
    k2 = np.asarray(wo, dtype=float)
    k1, k2 = np.broadcast_arrays(k1, k2)
    n_dot_k1 = k1[..., 2]
    n_dot_k2 = k2[..., 2]
    h = k1 + k2
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    n_dot_h = h[..., 2]
    phi_h = np.arctan2(h[..., 1], h[..., 0])  # azimuth of h from the u (x) axis
    exponent = nu * np.cos(phi_h) ** 2 + nv * np.sin(phi_h) ** 2  # = (nu (h.u)^2 + nv (h.v)^2) / (1 - (h.n)^2)
    h_dot_k = np.sum(k1 * h, axis=-1)
    fresnel = rs + (1.0 - rs) * (1.0 - h_dot_k) ** 5  # eq. 5 (Schlick)
    rho_s = (math.sqrt((nu + 1.0) * (nv + 1.0)) / (8.0 * math.pi) * n_dot_h**exponent
             / (h_dot_k * np.maximum(n_dot_k1, n_dot_k2)) * fresnel)  # eq. 4
    rho_d = (28.0 * rd / (23.0 * math.pi) * (1.0 - rs) * (1.0 - (1.0 - n_dot_k1 / 2.0) ** 5)
             * (1.0 - (1.0 - n_dot_k2 / 2.0) ** 5))  # eq. 5
    up = (n_dot_k1 > 0) & (n_dot_k2 > 0)
    with np.errstate(invalid="ignore"):
        return np.where(up, rho_s + rho_d, 0.0)


def direction(mu, phi):
    """The unit vector with cos(theta) = mu at azimuth phi."""
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    return np.array([s * math.cos(phi), s * math.sin(phi), mu])


def graded(centres, lo, hi, w, ratio=2.0):
    """Breaks in [lo, hi]: the ends, each centre and centre +- w ratio^k."""
    pts = {lo, hi}
    for c in centres:
        if lo < c < hi:
            pts.add(c)
        d = w
        while d < hi - lo:
            for x in (c - d, c + d):
                if lo < x < hi:
                    pts.add(x)
            d *= ratio
    pts = np.array(sorted(pts))
    keep = np.r_[True, np.diff(pts) > 1e-14]
    return pts[keep]


def _rule(breaks, n):
    """Gauss-Legendre nodes and weights, n per panel between consecutive breaks."""
    x, w = leggauss(n)
    a, b = breaks[:-1, None], breaks[1:, None]
    return (0.5 * (b - a) * x + 0.5 * (b + a)).ravel(), (0.5 * (b - a) * w).ravel()


def hemisphere_integral(g, theta_c, phi_c, width, axes_width, n=20, chunk=200_000):
    """Integral over the upper hemisphere of g(w) d omega (g maps (..., 3) directions to values).

    theta_c, phi_c: the peak; width: the smallest panel about it [rad]; axes_width: the smallest panel in phi about
    the tangent axes (phi = k pi / 2).  Returns the value on n nodes per panel."""
    tb = graded([theta_c], 0.0, 0.5 * math.pi, width)
    wphi = width / max(math.sin(theta_c), width)
    lo, hi = phi_c - math.pi, phi_c + math.pi
    axes = [k * 0.5 * math.pi for k in range(-4, 9)]
    pb = np.union1d(graded([phi_c], lo, hi, min(wphi, 1.0)),
                    graded([a for a in axes if lo < a < hi], lo, hi, axes_width))
    pb = pb[np.r_[True, np.diff(pb) > 1e-14]]
    t, wt = _rule(tb, n)
    p, wp = _rule(pb, n)
    st, ct = np.sin(t), np.cos(t)
    total = 0.0
    step = max(1, chunk // len(p))
    for i in range(0, len(t), step):
        s_, c_ = st[i:i + step, None], ct[i:i + step, None]
        w = np.stack(np.broadcast_arrays(s_ * np.cos(p), s_ * np.sin(p), c_), axis=-1)
        total += float(np.sum(g(w) * (s_ * wt[i:i + step, None]) * wp))
    return total


def _widths(nu, nv, mu):
    """(smallest panel about the peak, about the axes in phi): a quarter of the narrowest lobe's width in wo,
    2 / sqrt(e + 1) (h tilted by delta has (N.h)^e ~ exp(-e delta^2 / 2), and wo moves by 2 delta in the plane of
    incidence, by |wi + wo| delta = 2 mu delta across it at the mirror direction), and of the azimuthal width
    sqrt((min + 1) / (max + 1)) of a ridge."""
    e_max, e_min = max(nu, nv), min(nu, nv)
    w = 0.25 * max(mu, 1e-6) * min(1.0, 2.0 / math.sqrt(e_max + 1.0))
    return w, 0.25 * min(1.0, math.sqrt((e_min + 1.0) / (e_max + 1.0)))


def albedo(mu, nu, nv, rs, rd=0.0, phi=0.0, n=20):
    """(a, error): a(mu, phi) on 3n/2 nodes per panel, error = |a(n) - a(3n/2)| plus rounding."""
    wi = direction(mu, phi)
    w, wa = _widths(nu, nv, mu)

    def g(wo):
        return brdf(wi, wo, nu, nv, rs, rd) * wo[..., 2]

    theta_m, phi_m = math.acos(mu), phi + math.pi  # the mirror direction of wi
    a1 = hemisphere_integral(g, theta_m, phi_m, w, wa, n)
    a2 = hemisphere_integral(g, theta_m, phi_m, w, wa, (3 * n) // 2)
    return a2, abs(a2 - a1) + 1e-14 * abs(a2)


def pdf_integral(pdf, wo, nu, nv, n=20):
    """(integral over the upper hemisphere of pdf(wi, wo) d omega_i, error), as :func:`albedo`."""
    wo = np.asarray(wo, dtype=float)
    w, wa = _widths(nu, nv, float(wo[2]))
    theta_m, phi_m = math.acos(wo[2]), math.atan2(wo[1], wo[0]) + math.pi

    def g(wi):
        return pdf(wi, wo)

    a1 = hemisphere_integral(g, theta_m, phi_m, w, wa, n)
    a2 = hemisphere_integral(g, theta_m, phi_m, w, wa, (3 * n) // 2)
    return a2, abs(a2 - a1) + 1e-14 * abs(a2)


# --- method B: cylindrical coordinates about a tangent axis ------------------------------------------------


def cylinder_integral(g, axis, t_c, psi_c, kink_mu, width, n=20):
    """Integral over the upper hemisphere of g(w) d omega in cylindrical coordinates about the tangent axis
    ``axis`` (0 = x, 1 = y): w_axis = t in [-1, 1], (w_other, w_z) = sqrt(1 - t^2) (cos psi, sin psi), psi in
    [0, pi], d omega = dt d psi (Archimedes).  The horizon is psi = 0 and pi, the ends of every slice.

    t_c: the line of the lobe's ridge (t = const); psi_c(t): its centre in psi on the slice t (or None);
    kink_mu: w_z = kink_mu is a break on every slice (max(N.wi, N.wo)); width: the smallest panel about the
    centres (graded by 2)."""
    other = 1 - axis
    rt = math.sqrt((1.0 - kink_mu) * (1.0 + kink_mu))  # |t| where the slice leaves the region w_z > kink_mu
    tb = graded([t_c, -rt, rt], -1.0, 1.0, width)
    t, wt = _rule(tb, n)
    total = 0.0
    for tk, wk in zip(t, wt):
        r = math.sqrt((1.0 - tk) * (1.0 + tk))
        centres = []
        pc = psi_c(tk)
        if pc is not None:
            centres.append(pc)
        pb = graded(centres, 0.0, math.pi, width / max(r, width))
        if kink_mu < r:
            p1 = math.asin(kink_mu / r)
            pb = np.union1d(pb, [p1, math.pi - p1])
            pb = pb[np.r_[True, np.diff(pb) > 1e-15]]
        p, wp = _rule(pb, n)
        w = np.empty((len(p), 3))
        w[:, axis] = tk
        w[:, other] = r * np.cos(p)
        w[:, 2] = r * np.sin(p)
        total += wk * float(np.sum(g(w) * wp))
    return total


def _cylinder_setup(k, nu, nv):
    """(axis, t_c, psi_c, width) for a lobe about the mirror direction of k: the axis of the larger exponent (the
    ridge s_axis = k_axis + w_axis = 0 is then the line t = -k_axis), the centre of each slice where the other
    component of s vanishes, and a smallest panel well inside the narrowest width (near grazing the lobe's width
    in wo shrinks with |k + w| = 2 N.k at the mirror direction)."""
    axis = 1 if nv >= nu else 0
    other = 1 - axis
    t_c = -float(k[axis])
    target = -float(k[other])

    def psi_c(t):  # where s_other = 0 on the slice, or the nearer end (the horizon) where it cannot vanish
        r = math.sqrt((1.0 - t) * (1.0 + t))
        return math.acos(min(1.0, max(-1.0, target / r))) if r > 0 else None

    width = 0.05 * max(float(k[2]), 1e-6) * min(1.0, 2.0 / math.sqrt(max(nu, nv) + 1.0))
    return axis, t_c, psi_c, width


def albedo_cylinder(mu, nu, nv, rs, rd=0.0, phi=0.0, n=20):
    """(a, error) as :func:`albedo`, by :func:`cylinder_integral` (for strongly anisotropic lobes, whose ridge
    is a straight line in these coordinates and a curve in (theta, phi))."""
    wi = direction(mu, phi)
    axis, t_c, psi_c, width = _cylinder_setup(wi, nu, nv)

    def g(wo):
        return brdf(wi, wo, nu, nv, rs, rd) * wo[..., 2]

    a1 = cylinder_integral(g, axis, t_c, psi_c, mu, width, n)
    a2 = cylinder_integral(g, axis, t_c, psi_c, mu, width, (3 * n) // 2)
    return a2, abs(a2 - a1) + 1e-14 * abs(a2)
