"""30-digit albedos of GGX (separable Smith G, F = 1) and Schlick's model by mpmath, for the half-vector path's tests.

Independent of pumpup: h at tan(alpha_h) = alpha y (GGX; sqrt(r) y for Schlick), azimuth beta about N;
d omega_o = 4 (wo.h) d omega_h, wi.h = c = mu u + s sin(alpha_h) cos(beta), N.wo = 2 u c - mu, and

    a(mu) = integral_0^Y y / (4 pi u (1 + y^2)^2) K(y) dy,  K = 2 integral_0^beta0 4 c Gamma d beta

(the arc beta < beta0 where N.wo > 0), Gamma = G1(N.wo) G1(mu) / mu for GGX (Walter et al. 2007 eq. 20, 33, 34),
N.wo / (N.wo P(mu) + mu P(N.wo) - mu N.wo) for "ggx-correlated" (Heitz 2014; P(w) = w / G1(w))
and N.wo / ((r + (1 - r) N.wo)(r + (1 - r) mu)) for Schlick (000 eq. 36, with c = 1); Y = 1 / (tan(pi/4 -
theta_i / 2) alpha), where h's whole circle sends wo below the horizon.  Both integrals by tanh-sinh (mpmath.quad,
which crowds its nodes at the ends of every piece, where the features are), split at the arc's end and around the
horizon break; the printed error is mpmath's.  A few minutes per value on one core.

    python tests/reference/half_mpmath_reference.py ggx 1e-8 1e-6       # alpha, mu: 0.99994923964388905852
    python tests/reference/half_mpmath_reference.py ggx 0.001 0.59      # 0.9999980591288865563
    python tests/reference/half_mpmath_reference.py ggx 1e-4 1e-4       # 0.88161827515105007481
    python tests/reference/half_mpmath_reference.py ggx-correlated 0.5 1e-8
    python tests/reference/half_mpmath_reference.py schlick 1e-6 1e-5   # r, mu: 45.887293650878604133
    python tests/reference/half_mpmath_reference.py schlick 1e-6 1e-3   # 1.1685049698945183549
"""

import sys

import mpmath as mp


def albedo(model: str, width: float, mu_: float):
    mp.mp.dps = 30
    mu = mp.mpf(mu_)
    r = mp.mpf(width)
    al = mp.sqrt(r) if model == "schlick" else r  # the GGX weight's alpha (Schlick: sqrt(r))
    s = mp.sqrt(1 - mu * mu)
    th = mp.acos(mu)
    tf = mp.tan(mp.pi / 4 - th / 2)
    big_y = 1 / (tf * al)

    def g1(w):
        return 2 * w / (w + mp.sqrt(w * w + al * al * (1 - w * w)))  # Walter eq. 34

    def gamma(z):
        if model == "schlick":
            return z / ((r + (1 - r) * z) * (r + (1 - r) * mu))  # 000 eq. 36
        if model == "ggx-correlated":  # 1 / (mu (1 + Lambda(mu) + Lambda(z))), Heitz 2014; P(w) = w / G1(w)
            return z / (z * mu / g1(mu) + mu * z / g1(z) - mu * z)
        return g1(z) * g1(mu) / mu

    def k(y):
        u = 1 / mp.sqrt(1 + (al * y) ** 2)
        a, b, c0 = mu * u, s * al * y * u, mu / (2 * u)
        if a + b <= c0:
            return mp.mpf(0)
        x = (c0 - a) / b if b > 0 else -2
        beta0 = mp.acos(x) if x > -1 else mp.pi

        def g(beta):
            c = a + b * mp.cos(beta)
            return 4 * c * gamma(2 * u * c - mu)

        return 2 * mp.quad(g, [0, beta0 / 2, beta0 * 0.9, beta0 * 0.99, beta0 * 0.999, beta0])

    def outer(y):
        u = 1 / mp.sqrt(1 + (al * y) ** 2)
        return y / (4 * mp.pi * u * (1 + y * y) ** 2) * k(y)

    yf = tf / al
    pts = sorted({mp.mpf(0), mp.mpf(1), mp.mpf(10), mp.mpf(100), yf * 0.5, yf * 0.9, yf, yf * 1.1, yf * 2,
                  big_y * 0.5, big_y * 0.9, big_y * 0.99, big_y})
    return mp.quad(outer, [p for p in pts if p <= big_y], error=True)


if __name__ == "__main__":
    value, err = albedo(sys.argv[1], float(sys.argv[2]), float(sys.argv[3]))
    print(sys.argv[1], sys.argv[2], sys.argv[3], mp.nstr(value, 20), mp.nstr(err, 3))
