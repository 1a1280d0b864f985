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
(:func:`_foreign_roots`; without it, stretched Phong n = 10 at mu = 0.866025 was 3.2e-12 off
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

The closed forms (p in {0, 1}) take the smaller of that estimate and a sharper one read from the decay of the rule's
own coefficients (:data:`pumpup.engine.outer_rule.DECAY_ROWS`, :func:`~pumpup.engine.outer_rule._gk_closed`): the 21
values' coefficients of degree 13 to 20 in the polynomials orthonormal for the Kronrod weights, in pairs of
consecutive degrees; where their largest ratio r from pair to pair is at most 1/2, the coefficients from degree 32 on,
which the rule does not integrate, are estimated as 10 E_20 r^6 (E_20 the last pair's size), r never below rho^-2 of
the nearest point where K(u) or u^n is singular (u = +-s, +-1, cos 2 theta_i and their images in z; the Bernstein
ellipse through it after the smoothing substitution): a singular term too small to show in the first 21 coefficients
still decays no faster than that.  QUADPACK's calibration is made for integrands that only just converge: near normal
incidence Phong n = 20's peak piece, e^-z K on z in [0, 14.6], has |K - G| = 4e-9 of the integral and a calibrated
5e-10 against a true error of 2e-16, so 95 of the 257 mu of its table at rtol 1e-10 were bisected for nothing; with the
sharper estimate none is (84.7 evaluations per mu instead of 99.2; stretched Phong n = 5000: 68 instead of 106).  The
peak's pieces are integrated first, and an interval whose QUADPACK error is already below a tenth of its share of the
tolerance keeps it (:data:`~pumpup.engine.outer_rule.DECAY_SHARE`).  ``scripts/calibration/error_calibration.py
--quick`` over the same references: no estimate below the true error, the largest ratio 0.06 as before, 90 % of the
ratios below 0.0079 (0.0065 with QUADPACK's alone).  ``python scripts/bench/bench_polar.py`` times the table with and
without it (``decay_estimate=False``, or ``pumpup.engine.routes.using(decay_estimate=False)``) against a fixed
Gauss-Legendre rule on the same pieces.

Pumped lobes (001 eq. 16): a pumped Phong-family BRDF f / (g_1 ... g_k) divides the lobe by g(mu,
N.wo), which for a fixed wi depends on wo through N.wo = t only (:meth:`pumpup.operators.pumping.Pumped.polar`,
``DivideByG``).  So the frame turns to N: with wo at elevation x (t = sin x) and azimuth phi,

    a(mu) / scale = integral_0^(pi/2) t cos(x) / (max(mu, t)^p g(mu, t)) W(t) dx,
    W(t) = integral over phi of u_+^n,  u = A + B cos(phi),  A = mu t,  B = s cos(x),

g is looked up once per node of x (the albedo engine divides by it: ``pumpup.physics.lookups.g_product``,
``g_levels``), and W, the lobe on the circle N.wo = t, is (A + B)^n V(kappa) with kappa = 2B / (A + B) in
[0, 2], u = (A + B)(1 - kappa sin^2(phi / 2)): V depends on n and kappa only, so it is tabulated once per n
(:func:`ring_table`: Chebyshev pieces to 1e-14, their errors carried; pieces next to kappa = 1, where V has a
term |kappa - 1|^(n + 1/2), computed by quadrature when they cannot be fitted; for n < 1 the quadrature takes
the arc's end, where the integrand's derivative is unbounded, in s = cos(phi / 2) = s0 + e^u), and A + B = cos(x - x_mu)
keeps (A + B)^n = exp(n log1p(-2 sin^2((x - x_mu) / 2))) accurate for any n (a plain power of A + B cos(phi)
lost n ulp: 2.2e-13 for n = 2000, measured).  The x integral (:func:`_integrate_chain`, adaptive 10/21) is cut
at the levels of g (``Pumped.lobe(mu).levels``), at N.wo = mu and s (V's kappa = 1), around the lobe's peak
theta_i +- 3, 8 and 13 / sqrt(n), at N.wo = 2^-(1 + 2k) (g's tables are splines in ln N.wo), every pi / 16, and
for n < 8 graded towards x_s (:func:`chain_cuts`).  g's splines have breakpoints no cut marks, so the estimate
per interval is ``CHAIN_SAFETY`` (3) times the raw |K - G| (measured: true error at most 0.49 of it over 15
chains, 351 mu from 1e-10 to 1, rtol 1e-6 ... 1e-12).  The lobe frame, with an adaptive rule on the arc for every
outer node, would look g up ~50 000 times per mu instead of ~400: the three tables of 3-level g2 pumped Phong n = 20
take 58-83 ms here against 180-230 ms there.
Checked in ``tests/engine/test_route_pumped_lobe.py`` against an independent quadrature about N (numpy's
level-by-level reference), the nested engine at rtol 1e-13 and the 2-D engine, and the ring table against
40-digit mpmath.

The Blinn family (reciprocal Blinn c (N.H)^n, 000 eq. 31; stretched Blinn c (N.H)^n / max(N.L, N.V),
eq. 32; Lewis's Phong-Blinn, 002 eq. 24) takes the same path in the frame of N for the half vector h
(``HalfVectorLobe``): with h at u = N.h = cos(alpha) and azimuth beta, d omega_o = 4 (wo.h) d omega_h,
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
``HalfVectorLobe(radial="beckmann")`` integrates it in t = tan^2(alpha) / m^2 (weight e^-t, :func:`_u_at` kind 2) up to
Z_MAX or the break of u_lo, cut at the same breaks.  Ward's model (000 eq. 34, sqrt(N.L N.V) in the
denominator; ``WardLobe``) has 4 (wi.h) sqrt(N.wo) on the arc instead: complete elliptic integrals
(:func:`_k_ward`, Carlson's R_F and R_D by the arithmetic-geometric mean), with 1 / sqrt(mu) in the scale; its K has a
logarithmic term where h's circle starts to be cut, so Ward keeps the raw |K - G| (QUADPACK's calibration measured 4.4 x
below the true error there).  The V-cavity microfacet models with F = 1 (Cook-Torrance, 001 eq. 9-10; Torrance-Sparrow
with D1 or D4, 002 eq. 10; ``VCavityLobe``) integrate 4 c G = 4 min(c, 2 u mu, 2 u N.wo) on the arc: a
minimum of three lines in c, so each range of c between their crossings contributes its arc length and its
integral of c (:func:`_k_vcavity`, with cancellation-free differences: near grazing incidence the integrand lives
on arcs of width ~mu), and the pieces' changes in u are breaks (:func:`_vcavity_breaks`); Torrance-Sparrow's D3 = b /
(cos^4 (1 + tan^2 / c3^2)^2) is the same azimuth under the GGX weight (``radial="ggx"``: z = ln(1 + tan^2(alpha) / m^2),
weight e^-z dz, :func:`_u_at` kind 3).  Pumped Blinn BRDFs stay on the nested engine (``Pumped.polar`` takes lobes about
R only).

Where the integrand over beta is a function of c alone but has no elementary integral (frame 4, :func:`_k_numeric`)
the arc is integrated by a rule: the Smith microfacet models (GGX, Beckmann, alpha <= 1: 4 c F(c) G / mu with
G = G1(mu) G1(N.wo) or the height-correlated form, Walter et al. 2007 eq. 20; ``SmithLobe``), the V-cavity
models with a Fresnel factor (4 F(c) min(c, 2 u mu, 2 u N.wo); ``VCavityLobe(fresnel=...)``) and Schlick's
model (4 c N.wo / (r + (1 - r) N.wo), 000 eq. 36, under the GGX weight with alpha = sqrt(r); ``SchlickLobe(r)``).
Ashikhmin and Shirley's lobe (4 F(c) min(N.wo, mu) / mu with Schlick's F, ``AshikhminShirleyLobe``) takes this frame
too, but its arc is a polynomial in 1 - c = g + 2 b sin^2(beta / 2) (g = 1 - cos(theta_i - alpha) >= 0), which
:func:`~pumpup.engine.half_arc._k_ashikhmin` integrates in closed form from the moments W_k of sin^(2k)(beta / 2),
sums of terms >= 0; the band below the kink N.wo = mu is a difference of two arcs' moments, whose rounding bound
(64 eps times every term) is the node's error, and where that exceeds half the node's tolerance (near grazing
incidence) the rule below takes the node instead (``python scripts/bench/bench_polar.py`` times a 257-point table
at rtol 1e-10 with and without the closed form).
The rule is globally adaptive 7/15 Gauss-Kronrod in delta = beta0 - beta from the arc's end (where d = c - c0 =
2 e0 sin^2(delta / 2) + b sin(beta0) sin(delta), no cancellation), cut at the kinks and jumps (the V-cavity's
crossings, Walter's G1 switch) and, where a factor has a singularity near the arc's small end (P(N.wo) at N.wo ~ +-i
alpha, Schlick's pole at -r / (1 - r), the Fresnel factor at c ~ +-i sqrt(|1 - index^2|)), at N.wo or c = scale 3^k,
so that each piece lies its own length from it.  The outer variable is cut at the same scale where K(u) turns (around
the horizon break and the range's end, :func:`_pieces`).  Each K carries its error (relative ``itol``, or an absolute
share of the integral's lower bound so far), added to the outer estimate through the Kronrod weights and into |K - G|
before its calibration.  GGX alpha = 0.001 showed why the cuts are needed: without the outer ones the first version was
1.6e-10 off at rtol 1e-12 with an estimate of 6e-13 (30-digit mpmath, ``tests/reference/half_mpmath_reference.py``, and
the nested engine agree).  alpha > 1 (P then has a singularity near N.wo = 1, which is not graded) and
Torrance-Sparrow's D2 stay on the nested engine.

000 eq. 28's Fresnel factor F(Theta_min) = F(max(N.L, N.V)) (metal, plastic with an index, the ``fresnel`` wrapper of a
lobe with p in {0, 1}; ``PowerLobe`` with ``FresnelAtMax``) takes the lobe frame with a rule on the arc (frame 5,
:func:`_k_lobe_fresnel`): where N.wo < mu the factor is the constant F(mu) / mu^p, so that part is the closed form's;
where N.wo = t >= mu the integrand F(t) t^(1 - p) is integrated by Gauss-Legendre rules with an a-priori bound on
Bernstein ellipses (:func:`_lobe_f_gauss`; the adaptive 7/15 rule in beta where they
would want too many points), cut at t = x0 -+
y0 3^j about F's branch point w = sqrt(1 - (eta + i k)^2) = x0 - i y0 (:func:`fresnel_branch`) and at t = rho 3^j
towards the pole of its parallel reflectance near c = 0 (rho = 1 / |sqrt((eta + i k)^2 + 1)|, :func:`fresnel_pole`: a
strong absorber's, eta 1.1, k 30, sits at -0.0012 + 0.033 i); the outer variable is cut where the arc's ends pass those
points (features narrower than :data:`LOBE_F_WIDE`).  A near-kink (Im w < :data:`LOBE_F_Y0_MIN`, or w real in (0, 1): a
dielectric's total reflection below eta = 1) stays on the nested engine.  A pumped metal, and the fresnel wrapper of a
pumped lobe, multiply the pumped lobe's frame of N by F(max(mu, N.wo)) (:func:`_x_rule`, cut likewise by
:func:`chain_cuts`; Im w >= :data:`CHAIN_F_Y0_MIN` there).  A lobe with n >=
:data:`LOBE_N_MIN` takes that frame too, with g = 1 (:func:`takes_lobe_n_frame`; its cuts :func:`chain_cut_matrix`,
compiled, and QUADPACK's calibration instead of CHAIN_SAFETY |K - G|): F is then one factor per node of the elevation
instead of a rule on every arc, 60-400 evaluations per mu instead of 15 per arc times ~110 arcs (metal n = 20, eta 0.2,
k 3: 5.5 ms for 257 mu instead of 60 ms); below n = 8 the ring table leaves the pieces next to kappa = 1 to quadrature,
and frame 5 is faster.

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
(:func:`_n_cuts`); 10/21 Gauss-Kronrod with QUADPACK's calibration.  GGX's and
Schlick's pieces off the peak are integrated in u = ln |d| and graded by 27 instead of 3 (:data:`N_LOG_GRADE`: the
peak's singularities lie pi / 2 from the real u axis whatever |d|; GGX alpha = 1e-8: 803 evaluations per mu instead
of 1099), and the pieces from x = 0 up to x_mu / 8 in u = ln x, graded by 27 too (P(t)'s singularities
lie pi / 2 from that axis; alpha = 1e-8: 608 evaluations per mu, a 257-point table in 15 ms instead of 19-23).
No inner rule: 41-184 evaluations per mu for alpha
>= 0.1, a 257-point table in 0.7-2.6 ms for GGX and Schlick (frame 4 took 20-70 ms), 4-12 ms for Beckmann (frame 4:
45-200 ms), and mu down to the smallest double.  ``scripts/calibration/n_frame_calibration.py`` measures it against
frame 4 (``using(without={"normal", "lobe_normal"})``, :mod:`pumpup.engine.routes`) at rtol 1e-13 over 45 models, 64 mu
and rtol 1e-6 ... 1e-12: at most 4e-5 of the estimate beyond that reference's own error.

GGX with a Fresnel factor takes frame 6 too (:func:`_ggx_ring_f`).  On the ring
F(wi.h) depends on the azimuth, through c = wi.h = sqrt(S^2 + s cos(x) sin^2(psi / 2)) (psi from the mirror side, S =
sin((x + x_mu) / 2) the ring's smallest c), and has no closed form against D; but D's Fourier cosine coefficients do,
M_k = 2 a2 (delta_k0 + rho^k (2 k1 + t2 + k k1^2)) (the terms of :func:`_ggx_ring`, rho = (a' - R) / Q), so F's cosine
interpolant at psi = n pi / N integrates against D exactly: a product rule whose weights are geometric sums in rho
e^(i psi_n) (:func:`_ring_f_sums`), however narrow the peak.  N doubles from 16 to at most 128; the ring's error is
|W_N - W_N/2|, or that times the larger ratio of the last three such steps where both are below 1/2 (the last ratio
alone, from N = 16, was 1100 x below the true error of a strong absorber at itol 1e-6).  The ring's tolerance is frame
4's: relative, or a share of the integral's lower bound so far, and its errors enter the outer estimate as frame 4's K
do.  F(c) has a square-root branch point at c = 0 (it is not even in c), at psi = +- 2 i asinh(S / sqrt(s cos x)) on the
ring, so the product rule needs S not small: frame 6 takes mu >= :data:`N_FRESNEL_MU_MIN` = 0.248
(S >= 1/8 on every ring), frame 4 the rest of a table, and an index whose other singularities (the refracted cosine's
branch points) lie at least 0.1 from [1/8, 1] (:func:`n_fresnel_ok`: not a near-kink conductor; a dielectric's lie on
the imaginary axis).  The elevation is cut where S passes 3^j times the scale of F's pole near c = 0
(:func:`fresnel_pole`) and of its branch point.  17-129 F values per ring (27-35 on average), 1.3-1.9 us; the 216 mu >=
0.248 of a 257-point table at rtol 1e-10 took 39-111 ms where frame 4 takes 87-196 ms (GGX alpha 0.3 with eta 0.2, k 3;
alpha 0.02 with ior 1.5), and the 41 below 0.248 stay at frame 4's 35-50 ms
(``scripts/bench/bench_albedo.py --nframe-f``).  Not taken: a rule per ring for S < 1/8 (adaptive 10/21 in psi graded at
D's and F's scales, measured at ~400 evaluations per ring: no faster than frame 4 there); pumped or 1/E-scaled GGX with
F (the nested engine, as before: frame 4 below 0.248 has no chain); Beckmann with F (frame 4: its ring's Fourier
coefficients are Bessel functions e^-kappa I_k(kappa), not attempted).

The ``fresnel`` wrapper's F(max(N.L, N.V)) (000 eq. 28) over GGX, Beckmann (F = 1) or Schlick's model, pumped or not,
takes frame 6 (``FresnelAtMax`` on a frame 6 family): for a fixed wi it depends
on N.wo alone, so it is one factor per ring, as a pumped chain's g is; its kink N.wo = mu is the cut d = 0, and the
elevation is cut about F's branch point and pole as a pumped metal's (:func:`chain_cuts`).  A near-kink (branch point
within :data:`LOBE_F_Y0_MIN` of the real axis, :data:`CHAIN_F_Y0_MIN` with a chain) stays on the nested engine.  A
257-point table takes 3-12 ms where the nested engine took 0.2-0.4 s (``scripts/bench/bench_albedo.py --fmax``).

A model offers these routes through :meth:`pumpup.core.BRDF.azimuth_hint`, which returns an
:class:`~pumpup.core.hints.AzimuthHint` (or None); the routing table (:mod:`pumpup.engine.routes`) picks the route
(``lobe`` frame 0, ``half`` 1, ``ward`` 2, ``vcavity`` 3, ``half_arc`` 4, ``lobe_fresnel`` 5, ``normal`` 6,
``lobe_normal`` and ``pumped_lobe`` the frame of N) and :func:`run` integrates it.  The 2-D engine stays the
reference: ``pumpup.albedo(..., engine="2d")`` leaves the 1-D routes out.
"""

from __future__ import annotations

import numpy as np

from ..core.hints import AzimuthHint, PowerLobe
from ..physics.quadrature import EPS, mode_code
from .chain_frame import CHAIN_RULE, N_INIT_CHAIN, _integrate_chain, chain_cut_matrix, ring_table
from .half_arc import MP_SIZE, numeric_params
from .hint_view import kernel_view
from .lobe_frame import _NO_JACOBI, N_INIT, ROUNDING, jacobi_rules
from .normal_frame import _integrate_n, n_params
from .outer_rule import _RADIAL, _RULES, DECAY_MODE, RULE, _integrate

__all__ = ["albedo_1d", "axis_albedo", "run"]


def run(route: str, hint: AzimuthHint, mu: np.ndarray, rtol: float, atol: float, max_regions: int,
        lobe_fresnel_gauss: bool = True, decay_estimate: bool = True):
    """(value, error, converged, evaluations) of the albedo of ``hint`` at every mu (a 1-D float array) by the 1-D
    ``route`` the routing table chose for it (:mod:`pumpup.engine.routes`).  ``decay_estimate``: the ``lobe`` route's
    closed forms (p in {0, 1}) take the sharper of QUADPACK's estimate and the one from the decay of the rule's
    coefficients (:data:`pumpup.engine.outer_rule.DECAY_ROWS`); else QUADPACK's alone.
    """
    hint = kernel_view(hint)
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    scale = np.broadcast_to(np.asarray(hint.scale(mu), dtype=np.float64), mu.shape)
    if route == "closed":
        ulps = hint.ulps(mu) if callable(hint.ulps) else hint.ulps
        with np.errstate(invalid="ignore"):  # (inf ulps of a scale that underflowed to 0: e^(-s/mu) at mu = 5e-324)
            err = np.where(scale == 0.0, 0.0, ulps * np.finfo(float).eps * np.abs(scale))
        return scale.copy(), err, np.ones(mu.shape, bool), np.zeros(mu.shape, np.int64)
    jac = jacobi_rules(1.0 - hint.p) if 0.0 < hint.p < 1.0 else _NO_JACOBI
    val = np.empty(mu.shape)
    err = np.empty(mu.shape)
    conv = np.empty(mu.shape, bool)
    evals = np.empty(mu.shape, np.int64)
    # atol applies to the scaled albedo: per mu, atol / scale for the unscaled integral (inf where the scale is 0)
    atol_q = np.full(mu.shape, np.inf)
    np.divide(float(atol), np.abs(scale), out=atol_q, where=scale != 0)
    budget = int(min(max_regions, 10000))
    if route == "normal":  # frame 6: GGX, Beckmann, Schlick about N (:func:`_integrate_n`)
        mp = n_params(hint)
        if hint.chain is None and hint.factor is None and hint.fmax is None:
            cut, ncut = np.zeros((len(mu), 0)), np.zeros(len(mu), np.int64)
        else:  # pumped or scaled: the kinks of g or U, its tables' grading and the pi / 16 cuts, as for a pumped lobe;
            # with F(Theta_min) (fmax) the cuts about its branch point and pole (its kink N.wo = mu: d = 0, a cut)
            cut, ncut = chain_cut_matrix(hint.levels, 0.0, mu, hint.fmax,
                                         chain=hint.chain is not None or hint.factor is not None)
        _integrate_n(mp, mu, float(rtol), atol_q, budget, ROUNDING, *_RULES["gk21"], mode_code(),
                     hint.chain, hint.factor, cut, ncut, val, err, conv, evals)
    elif route == "lobe_normal":  # a metal's lobe about N (:func:`_integrate_chain`, g = 1)
        fres = (float(hint.fresnel[1]), float(hint.fresnel[2]))
        cut, ncut = chain_cut_matrix(None, float(hint.n), mu, fres, chain=False)
        _integrate_chain(float(hint.n), float(hint.p), mu, float(rtol), atol_q, budget, ROUNDING,
                         *_RULES[CHAIN_RULE], N_INIT_CHAIN, cut, ncut, None, *ring_table(float(hint.n)),
                         np.array([1.0, *fres]), mode_code(), val, err, conv, evals)
    elif route == "pumped_lobe":  # a pumped lobe, about N (:func:`_integrate_chain`)
        lobe_f = any(hint.fresnel)
        fres = (float(hint.fresnel[1]), float(hint.fresnel[2])) if lobe_f else None
        fr = np.array([1.0 if lobe_f else 0.0, *(fres or (0.0, 0.0))])
        cut, ncut = chain_cut_matrix(hint.levels, float(hint.n), mu, fres)
        _integrate_chain(float(hint.n), float(hint.p), mu, float(rtol), atol_q, budget, ROUNDING,
                         *_RULES[CHAIN_RULE], N_INIT_CHAIN, cut, ncut, hint.chain, *ring_table(float(hint.n)), fr,
                         mode_code(), val, err, conv, evals)
    else:
        # frames 0-5.  Ward's K (elliptic integrals) has a logarithmic term where h's circle starts to be cut
        # (E(k^2) near k^2 = 1), which no substitution here makes analytic: QUADPACK's calibration measured 4.4 x below
        # the true error there (m = 0.1, mu = 0.6088: 7.1e-13 against 1.5e-13, at every rtol), the raw |K - G| at most
        # 0.11 of it (7 m x 63 mu x rtol 1e-6 .. 1e-12 against the nested engine at 1e-13): Ward keeps the raw one
        frame = _FRAMES[route]
        mode = 0 if hint.sqrt_cos else mode_code()
        if decay_estimate and frame == 0 and mode == 1 and hint.p in (0.0, 1.0) and RULE == "gk21":
            mode = DECAY_MODE
        # (frame 0 reads no parameter: a blank array there)
        mp = np.zeros(MP_SIZE) if frame == 0 else numeric_params(hint, lobe_fresnel_gauss)
        mp[12] = rtol
        _integrate(frame, _RADIAL[hint.radial], float(hint.n), float(hint.p), mu, float(rtol), atol_q, budget,
                   ROUNDING, *(_RULES[RULE]), mode, N_INIT, *_RULES["gk15"], jac, mp, val, err, conv, evals)
    return scale * val, np.abs(scale) * err, conv, evals


#: the frame number of each route ``_integrate`` takes
_FRAMES = {"lobe": 0, "half": 1, "ward": 2, "vcavity": 3, "half_arc": 4, "lobe_fresnel": 5}


def axis_albedo(n: float, nu: np.ndarray, scale: np.ndarray, rtol: float, atol: float, max_regions: int,
                decay_estimate: bool = True):
    """(value, error, converged, evaluations) of a power lobe scale (A.wo)_+^n about an axis A at elevation nu = N.A
    (:meth:`pumpup.core.BRDF.lobe_axis`: Lafortune's lobe, 000 eq. 14, at any azimuth of wi).  Without max(N.L, N.V)
    the integrand depends on wi only through A, so the albedo is the ``lobe`` route's p = 0 lobe about R with mu = nu
    (:func:`_k_closed`), times the scale.  The scale's rounding is added to the error: scale ~ |v|^n with |v| from a
    few roundings, (4 n + 16) eps relative.
    """
    hint = AzimuthHint(PowerLobe(n=float(n), p=0.0), scale=lambda m: scale)
    val, err, conv, evals = run("lobe", hint, nu, rtol, atol, max_regions, decay_estimate=decay_estimate)
    return val, err + (4.0 * n + 16.0) * EPS * np.abs(val), conv, evals


def albedo_1d(brdf, mu: np.ndarray, rtol: float, atol: float, max_regions: int, choice=None):
    """(value, error, converged, evaluations) of the albedo of ``brdf`` (one albedo term) at every mu (a 1-D float
    array) by the 1-D routes the routing table gives its hint (:func:`pumpup.engine.routes.hint_routes`), or None where
    they leave some mu to the nested or 2-D engines (for the tests and the calibrations).
    """
    from .routes import hint_routes

    hint = brdf.azimuth_hint()
    mu = np.ascontiguousarray(mu, dtype=np.float64)
    if hint is None:
        return None
    parts = hint_routes(hint, mu, choice)
    if sum(int(m.sum()) for _, m in parts) != mu.size:
        return None
    out = (np.empty(mu.shape), np.empty(mu.shape), np.empty(mu.shape, bool), np.empty(mu.shape, np.int64))
    for route, m in parts:
        for o, x in zip(out, run(route, hint, mu[m], rtol, atol, max_regions)):
            o[m] = x
    return out
