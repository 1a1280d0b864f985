"""The hints a model gives the albedo engine about the azimuth of its albedo integral.

:class:`Polar` says that the integral over the azimuth is closed-form (or a rule on an arc) for the model's family, so
the engine integrates one dimension (:mod:`pumpup.engine.polar`).  A model returns one from ``BRDF.polar()``; an
operator (pumping, a 1/E scaling, a Fresnel factor) adds its factor of N.wo to its base's.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Polar"]


@dataclass(frozen=True)
class Polar:
    """A model's closed-form-azimuth hint for :func:`albedo_1d`.

    a(mu) = scale(mu) * integral over the hemisphere of u^n / max(mu, N.wo)^p cos(theta_o)
    d omega_o, u = (A.wo)_+ with A the mirror direction of wi or wi itself (the integral is the
    same for both), or, for ``kind="constant"``, a(mu) = scale(mu) exactly.

    Parameters
    ----------
    n : float, >= 0
        Exponent of the lobe.
    p : float in [0, 1]
        Power of max(N.L, N.V) in the denominator (0 and 1 in closed form, between them an inner
        rule on the arc where N.wo >= mu, :func:`_arc_power`).
    scale : callable
        ``scale(mu) -> ndarray`` of the same shape: the constant of the model (c, c C^n for a
        Lafortune lobe, k_s / mu for Phong's shader, k_rho / H_s(mu) for Lewis's Phong).
    kind : {"lobe", "constant", "half"}
        "half": u is N.h, h the half vector of wi and wo (the Blinn family, 000 eq. 31, 32; 002
        eq. 24; with ``radial``, ``sqrt_cos``, ``vcavity`` below also modified Ward, Ward, Cook-Torrance and
        Torrance-Sparrow), p in {0, 1}: a(mu) = scale(mu) * integral_0^1 u^n K(u) du with the azimuth of h
        about N in closed form (:func:`_k_half`, :func:`_k_ward`, :func:`_k_vcavity`).
    chain : tuple, optional
        A pumped BRDF's divisor (:meth:`pumpup.operators.pumping.Pumped._chain_args`): the integrand is then
        divided by g_1 ... g_k (mu, N.wo) (001 eq. 16), a function of N.wo only for a fixed wi,
        and the integral is taken about N (:func:`_integrate_chain`; for a half-vector hint in frame 6,
        GGX, Beckmann with F = 1 and Schlick's model, :func:`_integrate_n`; GGX with F at mu >= N_FRESNEL_MU_MIN only,
        :func:`one_d_part`).
    levels : callable, optional
        With ``chain``: ``levels(mu)`` -> the values of N.wo where g has a kink
        (:meth:`pumpup.operators.pumping.Pumped.kink_levels` of every level, the kinks its tables inherit with their
        knots, :meth:`pumpup.operators.pumping.Pumped.table_kinks`, and the base's level mu).
    radial : {"power", "beckmann", "ggx"}
        The lobe's radial factor: u^n ("power"), or, with kind "half", the Beckmann weight
        exp(-tan^2(alpha) / m^2) with m = ``n`` (the modified Ward model, 000 eq. 35), or the GGX weight
        1 / (1 + tan^2(alpha) / m^2)^2 (GGX, Walter et al. 2007 eq. 33; Torrance-Sparrow's D3, 002 sec. 3.2).
    vcavity : bool
        With kind "half" and p = 0: the lobe is the V-cavity microfacet model's D G / (N.L N.V) with F = 1 (or ``fresnel``'s F, by
        the rule on h's arc, :func:`_k_numeric`)
        (Cook-Torrance, 001 eq. 9-10; Torrance-Sparrow, 002 eq. 10; :func:`_k_vcavity`), D the radial factor
        (u^n, or with the Beckmann weight D's 1 / cos^4), 1 / N.L in ``scale``.
    ulps : float or callable
        With kind "constant": the relative error of ``scale`` in units of eps (or ``ulps(mu)``), as bounded
        and measured for each closed form.
    sqrt_cos : bool
        With kind "half" and p = 0: the lobe is divided by sqrt(N.wo) (Ward, 000 eq. 34: sqrt(N.L N.V), its
        1 / sqrt(N.L) in ``scale``; :func:`_k_ward`).
    smith : tuple, optional
        With kind "half", p = 0 and the Beckmann or GGX weight: the lobe is a Smith microfacet model's
        D F G / (4 N.L N.V) (Walter et al. 2007 eq. 20), given as (distribution: 0 Beckmann, 1 GGX; G1: 0 exact, 1
        Walter's fit; shadowing: 0 separable, 1 height-correlated; alpha); its azimuth by a rule on h's arc
        (:func:`_k_numeric`; with F = 1 and alpha <= 1 about N instead, the azimuth of wo in closed form, frame 6,
        :func:`_integrate_n`), D's 1 / (pi alpha^2) and the 1 / 4 in ``scale``.
    fresnel : tuple
        (ior, eta, k): the Fresnel factor at wi.h of a Smith or V-cavity lobe, dielectric (ior > 0) or conductor
        (eta > 0), or none (all 0); a V-cavity lobe with one takes the rule on h's arc too.  With kind "lobe" (ior 0, eta
        > 0): 000 eq. 28's conductor factor F(max(N.L, N.V)) (frame 5, :func:`_k_lobe_fresnel`; with ``chain``, the
        pumped lobe's frame of N, :func:`_x_rule`).
    schlick : float, optional
        With kind "half", p = 0 and the GGX weight (n = sqrt(r)): Schlick's model (000 eq. 36) with this r, whose
        1 / (r + (1 - r) N.V) frame 6 integrates about N (:func:`_integrate_n`); 1 / (r + (1 - r) N.L) in ``scale``.
    factor : tuple, optional
        A 1/E-scaled model's factor 1 + F0 (1 / U(N.wo) - 1) (Turquin eq. 6, :class:`pumpup.operators.compensate.Scaled`): F0 and
        the arguments of its look-up U (:attr:`pumpup.operators.compensate._Bound.args`), a function of N.wo alone, so frame 6
        multiplies each node by it (:func:`_n_rule`); ``levels(mu)`` then gives U's kinks.  Frame 6 only.
    fmax : tuple, optional
        (eta, k): 000 eq. 28's conductor factor F(max(N.L, N.V)) on a frame 6 model (the ``fresnel`` wrapper of GGX,
        Beckmann with F = 1 or Schlick's model, pumped or not; :func:`with_fresnel_max`): a function of N.wo alone for a
        fixed wi, so frame 6 multiplies each node by it (:func:`_n_rule`), its kink N.wo = mu a cut already and the
        elevation cut about its branch point and pole as a pumped metal's (:func:`chain_cuts`).  Frame 6 only.
    """

    n: float = 0.0
    p: float = 0.0
    scale: object = None
    kind: str = "lobe"
    chain: tuple | None = None
    levels: object = None
    radial: str = "power"
    sqrt_cos: bool = False
    ulps: object = 4.0
    vcavity: bool = False
    smith: tuple | None = None
    fresnel: tuple = (0.0, 0.0, 0.0)
    schlick: float | None = None
    factor: tuple | None = None
    fmax: tuple | None = None
