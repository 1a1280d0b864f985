"""A linear mix of two BRDFs: f = (1 - m) a + m b (a metalness blend, a layer weight).

The albedo engine integrates each side's terms with its own lobe hint
(:meth:`~pumpup.core.BRDF.albedo_terms`), and the sampler draws from the mixture of their
strategies, so a mix is as accurate and as well sampled as its parts.
"""

from __future__ import annotations

import numpy as np

from ..core import BRDF, Param, register


@register("mix")
class Mix(BRDF):
    """f_r = (1 - m) a + m b [1/sr]: the metalness blend of two BRDFs.

    Parameters
    ----------
    a, b : spec
        The two BRDFs (e.g. a diffuse base and a conductor).
    m : float, in [0, 1]
        The weight of ``b`` (the metalness).

    Notes
    -----
    a(mu) = (1 - m) a_a(mu) + m a_b(mu): the albedo is linear in f.  Reciprocal when both
    parts are.

    Examples
    --------
    >>> import pumpup
    >>> f = pumpup.load({"type": "mix", "a": {"type": "lambert"}, "b": {"type": "lambert", "albedo": 0.5}, "m": 0.5})
    >>> round(float(pumpup.albedo(f, 0.3)), 12)
    0.75
    """

    params = {
        "a": Param(kind="spec", doc="the BRDF of weight 1 - m"),
        "b": Param(kind="spec", doc="the BRDF of weight m"),
        "m": Param(0.5, lo=0.0, hi=1.0, doc="weight of b (metalness)"),
    }
    constant = None
    examples = [
        {"a": {"type": "lambert"}, "b": {"type": "phong", "n": 20}, "m": 0.3},
        {"a": {"type": "lambert", "albedo": 0.8}, "b": {"type": "ggx", "alpha": 0.3}, "m": 1.0},
    ]

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.reciprocal = bool(self.p["a"].reciprocal and self.p["b"].reciprocal)

    def _eval(self, wi, wo):
        m = self.p["m"]
        fa = np.asarray(self.p["a"]._eval(wi, wo), dtype=np.float64) if m < 1 else 0.0
        fb = np.asarray(self.p["b"]._eval(wi, wo), dtype=np.float64) if m > 0 else 0.0
        shape = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1])
        return np.broadcast_to((1.0 - m) * fa + m * fb, shape).copy()

    def reference(self, wi, wo):
        """The plain numpy f_r: (1 - m) a + m b from the two references."""
        m = self.p["m"]
        return (1.0 - m) * np.asarray(self.p["a"].reference(wi, wo)) + m * np.asarray(self.p["b"].reference(wi, wo))

    def albedo_breaks(self):
        """The breaks of both BRDFs, sorted."""
        return tuple(sorted({*self.p["a"].albedo_breaks(), *self.p["b"].albedo_breaks()}))

    def albedo_terms(self):
        """The terms of a weighted 1 - m and those of b weighted m (a term of weight 0 left out)."""
        m = self.p["m"]
        out = []
        if m < 1:
            out += [((1.0 - m) * w, t) for w, t in self.p["a"].albedo_terms()]
        if m > 0:
            out += [(m * w, t) for w, t in self.p["b"].albedo_terms()]
        return out
