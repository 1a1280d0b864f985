"""An unbiased Mitsuba 3 path tracer that finds caustics through a planar near-mirror: ``pumpup_caustic``.

A point light seen through a near-mirror (a Phong lobe of exponent n = 5000) from a rough surface is a caustic
that a path tracer finds only by chance: the rough surface's BSDF sample must fall into the mirror's narrow
lobe.  This integrator adds a second technique for exactly those paths and combines the two by one-sample
multiple importance sampling (the balance heuristic, Veach 1997, sec. 9.2), so the image stays unbiased.

The path tracer (technique A) is Mitsuba's ``path`` with ``max_depth`` (counting edges: next-event estimation
at the i-th hit makes a path of i + 1 edges): at each vertex, next-event estimation to every point light
(visibility by a shadow ray), BSDF sampling to continue; the environment (a constant sky) only where a camera
ray or a BSDF-sampled ray escapes.  No Russian roulette.

Technique B, at every vertex x above the mirror and not on it, for every point light l: the mirror image l' of
l across the mirror's plane; the specular point s where the segment x -> l' crosses the plane (skipped if s is
off the mirror); a direction w sampled from the lobe::

    q_l(w; x) = (k + 1) / (2 pi) cos^k(w, d0),    d0 = (s - x) / |s - x|,    k = c n (1 + |x - s| / |s - l|)^2,

(the mirror lobe's angular width seen from x, widened by ``k_scale`` = c), traced from x; if its first hit p
is on the mirror, the path x -> p -> l contributes::

    beta f_x(w) cos_x / q_l(w) * w_B * f_p(p -> l) cos_p V(p, l) I / |p - l|^2,
    w_B = q_l(w) / (q_l(w) + p_x(w)),

with p_x the BSDF-sampling pdf at x.  The path tracer's own estimate of the same path (BSDF sample w from x
hitting the mirror at p, then next-event estimation at p towards l) is weighted w_A = p_x(w) / (p_x(w) +
q_l(w; x)) (1 after a camera ray), so w_A + w_B = 1 for every such path: the sum is unbiased for any k.

The mirror is one planar shape (a ``rectangle`` with normal +y, named by ``mirror``: its bounding box gives
the plane and its extent); every other vertex must lie on or above its plane.

Properties: ``max_depth`` (int, default 6), ``mirror`` (shape id, default "plate"), ``mirror_n`` (the mirror
lobe's exponent, default 5000), ``k_scale`` (c above, default 0.25), ``technique_b`` (bool, default True:
False gives the plain path tracer, equal to Mitsuba's ``path`` in expectation).

Registered by :func:`register` (``pumpup.scenes`` calls it); Mitsuba is imported only inside functions.
"""

from __future__ import annotations

import math

__all__ = ["register"]

_CLASSES: dict = {}


