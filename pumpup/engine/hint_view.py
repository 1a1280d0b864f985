"""The 1-D routes' view of a model's :class:`~pumpup.core.hints.AzimuthHint`: its family and factors as the kernels
take them (:func:`kernel_view`).
"""

from __future__ import annotations

import dataclasses
import math

from ..core.hints import (
    AshikhminShirleyLobe,
    AzimuthHint,
    ClosedForm,
    DivideByG,
    HalfVectorLobe,
    InverseAlbedoFactor,
    PowerLobe,
    SchlickLobe,
    SmithLobe,
    VCavityLobe,
    WardLobe,
)

#: the half-vector frames take mu >= this (below it mu / (2 u), tan^2(psi / 2) m^2 and their kin underflow; the nested
#: engine takes such values)
HALF_MU_MIN = 1e-100

#: the codes of a Smith lobe's distribution, G1 and shadowing in the kernels' parameter arrays
_SMITH_CODES = ({"beckmann": 0, "ggx": 1}, {"exact": 0, "walter": 1}, {"separable": 0, "correlated": 1})


@dataclasses.dataclass(frozen=True)
class KernelView:
    """An :class:`~pumpup.core.hints.AzimuthHint` as the kernels read it (:func:`kernel_view`): ``kind`` "constant",
    "lobe" (u = R.wo) or "half" (u = N.h); the exponent or width ``n``, the power ``p`` of max(N.wi, N.wo), the radial
    weight, Ward's ``sqrt_cos``, the V-cavity's ``vcavity``, Smith's codes ``smith`` = (distribution, G1, shadowing,
    alpha), the Fresnel factor ``fresnel`` = (ior, eta, k) at wi.h (ior = -1 - f0 < 0: Schlick's of f0; or, for a lobe,
    F(max) of (0, eta, k)),
    Schlick's ``schlick``; and the factors: ``chain`` (pumping's look-ups), ``factor`` (1/E's (f0, *U's arguments)),
    ``fmax`` (F(max) of (eta, k) on a half-vector family), ``levels`` (the kinks of g or U in N.wo).
    """

    scale: object
    kind: str = "lobe"
    n: float = 0.0
    p: float = 0.0
    radial: str = "power"
    sqrt_cos: bool = False
    vcavity: bool = False
    smith: tuple | None = None
    fresnel: tuple = (0.0, 0.0, 0.0)
    schlick: float | None = None
    schlick_fresnel: float | None = None
    ulps: object = 4.0
    chain: tuple | None = None
    factor: tuple | None = None
    fmax: tuple | None = None
    levels: object = None


def kernel_view(hint: AzimuthHint) -> KernelView:
    """The kernels' view of ``hint``: its family's parameters and its factors as the compiled routes take them."""
    f = hint.family
    out = {"scale": hint.scale}

    def fres(fr):
        """A Fresnel factor's (ior, eta, k) as floats (Schlick's: ior = -1 - f0), or zeros without one."""
        return (0.0, 0.0, 0.0) if fr is None else (float(fr.ior), float(fr.eta), float(fr.k))

    if isinstance(f, ClosedForm):
        out.update(kind="constant", ulps=f.ulps)
    elif isinstance(f, PowerLobe):
        out.update(n=f.n, p=f.p)
    elif isinstance(f, HalfVectorLobe):
        out.update(kind="half", n=f.n, p=f.p, radial=f.radial)
    elif isinstance(f, WardLobe):
        out.update(kind="half", n=f.m, radial="beckmann", sqrt_cos=True)
    elif isinstance(f, VCavityLobe):
        out.update(kind="half", n=f.n, radial=f.radial, vcavity=True, fresnel=fres(f.fresnel))
    elif isinstance(f, SmithLobe):
        codes = tuple(c[v] for c, v in zip(_SMITH_CODES, (f.distribution, f.g1, f.shadowing)))
        out.update(kind="half", n=f.alpha, radial=f.distribution, smith=(*codes, f.alpha), fresnel=fres(f.fresnel))
    elif isinstance(f, SchlickLobe):
        out.update(kind="half", n=math.sqrt(f.r), radial="ggx", schlick=f.r)
    elif isinstance(f, AshikhminShirleyLobe):
        out.update(kind="half", n=f.n, p=1.0, schlick_fresnel=f.rs)
    else:
        raise TypeError(f"kernel_view: unknown family {type(f).__name__}")
    for x in hint.factors:
        if isinstance(x, DivideByG):
            out.update(chain=x.lookups, levels=x.levels)
        elif isinstance(x, InverseAlbedoFactor):
            out.update(factor=(float(x.f0), *x.bound), levels=x.levels)
        elif isinstance(f, PowerLobe):  # F(max) on a lobe: frame 5, or a pumped lobe's frame of N, multiplies by it
            out.update(fresnel=(0.0, float(x.eta), float(x.k)))
        else:  # F(max) on frame 6's families: a factor of each node
            out.update(fmax=(float(x.eta), float(x.k)))
    return KernelView(**out)
