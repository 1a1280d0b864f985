"""What a model tells the albedo engine about the azimuth of its albedo integral.

A model whose albedo integral has a closed-form azimuth (or one the engine takes by a rule on known arcs) returns an
:class:`AzimuthHint` from :meth:`pumpup.core.BRDF.azimuth_hint`: the model's *family* (one of the records below, with
typed parameters), the constant ``scale(mu)`` in front of it, and the *factors* of N.wo that operators multiply it by.
The engine's routing table (:mod:`pumpup.engine.routes`) reads the hint and picks the route; a model or an operator
never names a route.

Families (each a frozen record):

- :class:`ClosedForm`: a(mu) = scale(mu) exactly (Lambert, Minnaert, Oren-Nayar, Kulla-Conty's lobe).
- :class:`PowerLobe`: u^n / max(N.wi, N.wo)^p with u = (R.wo)_+ (Phong, Lafortune, Lewis, metal; 000 eq. 14, 28).
- :class:`HalfVectorLobe`: w(N.h) / max(N.wi, N.wo)^p, w a power, Beckmann or GGX weight (Blinn, modified Ward; 000
  eq. 31, 35).
- :class:`WardLobe`: the Beckmann weight / sqrt(N.wi N.wo) (Ward, 000 eq. 34).
- :class:`VCavityLobe`: D G F / (N.wi N.wo) with the V-cavity G (Cook-Torrance, Torrance-Sparrow; 001 eq. 9-10).
- :class:`SmithLobe`: D F G / (4 N.wi N.wo) with Smith's G (Walter et al. 2007 eq. 20).
- :class:`SchlickLobe`: Schlick's model (000 eq. 36).
- :class:`AshikhminShirleyLobe`: Ashikhmin and Shirley's isotropic lobe with Schlick's F(wi.h) (AS 2000 eq. 4).

Factors (functions of N.wo for a fixed wi, which an operator adds to its base's hint):

- :class:`DivideByG`: pumping's divisor g_1 ... g_k (001 eq. 16).
- :class:`InverseAlbedoFactor`: 1/E compensation's 1 + F0 (1 / U(N.wo) - 1) (Turquin eq. 6).
- :class:`FresnelAtMax`: 000 eq. 28's conductor factor F(max(N.wi, N.wo)).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace

__all__ = [
    "AshikhminShirleyLobe", "AzimuthHint", "ClosedForm", "DivideByG", "Fresnel", "FresnelAtMax", "HalfVectorLobe",
    "InverseAlbedoFactor", "PowerLobe", "SchlickLobe", "SmithLobe", "VCavityLobe", "WardLobe",
]

RADIAL_WEIGHTS = ("power", "beckmann", "ggx")


def _bad(record: str, what: str) -> None:
    raise ValueError(f"{record}: {what}")


@dataclass(frozen=True)
class Fresnel:
    """A Fresnel factor at c = wi.h: a dielectric of real index ``ior`` > 0, a conductor ``eta`` + i ``k`` (eta > 0), or
    Schlick's f0 + (1 - f0) (1 - c)^5 with f0 = ``schlick`` in [0, 1] (Karis 2013; f0 = 0 is the Fc that weights the
    split sum's second term).  Schlick's record carries ior = -1 - f0 (< 0), the form the kernels read.
    """

    ior: float = 0.0
    eta: float = 0.0
    k: float = 0.0
    schlick: float | None = None

    def __post_init__(self):
        if self.schlick is not None and self.ior == -1.0 - self.schlick:  # (a copy of a Schlick record)
            object.__setattr__(self, "ior", 0.0)
        kinds = (self.ior > 0.0) + (self.eta > 0.0) + (self.schlick is not None)
        if kinds != 1:
            _bad("Fresnel", f"give ior > 0 (dielectric), eta > 0 (conductor) or schlick in [0, 1], got "
                            f"ior={self.ior!r}, eta={self.eta!r}, schlick={self.schlick!r}")
        if self.schlick is not None and not 0.0 <= self.schlick <= 1.0:
            _bad("Fresnel", f"schlick (f0) must be in [0, 1], got {self.schlick!r}")
        if self.schlick is not None:
            object.__setattr__(self, "ior", -1.0 - float(self.schlick))


@dataclass(frozen=True)
class ClosedForm:
    """a(mu) = scale(mu) exactly; ``ulps`` the relative error of the scale in units of eps (or ``ulps(mu)``), as
    bounded and measured for each closed form.
    """

    ulps: float | Callable = 4.0


@dataclass(frozen=True)
class PowerLobe:
    """u^n / max(N.wi, N.wo)^p with u = (R.wo)_+, R the mirror direction of wi (or wi itself: the integral is the
    same), n >= 0, p in [0, 1].
    """

    n: float
    p: float = 0.0

    def __post_init__(self):
        if not 0.0 <= self.p <= 1.0:
            _bad("PowerLobe", f"p must be in [0, 1], got {self.p!r}")
        if not self.n >= 0.0:
            _bad("PowerLobe", f"n must be >= 0, got {self.n!r}")


@dataclass(frozen=True)
class HalfVectorLobe:
    """w(N.h) / max(N.wi, N.wo)^p, p in {0, 1}: w = (N.h)^n ("power", the Blinn family, 000 eq. 31, 32), or the
    Beckmann weight exp(-tan^2(alpha) / n^2) (modified Ward, 000 eq. 35), or the GGX weight
    1 / (1 + tan^2(alpha) / n^2)^2 (Walter et al. 2007 eq. 33).
    """

    n: float
    p: float = 0.0
    radial: str = "power"

    def __post_init__(self):
        if self.p not in (0.0, 1.0):
            _bad("HalfVectorLobe", f"p must be 0 or 1, got {self.p!r}")
        if self.radial not in RADIAL_WEIGHTS or (self.radial != "power" and not self.n > 0.0):
            _bad("HalfVectorLobe", f"radial must be one of {RADIAL_WEIGHTS} (n > 0 for a weight), got {self.radial!r}")


@dataclass(frozen=True)
class WardLobe:
    """Ward's lobe (000 eq. 34): the Beckmann weight exp(-tan^2(alpha) / m^2) divided by sqrt(N.wo) (its 1 / sqrt(N.wi)
    in the scale).
    """

    m: float

    def __post_init__(self):
        if not self.m > 0.0:
            _bad("WardLobe", f"m must be > 0, got {self.m!r}")


@dataclass(frozen=True)
class VCavityLobe:
    """The V-cavity microfacet model's D G F / (N.wi N.wo) (Cook-Torrance, 001 eq. 9-10; Torrance-Sparrow, 002 eq.
    10): D the radial weight of exponent or width ``n`` (with the Beckmann weight D's 1 / cos^4), F = 1 or ``fresnel``
    at wi.h, 1 / N.wi in the scale.
    """

    n: float
    radial: str = "power"
    fresnel: Fresnel | None = None

    def __post_init__(self):
        if self.radial not in RADIAL_WEIGHTS or (self.radial != "power" and not self.n > 0.0):
            _bad("VCavityLobe", f"radial must be one of {RADIAL_WEIGHTS} (n > 0 for a weight), got {self.radial!r}")


@dataclass(frozen=True)
class SmithLobe:
    """A Smith microfacet model's D F G / (4 N.wi N.wo) (Walter et al. 2007 eq. 20): ``distribution`` "beckmann" or
    "ggx" of roughness ``alpha``, G1 "exact" or Walter's fit ("walter"), shadowing "separable" or "correlated", F = 1
    or ``fresnel`` at wi.h; D's 1 / (pi alpha^2) and the 1 / 4 in the scale.
    """

    distribution: str
    alpha: float
    g1: str = "exact"
    shadowing: str = "separable"
    fresnel: Fresnel | None = None

    def __post_init__(self):
        if self.distribution not in ("beckmann", "ggx") or self.g1 not in ("exact", "walter") \
                or self.shadowing not in ("separable", "correlated") or not self.alpha > 0.0:
            _bad("SmithLobe",
                 f"needs distribution 'beckmann' or 'ggx', g1 'exact' or 'walter', shadowing 'separable' or "
                 f"'correlated' and alpha > 0, got {self.distribution!r}, {self.g1!r}, {self.shadowing!r}, "
                 f"{self.alpha!r}")


@dataclass(frozen=True)
class SchlickLobe:
    """Schlick's model (000 eq. 36) with r in (0, 1]: the GGX weight with alpha = sqrt(r) and
    1 / (r + (1 - r) N.wo) (its 1 / (r + (1 - r) N.wi) in the scale).
    """

    r: float

    def __post_init__(self):
        if not 0.0 < self.r <= 1.0:
            _bad("SchlickLobe", f"r must be in (0, 1], got {self.r!r}")


@dataclass(frozen=True)
class AshikhminShirleyLobe:
    """Ashikhmin and Shirley's isotropic lobe (N.h)^n F(wi.h) / ((wi.h) max(N.wi, N.wo)) with Schlick's
    F(c) = rs + (1 - rs) (1 - c)^5 (AS 2000 eq. 4, 5); sqrt((nu + 1)(nv + 1)) / (8 pi) in the scale.
    """

    n: float
    rs: float

    def __post_init__(self):
        if not self.n >= 0.0 or not 0.0 <= self.rs <= 1.0:
            _bad("AshikhminShirleyLobe", f"needs n >= 0 and rs in [0, 1], got n={self.n!r}, rs={self.rs!r}")


Family = (ClosedForm | PowerLobe | HalfVectorLobe | WardLobe | VCavityLobe | SmithLobe | SchlickLobe
          | AshikhminShirleyLobe)


@dataclass(frozen=True)
class DivideByG:
    """Pumping's divisor g_1 ... g_k (mu, N.wo) (001 eq. 16): ``lookups``, the compiled look-ups of every level's
    bound (:class:`pumpup.physics.lookups.GChain`), and ``levels(mu)``, the values of N.wo where g has a kink.
    """

    lookups: tuple
    levels: Callable = field(compare=False)


@dataclass(frozen=True)
class InverseAlbedoFactor:
    """1/E compensation's factor 1 + f0 (1 / U(N.wo) - 1) (Turquin eq. 6): ``bound``, the arguments of the compiled
    look-up U (a bounded spline of the white model's albedo), and ``levels(mu)``, U's kinks.
    """

    f0: float
    bound: tuple
    levels: Callable = field(compare=False)


@dataclass(frozen=True)
class FresnelAtMax:
    """000 eq. 28's conductor factor F(eta + i k, max(N.wi, N.wo))."""

    eta: float
    k: float


Factor = DivideByG | InverseAlbedoFactor | FresnelAtMax


@dataclass(frozen=True)
class AzimuthHint:
    """A model's family, its constant ``scale(mu)`` (an array of the shape of mu) and the factors of N.wo operators
    multiply it by.  The albedo is scale(mu) times the family's integral with the factors (for :class:`ClosedForm`,
    scale(mu) itself).
    """

    family: Family
    scale: Callable
    factors: tuple = ()

    def factor(self, kind: type):
        """The factor of type ``kind``, or None."""
        return next((f for f in self.factors if isinstance(f, kind)), None)

    def times(self, factor) -> AzimuthHint:
        """The same hint with one more factor."""
        return replace(self, factors=(*self.factors, factor))