def _integrator_class():
    import drjit as dr
    import mitsuba as mi

    class PumpupCaustic(mi.SamplingIntegrator):
        """Path tracer plus mirror-image sampling through a planar near-mirror, one-sample MIS (module docstring)."""

        def __init__(self, props):
            mi.SamplingIntegrator.__init__(self, props)
            self.max_depth = int(props.get("max_depth", 6))
            self.mirror_id = str(props.get("mirror", "plate"))
            self.mirror_n = float(props.get("mirror_n", 5000.0))
            self.k_scale = float(props.get("k_scale", 0.25))
            self.technique_b = bool(props.get("technique_b", True))
            if self.max_depth < 1:
                raise ValueError(f"pumpup_caustic: max_depth must be an integer >= 1, got {self.max_depth}")
            if not (self.mirror_n > 0.0 and self.k_scale > 0.0):
                raise ValueError("pumpup_caustic: mirror_n and k_scale must be > 0, got "
                                 f"{self.mirror_n} and {self.k_scale}")

        # ---- the scene's pieces (Python-side, once per render) ------------------------------------
        def _setup(self, scene):
            mirror = [s for s in scene.shapes() if s.id() == self.mirror_id]
            if len(mirror) != 1:
                raise ValueError(f"pumpup_caustic: mirror must name one shape of the scene, got {self.mirror_id!r}")
            bb = mirror[0].bbox()
            lo, hi = [float(v) for v in bb.min], [float(v) for v in bb.max]
            if hi[1] - lo[1] > 1e-4 * max(hi[0] - lo[0], hi[2] - lo[2]):
                raise ValueError("pumpup_caustic: the mirror must be a horizontal plane (y = const)")
            lights = []
            for e in scene.emitters():
                if e.is_environment():
                    continue
                if not mi.has_flag(e.flags(), mi.EmitterFlags.DeltaPosition):
                    raise ValueError("pumpup_caustic: only point lights and one environment are supported")
                pos = mi.traverse(e)["position"]
                lights.append((e, [float(dr.slice(pos[i])) if dr.width(pos[i]) else float(pos[i])
                                   for i in range(3)]))
            return mi.ShapePtr(mirror[0]), 0.5 * (lo[1] + hi[1]), (lo[0], hi[0], lo[2], hi[2]), lights

        # ---- technique B's lobe about the specular direction towards a light's mirror image ------
        def _lobe(self, x, light, plane, ext, active):
            """d0, k and whether the lobe exists at vertex x for a light at ``light``."""
            ly = light[1] - plane
            h = x.y - plane
            t = h / (h + ly)  # s = x + t (l' - x), l' = (lx, plane - ly, lz)
            lp = mi.Point3f(light[0], plane - ly, light[2])
            s = x + t * (lp - x)
            ok = active & (h > 1e-4) & (s.x >= ext[0]) & (s.x <= ext[1]) & (s.z >= ext[2]) & (s.z <= ext[3])
            d = s - x
            dist_xs = dr.norm(d)
            dist_sl = dr.norm(mi.Point3f(*light) - s)
            d0 = d / dr.maximum(dist_xs, 1e-12)
            r = dist_xs / dr.maximum(dist_sl, 1e-12)
            k = self.k_scale * self.mirror_n * dr.square(1.0 + r)
            return d0, k, ok

        @staticmethod
        def _lobe_pdf(w, d0, k, ok):
            """(k + 1) / (2 pi) cos^k with 1 - cos from |w - d0|^2 / 2 (accurate near the axis)."""
            om = 0.5 * dr.squared_norm(w - d0)  # 1 - cos(w, d0)
            val = (k + 1.0) / (2.0 * math.pi) * dr.exp(k * dr.log(dr.maximum(1.0 - om, 1e-30)))
            return dr.select(ok & (om < 1.0), val, 0.0)

        @staticmethod
        def _lobe_sample(d0, k, u):
            """A direction of the lobe: cos = u0^(1 / (k + 1)), 1 - cos computed as -expm1(log(u0) / (k + 1))."""
            e = dr.log(dr.maximum(u.x, 1e-30)) / (k + 1.0)
            om = dr.select(e > -1e-3, -e * (1.0 + 0.5 * e), 1.0 - dr.exp(e))  # 1 - cos = -expm1(e)
            cos = 1.0 - om
            sin = dr.safe_sqrt(om * (2.0 - om))
            phi = 2.0 * math.pi * u.y
            local = mi.Vector3f(sin * dr.cos(phi), sin * dr.sin(phi), cos)
            return mi.Frame3f(d0).to_world(local)

        def _nee(self, scene, ctx, si, bsdf, em, active):
            """Next-event estimate f cos I / r^2 V towards a point light (Spectrum, 0 where occluded or inactive)."""
            ds, le = em.sample_direction(si, mi.Point2f(0.5, 0.5), active)
            vis = active & (ds.pdf > 0.0) & ~scene.ray_test(si.spawn_ray_to(ds.p), active)
            f = bsdf.eval(mi.BSDFContext(), si, si.to_local(ds.d), vis)
            return dr.select(vis, f * le, 0.0)

        # ---- the estimator ------------------------------------------------------------------------
        def sample(self, scene, sampler, ray, medium=None, active=True):
            mirror, plane, ext, lights = self._setup(scene)
            env = scene.environment()
            ctx = mi.BSDFContext()
            ray = mi.Ray3f(ray)
            active = mi.Bool(active)
            L = mi.Spectrum(0.0)
            beta = mi.Spectrum(1.0)
            prev_x = mi.Point3f(0.0)
            prev_pdf = mi.Float(0.0)
            prev_mis = mi.Bool(False)  # the previous vertex could have made this one by technique B
            for depth in range(self.max_depth):
                si = scene.ray_intersect(ray, active)
                escaped = active & ~si.is_valid()
                if env is not None:
                    L += dr.select(escaped, beta * env.eval(si, escaped), 0.0)
                active &= si.is_valid()
                if depth + 1 >= self.max_depth:
                    break
                bsdf = si.bsdf(ray)
                on_mirror = si.shape == mirror
                # next-event estimation to each point light; at a mirror vertex reached by a BSDF sample from
                # a vertex that technique B also serves, weighted w_A = p_x / (p_x + q_l)
                for em, pos in lights:
                    c = self._nee(scene, ctx, si, bsdf, em, active)
                    if self.technique_b and depth + 1 < self.max_depth:
                        d0, k, ok = self._lobe(prev_x, pos, plane, ext, prev_mis & on_mirror & active)
                        q = self._lobe_pdf(ray.d, d0, k, ok)
                        c *= dr.select(ok, prev_pdf / dr.maximum(prev_pdf + q, 1e-30), 1.0)
                    L += beta * c
                # technique B: x -> p (mirror) -> light through the light's mirror image
                x_ok = active & ~on_mirror
                if self.technique_b and depth + 2 < self.max_depth:
                    for em, pos in lights:
                        d0, k, ok = self._lobe(si.p, pos, plane, ext, x_ok)
                        w = self._lobe_sample(d0, k, sampler.next_2d(ok))
                        q = self._lobe_pdf(w, d0, k, ok)
                        fx, px = bsdf.eval_pdf(ctx, si, si.to_local(w), ok)
                        ok &= (q > 0.0) & (dr.max(fx) > 0.0)
                        ray_b = si.spawn_ray(w)
                        sp = scene.ray_intersect(ray_b, ok)
                        ok &= sp.is_valid() & (sp.shape == mirror)
                        bsdf_p = sp.bsdf(ray_b)
                        c = self._nee(scene, ctx, sp, bsdf_p, em, ok)
                        L += dr.select(ok, beta * fx * c / dr.maximum(q + px, 1e-30), 0.0)  # f/q * q/(q+p_x)
                # BSDF sampling to continue
                bs, wt = bsdf.sample(ctx, si, sampler.next_1d(active), sampler.next_2d(active), active)
                active &= bs.pdf > 0.0
                beta *= dr.select(active, wt, 0.0)
                prev_x = mi.Point3f(si.p)
                prev_pdf = mi.Float(bs.pdf)
                prev_mis = active & ~on_mirror & (depth + 2 < self.max_depth)
                ray = si.spawn_ray(si.to_world(bs.wo))
            return L, mi.Bool(True), []

        def aov_names(self):
            return []

        def to_string(self):
            return (f"PumpupCaustic[max_depth={self.max_depth}, mirror={self.mirror_id!r}, n={self.mirror_n}, "
                    f"k_scale={self.k_scale}, technique_b={self.technique_b}]")

    return PumpupCaustic


def register() -> None:
    """Register the ``pumpup_caustic`` integrator for the current Mitsuba variant (idempotent)."""
    import mitsuba as mi

    v = mi.variant()
    if v not in _CLASSES:
        _CLASSES[v] = _integrator_class()
    cls = _CLASSES[v]
    mi.register_integrator("pumpup_caustic", lambda props: cls(props))
