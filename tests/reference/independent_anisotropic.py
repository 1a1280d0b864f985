#!/usr/bin/env python
"""Independent reference albedos of anisotropic BRDFs at several azimuths of incidence.

Written from scratch with scipy only; it does NOT import pumpup (the code these numbers check).

Conventions: N = (0, 0, 1); wi = (s cos(phi_i), s sin(phi_i), mu) with s = sqrt(1 - mu^2) points
towards the light; a(mu, phi_i) = integral over the hemisphere of f_r(wi, wo) cos(theta_o) d omega_o.

Models (the formulas typed again from the papers, not from pumpup):

* ``ward_aniso`` (Ward 1992): f = c exp(-(hx/hz)^2/ax^2 - (hy/hz)^2/ay^2) / (4 pi ax ay sqrt(mu_i mu_o)),
  with h = wi + wo (only its ratios enter);
* ``lafortune`` (000 eq. 14-15): f = c [(-cx Lx Vx - cy Ly Vy + cz Lz Vz)_+]^n / max(mu_i, mu_o)^p.

Two methods per case, each nested adaptive QUADPACK (scipy.integrate.quad):

A  spherical coordinates about N: outer theta_o in [0, pi/2], inner phi_o over one turn starting at
   the mirror azimuth phi_i + pi (so the lobe sits at the ends of the inner range), with break points
   at geometric distances from the mirror polar angle;
B  half-vector coordinates: outer phi_h over one turn, inner theta_h in [0, pi/2] with break points
   graded towards h = N; wo = 2 (wi.h) h - wi, d omega_o = 4 (wo.h) d omega_h, 0 where wo_z <= 0.

The stored value is A; its error is max(|A - B|, the quad error estimates of both, 1e-15).
Run: ``python tests/reference/independent_anisotropic.py`` (a few minutes) writes
``tests/data/independent_anisotropic.json``.
"""

import json
import math
import os
import sys
import time

from scipy.integrate import quad

CASES = [
    ("ward_aniso", {"ax": 0.05, "ay": 0.5}, 0.9, 0.0),
    ("ward_aniso", {"ax": 0.1, "ay": 0.3}, 0.2, 0.0),
    ("ward_aniso", {"ax": 0.1, "ay": 0.3}, 0.2, math.pi / 2),
    ("ward_aniso", {"ax": 0.1, "ay": 0.3}, 0.6, math.pi / 5),
    ("ward_aniso", {"ax": 0.4, "ay": 0.02}, 0.5, 0.0),
    ("ward_aniso", {"ax": 0.4, "ay": 0.02}, 0.5, math.pi / 3),
    ("ward_aniso", {"ax": 0.5, "ay": 0.05}, 0.5, 0.0),
    ("ward_aniso", {"ax": 0.5, "ay": 0.05}, 0.05, 1.0),
    ("lafortune", {"n": 10, "cx": 0.8, "cy": 1.2, "cz": 1.1}, 0.5, 0.0),
    ("lafortune", {"n": 10, "cx": 0.8, "cy": 1.2, "cz": 1.1}, 0.5, math.pi / 3),
    ("lafortune", {"n": 30, "cx": 1.0, "cy": 0.5, "cz": 1.0, "p": 1.0}, 0.3, math.pi / 2),
    ("lafortune", {"n": 30, "cx": 1.0, "cy": 0.5, "cz": 1.0, "p": 1.0}, 0.3, 0.7),
]


def brdf(model, q):
    if model == "ward_aniso":
        ax, ay, c = q["ax"], q["ay"], q.get("c", 1.0)

        def f(L, V):
            if L[2] <= 0 or V[2] <= 0:
                return 0.0
            hz = L[2] + V[2]
            ex = ((L[0] + V[0]) / hz / ax) ** 2 + ((L[1] + V[1]) / hz / ay) ** 2
            return c * math.exp(-ex) / (4 * math.pi * ax * ay * math.sqrt(L[2] * V[2]))
        return f
    if model == "lafortune":
        n, cx, cy, cz = q["n"], q.get("cx", 1.0), q.get("cy", 1.0), q.get("cz", 1.0)
        p, c = q.get("p", 0.0), q.get("c", 1.0)

        def f(L, V):
            if L[2] <= 0 or V[2] <= 0:
                return 0.0
            rv = -cx * L[0] * V[0] - cy * L[1] * V[1] + cz * L[2] * V[2]
            if rv <= 0:
                return 0.0
            return c * rv ** n / max(L[2], V[2]) ** p
        return f
    raise ValueError(model)


