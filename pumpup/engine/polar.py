"""One-dimensional albedo where the azimuth integrates in closed form (Phong, Blinn, Ward, Cook-Torrance families) or by
a rule on known arcs (GGX, Beckmann, Schlick, Fresnel factors, metal).

Method
------
For a lobe that is a power of cos(alpha) = u around the mirror direction R (reciprocal Phong,
stretched Phong / the p-model with p in [0, 1], Phong's original shader, Lewis's Phong,
isotropic Lafortune lobes) or around wi itself (the retro-reflective model, Lafortune with
cx = cy = -cz), write the outgoing direction in the lobe frame,
wo = A u + sqrt(1 - u^2) (e1 cos(beta) + e2 sin(beta)).  In both frames

    N.wo = a + b cos(beta),   a = mu u,   b = s sqrt(1 - u^2),   s = sqrt(1 - mu^2)

(the frame the 2-D engine uses, ``pumpup.albedo``).  The integrand f_r cos(theta_o) depends on
beta only through N.wo, so for every u the integral over the visible arc |beta| < beta0
(N.wo > 0) is elementary:

* p = 0, f = c u^n:  integral (a + b cos beta) d beta = 2 (a beta0 + b sin beta0);
* p = 1, f = c u^n / max(mu, N.wo) (000 eq. 7, 10, 13): the arc |beta| < beta1 where
  N.wo >= mu contributes its length, the rest N.wo / mu:
  2 [beta1 + (a (beta0 - beta1) + b (sin beta0 - sin beta1)) / mu];
* 0 < p < 1, f = c u^n / max(mu, N.wo)^p (000 eq. 12): the arc where N.wo < mu in closed form as
  for p = 1, divided by mu^p, plus H = integral_0^beta1 (a + b cos beta)^(1 - p) d beta, which is
  not elementary: an inner quadrature per value of u (:func:`_arc_power`: with N.wo = T - D s^2 an even analytic
  integrand in s, by the fewest Gauss-Legendre points whose Bernstein-ellipse error bound meets the tolerance, and
  near grazing incidence a Gauss-Jacobi rule for the weight (N.wo)^(1 - p) at the arc's end where N.wo -> mu -> 0),
  its error added to the outer estimate through the outer weights

(the same closed form as Lewis's H_s, 002 sec. 4.1, and as ``phong_1d`` of
``tests/reference/independent_reference.py``).  With b^2 - a^2 = sin^2(alpha) - mu^2 and
b^2 - (mu - a)^2 = (1 - u)(u - cos 2 theta_i) the sines and angles are computed without
cancellation, and b (sin beta0 - sin beta1) as mu^2 (1 - 2u) / (b sin beta0 + b sin beta1).

This leaves a(mu) = c * integral_0^1 u^n K(u) du.  Its kinks are where the arc starts to be
cut by the horizon (u = s) and where the level N.wo = mu leaves the circle (u = cos 2 theta_i,
p > 0 only): these, and u = 1/2 (or the nearest of 0.45, 0.55, 0.4, 0.6 at least 0.02 from every break,
:data:`SPLITS`), are breakpoints.  A break's square root reaches across the breaks next to it: where two nearly
coincide (s and cos 2 theta_i near mu = sqrt(3) / 2) the piece beyond the other is graded towards it
(:func:`_foreign_roots`; found in issue 14's twelfth session: stretched Phong n = 10 at mu = 0.866025 was 3.2e-12 off
at rtol 1e-12 with an estimate of 6.6e-13).  On [0, 1/2] the variable is u itself; above
it is z = -(n + 1) ln u, i.e. y = u^(n+1) = e^-z, which absorbs the u^n peak exactly
(u^n du = e^-z dz / (n + 1); the engine's "power" map, 000 eq. 20, graded logarithmically); z
stops at Z_MAX = 40, the rest is bounded and added to the error.  Above the horizon break z_s
the arc shrinks on the scale of z_s itself (tiny near grazing), so that piece is cut at
z_s (1 + 4^i).  Every piece is integrated by globally adaptive 10/21 Gauss-Kronrod quadrature
(QUADPACK's qk21; ``RULE = "gk15"`` selects the engine's 7/15 rule) with a one-sided smoothing
substitution (x = tau^2 at a square-root end, tau^2 (3 - 2 tau) at two), which turns the
square-root behaviour at the breakpoints into smooth functions.  Every piece starts as one
interval (``N_INIT``).

Error estimate (issue 14 item 4): per interval QUADPACK's calibration of |K - G|,
resasc min(1, (200 |K - G| / resasc)^1.5) with its floor 50 eps resabs
(:func:`pumpup.physics.quadrature.calibrated`), summed, plus the rounding term ``ROUNDING`` sum |K| and
the bound of the part beyond Z_MAX.  Measured by ``scripts/calibration/error_calibration.py`` over every
independent reference of ``tests/`` (30-digit mpmath Phong values n = 0 .. 1e5 from normal to
grazing incidence, tests/data/independent_reference.json, the closed forms) at rtol 1e-6 ..
1e-12: true error / estimate at most 0.015 (median 2.5e-4; the raw |K - G| gave at most 0.03),
no case above 1.  The estimate sits mostly on the rounding term, and the first intervals already
meet rtol 1e-10 almost everywhere: 98 evaluations per mu for Phong n = 20 on a 257-point table
(165 before, with two first intervals per piece and the raw estimate), 112 for stretched Phong
n = 20, 99 for retro n = 10.

Pumped lobes (001 eq. 16): a pumped Phong-family BRDF f / (g_1 ... g_k) divides the lobe by g(mu,
N.wo), which for a fixed wi depends on wo through N.wo = t only (:meth:`pumpup.operators.pumping.Pumped.polar`,
``Polar.chain``).  So the frame turns to N: with wo at elevation x (t = sin x) and azimuth phi,

    a(mu) / scale = integral_0^(pi/2) t cos(x) / (max(mu, t)^p g(mu, t)) W(t) dx,
    W(t) = integral over phi of u_+^n,  u = A + B cos(phi),  A = mu t,  B = s cos(x),

g is looked up once per node of x (exactly as the chain kernel divides by it, ``pumpup.physics.lookups.g_product``,
``g_levels``), and W, the lobe on the circle N.wo = t, is (A + B)^n V(kappa) with kappa = 2B / (A + B) in
[0, 2], u = (A + B)(1 - kappa sin^2(phi / 2)): V depends on n and kappa only, so it is tabulated once per n
(:func:`ring_table`: Chebyshev pieces to 1e-14, their errors carried; pieces next to kappa = 1, where V has a
term |kappa - 1|^(n + 1/2), computed by quadrature when they cannot be fitted), and A + B = cos(x - x_mu)
keeps (A + B)^n = exp(n log1p(-2 sin^2((x - x_mu) / 2))) accurate for any n (a plain power of A + B cos(phi)
lost n ulp: 2.2e-13 for n = 2000, measured).  The x integral (:func:`_integrate_chain`, adaptive 10/21) is cut
at the levels of g (``Pumped.lobe(mu).levels``), at N.wo = mu and s (V's kappa = 1), around the lobe's peak
theta_i +- 3, 8 and 13 / sqrt(n), at N.wo = 2^-(1 + 2k) (g's tables are splines in ln N.wo), every pi / 16, and
for n < 8 graded towards x_s (:func:`chain_cuts`).  g's splines have breakpoints no cut marks, so the estimate
per interval is ``CHAIN_SAFETY`` (3) times the raw |K - G| (measured: true error at most 0.49 of it over 15
chains, 351 mu from 1e-10 to 1, rtol 1e-6 ... 1e-12).  Until issue 14's fifth session the lobe frame served
pumped lobes too, with an adaptive rule on the arc for every outer node: g was looked up ~50 000 times per mu
instead of ~400, and the three tables of 3-level g2 pumped Phong n = 20 took 180-230 ms instead of 58-83.
Checked in ``tests/test_polar_pumped.py`` against an independent quadrature about N (numpy's
level-by-level reference), the nested engine at rtol 1e-13 and the 2-D engine, and the ring table against
40-digit mpmath.

The Blinn family (reciprocal Blinn c (N.H)^n, 000 eq. 31; stretched Blinn c (N.H)^n / max(N.L, N.V),
eq. 32; Lewis's Phong-Blinn, 002 eq. 24) takes the same path in the frame of N for the half vector h
(``Polar(kind="half")``): with h at u = N.h = cos(alpha) and azimuth beta, d omega_o = 4 (wo.h) d omega_h,
wo.h = wi.h = c = mu u + s sin(alpha) cos(beta) (the form N.wo has about R) and N.wo = 2 c u - mu, so the
integrand 4 c N.wo / max(mu, N.wo)^p is a polynomial of degree 2 in cos(beta) on the arc where N.wo > 0 (and
on the parts where N.wo >= mu and < mu for p = 1): :func:`_k_half` integrates it in closed form, with the
ends of the arcs exact in the angles (psi = pi/2 - theta_i kept exact near grazing incidence), the moments
of d = c - c0 >= 0 instead of those of c (no cancellation) and their series below an arc of 1 rad (where
the closed forms cancel to the 5th order; :func:`_trig_tail`).  Its breakpoints (:func:`_pieces`, frame 1)
are u = cos(pi/4 - theta_i/2) (the horizon starts to cut h's circle), cos(theta_i) (p = 1: N.wo = mu
leaves it) and u_lo = cos(pi/4 + theta_i/2), below which no h sends wo above the horizon; near grazing
incidence the pieces above u_lo ~ mu / 2 and above the level u = mu are cut at lo (1 + 4^i), since the
arc's end c0 = mu / (2u) changes on the scale of u there (found by the comparison with the nested engine:
stretched Blinn n = 0 at mu = 1e-8 was 2.5e-8 off without them).  The modified Ward model (000 eq. 35,
c exp(-tan^2(alpha) / m^2) / (4 pi m^2 max(N.L, N.V))) is stretched Blinn's azimuth under the Beckmann weight:
``Polar(radial="beckmann")`` integrates it in t = tan^2(alpha) / m^2 (weight e^-t, :func:`_u_at` kind 2) up to
Z_MAX or the break of u_lo, cut at the same breaks.  Ward's model (000 eq. 34, sqrt(N.L N.V) in the
denominator; ``Polar(sqrt_cos=True)``) has 4 (wi.h) sqrt(N.wo) on the arc instead: complete elliptic integrals
(:func:`_k_ward`, Carlson's R_F and R_D by the arithmetic-geometric mean), with 1 / sqrt(mu) in the scale; its K has a logarithmic term where
h's circle starts to be cut, so Ward keeps the raw |K - G| (QUADPACK's calibration measured 4.4 x below the
true error there).  The V-cavity microfacet models with F = 1 (Cook-Torrance, 001 eq. 9-10; Torrance-Sparrow
with D1 or D4, 002 eq. 10; ``Polar(vcavity=True)``) integrate 4 c G = 4 min(c, 2 u mu, 2 u N.wo) on the arc: a
minimum of three lines in c, so each range of c between their crossings contributes its arc length and its
integral of c (:func:`_k_vcavity`, with cancellation-free differences: near grazing incidence the integrand lives
on arcs of width ~mu), and the pieces' changes in u are breaks (:func:`_vcavity_breaks`); Torrance-Sparrow's D3 = b / (cos^4 (1 + tan^2 /
c3^2)^2) is the same azimuth under the GGX weight (``Polar(radial="ggx")``: z = ln(1 + tan^2(alpha) / m^2), weight
e^-z dz, :func:`_u_at` kind 3).  Pumped Blinn BRDFs stay on the nested engine (``Pumped.polar`` takes lobes about R
only).

Where the integrand over beta is a function of c alone but has no elementary integral (frame 4, :func:`_k_numeric`)
the arc is integrated by a rule: the Smith microfacet models (GGX, Beckmann, alpha <= 1: 4 c F(c) G / mu with
G = G1(mu) G1(N.wo) or the height-correlated form, Walter et al. 2007 eq. 20; ``Polar(smith=...)``), the V-cavity
models with a Fresnel factor (4 F(c) min(c, 2 u mu, 2 u N.wo); ``Polar(vcavity=True, fresnel=...)``) and Schlick's
model (4 c N.wo / (r + (1 - r) N.wo), 000 eq. 36, under the GGX weight with alpha = sqrt(r); ``Polar(schlick=r)``).
The rule is globally adaptive 7/15 Gauss-Kronrod in delta = beta0 - beta from the arc's end (where d = c - c0 =
2 e0 sin^2(delta / 2) + b sin(beta0) sin(delta), no cancellation), cut at the kinks and jumps (the V-cavity's
crossings, Walter's G1 switch) and, where a factor has a singularity near the arc's small end (P(N.wo) at N.wo ~ +-i
alpha, Schlick's pole at -r / (1 - r), the Fresnel factor at c ~ +-i sqrt(|1 - index^2|)), at N.wo or c = scale 3^k,
so that each piece lies its own length from it.  The outer variable is cut at the same scale where K(u) turns (around
the horizon break and the range's end, :func:`_pieces`).  Each K carries its error (relative ``itol``, or an absolute
share of the integral's lower bound so far), added to the outer estimate through the Kronrod weights and into |K - G|
before its calibration.  GGX alpha = 0.001 showed why the cuts are needed: without the outer ones the first version was
1.6e-10 off at rtol 1e-12 with an estimate of 6e-13 (30-digit mpmath, ``tests/reference/half_mpmath_reference.py``, and the
nested engine agree).  alpha > 1 (P then has a singularity near N.wo = 1, which is not graded) and Torrance-Sparrow's
D2 stay on the nested engine.

000 eq. 28's Fresnel factor F(Theta_min) = F(max(N.L, N.V)) (metal, plastic with an index, the ``fresnel`` wrapper of a
lobe with p in {0, 1}; ``Polar(kind="lobe", fresnel=(0, eta, k))``) takes the lobe frame with a rule on the arc (frame 5,
:func:`_k_lobe_fresnel`): where N.wo < mu the factor is the constant F(mu) / mu^p, so that part is the closed form's;
where N.wo = t >= mu the integrand F(t) t^(1 - p) is integrated by Gauss-Legendre rules with an a-priori bound on
Bernstein ellipses (:func:`_lobe_f_gauss`, since issue 14's sixteenth session; the adaptive 7/15 rule in beta where they
would want too many points), cut at t = x0 -+
y0 3^j about F's branch point w = sqrt(1 - (eta + i k)^2) = x0 - i y0 (:func:`fresnel_branch`) and at t = rho 3^j towards
the pole of its parallel reflectance near c = 0 (rho = 1 / |sqrt((eta + i k)^2 + 1)|, :func:`fresnel_pole`: a strong
absorber's, eta 1.1, k 30, sits at -0.0012 + 0.033 i); the outer variable is cut where the arc's ends pass those points
(features narrower than :data:`LOBE_F_WIDE`).  A near-kink (Im w < :data:`LOBE_F_Y0_MIN`, or w real in (0, 1): a
dielectric's total reflection below eta = 1) stays on the nested engine.  A pumped metal, and the fresnel wrapper of a
pumped lobe, multiply the pumped lobe's frame of N by F(max(mu, N.wo)) (:func:`_x_rule`, cut likewise by
:func:`chain_cuts`; Im w >= :data:`CHAIN_F_Y0_MIN` there).  Since issue 14's twelfth session a lobe with n >= :data:`LOBE_N_MIN`
takes that frame too, with g = 1 (:func:`takes_lobe_n_frame`; its cuts :func:`chain_cut_matrix`, compiled, and QUADPACK's
calibration instead of CHAIN_SAFETY |K - G|): F is then one factor per node of the elevation instead of a rule on every
arc, 60-400 evaluations per mu instead of 15 per arc times ~110 arcs (metal n = 20, eta 0.2, k 3: 5.5 ms for 257 mu
instead of 60 ms); below n = 8 the ring table leaves the pieces next to kappa = 1 to quadrature, and frame 5 is faster.

GGX and Beckmann with F = 1 and alpha <= 1 (either Smith G, exact or Walter's G1) and Schlick's model take the frame of
N instead (frame 6, :func:`_integrate_n`): for wo at elevation x (N.wo = t = sin x) their G and 1 / (N.L N.V) depend on
t only, and the weight integrates over the azimuth of wo in closed form, (N.h)^2 = m^2 / |wi + wo|^2 being linear in
cos(phi) in the denominator.  GGX's D = alpha^2 / (pi (1 - (1 - alpha^2) (N.h)^2)^2) is rational in cos(phi)
(:func:`_ggx_ring`: three terms >= 0, its two square roots products of sums of squares, with no cancellation and no
division by N.wi + N.wo); Beckmann's exp(-tan^2 / alpha^2) / (pi alpha^2 cos^4) is exp(-kappa (1 - cos psi)) times a
quadratic in cos psi, so its integral is three Kummer functions e^-z 1F1(1/2; j + 1; z), z = 2 kappa
(:func:`_beckmann_ring`; :func:`_kummer_half` sums their series, :func:`_kummer_fast` evaluates Chebyshev pieces of them
below z = 200).  What is left is one integral over x of analytic pieces, graded towards the singularities near the real
axis: the peak's (x_mu +- 2 i atanh(alpha) for GGX; Beckmann's Gaussian 2 alpha wide; the variable is d = x - x_mu,
exact where the peak is narrow), P(t)'s at +- i atanh(alpha) (GGX) or its turn on the scale alpha (Beckmann), Schlick's
pole at sin x = -r / (1 - r), the pole at x = -x_mu of the height-correlated G and of Beckmann's kappa, Walter's switch
(:func:`_n_cuts`); 10/21 Gauss-Kronrod with QUADPACK's calibration.  Since issue 14's thirteenth session GGX's and
Schlick's pieces off the peak are integrated in u = ln |d| and graded by 27 instead of 3 (:data:`N_LOG_GRADE`: the peak's
singularities lie pi / 2 from the real u axis whatever |d|; GGX alpha = 1e-8 took 1099 evaluations per mu, then 803),
and since its eighteenth the pieces from x = 0 up to x_mu / 8 in u = ln x, graded by 27 too (P(t)'s singularities lie
pi / 2 from that axis; alpha = 1e-8: 608 evaluations per mu, a 257-point table in 15 ms instead of 19-23).
No inner rule: 41-184 evaluations per mu for alpha
>= 0.1, a 257-point table in 0.7-2.6 ms for GGX and Schlick (frame 4 took 20-70 ms), 4-12 ms for Beckmann (frame 4: 45-200
ms), and mu down to the smallest double.  ``scripts/calibration/n_frame_calibration.py`` measures it against frame 4
(:func:`without_n_frame`) at rtol 1e-13 over 45 models, 64 mu and rtol 1e-6 ... 1e-12: at most 4e-5 of the estimate beyond
that reference's own error.

GGX with a Fresnel factor takes frame 6 too since issue 14's thirteenth session (:func:`_ggx_ring_f`).  On the ring F(wi.h)
depends on the azimuth, through c = wi.h = sqrt(S^2 + s cos(x) sin^2(psi / 2)) (psi from the mirror side, S = sin((x +
x_mu) / 2) the ring's smallest c), and has no closed form against D; but D's Fourier cosine coefficients do, M_k = 2 a2
(delta_k0 + rho^k (2 k1 + t2 + k k1^2)) (the terms of :func:`_ggx_ring`, rho = (a' - R) / Q), so F's cosine interpolant
at psi = n pi / N integrates against D exactly: a product rule whose weights are geometric sums in rho e^(i psi_n)
(:func:`_ring_f_sums`), however narrow the peak.  N doubles from 16 to at most 128; the ring's error is |W_N - W_N/2|, or
that times the larger ratio of the last three such steps where both are below 1/2 (the last ratio alone, from N = 16, was
1100 x below the true error of a strong absorber at itol 1e-6).  The ring's tolerance is frame 4's: relative, or a share
of the integral's lower bound so far, and its errors enter the outer estimate as frame 4's K do.  F(c) has a square-root
branch point at c = 0 (it is not even in c), at psi = +- 2 i asinh(S / sqrt(s cos x)) on the ring, so the product rule
needs S not small: frame 6 takes mu >= :data:`N_FRESNEL_MU_MIN` = 0.248 (S >= 1/8 on every ring), frame 4 the rest of a
table, and an index whose other singularities (the refracted cosine's branch points) lie at least 0.1 from [1/8, 1]
(:func:`n_fresnel_ok`: not a near-kink conductor; a dielectric's lie on the imaginary axis).  The elevation is cut where
S passes 3^j times the scale of F's pole near c = 0 (:func:`fresnel_pole`) and of its branch point.  17-129 F values per
ring (27-35 on average), 1.3-1.9 us; the 216 mu >= 0.248 of a 257-point table at rtol 1e-10 took 39-111 ms where frame 4
takes 87-196 ms (GGX alpha 0.3 with eta 0.2, k 3; alpha 0.02 with ior 1.5), and the 41 below 0.248 stay at frame 4's
35-50 ms (``scripts/bench/bench_albedo.py --nframe-f``).  Not taken: a rule per ring for S < 1/8 (adaptive 10/21 in psi graded
at D's and F's scales, measured at ~400 evaluations per ring: no faster than frame 4 there); pumped or 1/E-scaled GGX with
F (the nested engine, as before: frame 4 below 0.248 has no chain); Beckmann with F (frame 4: its ring's Fourier
coefficients are Bessel functions e^-kappa I_k(kappa), not attempted).

The ``fresnel`` wrapper's F(max(N.L, N.V)) (000 eq. 28) over GGX, Beckmann (F = 1) or Schlick's model, pumped or not,
takes frame 6 since issue 14's twenty-second session (``Polar.fmax``, :func:`with_fresnel_max`): for a fixed wi it depends
on N.wo alone, so it is one factor per ring, as a pumped chain's g is; its kink N.wo = mu is the cut d = 0, and the
elevation is cut about F's branch point and pole as a pumped metal's (:func:`chain_cuts`).  A near-kink (branch point
within :data:`LOBE_F_Y0_MIN` of the real axis, :data:`CHAIN_F_Y0_MIN` with a chain) stays on the nested engine.  A
257-point table takes 3-12 ms where the nested engine took 0.2-0.4 s (``scripts/bench/bench_albedo.py --fmax``).

A model offers this path through :meth:`pumpup.core.BRDF.polar`, which returns a
:class:`Polar` hint (or None); ``pumpup.albedo`` uses it before the 2-D engine.  The 2-D
engine stays the reference: :func:`two_d_only` switches the 1-D path off.
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
import threading
import warnings

import numpy as np
from numba import njit

from ..core.hints import Polar
from ..physics.fresnel import fresnel_branch, fresnel_brewster, fresnel_pole

__all__ = ["Polar", "albedo_1d", "two_d_only", "integrand", "integrand_reference"]

#: the 1-D path is used when a model offers it (``two_d_only`` switches it off)
ENABLED = True

#: relative rounding error of the 1-D quadrature (per unit of sum |K|): the integrand is a few
#: elementary functions of u, accurate to a few ulp, summed over a few hundred nodes
ROUNDING = 64.0 * np.finfo(float).eps

#: initial subintervals of every piece (1 since the calibrated estimate: every piece is smooth
#: after its substitution, and 2 only doubled the evaluations; measured in scripts/calibration/error_calibration.py)
N_INIT = 1


@contextlib.contextmanager
def two_d_only():
    """Within the block, ``pumpup.albedo`` ignores the 1-D path and uses the 2-D engine (the
    reference; the benchmark and the tests use it).  Not meant for concurrent toggling."""
    global ENABLED
    old = ENABLED
    ENABLED = False
    try:
        yield
    finally:
        ENABLED = old


# --- the integrand ----------------------------------------------------------------------------


#: the inner rule on the arc where N.wo >= mu (p in (0, 1)), should the Gauss-Legendre bound (:func:`_arc_bound`) want
#: more than GL_MAX points, is the engine's 7/15 Gauss-Kronrod pair, globally adaptive on at most INNER_MAX intervals
INNER_MAX = 64
#: the inner rule's relative tolerance is rtol / 8, but not below this (its rounding floor is
#: QUADPACK's 50 eps of the integral)
INNER_RTOL_MIN = 1e-14
#: the orders of the Gauss-Jacobi rules on the arc's end near grazing incidence (:func:`_arc_power`, :func:`_jacobi_bound`)
JACOBI_ORDERS = (10, 14)


@njit(cache=True, nogil=True)
def _arc_rule(q, a, b, lo, hi, nodes, wk, wg, mode, ibuf):  # pragma: no cover - compiled
    """(value, error) of the rule on beta in [lo, hi] for the integrand (a + b cos beta)^q."""
    h = hi - lo
    k = 0.0
    g = 0.0
    ab = 0.0
    for j in range(nodes.shape[0]):
        f = (a + b * math.cos(lo + h * nodes[j])) ** q
        ibuf[j] = f
        k += wk[j] * f
        g += wg[j] * f
        ab += wk[j] * abs(f)
    asc = 0.0
    if mode != 0:
        for j in range(nodes.shape[0]):
            asc += wk[j] * abs(ibuf[j] - k)
    return k * h, calibrated(abs(k - g) * h, asc * h, ab * h, mode)


@njit(cache=True, nogil=True)
def _jacobi_sum(q, top, low, c, jt, jw):  # pragma: no cover - compiled
    """integral_0^c t^q / sqrt((top - t)(t - low)) dt by the Gauss-Jacobi rule (nodes ``jt`` on
    [0, 1], weights ``jw`` for the weight t^q)."""
    s = 0.0
    for j in range(jt.shape[0]):
        t = c * jt[j]
        s += jw[j] / math.sqrt((top - t) * (t - low))
    return c ** (q + 1.0) * s


#: the Bernstein ellipse of :func:`_jacobi_bound`: log(rho) = JACOBI_RHO log(rho_max), at most JACOBI_LOG_RHO_CAP (rho_max
#: overflows where c = mu is subnormal: a hypothesis test found mu = 5e-324 giving a NaN error)
JACOBI_RHO = 0.95
JACOBI_LOG_RHO_CAP = math.log(1e4)


@njit(cache=True, nogil=True)
def _jacobi_bound(q, top, low, c, n):  # pragma: no cover - compiled; see the tests' mpmath check
    """A bound of the n-point Gauss-Jacobi rule's error in :func:`_jacobi_sum` (low < 0 < c < top).  With t = c (1 + x) / 2,
    g(t) = ((top - t)(t - low))^-1/2 is analytic but at x_T = 2 top / c - 1 > 1 and x_L = 2 low / c - 1 < -1 (the square
    root's cuts lie on the real axis beyond them), so inside the Bernstein ellipse E_rho, |x| <= A = (rho + 1/rho) / 2 <
    min(x_T, -x_L), |g| <= M = 2 / (c sqrt((x_T - A)(-x_L - A))) (computed in t's units, finite as c -> 0).  A Gauss rule with a positive weight errs by at most
    2 W E_(2n-1)(g), W = c^(q+1) / (q + 1) the weight's integral, and E_m(g) <= 2 M rho^-m / (rho - 1) (Trefethen, ATAP
    Thm 8.2): the bound is 4 W M rho^(1 - 2n) / (rho - 1)."""
    xt = 2.0 * top / c - 1.0  # (inf where c is tiny: rho is then capped)
    xl = 1.0 - 2.0 * low / c
    r = min(xt, xl)
    rho = math.exp(min(JACOBI_RHO * math.log(r + math.sqrt((r - 1.0) * (r + 1.0))), JACOBI_LOG_RHO_CAP))
    big_a = 0.5 * (rho + 1.0 / rho)
    # M in t's units: the ellipse's ends lie at t = c (1 -+ A) / 2, so |T - t| >= T - c (1 + A) / 2 and |t - L| >= -L - c (A - 1) / 2
    m = 1.0 / math.sqrt((top - 0.5 * c * (1.0 + big_a)) * (-low - 0.5 * c * (big_a - 1.0)))
    return 4.0 * c ** (q + 1.0) / (q + 1.0) * m * rho ** (1.0 - 2.0 * n) / (rho - 1.0)


@njit(cache=True, nogil=True, inline="always")
def _tally(val, err, m, tot, e):  # pragma: no cover - compiled
    """(value, error, the interval with the largest error) of an adaptive rule's first m intervals, the
    sums starting from ``tot`` and ``e``."""
    worst = 0
    for i in range(m):
        tot += val[i]
        e += err[i]
        if err[i] > err[worst]:
            worst = i
    return tot, e, worst


#: the Gauss-Legendre rules of the arc's piece in s (:func:`_arc_bound`), n = 1 .. GL_MAX points: row n holds the
#: nodes x >= 0 (``GL_X``) and their weights, doubled for x > 0 (``GL_W``): the piece's integrand is even in s
GL_MAX = 64


def _gl_tables():
    xs, ws = np.zeros((GL_MAX + 1, (GL_MAX + 1) // 2)), np.zeros((GL_MAX + 1, (GL_MAX + 1) // 2))
    for n in range(1, GL_MAX + 1):
        x, w = np.polynomial.legendre.leggauss(n)  # (ascending; an odd rule's middle node is 0)
        k = (n + 1) // 2
        xs[n, :k], ws[n, :k] = x[::-1][:k], 2.0 * w[::-1][:k]  # the nonnegative half, largest first
        if n % 2:
            ws[n, k - 1] = w[n // 2]  # the middle node, once
    xs.flags.writeable = False
    ws.flags.writeable = False
    return xs, ws


GL_X, GL_W = _gl_tables()
#: the Bernstein ellipse of the piece's bound (:func:`_arc_bound`): log(rho) at most ARC_RHO_BRANCH times that of the
#: ellipse through t^q's branch point (the integrand stays bounded up to it) and ARC_RHO_POLE times that through the
#: pole of (t - L)^-1/2.  Measured over a 257-point table's nodes (q 0.1, 0.5, 0.9; itol 1.25e-7 .. 1.25e-13): 0.03 % more
#: values than the best of eight ellipses from 0.5 to 0.999 per call
ARC_RHO_BRANCH = 0.999
ARC_RHO_POLE = 0.99


@njit(cache=True, nogil=True)
def _arc_bound(q, big_t, d, b, c, tol):  # pragma: no cover - compiled; see arc_piece_reference
    """(n, bound): the fewest Gauss-Legendre points (at most GL_MAX; GL_MAX + 1 if none suffices) whose error on
    P = sqrt(D) c integral_-1^1 F(c x) dx, F(s) = t^q (t - L)^-1/2, t = T - D s^2, is at most ``tol``, and that error
    bound.  F is analytic but where t = 0 (s^2 = s0^2 = T / D, t^q's branch point) or t = L (s^2 = s1^2 = 2 b / D,
    a pole of order 1/2): inside the Bernstein ellipse E_rho of x, |x| <= A = (rho + 1 / rho) / 2, so where c A < min(s0,
    s1) |t| <= T + D c^2 A^2 < 2 T and |t - L| = D |s1^2 - s^2| >= D (s1^2 - c^2 A^2): |F| <= M = (2 T)^q /
    sqrt(D (s1^2 - c^2 A^2)).  The n-point Gauss rule's error is then at most 64 M / (15 (1 - rho^-2) rho^(2 n))
    (Trefethen, Approximation Theory and Approximation Practice, Thm 19.3) times sqrt(D) c.  log(rho) is the smaller of
    ARC_RHO_BRANCH log(rho_0) and ARC_RHO_POLE log(rho_1), rho_i the ellipse through s_i / c."""
    s0sq = big_t / d
    s1sq = 2.0 * b / d
    best_n = GL_MAX + 1
    best = 0.0
    if not tol > 0.0:
        return best_n, best
    r0, r1 = math.sqrt(s0sq) / c, math.sqrt(s1sq) / c  # (both > 1: s0^2 >= 4/3, s1^2 >= 2, c^2 = s0^2 / 2 beyond 4 mu)
    lrho = min(ARC_RHO_BRANCH * math.log(r0 + math.sqrt((r0 - 1.0) * (r0 + 1.0))),
               ARC_RHO_POLE * math.log(r1 + math.sqrt((r1 - 1.0) * (r1 + 1.0))))
    rho = math.exp(lrho)
    big_a = 0.5 * (rho + 1.0 / rho)
    gap = s1sq - c * c * big_a * big_a
    if gap > 0.0:
        # log of sqrt(D) c 64 M / (15 (1 - rho^-2) tol)
        lb = math.log(c * 64.0 / 15.0 * (2.0 * big_t) ** q / (math.sqrt(gap) * (1.0 - 1.0 / (rho * rho)) * tol))
        n = max(1.0, math.ceil(lb / (2.0 * lrho)))
        if n <= GL_MAX:
            best_n = int(n)
            best = math.exp(lb - 2.0 * n * lrho) * tol
    return best_n, best


@njit(cache=True, nogil=True)
def _arc_piece(q, big_t, d, b, c, n):  # pragma: no cover - compiled; see arc_piece_reference
    """P = sqrt(D) c integral_-1^1 F(c x) dx by the n-point Gauss-Legendre rule, F even (:func:`_arc_bound`):
    integral_(T - D c^2)^T t^q / sqrt((T - t)(t - L)) dt with t = T - D s^2, 2 b = T - L."""
    tot = 0.0
    for j in range((n + 1) // 2):
        s2 = c * c * GL_X[n, j] * GL_X[n, j]
        t = big_t - d * s2
        tot += GL_W[n, j] * t**q / math.sqrt(2.0 * b - d * s2)
    return math.sqrt(d) * c * tot


@njit(cache=True, nogil=True)
def _arc_power(q, mu, a, b, d1, beta1, rtol, rest, nodes, wk, wg, mode, ibuf, iwork, jac):  # pragma: no cover - compiled
    """(H, error) of H = integral_0^beta1 (a + b cos beta)^q d beta, q = 1 - p in (0, 1): the arc
    where N.wo = a + b cos beta >= mu (000 eq. 12's max(N.L, N.V) = N.wo there); d1 = b^2 - (mu - a)^2.

    With t = N.wo, d beta = dt / sqrt((T - t)(t - L)), T = a + b (beta = 0), L = a - b: H is
    integral_mu^T t^q / sqrt((T - t)(t - L)) dt.  Where T > 4 mu (near grazing incidence: (N.wo)^q
    then nears its branch point t = 0 at the arc's end), the range t in [mu, T / 2] is
    integral_0^(T/2) - integral_0^mu by the Gauss-Jacobi rule for the weight t^q (``jac``: nodes and
    weights of two orders): the rest of the integrand has its singularities at T and at L <= mu - (T - 2 mu) < -T / 2,
    at least T / 2 away, so the rules converge geometrically, and the shorter one is taken where its a-priori bound
    (:func:`_jacobi_bound`) meets half the tolerance, the longer one else, the bound its error (until issue 14's
    fifteenth session: both rules, their difference the error).  The rest,
    t from T - D c^2 (mu, or T / 2 beyond 4 mu) to T, is t = T - D s^2, s in [0, c] (D = T - mu = d1 / (b + mu - a),
    without cancellation): an even, analytic integrand in s (:func:`_arc_piece`), by the fewest Gauss-Legendre
    points whose a-priori error bound (:func:`_arc_bound`) meets ``rtol`` times a lower bound of K = ``rest`` + H
    (``rest`` >= 0, H >= beta1 mu^q), its rounding added; about 5 values of t^q per call where the 7/15 rule in beta
    took 15 to 45 (issue 14's fifteenth session).  Should the bound want more than GL_MAX points, the piece is
    the 7/15 rule in beta, globally adaptive on at most INNER_MAX intervals (``iwork``, 4 x INNER_MAX), until
    the summed calibrated error meets the same tolerance; the error is returned either way."""
    if beta1 <= 0.0:
        return 0.0, 0.0
    top = a + b
    d = d1 / (b + (mu - a))  # T - mu
    fixed = 0.0  # the Gauss-Jacobi part and its error
    fixed_err = 0.0
    end = beta1
    c = 1.0
    low_h = beta1 * mu**q  # H's lower bound: t >= mu on the arc (and t >= T / 2 on the piece beyond the Jacobi part)
    if top > 4.0 * mu:
        low = a - b
        half = 0.5 * top
        # the shorter rule where its bound (:func:`_jacobi_bound`) is at most half the tolerance's lower bound, else the
        # longer one, its bound the error either way (plus the sums' rounding)
        n1, n2 = JACOBI_ORDERS
        tol0 = rtol * (rest + low_h)
        e1 = _jacobi_bound(q, top, low, half, n1) + _jacobi_bound(q, top, low, mu, n1)
        if e1 <= 0.5 * tol0:
            fixed = _jacobi_sum(q, top, low, half, jac[0, :n1], jac[1, :n1]) - _jacobi_sum(q, top, low, mu, jac[0, :n1], jac[1, :n1])
        else:
            fixed = _jacobi_sum(q, top, low, half, jac[2], jac[3]) - _jacobi_sum(q, top, low, mu, jac[2], jac[3])
            e1 = _jacobi_bound(q, top, low, half, n2) + _jacobi_bound(q, top, low, mu, n2)
        fixed_err = e1 + 64.0 * EPS * abs(fixed)
        end = math.acos((half - a) / b)
        c = math.sqrt(half / d)  # T - D c^2 = T / 2
    if fixed > 0.0:
        low_h = max(low_h, fixed - fixed_err + end * (0.5 * top) ** q)
    tol = rtol * (rest + low_h)
    n, bound = _arc_bound(q, top, d, b, c, max(tol - fixed_err, 0.5 * tol))
    if n <= GL_MAX:
        h = _arc_piece(q, top, d, b, c, n)
        return fixed + h, fixed_err + bound + (n + 16) * EPS * h  # n / 2 terms of a few roundings each, and T, D's
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    lo[0], hi[0] = 0.0, end
    val[0], err[0] = _arc_rule(q, a, b, 0.0, end, nodes, wk, wg, mode, ibuf)
    m = 1
    while True:
        tot, e, worst = _tally(val, err, m, fixed, fixed_err)
        if e <= rtol * (rest + max(tot - e, beta1 * mu**q)) or m >= lo.shape[0]:
            return tot, e
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[m], hi[m] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _arc_rule(q, a, b, lo[worst], mid, nodes, wk, wg, mode, ibuf)
        val[m], err[m] = _arc_rule(q, a, b, mid, hi[m], nodes, wk, wg, mode, ibuf)
        m += 1


def arc_piece_reference(q: float, mu: float, a: float, b: float, d1: float, c: float = 1.0) -> float:
    """The arc's piece in s (:func:`_arc_piece`) in plain numpy, for N.wo = a + b cos(beta), d1 = b^2 - (mu - a)^2:
    P by numpy's 200-point Gauss-Legendre rule in s on [0, c] (c = 1: t from mu to T; the compiled kernel's twin)."""
    d = d1 / (b + (mu - a))  # (mu - a first: b + mu would round b away near mu = 1)
    x, w = np.polynomial.legendre.leggauss(200)
    sx = c * x
    t = a + b - d * sx * sx
    return float(math.sqrt(d) * c * np.sum(w * t**q / np.sqrt(2.0 * b - d * sx * sx)))


#: the unused Gauss-Jacobi argument of the closed forms p in {0, 1} (read-only, as jacobi_rules' arrays:
#: one compiled signature)
_NO_JACOBI = np.zeros((4, 1))
_NO_JACOBI.flags.writeable = False


@functools.lru_cache(maxsize=256)
def jacobi_rules(q: float) -> np.ndarray:
    """Nodes on [0, 1] and weights of the Gauss-Jacobi rules for integral_0^1 t^q g(t) dt, of
    :data:`JACOBI_ORDERS` (the shorter, the longer: :func:`_arc_power`): rows t, w of the first, t, w of the second
    (read-only, cached per q: scipy computes them in about 0.1 ms)."""
    from scipy.special import roots_jacobi

    lo_n, hi_n = JACOBI_ORDERS
    out = np.zeros((4, hi_n))
    for row, n in ((0, lo_n), (2, hi_n)):
        x, w = roots_jacobi(n, 0.0, q)  # weight (1 + x)^q on [-1, 1]
        out[row, :n] = 0.5 * (x + 1.0)
        out[row + 1, :n] = w / 2.0 ** (q + 1.0)  # (the shorter rule is padded: _arc_power reads its first n)
    out.flags.writeable = False
    return out


@njit(cache=True, nogil=True)
def _k_closed(p, mu, c2, u, um, sa):  # pragma: no cover - compiled; see integrand_reference
    """(K, beta1, below) for u = cos(alpha), um = 1 - u, sa = sin(alpha); c2 = cos(2 theta_i): K is
    the integral over the visible arc of N.wo / max(mu, N.wo)^p in closed form for p in {0, 1} (for
    other p, the p = 1 value); beta1 is the half-arc where N.wo >= mu (p > 0) and ``below`` the
    integral of N.wo over the half-arc where 0 < N.wo < mu."""
    a = mu * u
    d0 = (sa - mu) * (sa + mu)  # b^2 - a^2 = sin^2(alpha) - mu^2
    if d0 > 0.0:
        bs0 = math.sqrt(d0)  # b sin(beta0)
        beta0 = math.atan2(bs0, -a)  # cos(beta0) = -a / b
    else:
        bs0 = 0.0
        beta0 = math.pi
    if p == 0.0:
        return 2.0 * (a * beta0 + bs0), 0.0, 0.0  # 2 (a beta0 + b sin beta0)
    d1 = um * (u - c2)  # b^2 - (mu - a)^2
    if d1 > 0.0:
        bs1 = math.sqrt(d1)
        beta1 = math.atan2(bs1, mu * um)  # cos(beta1) = (mu - a) / b
    else:
        bs1 = 0.0
        beta1 = 0.0
    if bs0 > 0.0 and bs1 > 0.0:
        diff = mu * mu * (1.0 - 2.0 * u) / (bs0 + bs1)  # b sin(beta0) - b sin(beta1), no cancellation
    else:
        diff = bs0 - bs1
    below = a * (beta0 - beta1) + diff
    return 2.0 * (beta1 + below / mu), beta1, below  # 000 eq. 7: N.wo / max(mu, N.wo)


@njit(cache=True, nogil=True, inline="always")  # (a call passes 6 arrays, with reference counts, per node)
def _k_of_u(p, mu, c2, u, um, sa, itol, nodes, wk, wg, mode, ibuf, iwork, jac):  # pragma: no cover - compiled; see integrand_reference
    """(K(u), its error): K is the integral over the visible arc of N.wo / max(mu, N.wo)^p, for
    u = cos(alpha), um = 1 - u, sa = sin(alpha); c2 = cos(2 theta_i).  Closed form for p in
    {0, 1} (:func:`_k_closed`); for p in (0, 1) the arc where N.wo >= mu by :func:`_arc_power`
    (relative error ``itol``), the rest in closed form.  The error is 0 for the closed forms."""
    k, beta1, below = _k_closed(p, mu, c2, u, um, sa)
    if p == 0.0 or p == 1.0:
        return k, 0.0
    # 000 eq. 12: N.wo / max(mu, N.wo)^p, (N.wo)^(1 - p) on the arc N.wo >= mu
    below = below / mu**p
    b = math.sqrt((1.0 - mu) * (1.0 + mu)) * sa  # s sin(alpha)
    h, e = _arc_power(1.0 - p, mu, mu * u, b, um * (u - c2), beta1, itol, below, nodes, wk, wg, mode, ibuf, iwork, jac)
    return 2.0 * (h + below), 2.0 * e


# --- the Blinn family: the half vector's azimuth about N in closed form ----------------------------


@njit(cache=True, nogil=True)
def _trig_tail(x, which):  # pragma: no cover - compiled; see half_moments_reference
    """Integrals of trigonometric polynomials that cancel to high order at small x, by their series
    below x = 1 and in closed form above (where at most a digit cancels):

    which 0: x - sin(x);  1: F1 = integral_0^x (cos(t) - cos(x)) dt = sin(x) - x cos(x);
    2: F2 = integral_0^x (cos(t) - cos(x))^2 dt;  3: R2 = integral_0^x (1 - cos(t))^2 dt.
    """
    if x >= 1.0:
        if which == 0:
            return x - math.sin(x)
        if which == 1:
            return math.sin(x) - x * math.cos(x)
        if which == 2:
            c = math.cos(x)
            return x * (0.5 + c * c) - 1.5 * math.sin(x) * c
        return 1.5 * x - 2.0 * math.sin(x) + 0.25 * math.sin(2.0 * x)
    # the series sum_k coef(k) y^(2k+1) / (2k+1)!, y = 2x for F2 (then / 4), x otherwise
    y = 2.0 * x if which == 2 else x
    y2 = y * y
    term = y  # y^(2k+1) / (2k+1)! at k = 0
    total = 0.0
    for k in range(1, 30):
        term *= y2 / ((2.0 * k) * (2.0 * k + 1.0))
        sign = 1.0 if k % 2 == 0 else -1.0
        if which == 0:
            coef = -sign  # (-1)^(k+1)
        elif which == 1:
            coef = -sign * 2.0 * k  # (-1)^(k+1) 2k
        elif which == 2:
            coef = sign * (2.0 * k - 2.0)  # (-1)^k (2k - 2)
        else:
            coef = sign * (2.0 ** (2 * k - 1) - 2.0)  # (-1)^k (2^(2k-1) - 2)
        total += coef * term
        if term < 1e-18 * abs(total):
            break
    return 0.25 * total if which == 2 else total


@njit(cache=True, nogil=True, inline="always")
def _arc_moments(e, sb, b, beta):  # pragma: no cover - compiled; see half_moments_reference
    """(J1, J2) = integral_0^beta (d, d^2) d beta' for d = c - c_e = e + b cos(beta') >= 0 on the arc, where
    cos(beta) = -e / b, sb = b sin(beta) (sb = 0 and beta = pi for a full circle): J1 = sb + beta e,
    J2 = beta (e^2 + b^2 / 2) + 3/2 e sb, by their series b F1(beta), b^2 F2(beta) below beta = 1 (where
    e is near -b and the closed forms cancel)."""
    if beta < 1.0:
        return b * _trig_tail(beta, 1), b * b * _trig_tail(beta, 2)
    return sb + beta * e, beta * (e * e + 0.5 * b * b) + 1.5 * e * sb


@njit(cache=True, nogil=True, inline="always")
def _half_arc(mu, s, psi, u, sa):  # pragma: no cover - compiled; see the kernels' twins
    """The arc of h's azimuth where N.wo > 0, for h at u = N.h, sa = sin(alpha) (s = sin(theta_i),
    psi = pi/2 - theta_i): (live, b, c0, e0, sb0, beta0, low, f1, f2).  live is False where no h on the circle
    sends wo above the horizon; b = s sa, c0 = mu / (2 u) (wi.h there), e0 = a - c0 = mu cos(2 alpha) / (2 u);
    on the full circle (2 alpha <= psi, or b = 0) sb0 = 0, beta0 = pi and low = d(pi) = a - b - c0, else
    sb0 = b sin(beta0) = sqrt(sin(2 alpha + psi) sin(2 alpha - psi)) / (2 u), each sine with its angle written
    as a difference of small exact angles near its zero (alpha' = pi/2 - alpha), and low = 0; and those two
    sines, f1 = 2 u T with T = d(0) = a + b - c0 and f2 = 2 u (b - e0) (0 on the full circle): nine values."""
    al = math.atan2(sa, u)
    alc = math.atan2(u, sa)  # pi/2 - alpha, exact where u is small
    if u <= 0.0 or 2.0 * alc <= psi:  # 2 alpha + psi >= pi: the whole circle of h sends wo below the horizon
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    b = s * sa
    c0 = 0.5 * mu / u
    e0 = 0.5 * mu * (u - sa) * (u + sa) / u
    if 2.0 * al <= psi or b == 0.0:  # the whole circle sends wo above it (b = 0: mu = 1, or h = N)
        low = 0.5 * math.sin(psi - 2.0 * al) / u
        return low + 2.0 * b > 0.0, b, c0, e0, 0.0, math.pi, low, 0.0, 0.0
    f1 = math.sin(2.0 * alc - psi) if 2.0 * al + psi > 0.5 * math.pi else math.sin(2.0 * al + psi)
    f2 = math.sin(2.0 * alc + psi) if 2.0 * al - psi > 0.5 * math.pi else math.sin(2.0 * al - psi)
    sb0 = 0.5 * math.sqrt(max(0.0, f1 * f2)) / u
    return True, b, c0, e0, sb0, math.atan2(sb0, -e0), 0.0, f1, f2


@njit(cache=True, nogil=True)
def _k_half(p, mu, s, psi, u, sa):  # pragma: no cover - compiled; see half_integrand_reference
    """K(u) of the half-vector frame, p in {0, 1}: the integral over the azimuth beta of h about N of
    4 (wi.h) N.wo / max(mu, N.wo)^p where N.wo > 0, for h at u = N.h = cos(alpha), sa = sin(alpha);
    s = sin(theta_i), psi = pi / 2 - theta_i = atan2(mu, s) (exact near grazing incidence, where the
    arc's ends depend on 2 alpha - psi).

    d omega_o = 4 (wo.h) d omega_h and wo.h = wi.h = c = a + b cos(beta), a = mu u, b = s sa (the
    form of N.wo about R, pumpup.engine.polar's lobe frame); N.wo = 2 c u - mu, so N.wo > 0 where
    c > c0 = mu / (2 u), and N.wo >= mu where c >= c1 = 2 c0.  On the arc |beta| < beta0 (c > c0),
    with d = c - c0 >= 0: p = 0 integrates 4 c 2 u d = 8 u (c0 d + d^2); p = 1 that on the part
    |beta| > beta1 (c < c1), divided by mu = 2 u c0, and 4 c on |beta| < beta1.  The arc's end beta0 comes
    exact from :func:`_half_arc`, beta1 from b^2 - (a - c1)^2 = sa^2 (u - mu)(u + mu) / u^2; the part between
    beta1 and beta0 is integrated in delta = beta0 - beta (no cancellation when it is thin, near grazing
    incidence).
    """
    live, b, c0, e0, sb0, beta0, dpi, _, _ = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0
    j1, j2 = _arc_moments(e0, sb0, b, beta0)
    if p == 0.0:
        return 16.0 * u * (c0 * j1 + j2)  # 2 (both signs of beta) 8 u (c0 J1 + J2)
    # p = 1 (000 eq. 32's max(N.L, N.V)): |beta| < beta1 where N.wo >= mu, non-empty for alpha < theta_i
    if u <= mu or b == 0.0:
        return 8.0 * (j1 + j2 / c0)  # (8 u / mu) (c0 J1 + J2) on the whole arc
    e1 = -mu * sa * sa / u  # a - c1
    sb1 = sa * math.sqrt((u - mu) * (u + mu)) / u  # b sin(beta1)
    beta1 = math.atan2(sb1, -e1)
    k1, _ = _arc_moments(e1, sb1, b, beta1)
    # beta1 < beta < beta0: d = D + X, X = P sin(delta) + Q (cos(delta) - 1) >= 0, with D = d(beta0) (0 on
    # a partial arc), P = b sin(beta0), Q = b cos(beta0) (-e0 on a partial arc, -b on the full circle)
    dl = beta0 - beta1
    hs = math.sin(0.5 * dl)
    P = sb0
    Q = -b if beta0 == math.pi else -e0
    ix = 2.0 * P * hs * hs - Q * _trig_tail(dl, 0)
    ix2 = P * P * 0.25 * _trig_tail(2.0 * dl, 0) - 4.0 * P * Q * hs ** 4 + Q * Q * _trig_tail(dl, 3)
    i1 = dpi * dl + ix
    i2 = dpi * dpi * dl + 2.0 * dpi * ix + ix2
    return 8.0 * (2.0 * c0 * beta1 + k1 + i1 + i2 / c0)  # 2 [4 (c1 beta1 + J1(c1)) + (4 / c0)(c0 I1 + I2)]


@njit(cache=True, nogil=True)
def _complete_kd(y):  # pragma: no cover - compiled; tested against scipy.special.elliprf, elliprd, ellipk, ellipe
    """(K, D) = (R_F(0, y, 1), R_D(0, y, 1) / 3) for 0 < y <= 1: with m = 1 - y the complete elliptic integrals
    K(m) = integral_0^(pi/2) d phi / Delta and D(m) = (K - E) / m = integral_0^(pi/2) sin^2 phi d phi / Delta,
    Delta = sqrt(1 - m sin^2 phi), by the arithmetic-geometric mean (DLMF 19.8.1, 19.8.6): a_0 = 1, g_0 = sqrt(y),
    c_(n+1) = (a_n - g_n) / 2 = c_n^2 / (4 a_(n+1)) (c_1 = m / (2 (1 + sqrt(y))): no cancellation), K = pi / (2 AGM),
    K - E = K sum_(n>=0) 2^(n-1) c_n^2 with c_0^2 = m, so D = K (1/2 + sum_(n>=1) 2^(n-1) c_n^2 / m), a sum of
    positive terms.  Quadratic convergence: at most about 10 steps of one square root each for y down to 1e-300
    (issue 14's fifteenth session: Carlson's duplication, 170 ns per pair, took most of Ward's K(u))."""
    m = 1.0 - y
    kc = math.sqrt(y)
    a = 0.5 * (1.0 + kc)
    g = math.sqrt(kc)
    c = 0.5 * m / (1.0 + kc)
    tot = c * c
    w = 1.0
    for _ in range(64):
        if c <= EPS * a:
            break
        an = 0.5 * (a + g)
        c = c * c / (4.0 * an)
        g = math.sqrt(a * g)
        a = an
        w *= 2.0
        tot += w * c * c
    k = 0.5 * math.pi / a
    return k, k * (0.5 + (tot / m if m > 0.0 else 0.0))


@njit(cache=True, nogil=True)
def _k_ward(mu, s, psi, u, sa):  # pragma: no cover - compiled; see ward_integrand_reference
    """K(u) of Ward's model (000 eq. 34) in the half-vector frame: the integral over the azimuth beta of h
    about N of 4 (wi.h) sqrt(N.wo) where N.wo > 0 (its 1 / sqrt(N.L) goes into the scale), for h at
    u = N.h, sa = sin(alpha); s = sin(theta_i), psi = pi/2 - theta_i.

    As in :func:`_k_half`, c = wi.h = c0 + d, N.wo = 2 u d, d = e0 + b cos(beta) >= 0 on the arc |beta| <
    beta0: K = 8 sqrt(2 u) (c0 I_1/2 + I_3/2), I_q = integral_0^beta0 d^q d beta, complete elliptic integrals
    (Carlson's R_F, R_D; :func:`_complete_kd`): with x = sin(beta / 2), d = T - 2 b x^2, T = d(0), on a partial arc (T < 2 b,
    M = T / (2 b)) I_1/2 = 2 T / sqrt(2 b) (R_F - R_D / 3), I_-1/2 = 2 R_F / sqrt(2 b), the R at (0, 1 - M, 1);
    on the full circle (k^2 = 2 b / T <= 1) I_1/2 = 2 sqrt(T) E(k^2) = 2 sqrt(T) (R_F - k^2 R_D / 3),
    I_-1/2 = 2 R_F / sqrt(T) at (0, 1 - k^2, 1); and 3 I_3/2 = 4 e0 I_1/2 + (b^2 - e0^2) I_-1/2 (the
    recurrence (q + 1) I_(q+1) = (2q + 1) e0 I_q + q (b^2 - e0^2) I_(q-1), from d/d beta (d^q sin(beta)),
    whose boundary terms vanish).  T, 1 - M and 1 - k^2 come from :func:`_half_arc`'s exact angle forms.
    """
    live, b, c0, e0, _, beta0, low, f1, f2 = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0
    if beta0 == math.pi:  # the full circle: d(pi) = low >= 0, d(0) = T = low + 2 b
        top = low + 2.0 * b
        if b == 0.0:
            ih, imh = math.pi * math.sqrt(top), math.pi / math.sqrt(top)
        else:
            k2 = 2.0 * b / top
            rf, rd3 = _complete_kd(low / top)
            ih = 2.0 * math.sqrt(top) * (rf - k2 * rd3)
            imh = 2.0 * rf / math.sqrt(top)
        bb = -low * top  # b^2 - e0^2 = (b - e0)(b + e0)
    else:
        top = 0.5 * f1 / u  # T = a + b - c0
        gap = 0.5 * f2 / u  # 2 b - T = b - e0
        rf, rd3 = _complete_kd(gap / (2.0 * b))
        sb2 = math.sqrt(2.0 * b)
        ih = 2.0 * top / sb2 * (rf - rd3)
        imh = 2.0 * rf / sb2
        bb = gap * top
    i3h = (4.0 * e0 * ih + bb * imh) / 3.0
    return 8.0 * math.sqrt(2.0 * u) * (c0 * ih + i3h)


@njit(cache=True, nogil=True)
def _k_vcavity(mu, s, psi, u, sa):  # pragma: no cover - compiled; see vcavity_integrand_reference
    """K(u) of the V-cavity microfacet models with F = 1 (Cook-Torrance, 001 eq. 9-10; Torrance-Sparrow, 002
    eq. 10) in the half-vector frame, without their D(u): the integral over the azimuth beta of h about N of
    4 (wi.h) G N.wo / N.wo = 4 c G where N.wo > 0, G = min(1, 2 u min(mu, N.wo) / c) (001 eq. 10; the
    1 / (N.L) goes into the scale), i.e. 4 min(c, 2 u mu, 4 u^2 c - 2 u mu) with c = wi.h = a + b cos(beta)
    (N.wo = 2 u c - mu, as in :func:`_k_half`).  A minimum of three lines in c: on each range of c between
    their crossings (c = 2 u mu, mu / u, 2 u mu / (4 u^2 - 1)) and the arc's end c0 = mu / (2 u) the integral is
    p J0 + q J1, J0 = integral d beta and J1 = integral c d beta over {beta: c(beta) in the range}.  The arc's
    end (c0, b sin(beta0)) comes from the exact forms of _k_half; at the interior crossings X = c - a and
    S = b sin(beta) = sqrt((b - X)(b + X)) are consistent, so their rounding moves a kink of the (continuous)
    minimum and changes the integral only to second order.
    """
    live, b, c0, e0, sb0, _, _, _, _ = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0
    a = mu * u
    lo = max(c0, a - b)  # the range of c on the arc
    hi = a + b
    if b == 0.0:  # c = a on the whole circle (mu = 1 or h = N)
        g = min(a, 2.0 * u * mu, 4.0 * u * u * a - 2.0 * u * mu)
        return 8.0 * math.pi * g if a > c0 else 0.0
    # the lines' crossings inside (lo, hi), sorted (those outside stand at hi: their pieces are empty); scalars,
    # not an array: this runs at every node
    x1, x2 = 2.0 * u * mu, mu / u
    x3 = 2.0 * u * mu / (4.0 * u * u - 1.0) if 4.0 * u * u > 1.0 else hi
    x1, x2, x3 = (x1 if lo < x1 < hi else hi), (x2 if lo < x2 < hi else hi), (x3 if lo < x3 < hi else hi)
    x1, x2 = min(x1, x2), max(x1, x2)
    x2, x3 = min(x2, x3), max(x2, x3)
    x1, x2 = min(x1, x2), max(x1, x2)
    total = 0.0
    for j in range(4):
        c_lo = lo if j == 0 else (x1 if j == 1 else (x2 if j == 2 else x3))
        c_hi = x1 if j == 0 else (x2 if j == 1 else (x3 if j == 2 else hi))
        if not c_hi > c_lo:
            continue
        # X = c - a = b cos(beta) and S = b sin(beta) at both ends (c decreases with beta): the arc's end exactly
        # (X = -e0, S = b sin(beta0)), the circle's bottom and top (X = -+b, S = 0), the rest S = sqrt((b - X)(b + X))
        if j == 0 and c_lo == c0:
            x_lo, s_lo = -e0, sb0
        elif j == 0:
            x_lo, s_lo = -b, 0.0
        else:
            x_lo = c_lo - a
            s_lo = math.sqrt(max(0.0, (b - x_lo) * (b + x_lo)))
        if c_hi == hi:
            x_hi, s_hi = b, 0.0
        else:
            x_hi = c_hi - a
            s_hi = math.sqrt(max(0.0, (b - x_hi) * (b + x_hi)))
        # J0 = beta_lo - beta_hi and J1 = a J0 + S_lo - S_hi without cancellation: b^2 sin(J0) and S_lo - S_hi
        # from X_hi^2 - X_lo^2 = (c_hi - c_lo)(X_hi + X_lo) (thin pieces near grazing incidence, where the
        # integrand lives on arcs of width ~mu: the plain differences lost 8 digits at mu = 1e-8)
        dc, xs = c_hi - c_lo, x_hi + x_lo
        if x_lo * x_hi > 0.0:
            sin_b2 = b * b * dc * xs / (s_lo * x_hi + x_lo * s_hi)
        else:
            sin_b2 = s_lo * x_hi - x_lo * s_hi
        j0 = math.atan2(sin_b2, x_lo * x_hi + s_lo * s_hi)
        j1 = a * j0 + (dc * xs / (s_lo + s_hi) if s_lo + s_hi > 0.0 else 0.0)
        cm = 0.5 * (c_lo + c_hi)
        l1, l2, l3 = cm, 2.0 * u * mu, 4.0 * u * u * cm - 2.0 * u * mu
        if l1 <= l2 and l1 <= l3:
            total += j1  # G = 1: c
        elif l2 <= l3:
            total += 2.0 * u * mu * j0  # G = 2 u mu / c
        else:
            total += 4.0 * u * u * j1 - 2.0 * u * mu * j0  # G = 2 u N.wo / c
    return 8.0 * total  # 2 (both signs of beta) 4 c G


# --- frame 4: the half vector's azimuth by a rule on its arc (Smith microfacet models, Fresnel factors) ------


#: frame 4's models (``mp[0]``): the Smith microfacet models (Beckmann, GGX; :class:`Polar` ``smith``), the
#: V-cavity models with a Fresnel factor (Cook-Torrance, Torrance-Sparrow with ``ior``) and Schlick's model
#: (``Polar.schlick``)
SMITH, VCAVITY_F, SCHLICK, LOBE_F = 0, 1, 2, 3
#: the slots of frame 4's parameter array ``mp`` (float64): model, Smith's distribution (0 Beckmann, 1 GGX), G1 (0
#: exact, 1 Walter's fit), shadowing (0 separable, 1 height-correlated), alpha, ior, eta, k, P(mu) (set per mu by
#: :func:`_integrate`), the level N.wo of Walter's G1 switch (-1 for none), the scale c_F of the Fresnel factor's
#: feature at small wi.h (sqrt(|1 - (eta + i k)^2|), sqrt(ior^2 - 1); inf for none: :func:`fresnel_scale`), the scale
#: z_s of the integrand's feature at small N.wo (alpha for the Smith models, Schlick's r / (1 - r); inf for none), the
#: relative tolerance (set by :func:`albedo_1d`; :func:`_pieces` leaves out the outer cuts where they cannot matter);
#: frame 5 (``LOBE_F``: the lobe frame with F(Theta_min), :func:`_k_lobe_fresnel`) also x0 and y0 of F's branch point
#: (:func:`fresnel_branch`), the distance rho of its pole near c = 0 (:func:`fresnel_pole`), Brewster's zero c_b (real
#: and imaginary part, 1 where found: :func:`fresnel_brewster`), |(eta + i k)^2 + 1| (:func:`_lobe_f_bound`) and 1 where
#: the Gauss-Legendre pieces are on (:data:`LOBE_F_GAUSS`); per mu (:func:`_lobe_f_prepare`, set by :func:`_integrate`) F(mu),
#: the number of the arc's cuts in (mu, 1] and the cuts, falling (:data:`MP_SIZE` = 23 + 3 LOBE_F_CUTS, set below)


def fresnel_scale(ior: float, eta: float, k: float) -> float:
    """c_F: the Fresnel factor F(c) has its singularities where c^2 = 1 - index^2, |c| = c_F = sqrt(|1 - index^2|)
    (a dielectric's real ior, or a conductor's eta + i k), which near an index of 1 come close to the arc's small c;
    :func:`_k_numeric` cuts the arc at c = c_F 3^k there.  inf without a Fresnel factor."""
    if eta > 0.0:
        return math.sqrt(abs(1.0 - complex(eta, k) ** 2))
    return math.sqrt((ior - 1.0) * (ior + 1.0)) if ior > 0.0 else math.inf


@njit(cache=True, nogil=True, inline="always")
def _fresnel_at(mp, c):  # pragma: no cover - compiled
    """The Fresnel factor at wi.h = c of frames 4 and 6: the conductor's (eta, k = mp[6], mp[7]; metal.py) or the
    dielectric's (ior = mp[5], 1 when ior <= 0; cook_torrance.py)."""
    return _fresnel_real(c, mp[6], mp[7]) if mp[6] > 0.0 else _fresnel(c, mp[5])


@njit(cache=True, nogil=True, inline="always")
def _phi_numeric(mp, mu, u, c0, d):  # pragma: no cover - compiled; see numeric_integrand_reference
    """Frame 4's integrand 4 c F(c) Gamma at d = c - c0 >= 0 (c = wi.h, N.wo = z = 2 u d): Gamma = G / mu for the
    Smith models (G = G1(mu) G1(z) = mu z / (P(mu) P(z)), Walter et al. 2007 eq. 20; or the height-correlated
    mu z / (z P(mu) + mu P(z) - mu z), Heitz 2014; P(w) = N.w / G1(w), pumpup.models.microfacet), Gamma = G =
    min(1, 2 u mu / c, 2 u z / c) for the V-cavity (001 eq. 10); F the dielectric (ior, 002 sec. 3.2) or conductor
    (eta, k) Fresnel factor at c, or 1."""
    c = c0 + d
    z = 2.0 * u * d
    f = _fresnel_at(mp, c)
    if mp[0] == VCAVITY_F:
        return 4.0 * f * min(c, 2.0 * u * mu, 2.0 * u * z)  # 4 c G, 001 eq. 10
    if mp[0] == SCHLICK:
        return 4.0 * c * z / (mp[4] + (1.0 - mp[4]) * z)  # 000 eq. 36's 1 / (r + (1 - r) N.V), times N.V
    if mp[1] == 1.0:  # GGX: P = (z + sqrt(z^2 + alpha^2 sin^2)) / 2, Walter eq. 34 (physics.microfacet.projected, one sqrt)
        pz = 0.5 * (z + math.sqrt(z * z + mp[4] * mp[4] * ((1.0 - z) * (1.0 + z))))
    else:
        pz = _projected(math.sqrt((1.0 - z) * (1.0 + z)), 0.0, z, 0, int(mp[2]), mp[4])
    if mp[3] == 0.0:
        return 4.0 * c * f * z / (mp[8] * pz)  # G1(mu) G1(z) / mu, Walter eq. 20
    return 4.0 * c * f * z / (z * mp[8] + mu * pz - mu * z)  # 1 / (mu (1 + Lambda_i + Lambda_o)), Heitz 2014


@njit(cache=True, nogil=True)
def _delta_rule(mp, mu, u, c0, low, sb0, q, lo, hi, nodes, wk, wg, mode, ibuf):  # pragma: no cover - compiled
    """(value, error) of the rule on delta in [lo, hi] for :func:`_phi_numeric` at d = low + sb0 sin(delta) +
    2 q sin^2(delta / 2) (:func:`_k_numeric`)."""
    h = hi - lo
    for j in range(nodes.shape[0]):
        x = 0.5 * (lo + h * nodes[j])
        sh = math.sin(x)
        d = low + 2.0 * sh * (sb0 * math.cos(x) + q * sh)
        ibuf[j] = _phi_numeric(mp, mu, u, c0, max(d, 0.0))
    k, diff, asc, ab = rule_sums(ibuf, wk, wg)
    return k * h, calibrated(diff * h, asc * h, ab * h, mode)


@njit(cache=True, nogil=True, inline="always")
def _delta_at(c, a, b, beta0):  # pragma: no cover - compiled
    """delta = beta0 - beta where wi.h = a + b cos(beta) = c (at most beta0)."""
    x = c - a
    return min(beta0 - math.atan2(math.sqrt(max(0.0, (b - x) * (b + x))), x), beta0)


@njit(cache=True, nogil=True)
def _k_numeric(mp, mu, s, psi, u, sa, itol, tol_abs, nodes, wk, wg, mode, ibuf, iwork):  # pragma: no cover - compiled; see numeric_integrand_reference
    """(K(u), its error) of frame 4: the integral over the azimuth beta of h about N, where N.wo > 0, of
    :func:`_phi_numeric` (4 c F(c) Gamma, which depends on beta through c = wi.h only, as in :func:`_k_half`), by a
    globally adaptive rule (``nodes``, ``wk``, ``wg``: the 7/15 rule) on the arc.

    The arc comes exact from :func:`_half_arc`, in delta = beta0 - beta measured from its end: d = c - c0 =
    2 e0 sin^2(delta / 2) + b sin(beta0) sin(delta) on a partial arc (N.wo = 0 at delta = 0), low + 2 b
    sin^2(delta / 2) on the full circle (beta0 = pi), no cancellation either way.  The arc is cut where the
    integrand has a kink or a jump: Walter's G1 switch (N.wo = ``mp[9]``), the crossings of the V-cavity's three
    lines (c = 2 u mu, mu / u, 2 u mu / (4 u^2 - 1), as :func:`_k_vcavity`); and graded towards the arc's small end
    where a factor has a singularity near it (N.wo = z_c 3^k, c = c_c 3^k, below).  The interval with the largest
    error is bisected until the summed error (QUADPACK's calibration: the integrand is analytic on every piece) is at
    most max(``itol`` |K|, ``tol_abs``) or INNER_MAX intervals are used; the error is returned either way.  Both signs
    of beta: 2 x."""
    live, b, c0, e0, sb0, beta0, low, _, _ = _half_arc(mu, s, psi, u, sa)
    if not live:
        return 0.0, 0.0
    q = b if beta0 == math.pi else e0
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    a = mu * u
    c_lo, c_hi = c0 + low, a + b  # the range of c on the arc (delta = 0 and beta0)
    # the cuts in c, as delta = beta0 - beta(c), sorted (at most three; scalars, not an array: this runs at every
    # node; those outside (0, beta0) stand at beta0, their pieces are empty)
    x1, x2, x3 = beta0, beta0, beta0
    if b > 0.0:
        for j in range(3):
            if mp[0] == VCAVITY_F:
                cb = 2.0 * u * mu if j == 0 else (mu / u if j == 1 else (2.0 * u * mu / (4.0 * u * u - 1.0) if 4.0 * u * u > 1.0 else -1.0))
            else:
                cb = 0.5 * (mu + mp[9]) / u if j == 0 and mp[9] > 0.0 else -1.0
            if c_lo < cb < c_hi:
                dl = _delta_at(cb, a, b, beta0)
                if 0.0 < dl < beta0:
                    if j == 0:
                        x1 = dl
                    elif j == 1:
                        x2 = dl
                    else:
                        x3 = dl
    x1, x2 = min(x1, x2), max(x1, x2)
    x2, x3 = min(x2, x3), max(x2, x3)
    x1, x2 = min(x1, x2), max(x1, x2)
    # graded cuts where a factor has a singularity near the arc's small end: P(N.wo) of the Smith models at
    # N.wo ~ +-i alpha (GGX's at +-i alpha / sqrt(1 - alpha^2); Beckmann's erf and exp turn on the scale
    # a = N.wo / (alpha sin) ~ 1), the Fresnel factor at c ~ +-i c_F (:func:`fresnel_scale`).  Where the arc runs from
    # below that scale to far above it, a rule on the whole arc does not see the feature at its end (GGX
    # alpha = 0.001 was 1.6e-10 off at rtol 1e-12 with an estimate of 6e-13), so it is cut at N.wo = z_c 3^k,
    # z_c = max(alpha, 3 N.wo_min), and at c = c_c 3^k, c_c = max(c_F, 3 c_min): each piece then lies at least its own
    # length from the singularity
    z_lo, z_hi = 2.0 * u * low, 2.0 * u * (c_hi - c0)
    zc = 3.0 * z_lo if z_lo >= mp[11] else mp[11]
    cc = 3.0 * c_lo if c_lo >= mp[10] else mp[10]
    da = _delta_at(c0 + 0.5 * zc / u, a, b, beta0) if zc < z_hi / 1.5 else beta0
    db = _delta_at(cc, a, b, beta0) if cc < c_hi / 1.5 else beta0
    m = 0
    start = 0.0
    f = 0
    while True:
        fx = x1 if f == 0 else (x2 if f == 1 else (x3 if f == 2 else beta0))
        end = min(da, db, fx)
        if end > start:
            lo[m], hi[m] = start, end
            val[m], err[m] = _delta_rule(mp, mu, u, c0, low, sb0, q, start, end, nodes, wk, wg, mode, ibuf)
            m += 1
            start = end
        if end >= beta0:
            break
        if m >= lo.shape[0] - 8:  # (keeps room to bisect)
            da, db, f = beta0, beta0, 3
            continue
        if da <= end:
            zc *= 3.0
            da = _delta_at(c0 + 0.5 * zc / u, a, b, beta0) if zc < z_hi / 1.5 else beta0
        if db <= end:
            cc *= 3.0
            db = _delta_at(cc, a, b, beta0) if cc < c_hi / 1.5 else beta0
        if fx <= end:
            f += 1
    while True:
        tot, e, worst = _tally(val, err, m, 0.0, 0.0)
        if 2.0 * e <= max(2.0 * itol * abs(tot), tol_abs) or m >= lo.shape[0]:
            return 2.0 * tot, 2.0 * e
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[m], hi[m] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _delta_rule(mp, mu, u, c0, low, sb0, q, lo[worst], mid, nodes, wk, wg, mode, ibuf)
        val[m], err[m] = _delta_rule(mp, mu, u, c0, low, sb0, q, mid, hi[m], nodes, wk, wg, mode, ibuf)
        m += 1


# --- frame 5: the lobe frame with 000 eq. 28's Fresnel factor F(Theta_min) (metal, plastic, the fresnel wrapper) ------


#: frame 5 refuses (the nested engine takes the model) where the Fresnel factor's branch point w = sqrt(1 - (eta + i k)^2)
#: lies closer than this to the real axis but off it (a near-kink: graded cuts would need log(1 / Im w) pieces per arc),
#: or on it inside (0, 1) (a dielectric's total reflection below eta = 1: F = 1 up to a square-root kink)
LOBE_F_Y0_MIN = 1e-3
#: the pumped lobe's frame of N takes F(Theta_min) only where its branch point lies at least this far from the real axis (or
#: beyond 1): a pumped metal's g then has the near-kink too, on a spline whose nodes no cut marks (eta 0.3, k 0.01, n 20,
#: g1: Im w = 0.0031, 1.7 x the estimate at mu = 0.96, rtol 1e-10, against the nested and 2-D engines)
CHAIN_F_Y0_MIN = 1e-2
#: the most graded cuts per side of the branch point on an arc (:func:`_k_lobe_fresnel`) and in alpha (:func:`_pieces`)
LOBE_F_CUTS = 8
#: the slots of frame 4's and 5's parameter array ``mp`` (above)
MP_SIZE = 23 + 3 * LOBE_F_CUTS
#: no cuts in alpha (:func:`_pieces`) where the feature's scale there is at least this (rad): the outer rule's first
#: 21 nodes on a piece of at most pi / 2 see it (metal eta 0.2, k 3: its pole's scale 0.35 had doubled the pieces)
LOBE_F_WIDE = 0.25


def lobe_fresnel_ok(eta: float, k: float, chain: bool = False) -> bool:
    """Whether frame 5 (``chain``: the pumped lobe's frame of N) takes the Fresnel factor of (eta, k)
    (:data:`LOBE_F_Y0_MIN`, :data:`CHAIN_F_Y0_MIN`)."""
    x0, y0 = fresnel_branch(eta, k)
    if y0 == 0.0:
        return x0 == 0.0 or x0 >= 1.0  # on the real axis: only outside (0, 1) (eta = 1, k = 0: F = 0)
    return y0 >= (CHAIN_F_Y0_MIN if chain and x0 < 1.0 else LOBE_F_Y0_MIN)


def with_fresnel(hint, eta: float, k: float):
    """``hint`` (a lobe's, p in {0, 1}, or a pumped lobe's, any p) with 000 eq. 28's F(Theta_min) of (eta, k) added: frame
    5, or the pumped lobe's frame of N with the factor; None where the path declines it (no such hint, a factor already,
    a near-kink: :func:`lobe_fresnel_ok`).  For the ``fresnel`` wrapper and the colour-keeping pumped metal's channels."""
    import dataclasses

    if (hint is None or hint.kind != "lobe" or (hint.p not in (0.0, 1.0) and hint.chain is None) or any(hint.fresnel)
            or not lobe_fresnel_ok(float(eta), float(k), hint.chain is not None)):
        return None
    return dataclasses.replace(hint, fresnel=(0.0, float(eta), float(k)))


def with_fresnel_max(hint, eta: float, k: float):
    """``hint`` (frame 6's: GGX, Beckmann with F = 1 or Schlick's model, pumped or not, not 1/E-scaled) with 000 eq. 28's
    F(max(N.L, N.V)) of (eta, k) as a factor of each node (``Polar.fmax``); None where the path declines it: no such hint,
    a Fresnel factor already, or a near-kink (:func:`lobe_fresnel_ok`, as for a lobe: F's branch point at least
    :data:`LOBE_F_Y0_MIN` from the real axis, :data:`CHAIN_F_Y0_MIN` with a pumped chain, whose g has the near-kink
    too).  For the ``fresnel`` wrapper (issue 14's twenty-second session: the nested engine took GGX alpha 1.6e-4 with eta
    0.497, k 3.15 at mu = 7.3e-6 14.6 s at rtol 1e-10)."""
    import dataclasses

    if (hint is None or hint.kind != "half" or hint.factor is not None or any(hint.fresnel) or hint.fmax is not None
            or not takes_n_frame(dataclasses.replace(hint, chain=None, levels=None))
            or not lobe_fresnel_ok(float(eta), float(k), hint.chain is not None)):
        return None
    return dataclasses.replace(hint, fmax=(float(eta), float(k)))


@njit(cache=True, nogil=True)
def _lobe_rule(mp, q, a, b, lo, hi, nodes, wk, wg, mode, ibuf):  # pragma: no cover - compiled
    """(value, error) of the rule on beta in [lo, hi] for F(t) t^q, t = N.wo = a + b cos(beta) (:func:`_k_lobe_fresnel`)."""
    h = hi - lo
    for j in range(nodes.shape[0]):
        t = a + b * math.cos(lo + h * nodes[j])
        ibuf[j] = _fresnel_real(t, mp[6], mp[7]) * (t if q == 1.0 else 1.0)
    k, diff, asc, ab = rule_sums(ibuf, wk, wg)
    return k * h, calibrated(diff * h, asc * h, ab * h, mode)


@njit(cache=True, nogil=True, inline="always")
def _beta_at(t, top, b):  # pragma: no cover - compiled
    """beta where a + b cos(beta) = t, from top - t = 2 b sin^2(beta / 2) (no cancellation near beta = 0)."""
    return 2.0 * math.asin(min(1.0, math.sqrt(max(0.0, (top - t) / (2.0 * b)))))


#: frame 5's Gauss-Legendre pieces (:func:`_lobe_f_bound`): the candidate ellipses, log(R) = f log(R_max) for f in these
LOBE_F_FRACTIONS = (0.8, 0.5, 0.25)
#: and log(R) at most this (R_max overflows where a piece is short beside far singular points)
LOBE_F_LOG_R_CAP = math.log(1e4)
#: frame 5 drops the arc's first cut where it lies closer to the arc's top T than this times the next piece's length
#: (that piece, a rule in t, would otherwise see the (T - t)^-1/2 of d beta = dt / sqrt((T - t)(t - L)) next to its end)
LOBE_F_MERGE = 0.25


@njit(cache=True, nogil=True, inline="always")
def _sqrt_re(x, y):  # pragma: no cover - compiled
    """Re sqrt(x + i y), the principal root, without cancellation: sqrt((r + x) / 2), or |y| / sqrt(2 (r - x)) for x < 0
    (r = |x + i y|; 0 for a negative real x)."""
    r = math.sqrt(x * x + y * y)
    return math.sqrt(0.5 * (r + x)) if x >= 0.0 else abs(y) / math.sqrt(2.0 * (r - x))


@njit(cache=True, nogil=True, inline="always")
def _focal_sum(zr, zi, lo, hi):  # pragma: no cover - compiled
    """(|z - lo| + |z - hi|) / 2 for z = zr + i zi: the semi-major axis of the Bernstein ellipse of [lo, hi] through z
    (its parameter R = A + sqrt(A^2 - 1) for A = that over h = (hi - lo) / 2).  For t in the ellipse whose semi-major axis
    is h A_R, gap(z) = this - h A_R is a lower bound of |t - z| (not positive: z may lie inside): in elliptic
    coordinates t = m + h cosh(xi + i theta), |dt| >= h sinh(xi) d xi = h d(cosh xi), and a path from t to z crosses the
    confocal ellipses from t's to z's."""
    return 0.5 * (math.sqrt((zr - lo) * (zr - lo) + zi * zi) + math.sqrt((zr - hi) * (zr - hi) + zi * zi))


@njit(cache=True, nogil=True)
def _lobe_f_bound(mp, q, lo, d, top, low, first, tol):  # pragma: no cover - compiled; see the tests' mpmath check
    """(n, bound, values): the Gauss-Legendre rule (n <= GL_MAX points; GL_MAX + 1 if none suffices) of the fewest values
    whose error on a piece [lo, lo + d] of frame 5's arc (:func:`_lobe_f_gauss`) is at most ``tol``, and its bound.

    The piece is integral G(t) dt, G = F(t) t^q / sqrt((T - t)(t - L)), F the conductor Fresnel factor of
    e = eta + i k (``mp[6]``, ``mp[7]``; 000 eq. 28), T = ``top``, L = ``low``.  ``first``: lo + d = T, by s with
    t = T - d s^2, s in [-1, 1]: sqrt(d) integral F t^q / sqrt(t - L) ds, even in s, whose Bernstein ellipse of parameter
    r maps onto t's of [lo, T] with R = r^2; else in t itself.  The n-point rule errs by at most 64 M / (15 (1 - r^-2)
    r^(2 n)) times the length factor (Trefethen, ATAP Thm 19.3), M a bound of the integrand on the ellipse, which must
    avoid F's branch points +-w, +-conj(w) (w^2 = 1 - e^2; x0, y0 = ``mp[13]``, ``mp[14]``: :func:`fresnel_branch`),
    L and (in t) T.

    M on the t-ellipse E_R of [lo, hi] (semi-axes h A_R, h B_R about m).  Every bound holds for either sign of the
    refracted cosine A = sqrt(e^2 - 1 + t^2), so for F's continuation, whatever its branch:
    - |t| <= tau = m + h A_R; |A|^2 = |t - w| |t + w| <= tau^2 + |w|^2 and >= gap(w) gap(-w) (:func:`_focal_sum`);
    - F = r_s(e) r_s(conj e) (1 + N_e N_conj(e) / (D_e D_conj(e))) / 2 continues |r_s|^2 (1 + |N|^2 / |D|^2) / 2 of
      the real axis (R_p = R_s |N|^2 / |D|^2, pbrt-v3's FrConductor), r_s = (t - A) / (t + A), N = A t - (1 - t^2),
      D = A t + 1 - t^2; the bounds for e hold for conj(e) (E_R is symmetric about the real axis);
    - |r_s| <= (tau + |A|)^2 / |w|^2, as (t - A)(t + A) = w^2; or (tau + |A|) / |t + A|, where on [lo, hi] (A's real
      part rising, its imaginary part >= 0 falling with t) |t + A| >= max(lo + Re A(lo), Im A(hi)), and E_R lies within
      h B_R of the segment, where |d(t + A)/dt| <= 1 + tau / min |A|;
    - |N| <= |A| tau + 1 + tau^2; D N = (e^2 + 1)(t - c_b)(t + c_b), c_b^2 = 1 / (e^2 + 1), so |D| >= |e^2 + 1|
      gap(c_b) gap(-c_b) / max |N|; and where N(c_b) = 0 (Brewster's zero, ``mp[16:19]``: :func:`fresnel_brewster`,
      A continued along the real axis to Re c_b, then straight to c_b), |N(t)| <= max |N'| |t - c_b| on the Bernstein
      ellipse through c_b (or E_R, the larger: convex and symmetric, it holds that path and the straight one from t,
      and A is analytic on it where it avoids +-w), N' = A + t^2 / A + 2 t, so
      |D| >= |e^2 + 1| gap(-c_b) / max |N'|: no loss at Brewster's angle;
    - |t - L|, |T - t| >= gap(L), gap(T).
    log(R) is the first of LOBE_F_FRACTIONS of log(R_max) that gives a rule; ``values`` is (n + 1) // 2 for ``first``,
    n else."""
    eta, k, x0, y0 = mp[6], mp[7], mp[13], mp[14]
    h = 0.5 * d  # (d = hi - lo; for ``first`` T - lo without cancellation)
    m = lo + h
    hi = lo + d
    if not (tol > 0.0 and h > 0.0):
        return GL_MAX + 1, 0.0, GL_MAX + 1
    # the semi-major axes of the ellipses through w, -w, L, T, c_b, -c_b: gap(z) = s_z - h A_R (:func:`_focal_sum`)
    cbr, cbi = mp[16], abs(mp[17])
    s_w = _focal_sum(x0, y0, lo, hi)
    s_mw = _focal_sum(-x0, y0, lo, hi)
    s_l = m - low
    s_t = top - m
    s_b = _focal_sum(cbr, cbi, lo, hi)
    s_mb = _focal_sum(-cbr, cbi, lo, hi)
    amx = min(s_w, s_mw, s_l) / h
    if not first:
        amx = min(amx, s_t / h)
    lrmax = min(math.log(amx + math.sqrt(max(0.0, (amx - 1.0) * (amx + 1.0)))), LOBE_F_LOG_R_CAP)
    if not lrmax > 1e-3:
        return GL_MAX + 1, 0.0, GL_MAX + 1
    w2 = x0 * x0 + y0 * y0  # |w|^2 = |1 - e^2|
    e2r, e2i = (eta - k) * (eta + k), 2.0 * eta * k
    re_lo = _sqrt_re(e2r - 1.0 + lo * lo, e2i)  # Re A(lo)
    im_hi = e2i / (2.0 * _sqrt_re(e2r - 1.0 + hi * hi, e2i)) if e2i > 0.0 else 0.0  # Im A(hi) >= 0
    s_seg = max(lo + re_lo, im_hi)  # |t + A| on [lo, hi]
    ep1 = mp[19]
    brewster = mp[18] > 0.0
    for f in LOBE_F_FRACTIONS:
        lr = f * lrmax
        big_r = math.exp(lr)
        big_a = 0.5 * (big_r + 1.0 / big_r)
        big_b = 0.5 * (big_r - 1.0 / big_r)
        ha = h * big_a
        tau = m + ha
        dw, dmw, dl = s_w - ha, s_mw - ha, s_l - ha
        dt = 1.0 if first else s_t - ha
        if not (dw > 0.0 and dmw > 0.0 and dl > 0.0 and dt > 0.0):
            continue
        amin = math.sqrt(dw * dmw)
        amax = math.sqrt(tau * tau + w2)
        rs = (tau + amax) * (tau + amax) / w2 if w2 > 0.0 else math.inf
        s_low = s_seg - (1.0 + tau / amin) * h * big_b
        if s_low > 0.0:
            rs = min(rs, (tau + amax) / s_low)
        nmax = amax * tau + 1.0 + tau * tau
        d_low = -1.0
        dm = s_mb - ha  # |t + c_b|
        if dm > 0.0:
            if s_b - ha > 0.0:
                d_low = ep1 * (s_b - ha) * dm / nmax
            if brewster:
                ha2 = max(ha, s_b)  # the ellipse through c_b, or E_R
                tau2 = m + ha2
                dw2, dmw2 = s_w - ha2, s_mw - ha2
                if dw2 > 0.0 and dmw2 > 0.0:
                    d_low = max(d_low, ep1 * dm / (math.sqrt(tau2 * tau2 + w2) + tau2 * tau2 / math.sqrt(dw2 * dmw2) + 2.0 * tau2))
        if not (d_low > 0.0 and rs < math.inf):
            continue
        big_m = 0.5 * rs * rs * (1.0 + (nmax / d_low) ** 2) * (tau if q == 1.0 else 1.0) / math.sqrt(dl * dt)
        if first:  # sqrt(T - lo) 64 M / (15 (1 - 1 / R) R^n), n points, (n + 1) // 2 values
            c = math.sqrt(d) * 64.0 * big_m / (15.0 * (1.0 - 1.0 / big_r))
            n = max(1.0, math.ceil(math.log(c / tol) / lr))
            v = (n + 1.0) // 2.0
            bound = c * math.exp(-n * lr)
        else:  # h 64 M / (15 (1 - R^-2) R^(2 n)), n points and values
            c = h * 64.0 * big_m / (15.0 * (1.0 - 1.0 / (big_r * big_r)))
            n = max(1.0, math.ceil(math.log(c / tol) / (2.0 * lr)))
            v = n
            bound = c * math.exp(-2.0 * n * lr)
        if n <= GL_MAX:
            return int(n), bound, int(v)
    return GL_MAX + 1, 0.0, GL_MAX + 1


@njit(cache=True, nogil=True)
def _lobe_f_piece(eta, k, q, lo, d, top, low, first, n):  # pragma: no cover - compiled; see lobe_f_piece_reference
    """integral_lo^(lo + d) F(t) t^q / sqrt((T - t)(t - L)) dt by the n-point Gauss-Legendre rule (:func:`_lobe_f_bound`):
    ``first`` (lo + d = T) in s, t = T - d s^2, else in t."""
    tot = 0.0
    if first:
        for j in range((n + 1) // 2):
            s2 = d * GL_X[n, j] * GL_X[n, j]
            t = top - s2
            tot += GL_W[n, j] * _fresnel_real(t, eta, k) * t**q / math.sqrt((top - low) - s2)
        return math.sqrt(d) * tot
    h = 0.5 * d
    m = lo + h
    for j in range((n + 1) // 2):
        x = h * GL_X[n, j]
        t = m - x
        g = _fresnel_real(t, eta, k) * t**q / math.sqrt(((top - m) + x) * ((m - low) - x))
        if x == 0.0:  # (the middle node of an odd rule, its weight once)
            tot += GL_W[n, j] * g
            continue
        t = m + x
        g += _fresnel_real(t, eta, k) * t**q / math.sqrt(((top - m) - x) * ((m - low) + x))
        tot += 0.5 * GL_W[n, j] * g
    return h * tot


def lobe_f_piece_reference(eta: float, k: float, q: float, lo: float, d: float, top: float, low: float, first: bool) -> float:
    """Plain twin of :func:`_lobe_f_piece`: integral_lo^(lo + d) F(t) t^q / sqrt((T - t)(t - L)) dt by numpy's 200-point
    Gauss-Legendre rule in the same variable (s for ``first``, else t), F the complex-arithmetic
    :func:`pumpup.models.metal.fresnel`."""
    from ..physics.fresnel import fresnel_conductor as fresnel

    x, w = np.polynomial.legendre.leggauss(200)
    if first:
        t = top - d * x * x
        return float(math.sqrt(d) * np.sum(w * fresnel(t, eta, k) * t**q / np.sqrt((top - low) - d * x * x)))
    t = lo + 0.5 * d * (1.0 + x)
    return float(0.5 * d * np.sum(w * fresnel(t, eta, k) * t**q / np.sqrt((top - t) * (t - low))))


@njit(cache=True, nogil=True)
def _lobe_f_gauss(mp, q, mu, a, b, d, beta1, tol, cut):  # pragma: no cover - compiled
    """(H, error) of H = integral_0^beta1 F(t) t^q d beta, t = N.wo = a + b cos(beta) >= mu (frame 5's arc,
    :func:`_k_lobe_fresnel`), d = T - mu, by Gauss-Legendre rules with an a-priori bound (:func:`_lobe_f_bound`) on the
    pieces between frame 5's cuts (``cut``: falling t in (mu, T)), each at the tolerance ``tol`` times its share of
    [mu, T]; the error is the bounds plus (n + 64) eps of rounding per piece.  (0, -1) where a piece would want more
    than GL_MAX points: the caller then takes the adaptive rule."""
    eta, k = mp[6], mp[7]
    top = a + b
    low = a - b
    nc = cut.shape[0]
    # the first piece, in s, reaches down to the first cut; drop cuts that lie too close to T (LOBE_F_MERGE)
    i = 0
    while i < nc:
        nxt = cut[i + 1] if i + 1 < nc else mu
        if top - cut[i] >= LOBE_F_MERGE * (cut[i] - nxt):
            break
        i += 1
    tot = 0.0
    err = 0.0
    scale = tol / d
    lo = cut[i] if i < nc else mu
    d0 = top - lo if i < nc else d
    n, bound, _ = _lobe_f_bound(mp, q, lo, d0, top, low, True, scale * d0)
    if n > GL_MAX:
        return 0.0, -1.0
    p = _lobe_f_piece(eta, k, q, lo, d0, top, low, True, n)
    tot += p
    err += bound + (n + 64) * EPS * abs(p)
    while i < nc:
        hi = cut[i]
        lo = cut[i + 1] if i + 1 < nc else mu
        i += 1
        n, bound, _ = _lobe_f_bound(mp, q, lo, hi - lo, top, low, False, scale * (hi - lo))
        if n > GL_MAX:
            return 0.0, -1.0
        p = _lobe_f_piece(eta, k, q, lo, hi - lo, top, low, False, n)
        tot += p
        err += bound + (n + 64) * EPS * abs(p)
    return tot, err


#: 3^j, j < LOBE_F_CUTS (:func:`_lobe_f_cuts`)
_POW3 = 3.0 ** np.arange(LOBE_F_CUTS)


#: frame 5 takes its arcs by the Gauss-Legendre pieces with an a-priori bound (:func:`_lobe_f_gauss`; issue 14's
#: sixteenth session) where they apply; ``without_lobe_f_gauss`` switches them off (the adaptive 7/15 rule alone, as
#: before them): the tests' and the benchmark's second rule
LOBE_F_GAUSS = True


@contextlib.contextmanager
def without_lobe_f_gauss():
    """Within the block, frame 5 (:func:`_k_lobe_fresnel`) takes every arc by the adaptive 7/15 rule in beta, as before
    issue 14's sixteenth session (``mp[20]``, set by :func:`numeric_params`).  Not meant for concurrent toggling."""
    global LOBE_F_GAUSS
    old = LOBE_F_GAUSS
    LOBE_F_GAUSS = False
    try:
        yield
    finally:
        LOBE_F_GAUSS = old


@njit(cache=True, nogil=True)
def _lobe_f_cuts(mp, mu, out):  # pragma: no cover - compiled
    """Frame 5's cuts of the arcs t = N.wo in (mu, 1] (:func:`_k_lobe_fresnel`) into ``out``, falling, and their number:
    t = x0 + y0 3^j (j falling), x0 - y0 3^j (j rising), j < LOBE_F_CUTS, about F's branch point (``mp[13]``,
    ``mp[14]``), and rho 3^j (j falling) from max(rho, 3 mu), rho the distance of its pole near 0 (``mp[15]``)."""
    x0, y0 = mp[13], mp[14]
    rho = mp[15]
    r0 = rho if 3.0 * mu <= rho else 3.0 * mu
    m = 0
    ia, ib = 0, 0
    while True:
        ta = -1.0
        if ia < 2 * LOBE_F_CUTS:
            ta = x0 + y0 * _POW3[LOBE_F_CUTS - 1 - ia] if ia < LOBE_F_CUTS else x0 - y0 * _POW3[ia - LOBE_F_CUTS]
        tb = r0 * _POW3[LOBE_F_CUTS - 1 - ib] if ib < LOBE_F_CUTS else -1.0
        if ta < 0.0 and tb < 0.0:
            return m
        if ta >= tb:
            t = ta
            ia += 1
        else:
            t = tb
            ib += 1
        if t <= mu:  # (the rest fall below it too)
            return m
        if t <= 1.0 and (m == 0 or t < out[m - 1]):
            out[m] = t
            m += 1


@njit(cache=True, nogil=True)
def _lobe_f_prepare(mp, mu):  # pragma: no cover - compiled
    """Frame 5's per-mu quantities in ``mp``: F(mu) (``mp[21]``), the arc's cuts in (mu, 1] (:func:`_lobe_f_cuts`, at most
    3 LOBE_F_CUTS, falling: ``mp[23:]``) and their number (``mp[22]``); every node's arc takes those below its top."""
    mp[21] = _fresnel_real(mu, mp[6], mp[7])
    mp[22] = _lobe_f_cuts(mp, mu, mp[23:])


@njit(cache=True, nogil=True)
def _k_lobe_fresnel(mp, p, mu, c2, u, um, sa, itol, tol_abs, nodes, wk, wg, mode, ibuf, iwork):  # pragma: no cover - compiled; see lobe_fresnel_integrand_reference
    """(K(u), its error) of frame 5: the integral over the visible arc of N.wo F(max(mu, N.wo)) / max(mu, N.wo)^p,
    p in {0, 1}, for u = cos(alpha) about R (or wi), um = 1 - u, sa = sin(alpha), c2 = cos(2 theta_i); F the conductor
    Fresnel factor of (eta, k) = (``mp[6]``, ``mp[7]``), 000 eq. 28.

    Where N.wo < mu the factor is F(mu) / mu^p, a constant: that part is :func:`_k_closed`'s ``below`` times it.  Where
    N.wo = t = a + b cos(beta) >= mu (|beta| <= beta1 <= pi / 2) the integrand F(t) t^(1 - p) is analytic but near F's
    branch point w = x0 - i y0 (``mp[13]``, ``mp[14]``, :func:`fresnel_branch`) and its pole near 0 (at distance rho,
    ``mp[15]``, :func:`fresnel_pole`): that arc is cut at t = x0 -+ y0 3^j and at t = rho 3^j from max(rho, 3 mu) (each
    piece then lies about its own length from them; computed once per mu, :func:`_lobe_f_prepare`) and its pieces taken
    by Gauss-Legendre rules with an a-priori bound (:func:`_lobe_f_gauss`; issue 14's sixteenth session) at max(``itol``
    times a guess of K's lower bound, ``tol_abs`` / 2).  Where a piece would want more than GL_MAX points (or with
    :func:`without_lobe_f_gauss`) the arc is the globally adaptive 7/15 rule in beta, from the same cuts, the interval
    with the largest error bisected until the summed error (QUADPACK's calibration) is at most max(``itol`` |K|,
    ``tol_abs``) or INNER_MAX intervals are used; the error is returned either way.  Both signs of beta: 2 x."""
    _, beta1, below = _k_closed(1.0, mu, c2, u, um, sa)
    fm = mp[21]  # F(mu) (:func:`_lobe_f_prepare`)
    closed = below * fm / (mu if p == 1.0 else 1.0)
    if beta1 <= 0.0:
        return 2.0 * closed, 0.0
    a = mu * u
    b = math.sqrt((1.0 - mu) * (1.0 + mu)) * sa
    top = a + b  # t at beta = 0; t = mu at beta1
    q = 1.0 - p
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    nall = int(mp[22])  # the cuts in (mu, 1], falling (:func:`_lobe_f_prepare`): those below T
    i0 = 0
    while i0 < nall and mp[23 + i0] >= top:
        i0 += 1
    cut = mp[23 + i0:23 + nall]
    nc = nall - i0
    if mp[20] > 0.0:
        # the Gauss-Legendre pieces with an a-priori bound (issue 14's sixteenth session), at the tolerance's target for
        # H >= beta1 min(F) mu^q, min(F) guessed as half the smaller of F(mu), F(T)
        d = um * (u - c2) / (b + mu * um)  # T - mu = d1 / (b + mu - a), without cancellation
        h_low = 0.5 * beta1 * min(fm, _fresnel_real(top, mp[6], mp[7])) * (mu if q == 1.0 else 1.0)
        tol = max(itol * (closed + h_low), 0.5 * tol_abs)
        h, e = _lobe_f_gauss(mp, q, mu, a, b, d, beta1, tol, cut)
        if e >= 0.0:
            return 2.0 * (closed + h), 2.0 * e
    # else the globally adaptive 7/15 rule in beta from the same cuts
    m = 0
    start = 0.0
    for i in range(nc + 1):
        end = min(_beta_at(cut[i], top, b), beta1) if i < nc else beta1
        if end > start:
            lo[m], hi[m] = start, end
            val[m], err[m] = _lobe_rule(mp, q, a, b, start, end, nodes, wk, wg, mode, ibuf)
            m += 1
            start = end
        if end >= beta1:
            break
    while True:
        tot, e, worst = _tally(val, err, m, 0.0, 0.0)
        if 2.0 * e <= max(2.0 * itol * abs(tot + closed), tol_abs) or m >= lo.shape[0]:
            return 2.0 * (tot + closed), 2.0 * e
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[m], hi[m] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _lobe_rule(mp, q, a, b, lo[worst], mid, nodes, wk, wg, mode, ibuf)
        val[m], err[m] = _lobe_rule(mp, q, a, b, mid, hi[m], nodes, wk, wg, mode, ibuf)
        m += 1


def lobe_fresnel_integrand_reference(brdf, mu: float, u) -> np.ndarray:
    """Frame 5's K(u) (:func:`_k_lobe_fresnel`) for ``brdf``'s hint, independently: scipy's ``quad`` over the azimuth
    beta in [0, pi] of N.wo F(max(mu, N.wo)) / max(mu, N.wo)^p where N.wo = mu u + s sin(alpha) cos(beta) > 0, with F
    the complex-arithmetic :func:`pumpup.models.metal.fresnel`, the arcs' ends as the rule's points; times 2."""
    from scipy.integrate import quad

    from ..physics.fresnel import fresnel_conductor as fresnel

    hint = brdf.polar()
    _, eta, k = hint.fresnel
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    out = []
    for v in np.atleast_1d(np.asarray(u, dtype=float)):
        a, b = mu * v, s * math.sqrt((1.0 - v) * (1.0 + v))

        def g(beta):
            t = a + b * math.cos(beta)
            if t <= 0.0:
                return 0.0
            mx = max(mu, t)
            return t * float(fresnel(mx, eta, k)) / mx**hint.p

        pts = [math.acos(min(1.0, max(-1.0, x))) for x in ((mu - a) / b, -a / b)] if b > 0 else []
        out.append(2.0 * quad(g, 0.0, math.pi, points=pts or None, epsabs=0.0, epsrel=1e-13, limit=400)[0])
    return np.array(out)


def numeric_integrand_reference(brdf, mu: float, u) -> np.ndarray:
    """Plain twin of :func:`_k_numeric`: K(u) from the model's own numpy formula (``BRDF.reference`` at
    wo = 2 (wi.h) h - wi), integral over h's azimuth of 4 (wi.h) N.wo f_r where N.wo > 0 by scipy's QUADPACK (split at
    the arc's end, Walter's switch and the V-cavity's crossings), divided by the hint's scale and radial factor
    (w(t) / u^4 under the Beckmann and GGX weights, u^n under the power weight)."""
    from scipy.integrate import quad

    hint = brdf.polar()
    mp = numeric_params(hint)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    wi = np.array([s, 0.0, mu])
    scale = float(np.asarray(hint.scale(np.array([mu])), dtype=float).ravel()[0])
    out = []
    for v in np.atleast_1d(np.asarray(u, dtype=float)):
        sa = math.sqrt((1.0 - v) * (1.0 + v))

        def g(beta, v=v, sa=sa):
            h = np.array([sa * math.cos(beta), sa * math.sin(beta), v])
            c = float(wi @ h)
            wo = 2.0 * c * h - wi
            return 4.0 * c * wo[2] * float(brdf.reference(wi, wo)) if wo[2] > 0.0 else 0.0

        b, a = s * sa, mu * v
        cuts = [0.5 * mu / v] + ([0.5 * (mu + mp[9]) / v] if mp[9] > 0.0 else [])
        if mp[0] == VCAVITY_F:
            cuts += [2.0 * v * mu, mu / v] + ([2.0 * v * mu / (4.0 * v * v - 1.0)] if 4.0 * v * v > 1.0 else [])
        pts = [math.acos((cv - a) / b) for cv in cuts if b > 0.0 and abs((cv - a) / b) < 1.0] or None
        if hint.radial == "power":
            weight = v**hint.n
        else:
            t = sa * sa / (v * hint.n) ** 2
            weight = (math.exp(-t) if hint.radial == "beckmann" else 1.0 / (1.0 + t) ** 2) / v**4
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            k = 2.0 * quad(g, 0.0, math.pi, points=pts, epsabs=0.0, epsrel=1e-13, limit=400)[0]
        out.append(k / (scale * weight) if weight > 0.0 else math.nan)
    return np.array(out)


def vcavity_integrand_reference(mu: float, u) -> np.ndarray:
    """Plain twin of :func:`_k_vcavity` by scipy's QUADPACK over beta of 4 min(c, 2 u mu, 4 u^2 c - 2 u mu)
    where c > mu / (2 u) (split at the lines' crossings)."""
    import warnings

    from scipy.integrate import quad

    s = math.sqrt((1.0 - mu) * (1.0 + mu))

    def one(uu):
        if uu <= 0:
            return 0.0
        b, a = s * math.sqrt((1.0 - uu) * (1.0 + uu)), mu * uu

        def g(t):
            c = a + b * math.cos(t)
            return 4.0 * min(c, 2 * uu * mu, 4 * uu * uu * c - 2 * uu * mu) if c > 0.5 * mu / uu else 0.0

        pts = [math.acos((cv - a) / b) for cv in (0.5 * mu / uu, 2 * uu * mu, mu / uu, 2 * uu * mu / (4 * uu * uu - 1) if 4 * uu * uu != 1 else -9.0)
               if b > 0 and abs((cv - a) / b) < 1]
        return 2.0 * quad(g, 0.0, math.pi, points=pts or None, epsabs=0, epsrel=1e-13, limit=200)[0]

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return np.array([one(uu) for uu in np.atleast_1d(np.asarray(u, dtype=np.float64))])


def ward_integrand_reference(mu: float, u: np.ndarray) -> np.ndarray:
    """Plain numpy K(u) of :func:`_k_ward`: the arc integrals I_q = integral_0^beta0 (e0 + b cos(beta))^q
    d beta by scipy's QUADPACK (beta0 from arccos), K = 8 sqrt(2 u) (c0 I_1/2 + I_3/2)."""
    import warnings

    from scipy.integrate import quad

    s = math.sqrt((1.0 - mu) * (1.0 + mu))

    def one(uu):
        if uu <= 0:
            return 0.0
        b, c0 = s * math.sqrt((1.0 - uu) * (1.0 + uu)), 0.5 * mu / uu
        e0 = mu * uu - c0
        beta0 = math.pi if e0 - b >= 0 else (0.0 if e0 + b <= 0 else math.acos(-e0 / b))
        if beta0 == 0.0:
            return 0.0
        ih, i3 = (quad(lambda t, q=q: max(e0 + b * math.cos(t), 0.0) ** q, 0.0, beta0, epsabs=0, epsrel=1e-13, limit=200)[0]
                  for q in (0.5, 1.5))
        return 8.0 * math.sqrt(2.0 * uu) * (c0 * ih + i3)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (QUADPACK's roundoff notes at 1e-13 on these smooth arcs)
        return np.array([one(uu) for uu in np.atleast_1d(np.asarray(u, dtype=np.float64))])


def half_moments_reference(x):
    """Plain numpy twins of :func:`_trig_tail`'s four functions, in closed form (exact in exact arithmetic;
    the tests compare them with the series at x >= 1e-2, where these lose at most ~10 digits of 16)."""
    x = np.asarray(x, dtype=np.float64)
    return (x - np.sin(x), np.sin(x) - x * np.cos(x), x * (0.5 + np.cos(x) ** 2) - 1.5 * np.sin(x) * np.cos(x),
            1.5 * x - 2.0 * np.sin(x) + 0.25 * np.sin(2.0 * x))


def half_integrand_reference(p: float, mu: float, u: np.ndarray) -> np.ndarray:
    """Plain numpy K(u) of the half-vector frame (the readable twin of :func:`_k_half`), from the
    antiderivatives in beta of c and c^2 with beta from arccos:
    integral_0^beta (a + b cos t)^k dt = a beta + b sin(beta) (k = 1),
    a^2 beta + 2 a b sin(beta) + b^2 (beta / 2 + sin(2 beta) / 4) (k = 2)."""
    u = np.asarray(u, dtype=np.float64)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    a = mu * u
    b = s * np.sqrt((1.0 - u) * (1.0 + u))

    def ends(cv):  # beta where c = cv (0: none of the arc, pi: all of it)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(a - b >= cv, np.pi, np.where(a + b <= cv, 0.0, np.arccos(np.clip((cv - a) / b, -1, 1))))

    def i1(t):
        return a * t + b * np.sin(t)

    def i2(t):
        return a * a * t + 2 * a * b * np.sin(t) + b * b * (t / 2 + np.sin(2 * t) / 4)

    with np.errstate(divide="ignore", invalid="ignore"):
        c0 = np.where(u > 0, mu / (2 * u), np.inf)
        t0 = ends(c0)
        # 2 integral_0^beta0 4 c (2 c u - mu)
        k0 = 8 * (2 * u * i2(t0) - mu * i1(t0))
        if p == 0:
            return np.where(u > 0, k0, 0.0)
        t1 = ends(2 * c0)
        # N.wo / max(mu, N.wo): 4 c where N.wo >= mu, 4 c N.wo / mu elsewhere
        k1 = 8 * i1(t1) + 8 * ((2 * u * (i2(t0) - i2(t1)) - mu * (i1(t0) - i1(t1))) / mu)
        return np.where(u > 0, k1, 0.0)


def integrand_reference(n: float, p: float, mu: float, u: np.ndarray) -> np.ndarray:
    """Plain numpy u^n K(u), straight from the arccos form (the readable twin of the kernel).

    K(u) = J(a, b) for p = 0 and (J(a, b) - J(a - mu, b)) / mu for p = 1, with
    J(a, b) = integral over beta of (a + b cos beta)_+ = 2 (a acos(-a/b) + b sin(acos(-a/b))),
    a = mu u, b = s sqrt(1 - u^2).  For p in (0, 1): (J(a, b) - J(a - mu, b)) / mu^p for the arc
    where N.wo < mu, plus 2 integral_0^beta1 (a + b cos beta)^(1 - p) d beta by scipy's QUADPACK.
    """
    u = np.asarray(u, dtype=np.float64)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    b = s * np.sqrt((1.0 - u) * (1.0 + u))

    def J(a):
        with np.errstate(divide="ignore", invalid="ignore"):
            al = np.arccos(np.clip(-a / b, -1.0, 1.0))
        out = 2.0 * (a * al + b * np.sin(al))
        return np.where(a >= b, 2.0 * np.pi * a, np.where(a <= -b, 0.0, out))

    a = mu * u
    if p in (0, 1):
        k = J(a) if p == 0 else (J(a) - J(a - mu)) / mu
        return u**n * k
    from scipy.integrate import quad

    with np.errstate(divide="ignore", invalid="ignore"):
        beta1 = np.arccos(np.clip((mu - a) / b, -1.0, 1.0))
    beta1 = np.where(b > mu - a, beta1, 0.0)
    h = np.array([quad(lambda t, ai=ai, bi=bi: (ai + bi * math.cos(t)) ** (1.0 - p), 0.0, b1, epsabs=0, epsrel=1e-12,
                       limit=200)[0] if b1 > 0 else 0.0 for ai, bi, b1 in zip(a.ravel(), b.ravel(), beta1.ravel())])
    # the arc where 0 < N.wo < mu: all of it (J(a)) less its part above mu, J(a) - J(a - mu) - mu 2 beta1
    below = J(a) - J(a - mu) - 2.0 * mu * beta1
    k = below / mu**p + 2.0 * h.reshape(a.shape)
    return u**n * k


def integrand(n: float, p: float, mu: float, u, rtol: float = 1e-13):
    """(u^n K(u), its error) by the compiled kernel at every u in [0, 1] (for tests and checks;
    ``rtol`` is the inner rule's relative tolerance for p in (0, 1))."""
    from .cubature import NODES, WG, WK

    u = np.atleast_1d(np.asarray(u, dtype=np.float64))
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    c2 = (mu - s) * (mu + s)
    ibuf, iwork = np.empty(NODES.shape[0]), np.empty((4, INNER_MAX))
    jac = jacobi_rules(1.0 - p) if 0.0 < p < 1.0 else _NO_JACOBI
    val, err = np.empty(u.shape), np.empty(u.shape)
    for i, v in enumerate(u):
        k, e = _k_of_u(float(p), mu, c2, v, 1.0 - v, math.sqrt((1.0 - v) * (1.0 + v)), rtol, NODES, WK, WG, mode_code(),
                       ibuf, iwork, jac)
        un = v**n if n else 1.0
        val[i], err[i] = un * k, un * e
    return val, err


@njit(cache=True, nogil=True)
def _smoothing(sm, tau):  # pragma: no cover - compiled
    """(x, 1 - x, dx/dtau) of the smoothing substitution on [0, 1]: sm = 0 none, 1 at the left
    end (x = tau^2), 2 at the right end (1 - x = (1 - tau)^2), 3 at both (x = tau^2 (3 - 2 tau))."""
    tc = 1.0 - tau
    if sm == 0:
        return tau, tc, 1.0
    if sm == 1:
        return tau * tau, tc * (1.0 + tau), 2.0 * tau
    if sm == 2:
        return tau * (1.0 + tc), tc * tc, 2.0 * tc
    return tau * tau * (3.0 - 2.0 * tau), tc * tc * (1.0 + 2.0 * tau), 6.0 * tau * tc


@njit(cache=True, nogil=True, inline="always")
def _u_at(kind, sm, n, v0, w, cv1, tau):  # pragma: no cover - compiled
    """(u, 1 - u, sin(alpha), factor) at tau in [0, 1] of a piece: the integrand per d tau is
    K(u) times the factor.

    kind 0: u = v0 + w X in [0, 1/2], factor u^n w dX;
    kind 1: z = -(n + 1) ln u in [v0, v0 + w] (y = u^(n+1)), 1 - y = cv1 + w (1 - X), factor
    e^-z w dX / (n + 1) (u^n du = e^-z dz / (n + 1));
    kind 2 (the half frame's Beckmann weight exp(-tan^2(alpha) / m^2), ``n`` = m): t = tan^2(alpha) / m^2 in
    [v0, v0 + w], u = 1 / sqrt(1 + m^2 t), factor e^-t (m^2 / 2) u^3 w dX (du = -(m^2 / 2) u^3 dt);
    kind 3 (the half frame's GGX weight 1 / (1 + t)^2, ``n`` = alpha): z = ln(1 + t) in [v0, v0 + w],
    t = e^z - 1, factor e^-z (m^2 / 2) u^3 w dX (dt / (1 + t)^2 = e^-z dz);
    X(tau) is the smoothing substitution ``sm`` (:func:`_smoothing`) at the ends where K has a
    square-root behaviour.
    """
    x, xc, dx = _smoothing(sm, tau)
    if kind == 0:
        u = v0 + w * x
        um = 1.0 - u
        un = u**n if n > 0.0 else 1.0
        return u, um, math.sqrt(um * (1.0 + u)), un * w * dx
    if kind == 2:
        t = v0 + w * x if x < 0.5 else cv1 - w * xc  # t = tan^2(alpha) / m^2, from the nearer end
        q = n * n * t  # tan^2(alpha)
        r = math.sqrt(1.0 + q)
        u = 1.0 / r
        return u, q / (r * (r + 1.0)), math.sqrt(q) / r, math.exp(-t) * 0.5 * n * n * u * u * u * w * dx
    if kind == 3:
        z = v0 + w * x if x < 0.5 else cv1 - w * xc  # z = ln(1 + tan^2(alpha) / alpha^2), from the nearer end
        q = n * n * math.expm1(z)  # tan^2(alpha)
        r = math.sqrt(1.0 + q)
        u = 1.0 / r
        return u, q / (r * (r + 1.0)), math.sqrt(q) / r, math.exp(-z) * 0.5 * n * n * u * u * u * w * dx
    z = v0 + w * x if x < 0.5 else cv1 - w * xc  # z = -(n + 1) ln u, from the nearer end
    lu = -z / (n + 1.0)
    um = -math.expm1(lu)
    u = 1.0 - um if um < 0.5 else math.exp(lu)  # exact to an ulp either way (one exp saved)
    return u, um, math.sqrt(um * (1.0 + u)), math.exp(-z) * w * dx / (n + 1.0)


# Gauss-Kronrod 10/21 on [-1, 1] (QUADPACK qk21): Kronrod nodes, their weights, and the weights of
# the embedded 10-point Gauss rule on the odd nodes
_XGK21 = np.array([
    0.995657163025808080735527280689003, 0.973906528517171720077964012084452,
    0.930157491355708226001207180059508, 0.865063366688984510732096688423493,
    0.780817726586416897063717578345042, 0.679409568299024406234327365114874,
    0.562757134668604683339000099272694, 0.433395394129247190799265943165784,
    0.294392862701460198131126603103866, 0.148874338981631210884826001129720, 0.0])
_WGK21 = np.array([
    0.011694638867371874278064396062192, 0.032558162307964727478818972459390,
    0.054755896574351996031381300244580, 0.075039674810919952767043140916190,
    0.093125454583697605535065465083366, 0.109387158802297641899210590325805,
    0.123491976262065851077482296703034, 0.134709217311473325928054001771707,
    0.142775938577060080797094273138717, 0.147739104901338491374841515972068,
    0.149445554002916905664936468389821])
_WG10 = np.array([0.066671344308688137593568809893332, 0.149451349150580593145776339657697,
                  0.219086362515982043995534934228163, 0.269266719309996355091226921569469,
                  0.295524224714752870173892994651338])
#: the 21-point rule on [0, 1]
NODES21 = 0.5 * (1.0 + np.concatenate([-_XGK21[:-1], _XGK21[::-1]]))
WK21 = 0.5 * np.concatenate([_WGK21[:-1], _WGK21[::-1]])
WG21 = np.zeros(21)
WG21[1:10:2] = 0.5 * _WG10
WG21[11::2] = 0.5 * _WG10[::-1]
from ..physics.quadrature import EPS, calibrated, mode_code, rule_sums  # noqa: E402
from .cubature import NODES as _NODES, WG as _WG, WK as _WK  # noqa: E402  (the engine's 7/15 rule)
from ..physics.lookups import g_levels, g_product  # noqa: E402  (g of a pumped chain, as the BRDF divides by it)
from ..physics.lookups import scale_bound as _scale_bound  # noqa: E402  (U of a 1/E-scaled model, as its kernel looks it up)
from ..physics.fresnel import dielectric_scalar as _fresnel  # noqa: E402  (frame 4's factors, as the models' kernels)
from ..physics.fresnel import conductor_scalar as _fresnel_real  # noqa: E402
from ..physics.microfacet import projected as _projected  # noqa: E402
#: the rule of the 1-D path (measured and tested with "gk21": 90-190 evaluations per mu for the
#: Phong family at rtol 1e-10)
RULE = "gk21"


@njit(cache=True, nogil=True)
def _gk(frame, kind, sm, n, p, mu, c2, v0, w, cv1, t0, t1, nodes, wk, wg, mode, buf, itol, inodes, iwk, iwg, ibuf, iwork, jac, mp, iacc):  # pragma: no cover
    """(K, error) of the rule on [t0, t1]; the error is :func:`pumpup.physics.quadrature.calibrated` of
    |K - G| (``mode`` 1) or |K - G| itself (0), plus for p in (0, 1) and frame 4 the inner errors of the
    integrand's values (the inner rule ``inodes``, ``iwk``, ``iwg`` at relative tolerance
    ``itol``; frame 4 also at absolute tolerance ``iacc`` / the node's factor, :func:`_integrate`) summed with
    the Kronrod weights (frame 4: and |K - G| raised by what they can hide of it before its calibration); ``buf`` holds the values (one per node).  The
    closed forms p in {0, 1} have a loop of their own, with no call in it (a loop that may call
    :func:`_arc_power` ran 2.5 x slower for them; a pumped lobe has a loop of its own,
    :func:`_integrate_chain`: one integration loop that could call either rule ran 1.45 x slower for
    them)."""
    h = t1 - t0
    ie = 0.0
    noise = 0.0
    if 0.0 < p < 1.0:
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            k, e = _k_of_u(p, mu, c2, u, um, sa, itol, inodes, iwk, iwg, mode, ibuf, iwork, jac)
            buf[j] = k * fac
            ie += wk[j] * e * fac
    elif frame == 0:
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            buf[j] = _k_closed(p, mu, c2, u, um, sa)[0] * fac
    elif frame == 4:  # the rule on h's arc (:func:`_k_numeric`); D's 1 / u^4 under the Beckmann and GGX weights
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        psi = math.atan2(mu, s)
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            if fac == 0.0:
                buf[j] = 0.0
                continue
            if kind >= 2:
                # (u^4 underflows below u ~ 1e-81, near grazing incidence, mu < 1e-80: GGX alpha = 1e-8 with an ior at mu =
                # 1e-100 divided by 0 (the ninth session).  Where u^3 underflows too, below 1e-108, the weight's value there
                # is below 1e-96 K (GGX's e^-z (m^2 / 2) / u ~ m^4 u / 2, Beckmann's e^-t = 0): left out)
                u3 = u * u * u
                fac = fac / (u3 * u) if u3 * u > 0.0 else (fac / u3 / u if u3 > 0.0 else 0.0)
            # K's error may be itol |K| or iacc / fac: the second's share of the sum is at most itol times the
            # integral's lower bound so far (iacc, :func:`_integrate`).  Where that exceeds K's bound (0 <= K <= kmax:
            # 8 pi / P(mu) for the Smith models, 16 pi u mu for the V-cavity, 8 pi for Schlick's; F <= 1), K = 0 with
            # the error kmax (far in the weight's tail: a narrow GGX lobe's nodes beyond the horizon break)
            kmax = 8.0 * math.pi / mp[8] if mp[0] == SMITH else (16.0 * math.pi * u * mu if mp[0] == VCAVITY_F else 8.0 * math.pi)
            if iacc >= kmax * fac:
                k, e = 0.0, kmax
            else:
                k, e = _k_numeric(mp, mu, s, psi, u, sa, itol, iacc / fac, inodes, iwk, iwg, mode, ibuf, iwork)
            buf[j] = k * fac
            ie += wk[j] * e * fac
            noise += (wk[j] + wg[j]) * e * fac  # what the values' errors can hide of |K - G|
    elif frame == 5:  # the lobe frame with F(Theta_min) (:func:`_k_lobe_fresnel`), as frame 4 takes K's errors
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            if fac == 0.0:
                buf[j] = 0.0
                continue
            if iacc >= 2.0 * math.pi * fac:  # K <= 2 pi (N.wo F / max(mu, N.wo)^p <= 1)
                k, e = 0.0, 2.0 * math.pi
            else:
                k, e = _k_lobe_fresnel(mp, p, mu, c2, u, um, sa, itol, iacc / fac, inodes, iwk, iwg, mode, ibuf, iwork)
            buf[j] = k * fac
            ie += wk[j] * e * fac
            noise += (wk[j] + wg[j]) * e * fac
    else:  # the half-vector frame: the Blinn family and modified Ward, p in {0, 1} (frame 1); Ward (frame 2)
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        psi = math.atan2(mu, s)
        for j in range(nodes.shape[0]):
            u, um, sa, fac = _u_at(kind, sm, n, v0, w, cv1, t0 + h * nodes[j])
            if frame == 1:
                k = _k_half(p, mu, s, psi, u, sa)
            elif frame == 2:
                k = _k_ward(mu, s, psi, u, sa)
            else:  # 3: V-cavity G, F = 1; under the Beckmann and GGX weights D carries 1 / u^4 (001 eq. 9)
                k = _k_vcavity(mu, s, psi, u, sa) / (u * u * u * u if kind >= 2 else 1.0)
            buf[j] = k * fac
    k, diff, asc, ab = rule_sums(buf, wk, wg)
    # (frame 5: at most the raw |K - G| raised by the noise, QUADPACK's "min" mode: where the values' errors dominate
    # |K - G| on a small interval, the calibration's (200 |K - G| / resasc)^1.5 grows as resasc shrinks, and bisecting
    # raised the total: fresnel over stretched Phong n = 0, eta 0.999, k 0.001 at mu = 1e-3 and rtol 1e-6 went from
    # 4.1e-8 to 3.0e-7 in 1000 bisections)
    return k * h, calibrated((diff + noise) * h, asc * h, ab * h, 2 if frame == 5 and mode == 1 else mode) + ie * h


#: the peak variable z = -(n + 1) ln u runs at most to Z_MAX: below u = exp(-Z_MAX / (n + 1)) the
#: integral of u^n K(u) is at most 2 pi e^-Z_MAX / (n + 1) (K <= 2 pi), added to the error
Z_MAX = 40.0


#: the most breakpoints :func:`_pieces` takes (8, frame 4's graded cuts, 3 x 16, and its cuts about F's branch point,
#: 2 x (1 + 2 LOBE_F_CUTS))
MAX_BREAKS = 96

#: the most graded pieces :func:`_pieces` makes (:func:`_graded_cuts` stops there; 4 tail, the graded cuts above the
#: horizon break, 3 peak; frame 4's cuts)
MAX_PIECES = 128
#: the size of :func:`_pieces`'s arrays: MAX_PIECES graded ones and the pieces between every two breaks of the tail and the
#: peak, which come after them (with 128 slots in all, a narrow GGX lobe at grazing incidence, alpha = 1e-8 at mu = 1e-100
#: and rtol 1e-13 on frame 4, wrote past the end: found in the ninth session by NUMBA_BOUNDSCHECK=1)
#: the most cuts :func:`_foreign_roots` adds to the tail's or the peak's breaks
FOREIGN_CUTS = 64
#: a piece is graded where a break's root lies beyond its end closer than this fraction of its length (:func:`_foreign_roots`:
#: farther, the 10-point Gauss rule's error is at least 1e-3 of the piece, and the calibrated estimate is then the whole |K - G|)
FOREIGN_NEAR = 1.0 / 64.0
#: the split of tail (u) and peak (z) of :func:`_pieces`: the first of these without a break within SPLIT_CLEAR (else the one
#: farthest from them), so that no range's end lies next to a break it is not (the V-cavity's alpha = pi / 3 is an ulp above
#: 1/2; the level cos 2 theta_i passes 1/2 at mu = sqrt(3) / 2, where the horizon's s does)
SPLITS = (0.5, 0.45, 0.55, 0.4, 0.6)
SPLIT_CLEAR = 0.02
PIECES_CAP = MAX_PIECES + 2 * (MAX_BREAKS + 4 + FOREIGN_CUTS)


@njit(cache=True, nogil=True)
def _sorted_cuts(cv, cc, m):  # pragma: no cover - compiled
    """Insertion sort (stable) of the first m cut values ``cv`` with their codes ``cc``."""
    for a in range(1, m):
        v, c = cv[a], cc[a]
        b = a - 1
        while b >= 0 and cv[b] > v:
            cv[b + 1] = cv[b]
            cc[b + 1] = cc[b]
            b -= 1
        cv[b + 1] = v
        cc[b + 1] = c


@njit(cache=True, nogil=True)
def _foreign_roots(cv, cc, nc, rv, rc, nr, tail):  # pragma: no cover - compiled
    """Cuts (code 3) grading a piece between the cuts ``cv[:nc]`` towards its end where the square root of a break
    (``rv[:nr]``, codes ``rc``: every break, in the range or beyond it) lies beyond that end, closer than FOREIGN_NEAR of
    the piece's length: at that end -+ d 4^i (d the distance) over the piece's half next to it.  A break's root lies on one
    side of it (in u, ``tail``: code 0 below, 1 above, 2 both; in z = -(n + 1) ln u the other way round) and reaches across
    any cut next to it: near mu = sqrt(3) / 2 the level's (u = cos 2 theta_i) and the horizon's (u = s) nearly coincide,
    and the level's root lay 4.5e-6 beyond the end of the peak's piece [0, z_s], where no rule saw it (stretched Phong n =
    10 at mu = 0.866025, rtol 1e-12: 3.2e-12 off with an estimate of 6.6e-13; 40-digit mpmath, the nested engine and the
    frame of N agree to 1e-15).  Appends to ``cv``, ``cc`` and sorts them; returns their number."""
    m = nc
    for j in range(nr):
        c = rc[j]
        low = (c == 0 or c == 2) if tail else (c == 1 or c == 2)  # its root reaches down (to the pieces below it)
        high = (c == 1 or c == 2) if tail else (c == 0 or c == 2)
        for i in range(nc - 1):
            lo, hi = cv[i], cv[i + 1]
            if low and rv[j] > hi:
                d = rv[j] - hi
                x, sign = hi, -1.0
            elif high and rv[j] < lo:
                d = lo - rv[j]
                x, sign = lo, 1.0
            else:
                continue
            if not d < FOREIGN_NEAR * (hi - lo):
                continue
            while d < 0.5 * (hi - lo) and m < min(cv.shape[0], nc + FOREIGN_CUTS):
                cv[m], cc[m] = x + sign * d, 3
                m += 1
                d *= 4.0
    if m > nc:
        _sorted_cuts(cv, cc, m)
    return m


@njit(cache=True, nogil=True, inline="always")
def _graded_cuts(kind, lo, hi, left, k, margin, kinds, sms, v0, w, v1):  # pragma: no cover - compiled
    """Pieces of ``kind`` from lo cut at lo (1 + 4^i) while they fit below hi (and the arrays keep ``margin``
    slots), written from slot k; the first keeps the left smoothing ``left``.  Returns (where the rest of
    [lo, hi] starts, the next slot, the rest's left smoothing)."""
    a = lo
    step = lo  # the first cut at 2 lo
    while a + step < hi - step and k < MAX_PIECES - margin:
        kinds[k] = kind
        sms[k] = (1 if left else 0) if a == lo else 0
        v0[k] = a
        w[k] = step
        v1[k] = a + step
        k += 1
        a = a + step
        step = 3.0 * a - 3.0 * lo  # cuts at lo (1 + 4^i)
    return a, k, left and a == lo


@njit(cache=True, nogil=True)
def _vcavity_breaks(mu, s, psi):  # pragma: no cover - compiled
    """The angles alpha of h from N where :func:`_k_vcavity`'s pieces change (0 for none): where a crossing of
    its lines reaches the top of h's circle (c = 2 u mu at alpha = pi/2 - theta_i = psi; c = mu / u at
    alpha = theta_i) or the top or bottom (c = 2 u mu / (4 u^2 - 1): cos(theta_i -+ alpha) sin(3 alpha) =
    sin(2 alpha) mu, by bisection on (0, pi/3), where it changes sign), and where the crossings meet
    (alpha = pi/4) or one meets the arc's end mu / (2 u) (alpha = pi/3)."""
    th = 0.5 * math.pi - psi
    out = np.zeros(6)
    out[0], out[1], out[2], out[3] = psi, th, 0.25 * math.pi, math.pi / 3.0
    for k in range(2):
        sg = 1.0 if k == 0 else -1.0
        lo, hi = 1e-9, math.pi / 3.0 - 1e-9
        flo = (mu * math.cos(lo) + sg * s * math.sin(lo)) * math.sin(3.0 * lo) - math.sin(2.0 * lo) * mu
        fhi = (mu * math.cos(hi) + sg * s * math.sin(hi)) * math.sin(3.0 * hi) - math.sin(2.0 * hi) * mu
        if flo * fhi >= 0.0:
            continue
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = (mu * math.cos(mid) + sg * s * math.sin(mid)) * math.sin(3.0 * mid) - math.sin(2.0 * mid) * mu
            if (fm < 0.0) == (flo < 0.0):
                lo, flo = mid, fm
            else:
                hi = mid
        out[4 + k] = 0.5 * (lo + hi)
    return out


@njit(cache=True, nogil=True, inline="always")
def _zr(radial, tb, n):  # pragma: no cover - compiled
    """The peak variable at tan(alpha) = tb under the half frame's Beckmann weight (radial 1: t = tan^2(alpha) / m^2)
    or GGX weight (radial 2: ln(1 + t))."""
    t = (tb / n) ** 2
    return t if radial == 1 else math.log1p(t)


@njit(cache=True, nogil=True, inline="always")
def _branch_cuts(ub, zb, kb, m, th_i, x0, y0, st0, radial, n, n1):  # pragma: no cover - compiled
    """:func:`_pieces`' cuts about F's branch point x0 - i y0 (st0 = sqrt(1 - x0^2)): where the arc's (frame 5) or h's
    circle's (frame 4) highest or lowest cosine, cos(theta_i -+ alpha), passes x0 (alpha = |theta_i - theta_0| or theta_i +
    theta_0), and at -+ (y0 / sin(theta_0) / 2) 4^j from there, j < LOBE_F_CUTS, not smoothed (code 3); u = cos(alpha),
    z by the radial weight (``radial`` 0: -(n + 1) ln u).  Returns the new number of breaks (at most MAX_BREAKS)."""
    th_0 = math.atan2(st0, x0)
    for ax in (abs(th_i - th_0), th_i + th_0):
        if not 0.0 < ax < 0.5 * math.pi:
            continue
        for side in range(3):
            off = 0.5 * y0 / st0
            for _ in range(LOBE_F_CUTS if side else 1):
                ab = ax if side == 0 else (ax - off if side == 1 else ax + off)
                if not 0.0 < ab < 0.5 * math.pi or m >= MAX_BREAKS:
                    break
                ub[m], kb[m] = math.cos(ab), 3
                zb[m] = _zr(radial, math.tan(ab), n) if radial else -n1 * math.log1p(-2.0 * math.sin(0.5 * ab) ** 2)
                m += 1
                off *= 4.0
    return m


@njit(cache=True, nogil=True)
def _pieces(frame, radial, n, p, mu, s, kinds, sms, v0, w, v1, mp):  # pragma: no cover - compiled
    """The pieces between the breakpoints, written into ``kinds``, ``sms`` (the smoothing), ``v0``,
    ``w``, ``v1`` (arrays of :data:`PIECES_CAP`); returns (their number, c2 = cos 2 theta_i, a bound of
    the part left out).

    Breakpoints: u = 0, 1/2, 1 and, in the lobe frame (``frame`` 0), u = s (the horizon starts to cut
    the arc) and cos 2 theta_i (the level mu leaves it, p > 0); in the half-vector frame (1,
    :func:`_k_half`; 2, :func:`_k_ward`; 3, :func:`_k_vcavity`), u = cos(pi/4 - theta_i/2) (the horizon starts
    to cut h's circle), cos(theta_i) (the level mu leaves it, p > 0), u_lo = cos(pi/4 + theta_i/2), below which
    no h sends wo above the horizon (the range starts there), and for frame 3 :func:`_vcavity_breaks`.  kind 0: u in [v0, v1 = v0 + w] (u <= 1/2); kind 1:
    z = -(n + 1) ln u in [v0, v1].  Where exp(-Z_MAX / (n + 1)) > 1/2 the range of u below it is left
    out (its bound is returned).  With ``radial`` 1 (the half frame's Beckmann weight, ``n`` = m) the
    whole range is kind 2, t = tan^2(alpha) / m^2 in [0, Z_MAX] (:func:`_u_at`), cut at the same breaks; with
    ``radial`` 2 (the GGX weight, ``n`` = alpha) kind 3, z = ln(1 + t) up to u_lo (the weight e^-z dz leaves no
    tail to cut).  Frame 4 (:func:`_k_numeric`, parameters ``mp``) has the V-cavity's breaks for its V-cavity model,
    and for Walter's G1 the angles |arccos(z_w) -+ theta_i| / 2 where its switch level N.wo = z_w leaves h's
    circle (at its top and bottom, N.wo = cos(2 alpha -+ theta_i)).
    """
    c2 = (mu - s) * (mu + s)
    n1 = n + 1.0
    uz = math.exp(-Z_MAX / n1)
    skip = uz > 0.5
    z_split = Z_MAX if skip else n1 * math.log(2.0)
    # breakpoints in u, and their z = -(n + 1) ln u (or t) to full precision; codes 0: horizon (sqrt
    # below), 1: level mu (sqrt above), 2: a kink smoothed on both sides, 3: a cut (frame 4's grading), not smoothed
    ub = np.empty(MAX_BREAKS)
    zb = np.empty(MAX_BREAKS)
    kb = np.empty(MAX_BREAKS, np.int64)
    m = 0
    u_min, z_end, k_end = 0.0, z_split, -1  # the range: u >= u_min, z <= z_end (code of that end)
    peak = 1  # the kind of the peak's pieces
    if radial == 1:  # t = tan^2(alpha) / m^2 everywhere (half frame only)
        skip, z_end, peak = True, Z_MAX, 2
    elif radial == 2:  # ln(1 + t) everywhere, up to u_lo (half frame only)
        skip, z_end, peak = True, math.inf, 3
    if frame == 0 or frame == 5:
        if 0.0 < s < 1.0:
            ub[m], zb[m], kb[m] = s, -0.5 * n1 * math.log1p(-mu * mu), 0
            m += 1
        if (p > 0.0 or frame == 5) and 0.0 < c2 < 1.0:  # (frame 5: F(max(mu, N.wo)) has the level for any p)
            ub[m], zb[m], kb[m] = c2, -n1 * math.log1p(-2.0 * s * s), 1
            m += 1
        for pt in range(2 if frame == 5 else 0):
            x0, y0 = (mp[13], mp[14]) if pt == 0 else (0.0, mp[15])  # F's branch point; its pole near 0
            st0 = math.sqrt((1.0 - x0) * (1.0 + x0)) if x0 < 1.0 else 0.0
            if not (x0 < 1.0 and x0 + 2.0 * y0 > mu and y0 < LOBE_F_WIDE * st0):
                continue
            # K(u) turns where the arc's highest or lowest N.wo, cos(theta_i -+ alpha), passes F's branch point's x0
            # (alpha = |theta_i - theta_0| or theta_i + theta_0), on the scale y0 / sin(theta_0) in alpha: cuts there and
            # at -+ (that scale / 2) 4^j, not smoothed (code 3), as frame 4's (a first rule on a wide piece may not see it;
            # one on the scale LOBE_F_WIDE or wider does)
            m = _branch_cuts(ub, zb, kb, m, math.atan2(s, mu), x0, y0, st0, 0, n, n1)
    else:
        psi = math.atan2(mu, s)  # pi / 2 - theta_i, exact near grazing incidence
        hf = 0.25 * psi  # u_f = cos(pi/4 - theta_i/2) = cos(2 hf) = 1 - 2 sin^2(hf)
        tf = math.tan(2.0 * hf)  # tan(alpha_f); alpha_lo = pi/2 - alpha_f
        ub[m], kb[m] = math.cos(2.0 * hf), 0
        zb[m] = _zr(radial, tf, n) if radial else -n1 * math.log1p(-2.0 * math.sin(hf) ** 2)
        m += 1
        if p > 0.0 and 0.0 < mu < 1.0:
            ub[m], kb[m] = mu, 1
            zb[m] = _zr(radial, s / mu, n) if radial else -n1 * math.log(mu)  # tan(theta_i) = s / mu
            m += 1
        u_min = math.sin(0.5 * psi)  # cos(pi/4 + theta_i/2)
        if u_min > 0.0:
            if radial == 1:
                z_lo = 1.0 / (tf * n) ** 2
            elif radial == 2:
                z_lo = math.log1p((tf * n) ** 2) - 2.0 * math.log(tf * n)  # ln(1 + 1 / (tf n)^2), no overflow
            else:
                z_lo = -n1 * math.log(u_min)
            if z_lo < z_end:
                z_end, k_end = z_lo, 1
        if frame == 3 or (frame == 4 and mp[0] == VCAVITY_F):  # the V-cavity G's kinks (:func:`_vcavity_breaks`),
            for ab in _vcavity_breaks(mu, s, psi):  # smoothed on both sides (code 2)
                if ab > 0.0:
                    ub[m], kb[m] = math.cos(ab), 2
                    zb[m] = _zr(radial, math.tan(ab), n) if radial else -n1 * math.log1p(-2.0 * math.sin(0.5 * ab) ** 2)
                    m += 1
        if frame == 4 and mp[9] > 0.0:  # Walter's G1 switch N.wo = z_w leaves h's circle: a jump of G, a kink of K
            th = 0.5 * math.pi - psi
            aw = math.atan2(math.sqrt((1.0 - mp[9]) * (1.0 + mp[9])), mp[9])
            for ab in (0.5 * (aw + th), 0.5 * abs(aw - th)):
                if 0.0 < ab < 0.5 * math.pi:
                    ub[m], kb[m] = math.cos(ab), 2
                    zb[m] = _zr(radial, math.tan(ab), n) if radial else -n1 * math.log1p(-2.0 * math.sin(0.5 * ab) ** 2)
                    m += 1
        if frame == 4 and mp[0] == SMITH:
            # a conductor's F(c) whose branch point w = x0 - i y0 lies near the real axis inside (0, 1) (eta < 1, small k:
            # a near-kink at c = x0): h's circle at alpha has c = wi.h in [cos(alpha + theta_i), cos(alpha - theta_i)], so
            # K(u) turns where an end of that range passes x0, at alpha = |theta_i -+ theta_0|, on the scale y0 / sin(theta_0)
            # in alpha; near normal incidence c hardly varies on the circle and the whole near-kink is K's.  Cuts there
            # and at -+ (that scale / 2) 4^j, not smoothed (code 3), as frame 5's in the lobe frame.  Without them GGX
            # alpha = 0.003 with eta 0.271, k 0.0605 at mu = 1 was 2.4e-11 off with an estimate of 3.5e-12 (rtol 1e-10;
            # issue 14's twentieth session, scripts/studies/fuzz_engines.py)
            x0, y0 = mp[13], mp[14]
            st0 = math.sqrt((1.0 - x0) * (1.0 + x0)) if 0.0 < x0 < 1.0 else 0.0
            if st0 > 0.0 and y0 < x0 and y0 < LOBE_F_WIDE * st0:
                m = _branch_cuts(ub, zb, kb, m, 0.5 * math.pi - psi, x0, y0, st0, radial, n, n1)
        # (the weight's mass beyond alpha_f / 2, 1 / (1 + t) for GGX's and e^-t for Beckmann's, times K's bound over
        # P(mu) ~ mu, below 1e-3 rtol: the cuts cannot matter, a narrow lobe far from grazing incidence)
        tail = 0.0
        if frame == 4 and mp[11] < 1.0 and radial > 0:
            t_half = (math.tan(0.25 * psi) / n) ** 2
            tail = (1.0 / (1.0 + t_half) if radial == 2 else math.exp(-t_half)) / mu
        if tail > 1e-3 * mp[12]:
            # K(u) turns on the scale alpha (P's, :func:`_k_numeric`; Schlick's r / (1 - r)) where the lowest N.wo on h's circle,
            # sin(psi - 2 alpha_h) / (2 u) ~ alpha_f - alpha_h, nears 0 (the horizon break alpha_f = psi / 2, from both
            # sides) and where the arc's highest N.wo does (alpha_lo = pi / 2 - psi / 2): a first rule on a piece
            # hundreds of times wider did not see it (GGX alpha = 0.001, mu = 0.59: 1.6e-10 off at rtol 1e-12, the
            # estimate 6e-13), so these get cuts at alpha_f -+ (alpha / 2) 4^k and alpha_lo - (alpha / 2) 4^k,
            # without smoothing (code 3), up to the middle of [alpha_f, alpha_lo]
            a_f, a_lo = 0.5 * psi, 0.5 * math.pi - 0.5 * psi
            a_mid = 0.5 * (a_f + a_lo)
            for side in range(3):
                off = 0.5 * mp[11]
                for _ in range(16):
                    ab = a_f - off if side == 0 else (a_f + off if side == 1 else a_lo - off)
                    if (side == 0 and ab <= 0.0) or (side == 1 and ab >= a_mid) or (side == 2 and ab <= a_mid) or m >= MAX_BREAKS:
                        break
                    ub[m], kb[m] = math.cos(ab), 3
                    zb[m] = _zr(radial, math.tan(ab), n)
                    m += 1
                    off *= 4.0
    u_sp = 0.5
    if not skip:  # the split of tail and peak away from the breaks (SPLITS)
        far = -1.0
        for cand in SPLITS:
            gap = 1.0
            for j in range(m):
                if kb[j] != 3:
                    gap = min(gap, abs(ub[j] - cand))
            if gap > far:
                far, u_sp = gap, cand
            if gap >= SPLIT_CLEAR:
                break
        if u_sp != 0.5:
            if u_min < u_sp:  # the peak ends at the split
                z_end, k_end = -n1 * math.log(u_sp), -1
            elif k_end == -1:  # (u_min in [u_sp, 1/2): the range ends at u_min, before the split)
                z_end, k_end = -n1 * math.log(u_min), 1
    cv = np.empty(MAX_BREAKS + 4 + FOREIGN_CUTS)
    cc = np.empty(MAX_BREAKS + 4 + FOREIGN_CUTS, np.int64)
    k = 0
    # tail pieces (increasing u)
    if not skip and u_min < u_sp:
        nc = 0
        cv[nc], cc[nc] = u_min, (1 if u_min > 0.0 else -1)
        nc += 1
        for j in range(m):
            if u_min < ub[j] < u_sp:
                cv[nc], cc[nc] = ub[j], kb[j]
                nc += 1
        cv[nc], cc[nc] = u_sp, -1
        nc += 1
        _sorted_cuts(cv, cc, nc)
        nc = _foreign_roots(cv, cc, nc, ub, kb, m, True)
        for j in range(nc - 1):
            lo, hi = cv[j], cv[j + 1]
            if hi > lo:
                left = cc[j] == 1 or cc[j] == 2  # (code 1 only where p > 0, or the half frame's u_lo)
                right = cc[j + 1] == 0 or cc[j + 1] == 2
                a = lo
                if frame != 0 and frame != 5 and lo > 0.0:
                    # the half frame near grazing incidence: above u_lo ~ mu / 2 and the level u = mu the
                    # arc's end c0 = mu / (2 u) changes on the scale of u itself, so the piece is cut at
                    # lo (1 + 4^i) (as above z_s below): one first interval on [mu / 2, 1/2] hid it
                    a, k, left = _graded_cuts(0, lo, hi, left, k, 8, kinds, sms, v0, w, v1)
                kinds[k] = 0
                sms[k] = (1 if left else 0) + (2 if right else 0)
                v0[k] = a
                w[k] = hi - a
                v1[k] = hi
                k += 1
    # peak pieces (increasing z = decreasing u)
    nc = 0
    cv[nc], cc[nc] = 0.0, -2  # z = 0: u = 1, a square-root end for p = 1
    nc += 1
    for j in range(m):
        if zb[j] < z_end:
            cv[nc], cc[nc] = zb[j], kb[j]
            nc += 1
    top = p > 0.0 or frame == 5  # u = 1 (z = 0) is a square-root end: the level mu passes through R (through h = N)
    cv[nc], cc[nc] = z_end, k_end
    nc += 1
    _sorted_cuts(cv, cc, nc)
    nc = _foreign_roots(cv, cc, nc, zb, kb, m, False)
    for j in range(nc - 1):
        lo, hi = cv[j], cv[j + 1]
        if hi > lo:
            # in z the horizon's square root lies above z_s, the level's below z_c
            left = cc[j] == 0 or cc[j] == 2 or (top and cc[j] == -2)
            right = cc[j + 1] == 1 or cc[j + 1] == 2
            # above the horizon break z_s the arc shrinks from the full circle to half of it on
            # the scale of z_s itself (sin(alpha) ~ mu): near grazing z_s is tiny, and the piece
            # is cut at z_s (1 + 4^i) so that no first interval hides that feature
            a = lo
            if cc[j] == 0 or cc[j] == 2:
                a, k, left = _graded_cuts(peak, lo, hi, left, k, 4, kinds, sms, v0, w, v1)
            kinds[k] = peak
            sms[k] = (1 if left else 0) + (2 if right else 0)
            v0[k] = a
            w[k] = hi - a
            v1[k] = hi
            k += 1
    # beyond Z_MAX: K <= 2 pi in the lobe frame, <= 8 pi in the half-vector frame (4 (wi.h) N.wo / max^p <= 4);
    # with the Beckmann weight, integral_Z^inf e^-t 8 pi (m^2 / 2) u^3 dt, u^3 <= (1 + m^2 Z)^(-3/2) there
    # the V-cavity's K <= 16 pi u mu (c G <= 2 u mu): under the Beckmann weight e^-t (m^2 / 2) u^3 K / u^4 <= 8 pi m^2 mu
    # e^-t; under u^n, integral_0^uz u^(n+1) 16 pi mu du
    if radial == 2:
        left_out = 0.0  # the range ends at u_lo
    elif radial == 1 and frame == 4 and mp[0] == SMITH:
        # K <= 8 pi / P(mu) (4 c F Gamma <= 4 G / mu <= 4 / P(mu)), and (m^2 / 2) u^3 K / u^4 with
        # 1 / u = sqrt(1 + m^2 t) <= A + B (t - Z), A = sqrt(1 + m^2 Z), B = m^2 / (2 A) (concave)
        big_a = math.sqrt(1.0 + n * n * Z_MAX)
        left_out = 4.0 * math.pi * n * n * math.exp(-Z_MAX) * (big_a + 0.5 * n * n / big_a) / mp[8] if k_end == -1 else 0.0
    elif frame == 5:  # K <= 2 pi, as in the lobe frame
        left_out = 2.0 * math.pi * math.exp(-Z_MAX) / n1 if skip and k_end == -1 else 0.0
    elif radial == 1 and frame >= 3:
        left_out = 8.0 * math.pi * n * n * mu * math.exp(-Z_MAX) if k_end == -1 else 0.0
    elif frame >= 3:  # (frame 4 here: the V-cavity with F <= 1)
        left_out = 16.0 * math.pi * mu * math.exp(-Z_MAX * (n + 2.0) / n1) / (n + 2.0) if skip and k_end == -1 else 0.0
    elif radial == 1:
        left_out = 4.0 * math.pi * n * n * math.exp(-Z_MAX) / (1.0 + n * n * Z_MAX) ** 1.5 if k_end == -1 else 0.0
    else:
        left_out = (2.0 if frame == 0 else 8.0) * math.pi * math.exp(-Z_MAX) / n1 if skip and k_end == -1 else 0.0
    return k, c2, left_out


@njit(cache=True, nogil=True, inline="always")
def _buffers(max_intervals, nodes, inodes, rtol):  # pragma: no cover - compiled
    """The work arrays of the adaptive loop (intervals: piece, ends, value, error; rule values; the
    inner rule's) and the inner rule's relative tolerance, a small part of the total (rtol / 8)."""
    cap = max_intervals + 64
    return (cap, np.empty(cap, np.int64), np.empty(cap), np.empty(cap), np.empty(cap), np.empty(cap),
            np.empty(nodes.shape[0]), np.empty(inodes.shape[0]), np.empty((4, INNER_MAX)),
            max(0.125 * rtol, INNER_RTOL_MIN))


@njit(cache=True, nogil=True, inline="always")
def _status(kv, ke, m, left_out, rounding, rtol, atol):  # pragma: no cover - compiled
    """(value, error, rounding error, the interval with the largest error, done) of the first m
    intervals: done when the error meets the tolerance or is below the rounding error of the
    integrand (refining cannot help there)."""
    tot = 0.0
    e = left_out
    ab = 0.0
    worst = 0
    for j in range(m):
        tot += kv[j]
        e += ke[j]
        ab += abs(kv[j])
        if ke[j] > ke[worst]:
            worst = j
    r = rounding * ab
    return tot, e, r, worst, e <= max(rtol * abs(tot), atol) or e <= r


@njit(cache=True, nogil=True, inline="always")
def _bisect(pk, t0, t1, worst, m):  # pragma: no cover - compiled
    """Bisect interval ``worst``: it keeps the lower half, interval m (new) takes the upper; returns
    (piece, lower end, midpoint, upper end)."""
    i = pk[worst]
    a_, b_ = t0[worst], t1[worst]
    mid = 0.5 * (a_ + b_)
    t1[worst] = mid
    pk[m], t0[m], t1[m] = i, mid, b_
    return i, a_, mid, b_


@njit(cache=True, nogil=True)
def _integrate(frame, radial, n, p, mu_arr, rtol, atol_arr, max_intervals, rounding, nodes, wk, wg, mode, n_init, inodes, iwk, iwg, jac, mp, val, err, conv, evals):  # pragma: no cover
    """Adaptive Gauss-Kronrod (the rule ``nodes``, ``wk``, ``wg``) of integral u^n K(u) du for
    every mu (without the scale); ``frame`` 0 the lobe frame (:func:`_k_closed`, :func:`_k_of_u`), 1-3 the
    half vector's (:func:`_k_half`, :func:`_k_ward`, :func:`_k_vcavity`; 4 :func:`_k_numeric` with the parameters
    ``mp``, its P(mu) set here per mu), ``radial`` 1 the Beckmann weight, 2 the GGX weight, in place of u^n
    (:func:`_pieces`)."""
    # (room for every piece's first intervals besides max_intervals bisections: up to PIECES_CAP pieces)
    cap, pk, t0, t1, kv, ke, buf, ibuf, iwork, itol = _buffers(max_intervals + PIECES_CAP * n_init, nodes, inodes, rtol)
    kinds = np.empty(PIECES_CAP, np.int64)
    sms = np.empty(PIECES_CAP, np.int64)
    v0 = np.empty(PIECES_CAP)
    w = np.empty(PIECES_CAP)
    cv1 = np.empty(PIECES_CAP)
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        if frame == 4 and mp[0] == SMITH:  # P(mu) = mu / G1(mu)
            mp[8] = _projected(s, 0.0, mu, int(mp[1]), int(mp[2]), mp[4])
        elif frame == 5:  # F(mu) and the arcs' cuts
            _lobe_f_prepare(mp, mu)
        npieces, c2, left_out = _pieces(frame, radial, n, p, mu, s, kinds, sms, v0, w, cv1, mp)
        # frame 4's inner rule may leave an absolute error iacc / (the node's factor) in K, iacc = itol times a lower
        # bound of the integral so far over the pieces' total length in tau: its share of the sum is then at most
        # itol times that bound (the integrand is >= 0; the errors are added to the estimate either way)
        live = 0
        for i in range(npieces):
            live += n_init if w[i] > 0.0 else 0
        acc = 0.0
        m = 0
        for i in range(npieces):
            if w[i] <= 0.0:
                continue
            for j in range(n_init):
                iacc = itol * acc / live
                pk[m] = i
                t0[m] = j / n_init
                t1[m] = (j + 1.0) / n_init
                kv[m], ke[m] = _gk(frame, kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], t0[m], t1[m], nodes, wk, wg, mode, buf, itol, inodes, iwk, iwg, ibuf, iwork, jac, mp, iacc)
                acc += max(kv[m] - ke[m], 0.0)
                m += 1
        start = m
        while True:
            tot, e, r, worst, ok = _status(kv, ke, m, left_out, rounding, rtol, atol_arr[q])
            if ok or m - start >= max_intervals or m >= cap:
                break
            i, a_, mid, b_ = _bisect(pk, t0, t1, worst, m)
            iacc = itol * max(tot - e, 0.0) / live
            kv[worst], ke[worst] = _gk(frame, kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], a_, mid, nodes, wk, wg, mode, buf, itol, inodes, iwk, iwg, ibuf, iwork, jac, mp, iacc)
            kv[m], ke[m] = _gk(frame, kinds[i], sms[i], n, p, mu, c2, v0[i], w[i], cv1[i], mid, b_, nodes, wk, wg, mode, buf, itol, inodes, iwk, iwg, ibuf, iwork, jac, mp, iacc)
            m += 1
        val[q] = tot
        err[q] = e + r
        conv[q] = ok
        evals[q] = nodes.shape[0] * (m + (m - start))  # every split evaluates two halves


# --- frame 6: the frame of N with the GGX weight's azimuth in closed form (GGX with F = 1, Schlick's model) ---------


@njit(cache=True, nogil=True, inline="always")
def _ggx_ring(a2, xmu, xs, d):  # pragma: no cover - compiled; see ring_reference
    """integral over phi in [0, 2 pi) of the GGX weight D = a2 / (pi (1 - (1 - a2) (N.h)^2)^2) (Walter et al. 2007
    eq. 33; 000 eq. 36 with a2 = r) on the circle of wo at elevation x = x_mu + d (N.wo = sin x) for wi at elevation x_mu
    (x_s = pi / 2 - x_mu).

    With X = |wi + wo|^2 = P0 + Q cos(phi) and (N.h)^2 = m^2 / X, m = N.wi + N.wo, D = (a2 / pi) X^2 / (X - k)^2, k = (1 - a2)
    m^2, and the integral of (1 + k / Y)^2 over phi, Y = X - k = a' + Q cos(phi), is 2 pi (1 + 2 k / R + k^2 a' / R^3),
    R^2 = (a' - Q)(a' + Q).  Both factors are sums of squares: a' - Q = m^2 (a2 + tan^2(d / 2)), a' + Q = 4 cos^2(d / 2)
    (a2 S^2 + C^2), S, C = sin, cos((x + x_mu) / 2), m = 2 S cos(d / 2); so, with A = a2 + tan^2(d / 2) and B = a2 S^2 +
    C^2, the integral is 2 a2 (1 + 2 (1 - a2) S / sqrt(A B) + (1 - a2)^2 S (S^2 A + B) / (2 (A B)^(3/2))): every term
    >= 0 for a2 <= 1 (no cancellation), no division by m (which vanishes at grazing incidence), and d, the offset from
    the peak, exact where the peak is narrow (a rule in x itself lost ulp(x) / alpha there: GGX alpha = 1e-5 at mu =
    0.9986 was 3e-13 off with an estimate of 9e-14), and cosines near pi / 2 as sines of x_s - ... (cos(x) of a rounded x
    near pi / 2 lost ulp(pi / 2) / alpha: alpha = 1e-8 at mu = 1 did not converge)."""
    tau = math.tan(0.5 * d)
    sy, cy = math.sin(xmu + 0.5 * d), math.sin(xs - 0.5 * d)  # (cos(y) as sin(pi / 2 - y): exact near the normal)
    a = a2 + tau * tau  # (a' - Q) / m^2
    b = a2 * sy * sy + cy * cy  # (a' + Q) / (4 cos^2(d / 2))
    r = math.sqrt(a * b)
    k = 1.0 - a2
    return 2.0 * a2 * (1.0 + 2.0 * k * sy / r + k * k * sy * (sy * sy * a + b) / (2.0 * r * r * r))


#: frame 6 with a Fresnel factor (GGX, :func:`_ggx_ring_f`): the ring's product rule doubles its F samples from
#: RING_F_N0 + 1 to at most RING_F_NMAX + 1 on [0, pi]
RING_F_N0 = 16
RING_F_NMAX = 128
#: ... and takes |W_N - W_N/2| times the larger ratio of the last three such steps as W_N's error where both ratios are at most
#: this (geometric decay of F's coefficients; with the last ratio alone, from N = 16 on, it was 1100 x below the true error
#: of a strong absorber, eta 1.1, k 6, at itol 1e-6: measured by scripts/calibration/ring_fresnel_calibration.py)
RING_F_RATIO = 0.5
#: :func:`_ring_f_sums` sums term by term where nn |1 - z| is below this (at most the sample n = 0, where 1 - rho < 2 / nn:
#: n >= 1 has |1 - z| >= rho sin(pi / nn)); until issue 14's twenty-third session, where |1 - z| < 0.25, up to ~nn / 12
#: samples of nn + 1 terms each, a quarter of GGX alpha 0.02 with ior 1.5's table time
RING_F_DIRECT = 2.0
#: sin^2(psi / 2) at psi = j pi / RING_F_NMAX (the finest level's samples; a coarser level takes every stride-th)
_RING_F_SIN2 = np.sin(0.5 * np.pi * np.arange(RING_F_NMAX + 1) / RING_F_NMAX) ** 2
#: cos(psi), sin(psi) there
_RING_F_COS = np.cos(np.pi * np.arange(RING_F_NMAX + 1) / RING_F_NMAX)
_RING_F_SIN = np.sin(np.pi * np.arange(RING_F_NMAX + 1) / RING_F_NMAX)


@njit(cache=True, nogil=True, inline="always")
def _ring_f_sums(rho, rn, n, nn, j):  # pragma: no cover - compiled; see ring_f_sums_reference
    """(C0, C1) = the sums over k = 0 .. nn, the first and last halved, of rho^k cos(k theta) and k rho^k cos(k theta) at
    theta = n pi / nn = j pi / RING_F_NMAX (``rn`` = rho^nn): geometric sums in z = rho e^(i theta), z^nn = (-1)^n rho^nn
    real, 1 - z = w = (1 - rho) + 2 rho sin^2(theta / 2) - i rho sin(theta) without cancellation.  sum k z^k = z N / w^2
    with N = 1 - (nn + 1) z^nn + nn z^(nn + 1) = (1 - z^nn) - nn z^nn w: of size nn^2 |w|^2 where nn |w| is small, from
    terms of size nn |w| (the first form's terms are of size nn: it lost 2e-11 at nn = 128, n = 1).  Its error is then
    about eps (1 + nn |w|) / |w|^2, within a few eps of the sum's scale nn^2 where nn |w| >= 1; below RING_F_DIRECT, term
    by term."""
    zn = -rn if n % 2 else rn  # z^nn
    zr, zi = rho * _RING_F_COS[j], rho * _RING_F_SIN[j]
    p, r = (1.0 - rho) + 2.0 * rho * _RING_F_SIN2[j], zi  # 1 - z = p - i r
    dd = p * p + r * r
    if nn * nn * dd < RING_F_DIRECT * RING_F_DIRECT:  # (term by term)
        c0 = c1 = 0.0
        zk = complex(1.0, 0.0)
        z = complex(zr, zi)
        for k in range(nn + 1):
            h = 0.5 if k == 0 or k == nn else 1.0
            c0 += h * zk.real
            c1 += h * k * zk.real
            zk *= z
        return c0, c1
    # in real arithmetic, 1 / (1 - z) = (p + i r) / dd: sum z^k = (1 - zn z) / (1 - z), sum k z^k = z (1 - (nn + 1) zn +
    # nn zn z) / (1 - z)^2
    g0 = (((1.0 - zn) + zn * p) * p + zn * zi * r) / dd  # (1 - zn z = (1 - zn) + zn w)
    a = (1.0 - zn) - nn * zn * p  # N = a + i b
    b = nn * zn * r
    g1 = ((zr * a - zi * b) * (p * p - r * r) - (zr * b + zi * a) * (2.0 * p * r)) / (dd * dd)
    return g0 - 0.5 - 0.5 * zn, g1 - 0.5 * nn * zn


def ring_f_sums_reference(rho: float, n: int, nn: int) -> tuple:
    """:func:`_ring_f_sums` term by term in 40-digit mpmath (for the tests)."""
    import mpmath

    with mpmath.workdps(40):
        th = mpmath.pi * n / nn
        r = mpmath.mpf(rho)
        terms = [(mpmath.mpf(0.5) if k in (0, nn) else 1) * r ** k * mpmath.cos(k * th) for k in range(nn + 1)]
        return float(mpmath.fsum(terms)), float(mpmath.fsum(k * t for k, t in enumerate(terms)))


@njit(cache=True, nogil=True)
def _ggx_ring_f(mp, a2, xmu, xs, d, itol, tol_abs, fv):  # pragma: no cover - compiled; see ring_reference
    """(W, its error, F's samples): the integral over phi of the GGX weight D times the Fresnel factor F(wi.h) on the circle
    of wo at x = x_mu + d (:func:`_ggx_ring` with F; ``fv`` a work array of RING_F_NMAX + 1 values).

    On the circle, measured from the mirror side (psi = phi - pi), D = (a2 / pi)(1 + k / Y)^2 with Y = a' - Q cos(psi)
    (:func:`_ggx_ring`), whose Fourier cosine coefficients are closed forms: with rho = (sqrt(B) - S sqrt(A)) / (sqrt(B) +
    S sqrt(A)) (= (a' - R) / Q, no cancellation), the integral of D cos(k psi) is M_k = 2 a2 (delta_k0 + rho^k (2 k1 + t2 +
    k k1^2)), k1 = k / R = (1 - a2) S / sqrt(A B), t2 = k^2 a' / R^3 (M_0 is :func:`_ggx_ring`).  F depends on psi through
    c = wi.h = sqrt(S^2 + s cos(x) sin^2(psi / 2)) only, smooth and periodic: its cosine interpolant at psi = n pi / N
    (Chebyshev-Lobatto in cos psi) integrates against D exactly from the M_k, sum'' a_k M_k = (4 a2 / N) sum''_n F_n (1/2 +
    (2 k1 + t2) C0_n + k1^2 C1_n) (:func:`_ring_f_sums`).  N doubles from RING_F_N0 until W_N's error is at most
    max(itol W_N, ``tol_abs``) or N = RING_F_NMAX: |W_N - W_N/2|, times the larger ratio of the last three such steps where
    both are at most RING_F_RATIO (from N = 32: the coefficients then decay geometrically, or faster, so W_N's error is below
    |W_N - W_N/2| times that ratio).  F's singularities limit the decay: c = 0, at psi = +- 2 i asinh(S / sqrt(s cos x)) (so S must not be
    small: :data:`N_FRESNEL_S_MIN`), and the index's (:func:`n_fresnel_ok`)."""
    tau = math.tan(0.5 * d)
    sy, cy = math.sin(xmu + 0.5 * d), math.sin(xs - 0.5 * d)
    a = a2 + tau * tau
    b = a2 * sy * sy + cy * cy
    r = math.sqrt(a * b)
    k = 1.0 - a2
    k1 = k * sy / r
    al = 2.0 * k1 + k * k * sy * (sy * sy * a + b) / (2.0 * r * r * r)
    be = k1 * k1
    sa, sb = sy * math.sqrt(a), math.sqrt(b)
    rho = (sb - sa) / (sb + sa)
    q = math.sin(xs) * math.sin(xs - d)  # s cos(x)
    s2 = sy * sy
    stride = RING_F_NMAX // RING_F_N0
    for j in range(0, RING_F_NMAX + 1, stride):
        fv[j] = _fresnel_at(mp, math.sqrt(s2 + q * _RING_F_SIN2[j]))
    prev = _ring_f_level(fv, rho, al, be, RING_F_N0 // 2, 2 * stride)
    step, step2 = abs(prev - _ring_f_level(fv, rho, al, be, RING_F_N0 // 4, 4 * stride)), -1.0
    nn = RING_F_N0
    while True:
        w = _ring_f_level(fv, rho, al, be, nn, stride)
        e = abs(w - prev)
        # where the last three steps shrink, each by RING_F_RATIO at least (from N = 32 on: W_8 - W_4, W_16 - W_8, W_32 -
        # W_16), |W_N - W_N/2| times the larger of their two ratios; else |W_N - W_N/2|
        ratio = max(e / step, step / step2) if step > 0.0 and step2 > 0.0 else 1.0
        est = e * ratio if ratio <= RING_F_RATIO else e
        if est <= max(itol * w, tol_abs / (4.0 * a2)) or nn >= RING_F_NMAX:
            return 4.0 * a2 * w, 4.0 * a2 * (est + RING_F_ROUNDING * nn * w), nn + 1
        step, step2 = abs(w - prev), step
        prev = w
        stride //= 2
        for j in range(stride, RING_F_NMAX + 1, 2 * stride):  # the next level's new samples
            fv[j] = _fresnel_at(mp, math.sqrt(s2 + q * _RING_F_SIN2[j]))
        nn *= 2


@njit(cache=True, nogil=True, inline="always")
def _ring_f_level(fv, rho, al, be, nn, stride):  # pragma: no cover - compiled
    """The product rule of :func:`_ggx_ring_f` with nn + 1 samples (every ``stride``-th of ``fv``), over 4 a2."""
    tot = 0.0
    rn = rho ** nn
    for n in range(nn + 1):
        c0, c1 = _ring_f_sums(rho, rn, n, nn, n * stride)
        tot += (0.5 if n == 0 or n == nn else 1.0) * fv[n * stride] * (0.5 + al * c0 + be * c1)
    return tot / nn


#: the rounding of :func:`_ggx_ring_f`'s sums per unit of W and per sample: twice the 8 eps of their scale within which
#: tests/test_polar_ggx_fresnel.py finds :func:`_ring_f_sums` against a summation term by term in 40-digit mpmath
RING_F_ROUNDING = 16.0 * np.finfo(float).eps


def ring_reference(distribution: int, a2: float, mu: float, x: float, fresnel=None) -> float:
    """:func:`_ggx_ring` (``distribution`` 1) or :func:`_beckmann_ring` (0) at elevation ``x`` by scipy's adaptive
    quadrature of Walter's D over phi (their numpy/scipy twin, for the tests); with ``fresnel`` = (ior, eta, k), D times
    the Fresnel factor F(wi.h) (:func:`_ggx_ring_f`; pumpup.models.cook_torrance.fresnel, pumpup.models.metal.fresnel),
    graded towards the mirror side at the scale of S = sin((x + x_mu) / 2) too (F's branch point at c = 0; without it, at
    S ~ 0.05, scipy missed the feature by 3e-7, measured against mpmath)."""
    from scipy.integrate import quad

    from ..physics.fresnel import fresnel_conductor as conductor
    from ..physics.fresnel import fresnel_dielectric as dielectric

    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    wi = np.array([s, 0.0, mu])

    def d(phi):
        wo = np.array([math.cos(x) * math.cos(phi), math.cos(x) * math.sin(phi), math.sin(x)])
        h = wi + wo
        c2, s2 = h[2] * h[2] / (h @ h), (h[0] * h[0] + h[1] * h[1]) / (h @ h)  # cos^2, sin^2 of h's angle from N
        if distribution == 1:
            d = a2 / (math.pi * (a2 * c2 + s2) ** 2)  # Walter eq. 33: a2 / (pi (a2 cos^2 + sin^2)^2)
        else:
            t2 = s2 / c2
            d = math.exp(-t2 / a2) * (1.0 + t2) ** 2 / (math.pi * a2)  # Walter eq. 25
        if fresnel is None:
            return d
        c = float(wi @ h) / math.sqrt(h @ h)
        return d * float(conductor(c, fresnel[1], fresnel[2]) if fresnel[1] > 0.0 else dielectric(c, fresnel[0]))

    points = _peak_points(math.sqrt(a2))
    if fresnel is not None:  # (and towards F's branch point c = 0, at the scale of the ring's smallest c, S)
        points = sorted(points + _peak_points(math.sin(0.5 * (x + math.asin(mu)))))
    return 2.0 * quad(d, 0.0, math.pi, epsabs=0.0, epsrel=1e-13, limit=1000, points=points)[0]


def _peak_points(alpha: float) -> list:
    """Breakpoints in the azimuth phi in (0, pi) graded towards the mirror direction phi = pi, where a lobe alpha wide
    peaks (for scipy's quadrature in the references)."""
    w = alpha * 3.0 ** np.arange(-4, 30)
    return list(math.pi - w[w < math.pi])


#: above this z, :func:`_kummer_half` sums the asymptotic series (its smallest term ~ sqrt(2 pi z) e^-z < 1e-20)
KUMMER_ASYMPTOTIC = 50.0


@njit(cache=True, nogil=True)
def _kummer_half(z):  # pragma: no cover - compiled; tested against mpmath.hyp1f1
    """(H0, H1, H2), H_j = z^j e^-z 1F1(1/2; j + 1; z) for z >= 0 (inf included): below KUMMER_ASYMPTOTIC the power series
    (positive terms, DLMF 13.2.2), above it the asymptotic one, z^(j - 1/2) (j! / sqrt(pi)) sum_n (j + 1/2)_n (1/2)_n /
    (n! z^n) (DLMF 13.7.1; positive terms too, the rest of the function e^-z smaller)."""
    if z >= KUMMER_ASYMPTOTIC:
        r = 1.0 / math.sqrt(math.pi * z) if z < math.inf else 0.0
        h0 = h1 = h2 = 0.0
        for j in range(3):
            term, sm = 1.0, 1.0
            for n in range(200):
                term *= (j + 0.5 + n) * (0.5 + n) / ((n + 1.0) * z)
                sm += term
                if term <= 1e-17 * sm:
                    break
            if j == 0:
                h0 = r * sm
            elif j == 1:
                h1 = r * sm
            else:
                h2 = 2.0 * r * sm
        return h0, h1, h2
    t0 = t1 = t2 = 1.0
    s0 = s1 = s2 = 1.0
    n = 0
    while True:
        c = (0.5 + n) * z / (n + 1.0)
        t0 *= c / (1.0 + n)
        t1 *= c / (2.0 + n)
        t2 *= c / (3.0 + n)
        s0 += t0
        s1 += t1
        s2 += t2
        n += 1
        if n > z and t0 <= 1e-17 * s0:
            break
    e = math.exp(-z)
    return e * s0, z * e * s1, z * z * e * s2


#: :func:`_kummer_fast`'s Chebyshev pieces of H_j on [0, 200), interpolating :func:`_kummer_half` at KUMMER_DEGREE + 1
#: Chebyshev points each (built at import: at most 27 ulps of max H_j on the piece against 30-digit mpmath, the series
#: itself 10; the series took 120-670 ns a value there, the asymptotic one 130 ns up to 200, the pieces 70)
KUMMER_EDGES = np.array([0.0, 3.0, 8.0, 16.0, 28.0, 50.0, 80.0, 130.0, 200.0])
KUMMER_DEGREE = 18


def _kummer_table() -> np.ndarray:
    """The Chebyshev coefficients (piece, j, degree) of :data:`KUMMER_EDGES`' pieces (for :func:`_kummer_fast`)."""
    n = KUMMER_DEGREE + 1
    k = np.arange(n)
    ang = np.pi * (k + 0.5) / n
    cos = np.cos(np.outer(k, ang))  # [m, k]
    out = np.empty((len(KUMMER_EDGES) - 1, 3, n))
    for i, (a, b) in enumerate(zip(KUMMER_EDGES[:-1], KUMMER_EDGES[1:])):
        h = np.array([_kummer_half(0.5 * (a + b) + 0.5 * (b - a) * math.cos(t)) for t in ang])  # (k, j)
        c = (2.0 / n) * (cos @ h)
        c[0] *= 0.5
        out[i] = c.T
    return out


#: :func:`_kummer_table`, read from the package's data (computing it means running the compiled series at import);
#: ``tests/test_startup.py`` checks the file against :func:`_kummer_table`
KUMMER_COEF = np.load(os.path.join(os.path.dirname(__file__), "data", "kummer_chebyshev.npy"))


@njit(cache=True, nogil=True)
def _kummer_fast(z):  # pragma: no cover - compiled; tested against _kummer_half and mpmath
    """:func:`_kummer_half` by its Chebyshev pieces below 200 (Clenshaw's recurrence), the asymptotic series above."""
    if z >= KUMMER_EDGES[-1]:
        return _kummer_half(z)
    i = 0
    while z >= KUMMER_EDGES[i + 1]:
        i += 1
    a, b = KUMMER_EDGES[i], KUMMER_EDGES[i + 1]
    x = (2.0 * z - a - b) / (b - a)
    h0 = h1 = h2 = 0.0
    for j in range(3):
        b1 = b2 = 0.0
        for m in range(KUMMER_DEGREE, 0, -1):
            b1, b2 = 2.0 * x * b1 - b2 + KUMMER_COEF[i, j, m], b1
        v = x * b1 - b2 + KUMMER_COEF[i, j, 0]
        if j == 0:
            h0 = v
        elif j == 1:
            h1 = v
        else:
            h2 = v
    return h0, h1, h2


@njit(cache=True, nogil=True, inline="always")
def _beckmann_ring(a2, xmu, xs, d):  # pragma: no cover - compiled; see ring_reference
    """integral over phi in [0, 2 pi) of the Beckmann weight D = exp(-tan^2(h) / a2) / (pi a2 cos^4(h)) (Walter et al.
    2007 eq. 25) on the circle of wo at elevation x = x_mu + d, for wi at elevation x_mu (x_s = pi / 2 - x_mu).

    With X = |wi + wo|^2 = X_min + Q v, v = 1 - cos(psi) (psi = phi - pi, from the plane of incidence's mirror side),
    X_min = m^2 (1 + tan^2(d / 2)), Q = 2 sin(theta_i) cos(x), m = N.wi + N.wo: tan^2(h) = X / m^2 - 1 = tau^2 + (Q / m^2) v
    (tau = tan(d / 2)) and 1 / cos^4 = X^2 / m^4 = (1 + tau^2 + a2 kappa v)^2, kappa = Q / (m^2 a2), so the integral is
    e^-(tau^2 / a2) / (pi a2) times (1 + tau^2)^2 M0 + 2 (1 + tau^2) a2 kappa M1 + a2^2 kappa^2 M2, M_j = integral of v^j
    e^-(kappa v) over psi = c_j e^-z 1F1(1/2; j + 1; z), z = 2 kappa, c = (2 pi, 2 pi, 3 pi) (v = 2 sin^2(psi / 2)): in
    :func:`_kummer_half`'s H_j, (e^-(tau^2 / a2) / a2) (2 (1 + tau^2)^2 H0 + 2 a2 (1 + tau^2) H1 + (3 / 4) a2^2 H2),
    every term >= 0."""
    tau = math.tan(0.5 * d)
    g = math.exp(-tau * tau / a2)
    if g == 0.0:  # (far in the Gaussian's tail: the rest is finite)
        return 0.0
    sy, cd = math.sin(xmu + 0.5 * d), math.cos(0.5 * d)
    m2 = 4.0 * sy * sy * cd * cd  # (N.wi + N.wo)^2, m = 2 sin((x + x_mu) / 2) cos(d / 2)
    q = 2.0 * math.sin(xs) * math.sin(xs - d)  # 2 sin(theta_i) cos(x)
    z = 2.0 * q / (m2 * a2) if m2 * a2 > 0.0 else math.inf
    h0, h1, h2 = _kummer_fast(z)
    w = 1.0 + tau * tau
    return g / a2 * (2.0 * w * w * h0 + 2.0 * a2 * w * h1 + 0.75 * a2 * a2 * h2)


@njit(cache=True, nogil=True, inline="always")
def _n_value(mp, mu, xmu, xs, d):  # pragma: no cover - compiled; see n_integrand_reference
    """Frame 6's integrand at x = x_mu + d: pi a2 cos(x) sin(x) W(x) Gamma(sin x), W the weight's integral over the
    azimuth (:func:`_ggx_ring`, :func:`_beckmann_ring`), Gamma = 1 / (P(mu) P(t)) for the separable Smith G (Walter et al.
    2007 eq. 20), 1 / (t P(mu) + mu P(t) - mu t) for the height-correlated one (Heitz 2014), 1 / (r + (1 - r) t) for
    Schlick's model (000 eq. 36); P(t) = N.wo / G1(wo) (physics.microfacet.projected, Walter eq. 27, 34), P(mu) in mp[8]."""
    a2 = mp[4] if mp[0] == SCHLICK else mp[4] * mp[4]
    w = _beckmann_ring(a2, xmu, xs, d) if mp[0] == SMITH and mp[1] == 0.0 else _ggx_ring(a2, xmu, xs, d)
    if w == 0.0:  # (far in the Beckmann weight's tail)
        return 0.0
    return _n_times(mp, mu, xmu, xs, d, a2, w)


@njit(cache=True, nogil=True, inline="always")
def _n_times(mp, mu, xmu, xs, d, a2, w):  # pragma: no cover - compiled; see n_integrand_reference
    """:func:`_n_value` of the ring's integral ``w``: pi a2 cos(x) sin(x) w Gamma(sin x) (1 for ``w`` the factor)."""
    t = math.sin(xmu + d)
    ct = math.sin(xs - d)  # cos(x)
    v = math.pi * a2 * ct * t * w
    if mp[0] == SCHLICK:
        return v / (mp[4] + (1.0 - mp[4]) * t)  # 000 eq. 36's 1 / (r + (1 - r) N.V)
    pt = _projected(ct, 0.0, t, int(mp[1]), int(mp[2]), mp[4])  # P(t) = N.wo / G1(wo), Walter eq. 27, 34
    return v / (mp[8] * pt if mp[3] == 0.0 else t * mp[8] + mu * pt - mu * t)  # Walter eq. 20; Heitz 2014


@njit(cache=True, nogil=True)
def _n_incidence(mp, mu):  # pragma: no cover - compiled
    """(x_mu, x_s = pi / 2 - x_mu) of incidence mu, both from atan2 (each exact near its own 0), and P(mu) = mu / G1(mu) into
    mp[8] for the Smith models (Walter eq. 27, 34)."""
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    if mp[0] == SMITH:
        mp[8] = _projected(s, 0.0, mu, int(mp[1]), int(mp[2]), mp[4])
    return math.atan2(mu, s), math.atan2(s, mu)


@njit(cache=True, nogil=True, inline="always")
def _n_chain_g(chain, mu, t):  # pragma: no cover - compiled
    """g_1 ... g_k(mu, t) of a pumped chain at N.wo = t, as the chain kernel computes it (``pumpup.physics.lookups.g_product``,
    ``g_levels``; 001 eq. 16)."""
    if min(mu, t) > chain[13]:
        return g_product(max(mu, t), chain[14], chain[15], chain[16], chain[17])
    return g_levels(max(mu, t), min(mu, t), chain[0], chain[1], chain[2], chain[3], chain[4], chain[5], chain[6],
                     chain[7], chain[8], chain[9], chain[10], chain[11], chain[12])


@njit(cache=True, nogil=True)
def _n_rule(mp, mu, xmu, xs, lo, hi, nodes, wk, wg, buf, mode, chain, factor, itol, iacc, fv, kind):  # pragma: no cover - compiled
    """(value, error) of the rule on d = x - x_mu in [lo, hi] of :func:`_n_value`; with a pumped chain (``chain`` not
    None, :meth:`pumpup.operators.pumping.Pumped._chain_args`) divided by g_1 ... g_k(mu, N.wo) exactly as the chain kernel divides
    by it (001 eq. 16; written out as in :func:`_x_rule`; first times F(max(mu, N.wo)) where mp[15] = 1, ``Polar.fmax``,
    analytic between the cuts), or with a 1/E-scaled model's ``factor`` (not None: F0 and
    :attr:`pumpup.operators.compensate._Bound.args`) times 1 + F0 (1 / U(N.wo) - 1) as its kernel multiplies (Turquin eq. 6,
    :func:`pumpup.operators.compensate._scale_kernel`); its error then the larger of QUADPACK's calibration (for the weight's peak,
    as without g) and CHAIN_SAFETY |K - G| (for the splines of g or U, which are not analytic: :data:`CHAIN_SAFETY`).
    With a Fresnel factor (mp[13] = 1, GGX) the ring is :func:`_ggx_ring_f` at relative tolerance ``itol`` or absolute
    ``iacc`` / the node's factor (``fv`` its work array), and its errors are taken as frame 4 takes K's (:func:`_gk`):
    summed with the Kronrod weights, and into |K - G| before its calibration as far as they can hide it.  ``kind`` 0: the
    variable is d itself; 1 and 2 (a piece off the peak, GGX and Schlick): u = ln |d|, d = e^u or -e^u, the integrand times
    |d| (:data:`N_LOG_GRADE`); 3 (a piece near x = 0, GGX and Schlick): u = ln x, d = e^u - x_mu, the integrand times x
    (:data:`N_LOG_GRADE`)."""
    h = hi - lo
    ie = 0.0
    noise = 0.0
    ns = 0
    for j in range(nodes.shape[0]):
        d = lo + h * nodes[j]
        jac = 1.0
        if kind != 0:
            jac = math.exp(d)
            d = jac if kind == 1 else (-jac if kind == 2 else jac - xmu)
        we, rf = 0.0, 0.0  # the ring's error and its factor to the node's units (:func:`_ggx_ring_f`)
        g = 1.0
        if mp[13] > 0.0:
            if chain is not None:  # (g first: the ring's absolute tolerance is in the units of the node divided by it)
                g = _n_chain_g(chain, mu, math.sin(xmu + d))
            a2 = mp[4] * mp[4]
            fac = _n_times(mp, mu, xmu, xs, d, a2, 1.0) * jac
            w, we, nf = _ggx_ring_f(mp, a2, xmu, xs, d, itol, iacc * g / fac if fac > 0.0 else math.inf, fv)
            ns += nf
            v = w * fac
            rf = fac
        else:
            v = _n_value(mp, mu, xmu, xs, d) * jac
        if mp[15] > 0.0 and v != 0.0:  # the fresnel wrapper's F(max(N.wi, N.wo)), 000 eq. 28 (:attr:`Polar.fmax`)
            v *= _fresnel_real(max(mu, math.sin(xmu + d)), mp[16], mp[17])
        if chain is not None and v != 0.0:
            if mp[13] <= 0.0:
                g = _n_chain_g(chain, mu, math.sin(xmu + d))
            v /= g  # 001 eq. 16
            rf /= g
        ie += wk[j] * we * rf
        noise += (wk[j] + wg[j]) * we * rf
        if factor is not None and v != 0.0:
            u = _scale_bound(math.sin(xmu + d), factor[1], factor[2], factor[3], factor[4], factor[5], factor[6],
                             factor[7], factor[8], factor[9], factor[10], factor[11], factor[12])
            if factor[0] == 1.0:
                v /= u  # Turquin eq. 6 with F0 = 1: f / E(mu_o)
            else:
                v *= 1.0 + factor[0] * (1.0 / u - 1.0)  # Turquin eq. 6
        buf[j] = v
    k, diff, asc, ab = rule_sums(buf, wk, wg)
    e = calibrated((diff + noise) * h, asc * h, ab * h, mode) + ie * h
    return k * h, (max(e, CHAIN_SAFETY * diff * h + ie * h) if chain is not None or factor is not None else e), ns


@njit(cache=True, nogil=True)
def _n_values(mp, mu, x, chain, factor):  # pragma: no cover - compiled
    """:func:`_n_value` (divided by the chain's g, or times the scaled model's factor, where ``chain`` or ``factor`` is
    not None) at the elevations ``x`` (for the tests: the rule's own arithmetic, one node per call)."""
    xmu, xs = _n_incidence(mp, mu)
    out = np.empty(x.shape[0])
    buf = np.empty(1)
    one = np.ones(1)
    for i in range(x.shape[0]):
        d = x[i] - xmu
        out[i] = _n_rule(mp, mu, xmu, xs, d, d + 1.0, np.zeros(1), one, one, buf, 1, chain, factor, INNER_RTOL_MIN, 0.0,
                         np.empty(RING_F_NMAX + 1), 0)[0]
    return out


def n_params(hint) -> np.ndarray:
    """Frame 6's parameter array: :func:`numeric_params`, and for GGX with a Fresnel factor mp[13] = 1
    (:func:`_ggx_ring_f`) and mp[14] the scale of F's pole near c = 0 (:func:`fresnel_pole`, a conductor's; 0 for a
    dielectric) for :func:`_n_cuts`; with ``Polar.fmax`` = (eta, k) mp[15:18] = 1, eta, k (:func:`_n_rule`)."""
    mp = numeric_params(hint)
    if any(hint.fresnel):
        mp[13] = 1.0
        mp[14] = fresnel_pole(float(hint.fresnel[1]), float(hint.fresnel[2])) if hint.fresnel[1] > 0.0 else 0.0
    if hint.fmax is not None:  # 000 eq. 28's F(max(N.wi, N.wo)) of a conductor (eta, k): a factor per node (_n_rule)
        mp[15], mp[16], mp[17] = 1.0, *hint.fmax
    return mp


def n_integrand(brdf, mu: float, x) -> np.ndarray:
    """Frame 6's integrand (:func:`_n_value`, divided by g for a pumped model, times the factor of a 1/E-scaled one) for
    ``brdf``'s hint at N.wi = ``mu`` and elevations ``x`` of wo, as the engine computes it (for the tests)."""
    hint = brdf.polar()
    return _n_values(n_params(hint), float(mu), np.atleast_1d(np.asarray(x, dtype=float)), hint.chain, hint.factor)


def n_integrand_reference(brdf, mu: float, x) -> np.ndarray:
    """Frame 6's integrand (:func:`_n_value`) at elevations ``x`` from the model itself: its BRDF times N.wo integrated over
    the azimuth of wo by scipy's adaptive quadrature, times cos(x) and divided by the hint's scale (for the tests)."""
    from scipy.integrate import quad

    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    wi = np.array([[s, 0.0, mu]])
    hint = brdf.polar()
    scale = float(hint.scale(np.array([mu]))[0])
    alpha = math.sqrt(hint.schlick) if hint.schlick is not None else hint.smith[3]
    out = []
    for xv in np.atleast_1d(np.asarray(x, dtype=float)):
        def f(phi):
            wo = np.array([[math.cos(xv) * math.cos(phi), math.cos(xv) * math.sin(phi), math.sin(xv)]])
            return float(brdf.eval(wi, wo)[0]) * math.sin(xv)

        out.append(2.0 * quad(f, 0.0, math.pi, epsabs=0.0, epsrel=1e-13, limit=1000, points=_peak_points(alpha))[0]
                   * math.cos(xv) / scale)
    return np.array(out)


#: frame 6 grades GGX's and Schlick's peak by this factor per cut, and integrates every piece off the peak in u = ln |d|
#: (:func:`_n_rule`): there the singularities at d = +- 2 i atanh(alpha) lie pi / 2 from the real axis whatever |d|, so a
#: piece [a, 27 a] (length ln 27 = 3.3 in u) is as far from them, relative to its length, as [a, 3 a] is in d (0.52 of it
#: instead of 0.5); GGX alpha = 1e-8 at mu = 1/2 took 34 graded pieces in d, now 14
N_LOG_GRADE = 27.0
#: ... on the side short of the peak only for |d| <= this times x_mu: towards x = 0, P(t)'s singularity (or Schlick's
#: pole) lies near d = -x_mu, ln 8 = 2.1 from u = ln(x_mu / 8) (at 1/2 a piece came within 0.23 of its length in u of
#: it, on the cuts at mu = 1; tests/test_polar_ggx.py checks every piece in the variable it is integrated in)
#: ... and from x = 0 up to this times x_mu, by N_LOG_GRADE in u = ln x (:func:`_n_kind` 3; issue 14's eighteenth session):
#: P(t)'s singularities at x = +- i atanh(alpha) lie pi / 2 from the real u axis whatever x (Schlick's pole at x ~ -r / (1 -
#: r), pi), the peak's ln 8 beyond the last piece (GGX alpha = 1e-8 had 17 pieces graded by 3 in x there, now 6)
N_LOG_SIDE = 0.125
#: ... and beyond it up to this times the range's end pi / 2 - x_mu (the weight's singularity at x = pi - x_mu + - 2 i
#: atanh(alpha), where B = 0, lies ln 2 beyond that end in u), then by 3 in u
N_LOG_END = 0.25


@njit(cache=True, nogil=True, inline="always")
def _n_kind(mp, a, b, xmu):  # pragma: no cover - compiled
    """The variable of frame 6's piece [a, b] of d (:func:`_n_rule`): for GGX and Schlick (not Beckmann's Gaussian) 1 (u =
    ln d) beyond the peak, 2 (u = ln -d) short of it within N_LOG_SIDE x_mu, 3 (u = ln x, x = x_mu + d) near x = 0 within
    N_LOG_SIDE x_mu but off x = 0 itself (:data:`N_LOG_GRADE`); else 0 (d)."""
    if mp[0] == SMITH and mp[1] == 0.0:
        return 0
    if a > 0.0:
        return 1
    if b < 0.0 and a >= -N_LOG_SIDE * xmu:
        return 2
    if a > -xmu and b + xmu <= N_LOG_SIDE * xmu * (1.0 + 1e-12):
        return 3
    return 0


def n_pieces_reference(brdf, mu: float) -> list:
    """Frame 6's pieces for ``brdf``'s hint at N.wi = ``mu``: (lo, hi, kind) in d = x - x_mu, kind as :func:`_n_kind`
    (for the tests)."""
    hint = brdf.polar()
    mp = n_params(hint)
    cut = np.empty(N_CUTS)
    xmu = _n_incidence(mp, mu)[0]
    c = cut[:_n_cuts(mp, xmu, cut)]
    return [(a, b, _n_kind(mp, a, b, xmu)) for a, b in zip(c[:-1], c[1:]) if b > a]


#: frame 6's breakpoints per mu: 0, pi / 2, x_mu, Walter's switch and the graded ones (the peak's two sides, 2 x 17 at
#: alpha = 1e-8; from 0, up to 26 at Schlick's r = 1e-12; the x_mu grading takes what is left)
N_CUTS = 96


@njit(cache=True, nogil=True)
def _n_cuts(mp, xmu, cut):  # pragma: no cover - compiled; see n_cuts_reference
    """The breakpoints of frame 6's d = x - x_mu at incidence x_mu, sorted, into ``cut``; returns their number.  The
    integrand's singularities near x in [0, pi / 2] (:func:`_ggx_ring`, :func:`_n_value`): the weight's at x = x_mu +- 2 i
    atanh(alpha) (A = 0) and at pi - x_mu +- 2 i atanh(alpha) (B = 0, as far beyond pi / 2 as x_mu is short of it); P(t)'s
    branch point at x = +- i atanh(alpha) (sin^2 x + alpha^2 cos^2 x = 0); Schlick's pole at sin x = -r / (1 - r); the
    height-correlated G's pole at x = -x_mu (t P(mu) + mu P(t) - mu t = 0 at t = -mu).  The Beckmann weight
    (:func:`_beckmann_ring`) is a Gaussian 2 alpha wide in d, its kappa has a pole where N.wi + N.wo = 0 (x = -x_mu), and
    its P(t) turns on the scale alpha near x = 0 (erf(tan(x) / alpha)); Walter's rational G1 jumps at N.wo = mp[9].  So d
    is cut at 0 and +- 2 atanh(alpha) 3^j (Beckmann: +- 2 alpha 3^j; GGX and Schlick 27^j, in u = ln |d|, up to x_mu / 8
    short of the peak and a quarter of the range's end beyond it, :data:`N_LOG_GRADE`), and x at z 3^j from 0 (z =
    atanh(alpha), alpha or r / (1 - r), and x_mu for the correlated G and for Beckmann) and at Walter's switch: every piece
    then lies at least about its own length from the nearest singularity, in the variable it is integrated in.  With a
    Fresnel factor (mp[13], :func:`_ggx_ring_f`) x is also cut where the rings' smallest wi.h, sin((x + x_mu) / 2), is 3^j
    times the scales of F's pole (mp[14]) and branch point (mp[10])."""
    half = 0.5 * math.pi
    alpha = math.sqrt(mp[4]) if mp[0] == SCHLICK else mp[4]
    beckmann = mp[0] == SMITH and mp[1] == 0.0
    cut[0], cut[1], cut[2] = -xmu, half - xmu, 0.0
    m = 3
    if 0.0 < mp[9] < 1.0:  # Walter's G1 switch
        cut[m] = math.asin(mp[9]) - xmu
        m += 1
    d0 = 2.0 * alpha if beckmann else (2.0 * math.atanh(alpha) if alpha < 1.0 else math.inf)
    for side in range(2):  # beyond the peak (d > 0), then short of it; GGX and Schlick in u = ln |d| (:data:`N_LOG_GRADE`)
        end = half - xmu if side == 0 else xmu
        top = end * (N_LOG_END if side == 0 else N_LOG_SIDE)  # (where the log grading stops)
        d = d0
        while d < end and m < cut.shape[0] - 2:
            cut[m] = d if side == 0 else -d
            m += 1
            d = 3.0 * d if beckmann or d >= top else min(N_LOG_GRADE * d, top)
    top = 0.0 if beckmann else N_LOG_SIDE * xmu  # (GGX, Schlick: by N_LOG_GRADE in u = ln x up to there, :func:`_n_kind`)
    for which in range(2):
        if which == 0:
            if mp[0] == SCHLICK:
                d = mp[4] / (1.0 - mp[4]) if mp[4] < 1.0 else math.inf
            else:
                d = alpha if beckmann else (math.atanh(alpha) if alpha < 1.0 else math.inf)
        else:
            d = 3.0 * xmu if mp[0] == SMITH and (mp[3] != 0.0 or beckmann) else math.inf
        while d < half and m < cut.shape[0]:
            cut[m] = d - xmu
            m += 1
            d = min(N_LOG_GRADE * d, top) if which == 0 and d < top else 3.0 * d
    if mp[13] > 0.0:  # GGX with F (:func:`_ggx_ring_f`): the rings' smallest wi.h, S = sin((x + x_mu) / 2), at F's scales
        for which in range(2):  # (the parallel reflectance's pole, the refracted cosine's branch point: mp[14], mp[10])
            z = mp[14] if which == 0 else mp[10]
            if not 0.0 < z < 1.0:
                continue
            while z > N_FRESNEL_S_MIN:
                z /= 3.0
            z *= 3.0
            while z < 1.0 and m < cut.shape[0]:
                d = 2.0 * math.asin(z) - 2.0 * xmu
                if -xmu < d < half - xmu:
                    cut[m] = d
                    m += 1
                z *= 3.0
    cut[:m].sort()
    return m


def n_cuts_reference(brdf, mu: float) -> np.ndarray:
    """:func:`_n_cuts` for ``brdf``'s hint at N.wi = ``mu``, as elevations x (for the tests)."""
    mp = n_params(brdf.polar())
    cut = np.empty(N_CUTS)
    xmu = _n_incidence(mp, mu)[0]
    m = _n_cuts(mp, xmu, cut)
    return cut[:m] + xmu


@njit(cache=True, nogil=True)
def _integrate_n(mp, mu_arr, rtol, atol_arr, max_intervals, rounding, nodes, wk, wg, mode, chain, factor, ecut, necut, val,
                 err, conv, evals):  # pragma: no cover
    """Frame 6: adaptive 10/21 quadrature over the elevation x = x_mu + d of wo (:func:`_n_rule`) for every mu, from the
    pieces between :func:`_n_cuts` and, for a pumped or a 1/E-scaled model (``chain`` or ``factor`` not None), the
    elevations ``ecut[q, :necut[q]]`` (:func:`chain_cuts` of the kinks of g or U)."""
    cap, pk, t0, t1, kv, ke, buf, _, _, itol = _buffers(max_intervals + N_CUTS + ecut.shape[1], nodes, nodes, rtol)
    cut = np.empty(N_CUTS + ecut.shape[1])
    fv = np.empty(RING_F_NMAX + 1)
    kd = np.empty(cap, np.int64)
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        xmu, xs = _n_incidence(mp, mu)
        nc = _n_cuts(mp, xmu, cut[:N_CUTS])
        for i in range(necut[q]):
            cut[nc] = ecut[q, i] - xmu
            nc += 1
        cut[:nc].sort()
        # a ring's absolute tolerance iacc / (the node's factor), iacc = itol times a lower bound of the integral so far
        # over the pieces' total length in their variables (d or ln |d|): its share of the sum is then at most itol times
        # that bound (as :func:`_integrate`)
        m = 0
        length = 0.0  # (of the pieces in their variables)
        for i in range(nc - 1):
            if cut[i + 1] > cut[i]:
                pk[m], t0[m], t1[m], kd[m] = i, cut[i], cut[i + 1], _n_kind(mp, cut[i], cut[i + 1], xmu)
                if kd[m] == 1:  # off the peak: u = ln |d| (:data:`N_LOG_GRADE`)
                    t0[m], t1[m] = math.log(cut[i]), math.log(cut[i + 1])
                elif kd[m] == 2:
                    t0[m], t1[m] = math.log(-cut[i + 1]), math.log(-cut[i])
                elif kd[m] == 3:  # near x = 0: u = ln x (:data:`N_LOG_GRADE`)
                    t0[m], t1[m] = math.log(cut[i] + xmu), math.log(cut[i + 1] + xmu)
                length += t1[m] - t0[m]
                m += 1
        acc = 0.0
        ns = 0
        for i in range(m):
            kv[i], ke[i], nf = _n_rule(mp, mu, xmu, xs, t0[i], t1[i], nodes, wk, wg, buf, mode, chain, factor, itol,
                                       itol * acc / length, fv, kd[i])
            acc += max(kv[i] - ke[i], 0.0)
            ns += nf
        start = m
        while True:
            tot, e, r, worst, ok = _status(kv, ke, m, 0.0, rounding, rtol, atol_arr[q])
            if chain is not None or factor is not None:  # (as :func:`_integrate_chain`: the reported error within the tolerance)
                ok = ok and (e <= r or e + r <= max(rtol * abs(tot), atol_arr[q]))
            if ok or m - start >= max_intervals or m >= cap:
                break
            i, a_, mid, b_ = _bisect(pk, t0, t1, worst, m)
            kd[m] = kd[worst]
            iacc = itol * max(tot - e, 0.0) / length
            kv[worst], ke[worst], nf = _n_rule(mp, mu, xmu, xs, a_, mid, nodes, wk, wg, buf, mode, chain, factor, itol, iacc, fv,
                                               kd[worst])
            ns += nf
            kv[m], ke[m], nf = _n_rule(mp, mu, xmu, xs, mid, b_, nodes, wk, wg, buf, mode, chain, factor, itol, iacc, fv, kd[m])
            ns += nf
            m += 1
        val[q] = tot
        err[q] = e + r
        conv[q] = ok
        evals[q] = nodes.shape[0] * (m + (m - start)) + ns  # (and F's samples on the rings, :func:`_ggx_ring_f`)


#: frame 6 is used where it applies (``without_n_frame`` switches it off: those models then take frame 4, the rule on
#: h's arc, as before it)
N_FRAME = True


#: per thread: :func:`albedo_1d` switches frame 6 off for its own call on GGX with F below N_FRESNEL_MU_MIN (frame 4
#: there); a global switch, as ``without_n_frame`` is, raced under threads (another thread's mu took frame 4 meanwhile,
#: right but other bits; two threads restoring each other's old value could leave it off for good)
_LOCAL = threading.local()


def _n_frame_on() -> bool:
    """Frame 6 on: :data:`N_FRAME`, and not switched off in this thread (:data:`_LOCAL`)."""
    return N_FRAME and not getattr(_LOCAL, "n_frame_off", False)


@contextlib.contextmanager
def without_n_frame():
    """Within the block, ``pumpup.albedo`` takes GGX, Beckmann and Schlick's model by frame 4 (the rule on h's arc,
    :func:`_k_numeric`) instead of frame 6, and a lobe with F(Theta_min) by frame 5 (:func:`_k_lobe_fresnel`) instead of
    the frame of N (:func:`takes_lobe_n_frame`): the tests' and the benchmark's second 1-D path for them.  Not meant for
    concurrent toggling."""
    global N_FRAME
    old = N_FRAME
    N_FRAME = False
    try:
        yield
    finally:
        N_FRAME = old


#: frame 6 takes GGX with a Fresnel factor (:func:`_ggx_ring_f`) at the incidences where every ring's smallest wi.h, S =
#: sin((x + x_mu) / 2), is at least this (mu >= :data:`N_FRESNEL_MU_MIN`): F(c) has a square-root branch point at c = 0,
#: which for S below ~0.1 lies too close for the ring's RING_F_NMAX + 1 samples (measured: S = 0.05 was 1e-7 off at N = 64);
#: frame 4 takes the incidences below it
N_FRESNEL_S_MIN = 0.125
N_FRESNEL_MU_MIN = math.sin(2.0 * math.asin(N_FRESNEL_S_MIN))
#: ... and an index whose F(c) has no other singularity within this of [N_FRESNEL_S_MIN, 1] (:func:`n_fresnel_ok`)
N_FRESNEL_SING_MIN = 0.1


def n_fresnel_ok(ior: float, eta: float, k: float) -> bool:
    """Whether frame 6 takes the Fresnel factor of a dielectric ``ior`` or a conductor (``eta``, ``k``): F(c)'s singularities
    but c = 0 (the refracted cosine's branch points +- w, w = sqrt(1 - index^2); the parallel reflectance's poles, on the
    physical sheet in the left half-plane, :func:`fresnel_pole`) at least :data:`N_FRESNEL_SING_MIN` from the rings' range
    of c, [:data:`N_FRESNEL_S_MIN`, 1].  A dielectric with ior > 1 has w on the imaginary axis; ior <= 1 (a total
    reflection's kink at c = w real) and a near-kink conductor (w near the real segment) stay with frame 4."""
    if eta > 0.0:
        w = complex(1.0 - (eta * eta - k * k), -2.0 * eta * k) ** 0.5
        x = min(max(abs(w.real), N_FRESNEL_S_MIN), 1.0)
        return abs(complex(abs(w.real) - x, w.imag)) >= N_FRESNEL_SING_MIN
    return ior > 1.0


def takes_n_frame_operand(hint) -> bool:
    """Whether a 1/E scale (:meth:`pumpup.operators.compensate.Scaled.polar`) may build on ``hint`` in frame 6: GGX, Beckmann
    (F = 1) or Schlick, neither pumped nor scaled already, and without a Fresnel factor (GGX with F splits its mu with
    frame 4, which has no factor; F(Theta_min) with U not tested).  A pumped chain builds on more
    (:meth:`pumpup.operators.pumping.Pumped.polar`: GGX with F, and F(Theta_min) through :func:`with_fresnel_max`)."""
    return (hint is not None and hint.chain is None and hint.factor is None and not any(hint.fresnel) and hint.fmax is None
            and takes_n_frame(hint))


def takes_n_frame(hint) -> bool:
    """Whether :func:`albedo_1d` takes ``hint`` about N with the weight's azimuth in closed form (frame 6): GGX and
    Beckmann with F = 1 and alpha <= 1 (either Smith G, exact or Walter's G1), Schlick's model, and GGX with a Fresnel
    factor :func:`n_fresnel_ok` takes (pumped or not, not scaled; at mu >= :data:`N_FRESNEL_MU_MIN`, frame 4 below, or
    with a pumped chain the nested engine, :func:`one_d_part`)."""
    if not _n_frame_on() or hint.kind != "half" or hint.vcavity or hint.sqrt_cos:
        return False
    if any(hint.fresnel):  # (pumped too: g per node; below N_FRESNEL_MU_MIN the nested engine, one_d_part)
        return (hint.smith is not None and hint.smith[0] == 1 and hint.smith[3] <= 1.0 and hint.p == 0.0
                and hint.factor is None and n_fresnel_ok(*(float(x) for x in hint.fresnel)))
    if hint.schlick is not None:
        return hint.p == 0.0 and 0.0 < hint.schlick <= 1.0
    return hint.smith is not None and hint.smith[3] <= 1.0 and hint.p == 0.0


#: a lobe with 000 eq. 28's F(Theta_min) (metal, the fresnel wrapper of a lobe) is integrated about N (the pumped lobe's
#: frame with g = 1, :func:`_integrate_chain`) for n at least this, and in the lobe frame (frame 5) below it, where the ring
#: table leaves the pieces next to kappa = 1 to quadrature and the elevation is graded towards x_s (measured: n = 1 took 4 x
#: frame 5's time, n = 7.5 0.8 x, n = 20 0.17 x)
LOBE_N_MIN = 8.0  # (RING_SMOOTH_N)


def takes_lobe_n_frame(hint) -> bool:
    """Whether :func:`albedo_1d` takes a lobe hint with a Fresnel factor (and no chain) about N (:func:`_integrate_chain`
    with g = 1) instead of frame 5 (:func:`_k_lobe_fresnel`): n >= :data:`LOBE_N_MIN` and frame 6's switch on
    (:func:`without_n_frame`)."""
    return _n_frame_on() and hint.kind == "lobe" and hint.chain is None and any(hint.fresnel) and hint.n >= LOBE_N_MIN


# --- pumped Phong-family BRDFs: the frame of N -------------------------------------------------


@njit(cache=True, nogil=True, inline="always")
def _ring_f(n, kappa, phi):  # pragma: no cover - compiled
    """(1 - kappa sin^2(phi / 2))_+^n as exp(n log1p(-kappa sin^2(phi / 2))): accurate for any n (a power
    of A + B cos(phi) lost n ulp, 2.2e-13 for n = 2000, measured)."""
    sp = math.sin(0.5 * phi)
    omu = kappa * sp * sp
    return math.exp(n * math.log1p(-omu)) if omu < 1.0 else 0.0


@njit(cache=True, nogil=True)
def _ring_rule(n, kappa, lo, hi, nodes, wk, wg, ibuf):  # pragma: no cover - compiled
    """(value, |K - G|) of the rule on phi in [lo, hi] for :func:`_ring_f`."""
    h = hi - lo
    for j in range(nodes.shape[0]):
        ibuf[j] = _ring_f(n, kappa, lo + h * nodes[j])
    k, diff, asc, ab = rule_sums(ibuf, wk, wg)
    return k * h, diff * h


@njit(cache=True, nogil=True)
def _ring_quad(n, kappa, itol, nodes, wk, wg, ibuf, iwork):  # pragma: no cover - compiled
    """(V, its error): V(kappa) = integral over phi in (-pi, pi] of (1 - kappa sin^2(phi / 2))_+^n,
    kappa in [0, 2], by the 10/21 rule, globally adaptive, to the relative error ``itol``.

    The integrand f decreases on the half-arc [0, phi0] (phi0 = pi, or where 1 - kappa sin^2(phi / 2)
    = 0) from its peak f(0) = 1, of width sigma = sqrt(2 / (n kappa)) (f ~ exp(-(phi / sigma)^2 / 2)).
    The half-arc is cut at sigma (1, 2, 3, 4, 6, 8, 11, 15, ...) until the rest is at most
    (phi0 - c) f(c) <= 1e-18 sigma f(sigma) (f decreases: a bound, added to the error, its value left
    out): a rule on a piece that starts several widths out sees zeros at its nodes (n = 1e6,
    kappa = 0.95, with one piece beyond 4 sigma: 6.3e-5 off, estimate 2.6e-15)."""
    phi0 = math.pi if kappa <= 1.0 else 2.0 * math.asin(1.0 / math.sqrt(kappa))
    if n == 0.0:
        return 2.0 * phi0, 8.0 * EPS * phi0
    lo, hi, val, err = iwork[0], iwork[1], iwork[2], iwork[3]
    sig = math.sqrt(2.0 / (n * kappa)) if kappa > 0.0 else math.inf
    floor = 1e-18 * min(sig, phi0) * _ring_f(n, kappa, min(sig, phi0))
    nint = 0
    a = 0.0
    k = 1.0
    tail = 0.0
    while True:
        b = min(phi0, k * sig)
        lo[nint], hi[nint] = a, b
        val[nint], err[nint] = _ring_rule(n, kappa, a, b, nodes, wk, wg, ibuf)
        nint += 1
        if b >= phi0:
            break
        fb = _ring_f(n, kappa, b)
        if (phi0 - b) * fb <= floor or nint >= lo.shape[0] // 2:
            tail = (phi0 - b) * fb  # f decreases beyond b
            break
        a = b
        k = k + 1.0 if k < 4.0 else math.floor(1.35 * k)
    while True:
        tot, e, worst = _tally(val, err, nint, 0.0, tail)
        if e <= itol * tot or nint >= lo.shape[0]:
            return 2.0 * tot, 2.0 * e + 16.0 * EPS * tot
        mid = 0.5 * (lo[worst] + hi[worst])
        lo[nint], hi[nint] = mid, hi[worst]
        hi[worst] = mid
        val[worst], err[worst] = _ring_rule(n, kappa, lo[worst], mid, nodes, wk, wg, ibuf)
        val[nint], err[nint] = _ring_rule(n, kappa, mid, hi[nint], nodes, wk, wg, ibuf)
        nint += 1


@njit(cache=True)
def _ring_values(n, kappa, itol, nodes, wk, wg):  # pragma: no cover - compiled
    """:func:`_ring_quad` at every kappa: (values, errors)."""
    ibuf = np.empty(nodes.shape[0])
    iwork = np.empty((4, 4 * INNER_MAX))
    val = np.empty(kappa.shape[0])
    err = np.empty(kappa.shape[0])
    for i in range(kappa.shape[0]):
        val[i], err[i] = _ring_quad(n, kappa[i], itol, nodes, wk, wg, ibuf, iwork)
    return val, err


@njit(cache=True, nogil=True, inline="always")
def _ring_at(kappa, kb, kc, keps):  # pragma: no cover - compiled
    """(V(kappa), its error) from the table of :func:`ring_table`: the piece by bisection of the
    breaks ``kb``, its Chebyshev series ``kc[piece]`` by Clenshaw's recurrence.  Inlined where it is
    called."""
    a = 0
    b = kb.shape[0] - 1
    while b - a > 1:
        c = (a + b) >> 1
        if kappa >= kb[c]:
            a = c
        else:
            b = c
    x = (2.0 * kappa - kb[a] - kb[a + 1]) / (kb[a + 1] - kb[a])
    b1 = 0.0
    b2 = 0.0
    for k in range(kc.shape[1] - 1, 0, -1):
        b1, b2 = 2.0 * x * b1 - b2 + kc[a, k], b1
    v = x * b1 - b2 + kc[a, 0]
    return v, keps[a] * v


#: the ring table's Chebyshev degree per piece and relative tolerance (pieces bisected until met)
RING_DEGREE = 16
RING_TOL = 1e-14
#: a piece of the ring table narrower than this that misses RING_TOL is computed by quadrature
#: wherever it is needed (near kappa = 1 for small n)
RING_MIN_WIDTH = 1e-6
#: the relative tolerance of V by quadrature (:func:`_ring_quad`): the table's values, and the pieces left to it
RING_QUAD_RTOL = 1e-15


@functools.lru_cache(maxsize=64)
def ring_table(n: float) -> tuple:
    """(breaks, Chebyshev coefficients per piece, relative error per piece) of V(kappa) on [0, 2]
    (:func:`_ring_quad`) for the lobe exponent ``n``: the lobe u^n integrated over a circle N.wo = t
    is (A + B)^n V(2 B / (A + B)), u = A + B cos(phi) = (A + B)(1 - kappa sin^2(phi / 2)).

    Pieces: the octaves of kappa from 2 down to about 1 / (8 n), and [0, that]; on each a Chebyshev
    interpolant of degree :data:`RING_DEGREE` at the Chebyshev points, bisected until it matches V
    to :data:`RING_TOL` (relative) at 2 (degree + 1) + 1 test points.  The relative error of a piece:
    twice its largest miss, plus the values' own quadrature error (:data:`RING_QUAD_RTOL`), plus 4 ulp.  Near
    kappa = 1, where the arc stops being the whole circle, V has a term |kappa - 1|^(n + 1/2): a
    piece narrower than :data:`RING_MIN_WIDTH` that still misses gets the error -1, which tells the
    kernel to compute V there by quadrature.  Cached per n."""
    n = float(n)
    deg = RING_DEGREE
    if n == 0.0:  # (V = 2 phi0 in closed form, :func:`_x_rule`: no table)
        return np.array([0.0, 2.0]), np.zeros((1, deg + 1)), np.zeros(1)
    br = [2.0]
    k = 1.0
    while k > 1.0 / (8.0 * max(n, 1e-300)) and k > 1e-300:
        br.append(k)
        k *= 0.5
    br.append(0.0)
    br = sorted(br)
    xk = np.cos(np.pi * (np.arange(deg + 1) + 0.5) / (deg + 1))
    tt = np.linspace(-1.0, 1.0, 2 * (deg + 1) + 1)
    nodes, wk, wg = _RULES["gk21"]
    todo = list(zip(br[:-1], br[1:]))
    done = []
    while todo:
        lo = np.array([a for a, _ in todo])
        hi = np.array([b for _, b in todo])
        center, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
        x = np.concatenate([xk, tt])
        v, e = _ring_values(n, (center[:, None] + half[:, None] * x[None, :]).ravel(), RING_QUAD_RTOL, nodes, wk, wg)
        v, e = v.reshape(len(lo), -1), e.reshape(len(lo), -1)
        todo = []
        for i in range(len(lo)):
            coef = np.polynomial.chebyshev.chebfit(xk, v[i, :deg + 1], deg)
            miss = np.max(np.abs(np.polynomial.chebyshev.chebval(tt, coef) / v[i, deg + 1:] - 1.0))
            if miss <= RING_TOL or hi[i] - lo[i] <= RING_MIN_WIDTH:
                eps = 2.0 * miss + np.max(e[i] / v[i]) + 4.0 * np.finfo(float).eps if miss <= RING_TOL else -1.0
                done.append((lo[i], hi[i], coef, eps))
            else:
                todo += [(lo[i], center[i]), (center[i], hi[i])]
    done.sort(key=lambda r: r[0])
    return (np.array([r[0] for r in done] + [done[-1][1]]), np.ascontiguousarray([r[2] for r in done]),
            np.array([r[3] for r in done]))


@njit(cache=True, nogil=True)
def _x_rule(n, p, mu, s, lo, hi, chain, kb, kc, keps, nodes, wk, wg, buf, ibuf, iwork, fr, mode):  # pragma: no cover
    """(value, error) of the rule on the elevation x of wo in [lo, hi] for
    t / (max(mu, t)^p g(mu, t)) W(t) cos(x), t = N.wo = sin(x) (001 eq. 16 with 000 eq. 7, 12;
    d omega = dt d phi), g the product of the chain's levels exactly as the BRDF divides by it, and
    W(t) the lobe u^n integrated over the circle N.wo = t: u = A + B cos(phi), A = mu t, B = s cos(x),
    W = (A + B)^n V(kappa), kappa = 2 B / (A + B), A + B = cos(x - x_mu) (x_mu the elevation of the
    lobe's axis; (A + B)^n = exp(n log1p(-2 sin^2((x - x_mu) / 2))), accurate for any n), V from
    the ring table (:func:`ring_table`, its errors summed with the Kronrod weights); with ``fr`` = (1, eta, k) times
    000 eq. 28's F(max(mu, t)) (a pumped metal, or the fresnel wrapper of a pumped lobe).  Without a chain (None: g = 1,
    a metal's lobe, :func:`chain_cut_matrix`) the error is QUADPACK's calibration of |K - G| (``mode``) instead of
    CHAIN_SAFETY |K - G| (which is for g's splines)."""
    h = hi - lo
    ie = 0.0
    xmu = math.atan2(mu, s)
    for j in range(nodes.shape[0]):
        x = lo + h * nodes[j]
        t = math.sin(x)
        ct = math.cos(x)
        # g_1 ... g_k as the chain kernel divides by it (pumpup.operators.pumping._chain_kernel): the product
        # table where it applies, else level by level (written out: an inlined function that calls
        # the inlined look-ups ran 20 x slower, measured)
        g = 1.0  # (no chain: a metal's lobe)
        if chain is not None:
            if min(mu, t) > chain[13]:
                g = g_product(max(mu, t), chain[14], chain[15], chain[16], chain[17])
            else:
                g = g_levels(max(mu, t), min(mu, t), chain[0], chain[1], chain[2], chain[3], chain[4], chain[5], chain[6],
                              chain[7], chain[8], chain[9], chain[10], chain[11], chain[12])
        if p == 0.0:
            f = t * ct / g
        elif p == 1.0:
            f = t * ct / (max(mu, t) * g)
        else:
            f = t * ct / (max(mu, t) ** p * g)
        if fr[0] != 0.0:
            f *= _fresnel_real(max(mu, t), fr[1], fr[2])  # 000 eq. 28, as the kernels compute it
        sx = math.sin(0.5 * (x - xmu))
        d1 = 2.0 * sx * sx
        kappa = min(2.0 * s * ct / (1.0 - d1), 2.0)
        if n == 0.0:
            v = 2.0 * (math.pi if kappa <= 1.0 else 2.0 * math.asin(1.0 / math.sqrt(kappa)))
            ve = 8.0 * EPS * v
        else:
            v, ve = _ring_at(kappa, kb, kc, keps)
            if ve < 0.0:  # (a piece the table leaves to quadrature)
                v, ve = _ring_quad(n, kappa, RING_QUAD_RTOL, nodes, wk, wg, ibuf, iwork)
            an = math.exp(n * math.log1p(-d1))
            v *= an
            ve *= an
        buf[j] = f * v
        ie += wk[j] * f * ve
    k, diff, asc, ab = rule_sums(buf, wk, wg)
    if chain is None:
        return k * h, calibrated(diff * h, asc * h, ab * h, mode) + ie * h
    return k * h, CHAIN_SAFETY * diff * h + ie * h


@njit(cache=True, nogil=True)
def _integrate_chain(n, p, mu_arr, rtol, atol_arr, max_intervals, rounding, nodes, wk, wg, n_init, cuts, ncut, chain,
                      kb, kc, keps, fr, mode, val, err, conv, evals):  # pragma: no cover
    """Adaptive 10/21 quadrature over the elevation of wo of a pumped lobe (:func:`_x_rule`) for every
    mu, from the pieces between ``cuts[q, :ncut[q]]`` (:func:`chain_cuts`), each ``n_init`` intervals to
    start; ``kb``, ``kc``, ``keps`` the ring table of the lobe's exponent (:func:`ring_table`); ``fr`` the Fresnel
    factor's (on, eta, k) (:func:`_x_rule`)."""
    # (room for every piece's first intervals besides max_intervals bisections: a pumped metal near grazing incidence has
    # ~100 pieces, more than the 64 spare slots)
    cap, pk, t0, t1, kv, ke, buf, ibuf, iwork, itol = _buffers(max_intervals + cuts.shape[1] * n_init, nodes, nodes, rtol)
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        npc = ncut[q] - 1
        m = 0
        for i in range(npc):
            a_, b_ = cuts[q, i], cuts[q, i + 1]
            if b_ <= a_:
                continue
            for j in range(n_init):
                pk[m] = i
                t0[m] = a_ + (b_ - a_) * j / n_init
                t1[m] = a_ + (b_ - a_) * (j + 1.0) / n_init if j + 1 < n_init else b_
                kv[m], ke[m] = _x_rule(n, p, mu, s, t0[m], t1[m], chain, kb, kc, keps, nodes, wk, wg, buf, ibuf, iwork, fr, mode)
                m += 1
        start = m
        while True:
            tot, e, r, worst, ok = _status(kv, ke, m, 0.0, rounding, rtol, atol_arr[q])
            # (the reported error e + r within the tolerance, unless e is down to the rounding)
            ok = ok and (e <= r or e + r <= max(rtol * abs(tot), atol_arr[q]))
            if ok or m - start >= max_intervals or m >= cap:
                break
            i, a_, mid, b_ = _bisect(pk, t0, t1, worst, m)
            kv[worst], ke[worst] = _x_rule(n, p, mu, s, a_, mid, chain, kb, kc, keps, nodes, wk, wg, buf, ibuf, iwork, fr, mode)
            kv[m], ke[m] = _x_rule(n, p, mu, s, mid, b_, chain, kb, kc, keps, nodes, wk, wg, buf, ibuf, iwork, fr, mode)
            m += 1
        val[q] = tot
        err[q] = e + r
        conv[q] = ok
        evals[q] = nodes.shape[0] * (m + (m - start))


def chain_cuts(levels, n: float, mu: float, fresnel=None, chain: bool = True) -> np.ndarray:
    """The breakpoints in the elevation x of wo (N.wo = sin x) of a pumped lobe at incidence mu:
    0, pi/2, the levels of g (``levels``), N.wo = mu (max(mu, N.wo)), N.wo = s (u > 0 on the whole
    circle above it), the lobe's peak theta_o = theta_i +- k / sqrt(n), k = 3, 8, 13 (u^n ~
    exp(-n alpha^2 / 2)), N.wo = 2^-(1 + 2k) (:data:`GRADE`), every pi / 16 (:data:`X_PIECES`), and for
    n < :data:`RING_SMOOTH_N` a grading towards x_s; with ``fresnel`` = (eta, k), N.wo = x0 -+ y0 3^j about F's branch
    point and rho 3^j towards its pole near 0 (as frame 5's arcs, :func:`_k_lobe_fresnel`; the pole's only where rho <
    :data:`LOBE_F_WIDE`); x = atan2(L, sqrt(1 - L^2)) keeps levels near 1 to full precision.  ``chain`` False (a metal's
    lobe about N, g = 1): without g's grading in N.wo and the pi / 16 cuts.  The engine computes them compiled, for every
    mu at once (:func:`chain_cut_matrix`); this is their reference."""
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    L = np.asarray(levels, dtype=np.float64).reshape(-1)
    L = L[(L > 0.0) & (L < 1.0)]
    x_mu, x_s = math.atan2(mu, s), math.atan2(s, mu)
    x = [0.0, 0.5 * math.pi, x_mu, x_s]
    x.extend(np.arctan2(L, np.sqrt((1.0 - L) * (1.0 + L))))
    if n > 0.0:
        # (beyond 13 / sqrt(n), (A + B)^n = cos^n(x - x_mu) <= exp(-84.5): no rule there sees zeros where
        # the lobe is not negligible)
        for k in (3.0, 8.0, 13.0):
            x.extend([x_mu - k / math.sqrt(n), x_mu + k / math.sqrt(n)])
    if 0.0 < n < RING_SMOOTH_N:
        # W has a term |x - x_s|^(n + 1/2) at x_s (the ring table's kappa = 1): for small n the pieces
        # near it are graded towards it, so that none lies within a fraction of its width of it (stretched
        # Phong n = 0.5 at mu = 0.5, rtol 1e-8: a piece ending 0.002 short of it was 1.8e-8 off, estimate 3.4e-9)
        d = 0.5
        while d > 1e-9:
            x.extend([x_s - d, x_s + d])
            d *= 0.25
    if chain:
        # g's tables are splines in ln(N.wo): N.wo = 2^-(1 + 2 k) down to a quarter of mu or of the lowest level
        floor = max(0.25 * min(mu, L.min(initial=1.0)), GRADE_FLOOR)
        t = 0.5
        while t > floor:
            x.append(math.asin(t))
            t *= GRADE
        x.extend(np.arange(1, X_PIECES) * (0.5 * math.pi / X_PIECES))
    if fresnel is not None:
        x0, y0 = fresnel_branch(*fresnel)
        rho = fresnel_pole(*fresnel)
        js = 3.0 ** np.arange(LOBE_F_CUTS)
        t = np.concatenate([x0 + y0 * js, x0 - y0 * js, rho * js if rho < LOBE_F_WIDE else []])
        t = t[(t > 0.0) & (t < 1.0)]
        x.extend(np.arctan2(t, np.sqrt((1.0 - t) * (1.0 + t))))
    x = np.unique(np.asarray(x))
    return x[(x >= 0.0) & (x <= 0.5 * math.pi)]


#: room in :func:`_chain_cut_matrix` per mu besides the levels: 4 fixed cuts, 6 about the peak, 2 x 15 towards x_s, 20
#: graded in N.wo (GRADE down to GRADE_FLOOR), X_PIECES - 1, 3 x LOBE_F_CUTS about F's branch point and pole
CHAIN_CUTS_ROOM = 96


@njit(cache=True, nogil=True)
def _chain_cut_matrix(n, mu_arr, lev, nlev, chain, fres, x0, y0, rho):  # pragma: no cover - compiled; see chain_cuts
    """(cut, ncut): :func:`chain_cuts` for every mu, compiled (it was a quarter to a half of a pumped or 1/E-scaled table's
    time in Python): the levels ``lev[q, :nlev[q]]``, ``chain`` (g's grading in N.wo and the pi / 16 cuts), with ``fres``
    F's branch point x0 - i y0 and pole scale rho (:func:`fresnel_branch`, :func:`fresnel_pole`); sorted, duplicates
    dropped, as chain_cuts (np.unique) has them."""
    half = 0.5 * math.pi
    cap = CHAIN_CUTS_ROOM + lev.shape[1]
    cut = np.zeros((mu_arr.shape[0], cap))
    ncut = np.zeros(mu_arr.shape[0], np.int64)
    x = np.empty(cap)
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        x_mu, x_s = math.atan2(mu, s), math.atan2(s, mu)
        x[0], x[1], x[2], x[3] = 0.0, half, x_mu, x_s
        m = 4
        lmin = 1.0
        for i in range(nlev[q]):
            L = lev[q, i]
            if 0.0 < L < 1.0:
                x[m] = math.atan2(L, math.sqrt((1.0 - L) * (1.0 + L)))
                m += 1
                lmin = min(lmin, L)
        if n > 0.0:
            for k in (3.0, 8.0, 13.0):
                x[m], x[m + 1] = x_mu - k / math.sqrt(n), x_mu + k / math.sqrt(n)
                m += 2
        if 0.0 < n < RING_SMOOTH_N:
            d = 0.5
            while d > 1e-9:
                x[m], x[m + 1] = x_s - d, x_s + d
                m += 2
                d *= 0.25
        if chain:
            floor = max(0.25 * min(mu, lmin), GRADE_FLOOR)
            t = 0.5
            while t > floor:
                x[m] = math.asin(t)
                m += 1
                t *= GRADE
            for i in range(1, X_PIECES):
                x[m] = i * (0.5 * math.pi / X_PIECES)
                m += 1
        if fres:
            for side in range(3):
                if side == 2 and not rho < LOBE_F_WIDE:
                    break
                for j in range(LOBE_F_CUTS):
                    sc = 3.0 ** j
                    t = x0 + y0 * sc if side == 0 else (x0 - y0 * sc if side == 1 else rho * sc)
                    if 0.0 < t < 1.0:
                        x[m] = math.atan2(t, math.sqrt((1.0 - t) * (1.0 + t)))
                        m += 1
        x[:m].sort()
        c = 0
        for i in range(m):
            if 0.0 <= x[i] <= half and (c == 0 or x[i] > cut[q, c - 1]):
                cut[q, c] = x[i]
                c += 1
        ncut[q] = c
    return cut, ncut


def chain_cut_matrix(levels, n: float, mu: np.ndarray, fresnel=None, chain: bool = True) -> tuple:
    """(cut, ncut): :func:`chain_cuts` (``levels(mu)`` or, with None, no levels) at every mu, by the compiled
    :func:`_chain_cut_matrix`."""
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    if levels is None:
        lev, nlev = np.zeros((mu.size, 0)), np.zeros(mu.size, np.int64)
    else:
        lev, nlev = _cut_matrix([np.asarray(levels(float(m)), dtype=np.float64).reshape(-1) for m in mu])
    x0, y0, rho = (*fresnel_branch(*fresnel), fresnel_pole(*fresnel)) if fresnel is not None else (0.0, 0.0, math.inf)
    return _chain_cut_matrix(float(n), mu, lev, nlev, bool(chain), fresnel is not None, x0, y0, rho)


_RULES = {"gk15": (_NODES, _WK, _WG), "gk21": (NODES21, WK21, WG21)}
#: a pumped lobe's error estimate per interval: CHAIN_SAFETY |K - G| of the 10/21 rule.  g's tables are
#: splines whose 5th derivatives jump at every node: no cut marks them, and across many of them |K - G|
#: can fall well below the true error (2-level g1 Phong n = 20 at mu = 0.7133, rtol 1e-9: a piece over
#: the lobe's flank, 0.67 rad wide, was 3.5e-11 off with a raw |K - G| of 1e-12; its eighths were each
#: right to 1e-17).  So the elevation is also cut every pi / 16 (X_PIECES), where such errors (~ width^6)
#: are far below the rounding term, and the estimate is 3 |K - G|.  Measured over 15 chains (g1 and g2,
#: 1-4 levels, n from 0.5 to 5000, p in {0, 0.5, 1}, retro), 351 mu from 1e-10 to 1 and rtol 1e-6 ...
#: 1e-12, against the lobe frame's engine at 1e-13 on the same BRDFs: the worst true error was 0.49 of
#: the estimate (one case excepted, where the lobe frame was the one off: retro n = 10 at mu = 0.3705,
#: 9e-13, by the nested engine and this one at 1e-13); with the raw |K - G| it was 1.41, without the
#: pi / 16 cuts 4.19.  `python scripts/calibration/pumped_calibration.py` repeats it against the nested engine at
#: 1e-13 (in the tree): worst 0.50 over 149 mu.
CHAIN_SAFETY = 3.0
#: the rule of a pumped lobe's quadrature over the elevation (and of the ring table's)
CHAIN_RULE = "gk21"
#: graded cuts of a pumped lobe's elevation: N.wo = 1/2, 1/2 GRADE, 1/2 GRADE^2, ... down to a quarter of
#: mu or of the lowest level of g, but not below GRADE_FLOOR (g's tables are splines in ln(N.wo))
GRADE = 0.25
GRADE_FLOOR = 1e-12
#: below this lobe exponent the elevation is also graded towards x_s (:func:`chain_cuts`)
RING_SMOOTH_N = 8.0
#: the elevation of a pumped lobe is cut every pi / (2 X_PIECES) (see CHAIN_SAFETY)
X_PIECES = 8
#: first intervals per piece of a pumped lobe's elevation
N_INIT_CHAIN = 1


#: the radial weights of :class:`Polar` (``_integrate``'s codes)
_RADIAL = {"power": 0, "beckmann": 1, "ggx": 2}

#: the half-vector frame takes mu >= this (below it mu / (2 u), tan^2(psi / 2) m^2 and their kin underflow; the nested
#: engine takes such batches, as before the half frame)
HALF_MU_MIN = 1e-100

#: the 1-D path itself (``without_1d`` switches it off and leaves the nested engine on)
ONE_D = True


@contextlib.contextmanager
def without_1d():
    """Within the block, ``pumpup.albedo`` ignores the 1-D path only: the models that have it go to the
    nested engine (``pumpup.engine.nested``), as before they had it (the tests' and the calibration's
    second engine for them).  Not meant for concurrent toggling."""
    global ONE_D
    old = ONE_D
    ONE_D = False
    try:
        yield
    finally:
        ONE_D = old


def numeric_params(hint: Polar) -> np.ndarray:
    """Frame 4's parameter array ``mp`` (:data:`MP_SIZE` slots) of a :class:`Polar` hint with ``smith`` or a V-cavity
    lobe with ``fresnel`` (zeros but the Walter level -1 otherwise); P(mu) is set per mu by :func:`_integrate`."""
    mp = np.zeros(MP_SIZE)
    mp[9] = -1.0
    mp[5:8] = hint.fresnel
    mp[10] = fresnel_scale(*(float(x) for x in hint.fresnel))
    mp[11] = math.inf
    mp[12] = 1e-16  # (albedo_1d sets the tolerance)
    if hint.smith is not None:
        mp[0], mp[1:5] = SMITH, hint.smith
        mp[11] = hint.smith[3]
        if hint.fresnel[1] > 0.0:  # a conductor's branch point, for :func:`_pieces`' cuts (frame 6 reuses 13, 14: n_params)
            mp[13], mp[14] = fresnel_branch(float(hint.fresnel[1]), float(hint.fresnel[2]))
        if hint.smith[1] == 1:
            from ..physics.microfacet import walter_level

            mp[9] = walter_level(float(hint.smith[3]))
    elif hint.kind == "lobe" and any(hint.fresnel):  # frame 5: F(max(N.wi, N.wo)) of a conductor (eta, k)
        mp[0] = LOBE_F
        eta, k = float(hint.fresnel[1]), float(hint.fresnel[2])
        mp[13], mp[14] = fresnel_branch(eta, k)
        mp[15] = fresnel_pole(eta, k)
        cb, ok = fresnel_brewster(eta, k)
        mp[16], mp[17], mp[18] = cb.real, cb.imag, 1.0 if ok else 0.0
        mp[19] = abs(complex(eta * eta - k * k + 1.0, 2.0 * eta * k))  # |e^2 + 1|
        mp[20] = 1.0 if LOBE_F_GAUSS else 0.0
    elif hint.schlick is not None:
        r = float(hint.schlick)
        mp[0], mp[4], mp[11] = SCHLICK, r, (r / (1.0 - r) if r < 1.0 else math.inf)
    else:
        mp[0] = VCAVITY_F
    return mp


def numeric_integrand(brdf, mu: float, u, rtol: float = 1e-13):
    """(K(u), error) of frame 4 (:func:`_k_numeric`, ``u`` the values of N.h) or, for a lobe hint with a Fresnel factor,
    frame 5 (:func:`_k_lobe_fresnel`, ``u`` the values of cos(alpha) about R) for ``brdf``'s hint at N.wi = ``mu``, at
    relative tolerance ``rtol`` (the kernels as the engine calls them; for the tests)."""
    hint = brdf.polar()
    mp = numeric_params(hint)
    s = math.sqrt((1.0 - mu) * (1.0 + mu))
    if mp[0] == SMITH:
        mp[8] = _projected(s, 0.0, mu, int(mp[1]), int(mp[2]), mp[4])
    u = np.atleast_1d(np.asarray(u, dtype=float))
    ibuf, iwork = np.empty(_NODES.shape[0]), np.empty((4, INNER_MAX))
    val, err = np.empty(u.shape), np.empty(u.shape)
    if mp[0] == LOBE_F:
        _lobe_f_prepare(mp, mu)
    for i, v in enumerate(u):
        sa = math.sqrt((1.0 - v) * (1.0 + v))
        if mp[0] == LOBE_F:
            val[i], err[i] = _k_lobe_fresnel(mp, float(hint.p), mu, (mu - s) * (mu + s), float(v), 1.0 - float(v), sa, rtol,
                                             0.0, _NODES, _WK, _WG, mode_code(), ibuf, iwork)
        else:
            val[i], err[i] = _k_numeric(mp, mu, s, math.atan2(mu, s), float(v), sa, rtol, 0.0, _NODES, _WK, _WG,
                                        mode_code(), ibuf, iwork)
    return val, err


def _cut_matrix(cuts: list) -> tuple:
    """(cut, ncut): the per-mu arrays of cuts as one zero-padded matrix and their lengths."""
    ncut = np.array([len(c) for c in cuts], np.int64)
    cut = np.zeros((len(cuts), int(ncut.max(initial=2))))
    for q, c in enumerate(cuts):
        cut[q, :len(c)] = c
    return cut, ncut


def _hint(brdf):
    """``brdf``'s :class:`Polar` hint, or None (none, or the 1-D path off)."""
    polar = getattr(brdf, "polar", None) if ENABLED and ONE_D else None
    return polar() if polar is not None else None


def takes_1d_path(brdf) -> bool:
    """Whether :func:`albedo_1d` takes ``brdf`` (it has a :class:`Polar` hint and the path is on) at every mu."""
    hint = _hint(brdf)
    return hint is not None and not _partial(hint)


def _partial(hint) -> bool:
    """Whether frame 6 takes ``hint`` at mu >= :data:`N_FRESNEL_MU_MIN` only, and the nested engine the rest: a pumped GGX
    with a Fresnel factor (frame 4, which takes GGX with F below it, has no chain)."""
    return any(hint.fresnel) and hint.chain is not None and takes_n_frame(hint)


def one_d_part(brdf, mu: np.ndarray):
    """The mu (a mask) at which :func:`albedo_1d` takes ``brdf`` where it declines the batch as a whole, or None: a pumped
    GGX with a Fresnel factor at mu >= :data:`N_FRESNEL_MU_MIN` (:func:`_partial`; issue 14's twenty-second session: a
    257-point table of 1-level g2 pumped GGX 0.1 with eta 0.2, k 3 took the nested engine 0.70 s, now 0.28 s).
    ``pumpup.albedo`` gives the rest to the nested engine."""
    hint = _hint(brdf)
    if hint is None or not _partial(hint):
        return None
    return np.asarray(mu) >= N_FRESNEL_MU_MIN


def axis_albedo(n: float, nu: np.ndarray, scale: np.ndarray, rtol: float, atol: float, max_regions: int):
    """(value, error, converged, evaluations) of a power lobe scale (A.wo)_+^n about an axis A at elevation nu = N.A
    (:meth:`pumpup.core.BRDF.lobe_axis`: Lafortune's lobe, 000 eq. 14, at any azimuth of wi), or None where the 1-D path
    is off.  Without max(N.L, N.V) the integrand depends on wi only through A, so the albedo is frame 0's p = 0 lobe
    about R with mu = nu (:func:`_k_closed`), times the scale.  The scale's rounding is added to the error: scale ~
    |v|^n with |v| from a few roundings, (4 n + 16) eps relative."""

    class _Axis:
        def polar(self):
            return Polar(n=float(n), p=0.0, scale=lambda m: scale)

    out = albedo_1d(_Axis(), nu, rtol, atol, max_regions)
    if out is None:
        return None
    val, err, conv, evals = out
    return val, err + (4.0 * n + 16.0) * EPS * np.abs(val), conv, evals


def albedo_1d(brdf, mu: np.ndarray, rtol: float, atol: float, max_regions: int):
    """(value, error, converged, evaluations) of the albedo of ``brdf`` at every mu (a 1-D float
    array), or None when the model has no :class:`Polar` hint (or the 1-D path is off)."""
    hint = _hint(brdf)
    if hint is None:
        return None
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    scale = np.broadcast_to(np.asarray(hint.scale(mu), dtype=np.float64), mu.shape)
    if not np.isfinite(scale).all():
        return None  # (an overflowing constant) the 2-D engine reports what the model returns
    if hint.kind == "constant":
        ulps = hint.ulps(mu) if callable(hint.ulps) else hint.ulps
        with np.errstate(invalid="ignore"):  # (inf ulps of a scale that underflowed to 0: e^(-s/mu) at mu = 5e-324)
            err = np.where(scale == 0.0, 0.0, ulps * np.finfo(float).eps * np.abs(scale))
        return scale.copy(), err, np.ones(mu.shape, bool), np.zeros(mu.shape, np.int64)
    if not 0.0 <= hint.p <= 1.0:
        raise ValueError(f"{brdf!r}: a Polar hint needs p in [0, 1], got {hint.p!r}")
    if hint.kind == "half" and mu.size and mu.min() < HALF_MU_MIN and not takes_n_frame(hint):
        return None  # (the half frame's breaks and arcs underflow there: the nested engine, as before)
    off_n = hint.kind == "half" and hint.chain is not None or hint.factor is not None or hint.fmax is not None
    if off_n and not takes_n_frame(hint):
        return None  # (a pumped half-vector, a 1/E-scaled model or F(Theta_min) off frame 6: the nested engine)
    if hint.kind == "half" and hint.p not in (0.0, 1.0):
        raise ValueError(f"{brdf!r}: a half-vector Polar hint needs p in {{0, 1}}, got p={hint.p!r}")
    if hint.vcavity and (hint.kind != "half" or hint.p != 0.0 or hint.sqrt_cos):
        raise ValueError(f"{brdf!r}: a Polar hint with vcavity needs kind 'half', p = 0 and no sqrt_cos")
    if hint.sqrt_cos and (hint.kind != "half" or hint.p != 0.0):
        raise ValueError(f"{brdf!r}: a Polar hint with sqrt_cos needs kind 'half' and p = 0, got {hint.kind!r}, p={hint.p!r}")
    if hint.radial not in _RADIAL or (hint.radial != "power" and (hint.kind != "half" or not hint.n > 0)):
        raise ValueError(f"{brdf!r}: a Polar hint's radial is 'power', or 'beckmann' or 'ggx' with kind 'half' and n = m > 0, "
                         f"got {hint.radial!r} (kind {hint.kind!r}, n {hint.n!r})")
    numeric = hint.smith is not None or hint.schlick is not None or (hint.vcavity and any(hint.fresnel))
    if hint.schlick is not None and (hint.kind != "half" or hint.p != 0.0 or hint.vcavity or hint.sqrt_cos
                                     or hint.smith is not None or hint.radial != "ggx" or not 0.0 < hint.schlick <= 1.0):
        raise ValueError(f"{brdf!r}: a Polar hint with schlick = r in (0, 1] needs kind 'half', p = 0, the 'ggx' weight "
                         f"and neither smith, vcavity nor sqrt_cos")
    if hint.smith is not None and (hint.kind != "half" or hint.p != 0.0 or hint.vcavity or hint.sqrt_cos
                                   or hint.radial == "power" or len(hint.smith) != 4):
        raise ValueError(f"{brdf!r}: a Polar hint with smith = (distribution, g1, shadowing, alpha) needs kind 'half', "
                         f"p = 0, the 'beckmann' or 'ggx' weight and neither vcavity nor sqrt_cos")
    lobe_f = hint.kind == "lobe" and any(hint.fresnel)
    if lobe_f and ((hint.p not in (0.0, 1.0) and hint.chain is None) or hint.fresnel[0] != 0.0 or not hint.fresnel[1] > 0.0
                   or not lobe_fresnel_ok(float(hint.fresnel[1]), float(hint.fresnel[2]), hint.chain is not None)):
        raise ValueError(f"{brdf!r}: a lobe's Polar fresnel = (0, eta, k) needs p in {{0, 1}} (any p with a chain), "
                         f"eta > 0 and a branch point lobe_fresnel_ok accepts, got p={hint.p!r}, fresnel={hint.fresnel!r}")
    if any(hint.fresnel) and not (hint.smith is not None or hint.vcavity or lobe_f):
        raise ValueError(f"{brdf!r}: a Polar hint's fresnel applies to a smith, vcavity or lobe hint only")
    jac = jacobi_rules(1.0 - hint.p) if 0.0 < hint.p < 1.0 else _NO_JACOBI
    val = np.empty(mu.shape)
    err = np.empty(mu.shape)
    conv = np.empty(mu.shape, bool)
    evals = np.empty(mu.shape, np.int64)
    # atol applies to the scaled albedo: per mu, atol / scale for the unscaled integral (inf where the scale is 0)
    atol_q = np.full(mu.shape, np.inf)
    np.divide(float(atol), np.abs(scale), out=atol_q, where=scale != 0)
    if takes_n_frame(hint) and any(hint.fresnel) and mu.size and mu.min() < N_FRESNEL_MU_MIN:
        # GGX with F: frame 6 where every ring's wi.h >= N_FRESNEL_S_MIN, frame 4 below (:func:`_ggx_ring_f`)
        if hint.chain is not None:
            return None  # (pumped: frame 4 has no chain; ``pumpup.albedo`` asks one_d_part for the mu frame 6 takes)
        low = mu < N_FRESNEL_MU_MIN
        _LOCAL.n_frame_off = True  # (this thread only: frame 4 for these)
        try:
            parts = [albedo_1d(brdf, mu[low], rtol, atol, max_regions)]
        finally:
            _LOCAL.n_frame_off = False
        if parts[0] is None:  # (mu < HALF_MU_MIN: frame 4's breaks underflow, the nested engine takes the model, as before)
            return None
        parts.append(albedo_1d(brdf, mu[~low], rtol, atol, max_regions))
        out = tuple(np.empty(mu.shape, dtype=x.dtype) for x in parts[0])
        for o, a_, b_ in zip(out, *parts):
            o[low], o[~low] = a_, b_
        return out
    if takes_n_frame(hint):  # frame 6: GGX and Beckmann with F = 1 or GGX with F, Schlick's model, about N (:func:`_integrate_n`)
        mp = n_params(hint)
        if hint.chain is None and hint.factor is None and hint.fmax is None:
            cut, ncut = np.zeros((len(mu), 0)), np.zeros(len(mu), np.int64)
        else:  # pumped or scaled: the kinks of g or U, its tables' grading and the pi / 16 cuts, as for a pumped lobe;
            # with F(Theta_min) (fmax) the cuts about its branch point and pole (its kink N.wo = mu: d = 0, a cut)
            cut, ncut = chain_cut_matrix(hint.levels, 0.0, mu, hint.fmax,
                                         chain=hint.chain is not None or hint.factor is not None)
        _integrate_n(mp, mu, float(rtol), atol_q, int(min(max_regions, 10000)), ROUNDING, *_RULES["gk21"], mode_code(),
                     hint.chain, hint.factor, cut, ncut, val, err, conv, evals)
    elif lobe_f and hint.chain is None and takes_lobe_n_frame(hint):  # a metal's lobe about N (:func:`_integrate_chain`, g = 1)
        fres = (float(hint.fresnel[1]), float(hint.fresnel[2]))
        cut, ncut = chain_cut_matrix(None, float(hint.n), mu, fres, chain=False)
        _integrate_chain(float(hint.n), float(hint.p), mu, float(rtol), atol_q, int(min(max_regions, 10000)), ROUNDING,
                         *_RULES[CHAIN_RULE], N_INIT_CHAIN, cut, ncut, None, *ring_table(float(hint.n)), np.array([1.0, *fres]),
                         mode_code(), val, err, conv, evals)
    elif hint.chain is None:
        # Ward's K (elliptic integrals) has a logarithmic term where h's circle starts to be cut (E(k^2) near
        # k^2 = 1), which no substitution here makes analytic: QUADPACK's calibration measured 4.4 x below the
        # true error there (m = 0.1, mu = 0.6088: 7.1e-13 against 1.5e-13, at every rtol), the raw |K - G| at most
        # 0.11 of it (7 m x 63 mu x rtol 1e-6 .. 1e-12 against the nested engine at 1e-13): Ward keeps the raw one
        mode = 0 if hint.sqrt_cos else mode_code()
        mp = numeric_params(hint)
        mp[12] = rtol
        if numeric:
            frame = 4
        elif lobe_f:
            frame = 5
        else:
            frame = (3 if hint.vcavity else 2 if hint.sqrt_cos else 1) if hint.kind == "half" else 0
        _integrate(frame, _RADIAL[hint.radial], float(hint.n), float(hint.p), mu, float(rtol), atol_q, int(min(max_regions, 10000)), ROUNDING,
                   *(_RULES[RULE]), mode, N_INIT, *_RULES["gk15"], jac, mp, val, err, conv, evals)
    else:  # a pumped lobe, about N
        fres = (float(hint.fresnel[1]), float(hint.fresnel[2])) if lobe_f else None
        fr = np.array([1.0 if lobe_f else 0.0, *(fres or (0.0, 0.0))])
        cut, ncut = chain_cut_matrix(hint.levels, float(hint.n), mu, fres)
        _integrate_chain(float(hint.n), float(hint.p), mu, float(rtol), atol_q, int(min(max_regions, 10000)), ROUNDING,
                         *_RULES[CHAIN_RULE], N_INIT_CHAIN, cut, ncut, hint.chain, *ring_table(float(hint.n)), fr, mode_code(), val, err,
                         conv, evals)
    return scale * val, np.abs(scale) * err, conv, evals
