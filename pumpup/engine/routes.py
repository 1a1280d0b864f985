"""The albedo engine's routing table: which route integrates a model, from what the model declares.

:func:`pumpup.albedo` splits a model into its linear terms (:meth:`pumpup.core.BRDF.albedo_terms`) and, for each term
and each value of mu, takes the first route of :data:`RULES` that applies:

1. ``slope``: a model with a slope-space hint (:meth:`~pumpup.core.BRDF.slope_hint`, anisotropic Ward), at any azimuth
   of wi, mu >= :data:`pumpup.engine.slope.MU_MIN` (:mod:`pumpup.engine.slope`).
2. ``lobe_axis``: a power lobe about its own axis at any azimuth of wi (:meth:`~pumpup.core.BRDF.lobe_axis`,
   Lafortune's), the ``lobe`` route about that axis.
3. Where the albedo does not depend on the azimuth of wi (an isotropic model, or phi = 0): the model's
   :class:`~pumpup.core.hints.AzimuthHint` by its family and the kinds of its factors, each rule with its condition
   and range of mu (the table below; :func:`describe` prints it).  The 1-D routes live in :mod:`pumpup.engine.polar`.
4. ``nested``: the nested quadrature (:mod:`pumpup.engine.nested`) for a lobe hint it supports.
5. ``cubature``: the 2-D adaptive cubature (:mod:`pumpup.engine.cubature`), which takes any BRDF.

A route left out (``engine=`` of :func:`pumpup.albedo`, or :func:`using` around a block) hands its values of mu to the
next rule that applies.  ``engine="auto"`` uses every route; ``"1d"`` the 1-D routes only (an error where none
applies); ``"nested"`` skips the 1-D routes; ``"2d"`` uses the 2-D cubature alone, the reference the others are tested
against.
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..core.hints import (
    AshikhminShirleyLobe,
    AzimuthHint,
    ClosedForm,
    DivideByG,
    FresnelAtMax,
    HalfVectorLobe,
    InverseAlbedoFactor,
    PowerLobe,
    SchlickLobe,
    SmithLobe,
    VCavityLobe,
    WardLobe,
)
from ..physics.fresnel import fresnel_levels
from .chain_frame import LOBE_N_MIN
from .half_arc import ARC_F_Y0_MIN
from .hint_view import HALF_MU_MIN
from .lobe_fresnel import lobe_fresnel_ok
from .normal_frame import N_FRESNEL_MU_MIN, n_fresnel_ok

__all__ = ["ENGINES", "ONE_D_ROUTES", "ROUTES", "RULES", "Choice", "current", "describe", "hint_routes",
           "one_d_everywhere", "plan", "route_names", "using"]

ENGINES = ("auto", "1d", "nested", "2d")

#: the 1-D routes (their module: :mod:`pumpup.engine.polar`, but ``slope``)
ONE_D_ROUTES = ("slope", "lobe_axis", "closed", "lobe", "half", "ward", "vcavity", "half_arc", "lobe_fresnel",
                "lobe_normal", "normal", "pumped_lobe")
#: every route, 1-D first, then the nested quadrature and the 2-D cubature
ROUTES = (*ONE_D_ROUTES, "nested", "cubature")


@dataclass(frozen=True)
class Choice:
    """Which routes the engine may take: ``engine`` one of :data:`ENGINES`; ``without``, route names left out (the
    tests' and calibrations' second route for a model); ``lobe_fresnel_gauss``: the ``lobe_fresnel`` route's arcs by
    Gauss-Legendre pieces with an a-priori bound, and Ashikhmin-Shirley's arcs on the ``half_arc`` route in closed form
    (else both by the adaptive 7/15 rule); ``decay_estimate``: the ``lobe`` route's closed forms also estimate their
    error from the decay of the rule's coefficients (:func:`pumpup.engine.polar.run`; else by QUADPACK's calibration
    alone); ``generic_check``: the 2-D cubature checks a user function's kinks on a grid first.
    """

    engine: str = "auto"
    without: frozenset = frozenset()
    lobe_fresnel_gauss: bool = True
    decay_estimate: bool = True
    generic_check: bool = True

    def allows(self, route: str) -> bool:
        """Whether this choice lets the engine take ``route``."""
        if route in self.without:
            return False
        if route in ONE_D_ROUTES:
            return self.engine in ("auto", "1d")
        if route == "nested":
            return self.engine in ("auto", "nested")
        return self.engine != "1d"


_CHOICE: contextvars.ContextVar = contextvars.ContextVar("pumpup_engine_choice", default=Choice())


def check_engine(function: str, engine) -> str:
    """``engine`` checked: one of :data:`ENGINES` (one line naming the argument otherwise)."""
    if engine not in ENGINES:
        raise ValueError(f"{function}: engine must be one of {', '.join(map(repr, ENGINES))}, got {engine!r}")
    return engine


def current() -> Choice:
    """The choice in force (:func:`using`; by default every route)."""
    return _CHOICE.get()


@contextlib.contextmanager
def default_routes():
    """Within the block, every route, as by default, whatever :func:`using` block encloses it: the pumping and
    compensation operators build their tables, which define their BRDFs, in it, so that a BRDF is the same whichever
    routes compute its albedo (a table by other routes differs within its error).
    """
    token = _CHOICE.set(Choice())
    try:
        yield
    finally:
        _CHOICE.reset(token)


@contextlib.contextmanager
def using(engine: str | None = None, without=(), **options):
    """Within the block (in this thread or task only), :func:`pumpup.albedo` and everything built on it (tables,
    pumping, compensation) route by ``engine`` and leave out the routes ``without``; ``options`` set
    :class:`Choice`'s other fields.  Blocks nest: the inner one adds to the outer one's ``without``.  What defines a
    BRDF is computed as by default within it (:func:`default_routes`).
    """
    old = _CHOICE.get()
    bad = set(without) - set(ROUTES)
    if bad:
        raise ValueError(f"using: without names unknown routes {sorted(bad)}; the routes are {', '.join(ROUTES)}")
    new = Choice(engine=check_engine("using", engine) if engine is not None else old.engine,
                 without=old.without | frozenset(without),
                 lobe_fresnel_gauss=options.pop("lobe_fresnel_gauss", old.lobe_fresnel_gauss),
                 decay_estimate=options.pop("decay_estimate", old.decay_estimate),
                 generic_check=options.pop("generic_check", old.generic_check))
    if options:
        raise TypeError(f"using: unknown options {sorted(options)}")
    token = _CHOICE.set(new)
    try:
        yield new
    finally:
        _CHOICE.reset(token)


# --- the conditions ---------------------------------------------------------------------------------------------------

def _smith_ok(f) -> bool:
    """Whether any 1-D route takes a Smith lobe: alpha <= 1 (rougher, P(N.wo) has a singularity near N.wo = 1 that no
    route grades: GGX's branch point at alpha / sqrt(alpha^2 - 1)); not Walter's G1 in the height-correlated G with a
    Fresnel factor (G1's jump at the switch level: the rule on h's arc was up to 7 x its estimate against the 2-D engine
    at rtol 1e-13, alpha 0.0032, ior 1.917, mu 1.75e-6); not a conductor's near-kink at wi.h (:data:`ARC_F_Y0_MIN`).
    """
    if not f.alpha <= 1.0:
        return False
    if f.fresnel is not None and f.g1 == "walter" and f.shadowing == "correlated":
        return False
    return not (f.fresnel is not None and f.fresnel.eta > 0.0
                and fresnel_levels(f.fresnel.eta, f.fresnel.k, ARC_F_Y0_MIN))


def _normal_family(f) -> bool:
    """Whether the ``normal`` route takes the family ``f`` with no factor: Schlick's model, GGX and Beckmann with
    F = 1, GGX with a Fresnel factor :func:`n_fresnel_ok` takes.
    """
    if isinstance(f, SchlickLobe):
        return True
    if not isinstance(f, SmithLobe) or not _smith_ok(f):
        return False
    if f.fresnel is None:
        return True
    return f.distribution == "ggx" and n_fresnel_ok(f.fresnel.ior, f.fresnel.eta, f.fresnel.k)


def _normal(hint: AzimuthHint) -> bool:
    """The ``normal`` route's condition (its factors: g, 1/U or F(max) per node)."""
    f = hint.family
    if not _normal_family(f):
        return False
    fmax, divide = hint.factor(FresnelAtMax), hint.factor(DivideByG)
    if hint.factor(InverseAlbedoFactor) is not None:  # (1/U on a plain model only: its table was calibrated so)
        return len(hint.factors) == 1 and not _fresnel_at_h(hint)
    if fmax is not None:  # F(max) on F = 1 only (a factor of each node), near-kinks kept off as for a lobe
        return not _fresnel_at_h(hint) and lobe_fresnel_ok(fmax.eta, fmax.k, divide is not None)
    return True


def _fresnel_at_h(hint: AzimuthHint) -> bool:
    """Whether the family has a Fresnel factor at wi.h."""
    return isinstance(hint.family, (SmithLobe, VCavityLobe)) and hint.family.fresnel is not None


def _arc(hint: AzimuthHint) -> bool:
    """The ``half_arc`` route's condition: a Smith lobe any route takes (:func:`_smith_ok`), a V-cavity lobe with F, or
    Ashikhmin and Shirley's lobe.
    """
    f = hint.family
    if isinstance(f, AshikhminShirleyLobe):
        return True
    return _smith_ok(f) if isinstance(f, SmithLobe) else f.fresnel is not None


def _lobe_fmax(hint: AzimuthHint) -> bool:
    """F(max(N.wi, N.wo)) on a power lobe: p in {0, 1} and no near-kink (:func:`lobe_fresnel_ok`)."""
    f, fmax = hint.family, hint.factor(FresnelAtMax)
    return f.p in (0.0, 1.0) and lobe_fresnel_ok(fmax.eta, fmax.k)


def _lobe_normal(hint: AzimuthHint) -> bool:
    return _lobe_fmax(hint) and hint.family.n >= LOBE_N_MIN


def _pumped_lobe(hint: AzimuthHint) -> bool:
    fmax = hint.factor(FresnelAtMax)
    return fmax is None or lobe_fresnel_ok(fmax.eta, fmax.k, chain=True)


def _all_mu(mu):
    return np.ones(mu.shape, bool)


def _half_mu(mu):
    return mu >= HALF_MU_MIN


def _normal_mu(hint: AzimuthHint, mu):
    return mu >= N_FRESNEL_MU_MIN if _fresnel_at_h(hint) else np.ones(mu.shape, bool)


def _always(hint) -> bool:
    return True


@dataclass(frozen=True)
class Rule:
    """One row of the routing table: the ``families`` and the set of factor kinds (``factors``) it matches, its
    ``condition`` on the hint (``when`` says it in words), the values of mu it takes (``mu_range(hint, mu)`` -> a mask;
    ``mu_text`` in words), and the ``route``.
    """

    route: str
    families: tuple
    factors: frozenset
    when: str = ""
    condition: Callable = field(default=_always, compare=False)
    mu_text: str = "all"
    mu_range: Callable = field(default=lambda hint, mu: _all_mu(mu), compare=False)


_D, _U, _M = DivideByG, InverseAlbedoFactor, FresnelAtMax

#: the routes of an :class:`~pumpup.core.hints.AzimuthHint`, in the order they are tried
RULES = (
    Rule("closed", (ClosedForm,), frozenset()),
    Rule("lobe", (PowerLobe,), frozenset()),
    Rule("half", (HalfVectorLobe,), frozenset(), mu_text="mu >= HALF_MU_MIN", mu_range=lambda h, mu: _half_mu(mu)),
    Rule("ward", (WardLobe,), frozenset(), mu_text="mu >= HALF_MU_MIN", mu_range=lambda h, mu: _half_mu(mu)),
    Rule("vcavity", (VCavityLobe,), frozenset(), "F = 1", lambda h: h.family.fresnel is None, "mu >= HALF_MU_MIN",
         lambda h, mu: _half_mu(mu)),
    *(Rule("normal", (SmithLobe, SchlickLobe), frozenset(kinds),
           "Schlick; GGX or Beckmann, alpha <= 1, F = 1 or GGX's F(wi.h) n_fresnel_ok takes; "
           "F(max) without a near-kink",
           _normal, "mu >= N_FRESNEL_MU_MIN with F(wi.h), else all", _normal_mu)
      for kinds in ((), (_D,), (_U,), (_M,), (_D, _M))),
    Rule("half_arc", (SmithLobe, VCavityLobe, AshikhminShirleyLobe), frozenset(),
         "Smith: alpha <= 1, no Walter G1 in correlated G with F, no near-kink of F(wi.h); V-cavity: with F(wi.h)",
         _arc, "mu >= HALF_MU_MIN", lambda h, mu: _half_mu(mu)),
    Rule("lobe_normal", (PowerLobe,), frozenset({_M}), "p in {0, 1}, n >= LOBE_N_MIN, F without a near-kink",
         _lobe_normal),
    Rule("lobe_fresnel", (PowerLobe,), frozenset({_M}), "p in {0, 1}, F without a near-kink", _lobe_fmax),
    Rule("pumped_lobe", (PowerLobe,), frozenset({_D})),
    Rule("pumped_lobe", (PowerLobe,), frozenset({_D, _M}), "F without a near-kink for a chain", _pumped_lobe),
)


def _matches(rule: Rule, hint: AzimuthHint) -> bool:
    kinds = [type(f) for f in hint.factors]
    return (isinstance(hint.family, rule.families) and len(set(kinds)) == len(kinds)
            and frozenset(kinds) == rule.factors and rule.condition(hint))


def hint_routes(hint: AzimuthHint | None, mu: np.ndarray, choice: Choice | None = None) -> list:
    """[(route, mask)] for the values of mu (a 1-D array) an :class:`~pumpup.core.hints.AzimuthHint` takes by 1-D
    routes, in :data:`RULES`' order; the values in no mask are left to the nested quadrature or the 2-D cubature.
    """
    choice = current() if choice is None else choice
    out = []
    if hint is None:
        return out
    left = np.ones(mu.shape, bool)
    for rule in RULES:
        if not left.any():
            break
        if not choice.allows(rule.route) or not _matches(rule, hint):
            continue
        take = left & rule.mu_range(hint, mu)
        if take.any():
            out.append((rule.route, take))
            left &= ~take
    return out


def one_d_everywhere(brdf, mu: np.ndarray, choice: Choice | None = None) -> bool:
    """Whether the 1-D routes of ``brdf``'s own azimuth hint take it at every mu (its values then cost microseconds)."""
    hint = brdf.azimuth_hint()
    mu = np.asarray(mu, dtype=np.float64).reshape(-1)
    return hint is not None and sum(int(m.sum()) for _, m in hint_routes(hint, mu, choice)) == mu.size


def plan(brdf, mu: np.ndarray, phi: np.ndarray | None = None, choice: Choice | None = None) -> list:
    """The routes of one albedo term ``brdf`` (a :class:`~pumpup.core.BRDF` with no linear parts) at every mu (a 1-D
    array), wi at azimuth ``phi`` (None: 0): [(route, indices into mu, payload)], payload the hint for the 1-D routes
    and the lobe group for ``nested`` and ``cubature``.
    """
    from . import cubature, nested, slope

    choice = current() if choice is None else choice
    ph = np.zeros(mu.shape) if phi is None else phi
    left = np.ones(mu.shape, bool)
    out = []
    if choice.allows("slope") and brdf.slope_hint() is not None:
        take = mu >= slope.MU_MIN
        if take.any():
            out.append(("slope", np.flatnonzero(take), None))
            left &= ~take
    if left.all() and choice.allows("lobe_axis"):
        axis = brdf.lobe_axis(mu, ph)
        if axis is not None:
            out.append(("lobe_axis", np.flatnonzero(left), axis))
            left[:] = False
    turned = phi is not None and bool((phi != 0.0).any()) and brdf.azimuth_range() is not None
    if left.any() and not turned:
        hint = brdf.azimuth_hint()
        if hint is not None:
            scale = np.asarray(hint.scale(mu[left]), dtype=np.float64)
            if np.isfinite(scale).all():  # (an overflowing constant: the 2-D engine reports what the model returns)
                idx = np.flatnonzero(left)
                for route, take in hint_routes(hint, mu[idx], choice):
                    out.append((route, idx[take], hint))
                    left[idx[take]] = False
    if left.any():
        rest = np.flatnonzero(left)
        if choice.engine == "1d":
            i = int(rest[0])
            raise ValueError(f"albedo: engine '1d' has no 1-D route for {brdf!r} at mu={mu[i]:.6g}; use engine='auto'")
        for idx, group in cubature._groups(brdf, mu[rest], ph[rest] if turned else None):
            route = "nested" if choice.allows("nested") and nested.supports(group) else "cubature"
            out.append((route, rest[idx], group))
    return out


def route_names(brdf, mu, phi=None, choice: Choice | None = None) -> np.ndarray:
    """The route that integrates each albedo term of ``brdf`` at each value of ``mu`` (wi at azimuth ``phi``): an array
    of route names of shape (terms, len(mu)).
    """
    from .cubature import check_mu

    mu = np.asarray(check_mu(mu), dtype=np.float64).reshape(-1)
    terms = brdf.albedo_terms()
    names = np.empty((len(terms), mu.size), dtype=object)
    for j, (_, term) in enumerate(terms):
        for route, idx, _ in plan(term, mu, phi, choice):
            names[j, idx] = route
    return names


def describe() -> str:
    """The routing table as text: the routes before and after the hint's rules, and one line per rule."""
    lines = ["route         families                         factors            mu          condition",
             "slope         (BRDF.slope_hint)                -                  mu >= 1e-100  any azimuth of wi",
             "lobe_axis     (BRDF.lobe_axis)                 -                  all           any azimuth of wi"]
    for r in RULES:
        fam = ", ".join(f.__name__ for f in r.families)
        fac = ", ".join(sorted(f.__name__ for f in r.factors)) or "-"
        lines.append(f"{r.route:13s} {fam:32s} {fac:18s} {r.mu_text:11s} {r.when}")
    lines.append("nested        (BRDF.lobe)                      any                the rest    "
                 "the lobe hint it supports")
    lines.append("cubature      any BRDF                         any                the rest    -")
    return "\n".join(lines)