def method_a(f, mu, phi_i, tol):
    s = math.sqrt((1 - mu) * (1 + mu))
    wi = (s * math.cos(phi_i), s * math.sin(phi_i), mu)
    th_r = math.acos(mu)
    pts_t = sorted({min(max(th_r + d, 1e-9), math.pi / 2 - 1e-9)
                    for k in range(8) for d in (0.01 * 2 ** k, -0.01 * 2 ** k, 0.0)})
    errs = []

    def inner(th):
        st, ct = math.sin(th), math.cos(th)

        def g(ph):
            a = phi_i + math.pi + ph
            return f(wi, (st * math.cos(a), st * math.sin(a), ct))
        pts = [d for k in range(6) for d in (0.02 * 2 ** k, -0.02 * 2 ** k)]
        v, e = quad(g, -math.pi, math.pi, points=pts, epsabs=tol * 1e-2, epsrel=tol, limit=400)
        errs.append(e)
        return v * ct * st

    v, e = quad(inner, 0.0, math.pi / 2, points=pts_t, epsabs=tol * 1e-2, epsrel=tol, limit=400)
    return v, e + max(errs) * math.pi / 2


def method_b(f, mu, phi_i, tol):
    s = math.sqrt((1 - mu) * (1 + mu))
    wi = (s * math.cos(phi_i), s * math.sin(phi_i), mu)
    errs = []

    def inner(ph):
        cp, sp = math.cos(ph), math.sin(ph)

        def g(th):
            st, ct = math.sin(th), math.cos(th)
            h = (st * cp, st * sp, ct)
            ih = wi[0] * h[0] + wi[1] * h[1] + wi[2] * h[2]
            if ih <= 0:
                return 0.0
            wo = (2 * ih * h[0] - wi[0], 2 * ih * h[1] - wi[1], 2 * ih * h[2] - wi[2])
            if wo[2] <= 0:
                return 0.0
            return f(wi, wo) * wo[2] * 4 * ih * st
        pts = [0.005 * 2 ** k for k in range(8)]
        v, e = quad(g, 0.0, math.pi / 2, points=pts, epsabs=tol * 1e-2, epsrel=tol, limit=400)
        errs.append(e)
        return v

    pts = [phi_i + k * math.pi / 2 for k in range(-4, 5)]
    lo = phi_i - math.pi
    pts = [p for p in pts if lo < p < lo + 2 * math.pi]
    v, e = quad(inner, lo, lo + 2 * math.pi, points=pts, epsabs=tol * 1e-2, epsrel=tol, limit=400)
    return v, e + max(errs) * 2 * math.pi


def main(out=None, tol=1e-10):
    out = out or os.path.join(os.path.dirname(__file__), "..", "data", "independent_anisotropic.json")
    rows = []
    for model, q, mu, phi in CASES:
        f = brdf(model, q)
        t0 = time.time()
        a, ea = method_a(f, mu, phi, tol)
        b, eb = method_b(f, mu, phi, tol)
        err = max(abs(a - b), ea, eb, 1e-15)
        rows.append(dict(model=model, params=q, mu=mu, phi=phi, albedo=a, method_b=b, abs_err_estimate=err,
                         seconds=round(time.time() - t0, 1)))
        print(model, q, mu, round(phi, 6), a, b, err, rows[-1]["seconds"], flush=True)
    doc = dict(description=__doc__.split("\n\n")[0], conventions="wi = (s cos phi, s sin phi, mu), N = (0, 0, 1)",
               method="A: nested quad about N; B: nested quad in half-vector coordinates; value A, "
                      "error max(|A-B|, quad estimates)",
               rows=rows)
    with open(out + ".tmp", "w") as fh:
        json.dump(doc, fh, indent=1)
    os.replace(out + ".tmp", out)


if __name__ == "__main__":
    main(*sys.argv[1:2])
