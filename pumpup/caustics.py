"""An unbiased Mitsuba 3 path tracer that finds caustics through planar near-mirrors: ``pumpup_caustic``.

A point light seen through a near-mirror (a Phong lobe of exponent n = 5000) from a rough surface is a caustic
that a path tracer finds only by chance: the rough surface's BSDF sample must fall into the mirror's narrow
lobe.  This integrator adds a technique for the paths that reach a light through one mirror (B) and a
continuation that aims at a light seen through two mirrors (C), and combines them with the path tracer by
one-sample multiple importance sampling (the balance heuristic, Veach 1997, sec. 9.2), so the image stays
unbiased.

The path tracer (technique A) is Mitsuba's ``path`` with ``max_depth`` (counting edges: next-event estimation
at the i-th hit makes a path of i + 1 edges): at each vertex, next-event estimation to every point light
(visibility by a shadow ray), a sampled direction to continue (the BSDF's, or technique C's where it applies,
below); the environment (a constant sky) only where a camera ray or a continuation escapes.  No Russian
roulette.

The mirrors are planar rectangles: a ``rectangle`` shape, or each planar face of a mesh made of rectangles (a
``cube``).  Technique B, at every vertex x, for every point light l: the faces f in front of both x and l whose
plane holds a specular point s (where the segment from x to l's mirror image l' in f's plane crosses that plane)
on f or within a margin of it; their number N(x, l); one of them picked uniformly, and a direction w sampled from
the lobe::

    q_f(w; x) = (k + 1) / (2 pi) cos^k(w, d0),    d0 = (s - x) / |s - x|,    k = c n (1 + |x - s| / |s - l|)^2,

(the mirror lobe's angular width seen from x, widened by ``k_scale`` = c), traced from x.  The margin is
m |x - s| sqrt(2 / k) / max(cos, 0.05) (cos between d0 and f's normal): the lobe's footprint on f's plane, m
times, so that points near a face's edge, which reflect l towards x although s is just outside f, are sampled
too.  If w's first hit p is on f, the path x -> p -> l contributes::

    beta f_x(w) cos_x / (q_f(w) / N) * w_B * f_p(p -> l) cos_p V(p, l) I / |p - l|^2,
    w_B = (q_f(w) / N) / (q_f(w) / N + p_x(w)),

with p_x the continuation's pdf at x (below).  The path tracer's own estimate of the same path (a continuation
w from x hitting face f at p, then next-event estimation at p towards l) is weighted w_A = p_x(w) / (p_x(w) +
q_f(w; x) / N(x, l)) (1 after a camera ray), so w_A + w_B = 1 for every such path: the sum is unbiased for any
k.

Technique C reaches a light through two mirror faces, x -> p1 (on f1) -> p2 (on f2) -> l.  Unfolded, p1 -> p2
-> l is a straight line from p1 to l's image l' in f2's plane, so x -> p1 is B's lobe for a light at l' and the
face f1: about x -> s1 (s1 where x -> l'' crosses f1's plane, l'' the image of l' in it), k = c n (1 + |x - s1| /
|s1 - l'|)^2, valid where s1 is on f1 within B's margin and the segment s1 -> l' crosses f2's plane at s2 on f2
within m (|x - s1| + |s1 - s2|) sqrt(2 / k) / max(cos2, 0.05) (cos2 between s1 -> l' and f2's normal).  The
ordered pairs (f1, f2) are pruned once per render (:func:`mirror_pairs`: l in front of f2, each face partly in
front of the other's plane, l' in front of f1, and the lobe valid somewhere on the shapes that are not mirrors).
q_C(w; x) is the uniform mixture of the M(x) valid lobes over all point lights and pairs, and the continuation
at x samples::

    p_x(w) = a p_bsdf(w) + (1 - a) q_C(w; x),    beta *= f_x(w) cos_x / p_x(w),

whichever of the two produced w; 1 - a = ``C_SHARE`` (1/10) where M(x) > 0 and x is on no mirror shape, its BSDF
has no delta component and the path has room for both bounces and the next-event estimate (depth + 3 <
``max_depth``); a = 1 (BSDF sampling alone) elsewhere.  q_C is a pdf over all directions (no test whether w hits
f1), so p_x is exact for every w, and a depends on x only: the continuation is unbiased for any lobes.  At p1,
technique B samples the second bounce p1 -> p2 -> l.  p_x enters both weights w_A and w_B above.

Properties: ``max_depth`` (int, default 6), ``mirror`` (the mirror shapes' ids, comma-separated, or ``*`` for
every shape and ``-id`` to leave one out; default "plate"), ``mirror_n`` (the mirror lobe's exponent, default
5000), ``k_scale`` (c above, default 0.25), ``technique_b`` (bool, default True: False gives the path tracer
without B), ``technique_c`` (bool, default True: False samples every continuation from the BSDF; both False give
the plain path tracer, equal to Mitsuba's ``path`` in expectation), ``margin`` (m above, default 3; 0 takes only
specular points on the face).  The set of faces and pairs, N, M and the lobes depend on x and l only, and every
weight uses the same ones, so the image is unbiased for any k and m.

Registered by :func:`register` (``pumpup.scenes`` calls it); Mitsuba is imported only inside functions.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["register", "mirror_pairs", "K_SCALE", "C_SHARE"]

#: the default widening c of technique B's lobe (``k_scale``)
K_SCALE = 0.25

#: technique C's share 1 - a of the continuation where its lobes apply (module docstring)
C_SHARE = 0.1

_CLASSES: dict = {}


def _lobe_np(x, light, face, kn, margin):
    """The numpy twin of the integrator's lobe test for points ``x`` (P, 3): (s, k, ok) for a light's image in a face.

    ``face`` is (c, n, u, v) (centre, unit normal, half-edge vectors), ``kn`` = c n of the module docstring.
    """
    c, n, u, v = face
    side_l = float((light - c) @ n)
    side_x = (x - c) @ n
    lp = light - 2.0 * side_l * n
    t = side_x / np.where(np.abs(side_x + side_l) > 1e-12, side_x + side_l, 1e-12)
    s = x + t[:, None] * (lp - x)
    d = s - x
    dist_xs = np.linalg.norm(d, axis=1)
    dist_sl = np.linalg.norm(light - s, axis=1)
    k = kn * (1.0 + dist_xs / np.maximum(dist_sl, 1e-12)) ** 2
    cos_s = np.abs(d @ n) / np.maximum(dist_xs, 1e-12)
    m = margin * dist_xs * np.sqrt(2.0 / k) / np.maximum(cos_s, 0.05)
    lu, lv = np.linalg.norm(u), np.linalg.norm(v)
    ok = ((side_x > 1e-4) & (np.abs((s - c) @ (u / lu)) <= lu + m) & (np.abs((s - c) @ (v / lv)) <= lv + m))
    return s, k, ok


def mirror_pairs(faces, light, points, kn, margin) -> list:
    """Technique C's ordered face pairs (i1, i2) for a point light at ``light``, pruned (numpy, once per render).

    ``faces`` is a list of (shape index, c, n, u, v) (the index is not used): the mirror faces (centre, unit normal,
    half-edge vectors); ``points`` (P, 3) are points where a vertex may use technique C (a grid over the shapes that
    are not mirrors). A pair is kept if the light is in front of f2, f1 != f2, each is partly in front of the
    other's plane (two faces of one cube never are, nor of two cubes merged into one mesh), the light's image l' in
    f2's plane is in front of f1, and at one of the points at least the path x -> f1 -> f2 -> l passes the
    integrator's test with twice its margin (q_C is a valid pdf for any set of pairs: the pruning changes the noise,
    not the mean).
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    corners = [np.array([c + a * u + b * v for a in (-1, 1) for b in (-1, 1)]) for _, c, _, u, v in faces]
    tol = [1e-5 * float(np.linalg.norm(u) + np.linalg.norm(v)) for _, _, _, u, v in faces]
    out = []
    for i2, (_, c2, n2, u2, v2) in enumerate(faces):
        side_l2 = float((light - c2) @ n2)
        if side_l2 <= 1e-6:
            continue
        lp = light - 2.0 * side_l2 * n2  # the light's image in f2's plane
        for i1, (_, c1, n1, u1, v1) in enumerate(faces):
            # (two faces of one convex shape fail the first two tests: each lies behind the other's plane)
            if i1 == i2 or not (np.any((corners[i1] - c2) @ n2 > tol[i1])
                                and np.any((corners[i2] - c1) @ n1 > tol[i2]) and (lp - c1) @ n1 > 1e-6):
                continue
            if not len(points):
                continue
            s1, k, ok = _lobe_np(points, lp, (c1, n1, u1, v1), kn, 2.0 * margin)
            if ok.any() and _second_face_np(points[ok], s1[ok], k[ok], lp, (c2, n2, u2, v2), 2.0 * margin).any():
                out.append((i1, i2))
    return out


def _second_face_np(x, s1, k, lp, face, margin):
    """The numpy twin of the integrator's test that s1 -> l' crosses f2's plane on f2 (within the margin)."""
    c, n, u, v = face
    side1 = (s1 - c) @ n
    side_lp = float((lp - c) @ n)
    t = side1 / np.where(side1 - side_lp > 1e-12, side1 - side_lp, 1e-12)
    s2 = s1 + t[:, None] * (lp - s1)
    e = lp - s1
    cos2 = np.abs(e @ n) / np.maximum(np.linalg.norm(e, axis=1), 1e-12)
    dist = np.linalg.norm(s1 - x, axis=1) + np.linalg.norm(s2 - s1, axis=1)
    m = margin * dist * np.sqrt(2.0 / k) / np.maximum(cos2, 0.05)
    lu, lv = np.linalg.norm(u), np.linalg.norm(v)
    return ((side1 > 1e-4) & (np.abs((s2 - c) @ (u / lu)) <= lu + m) & (np.abs((s2 - c) @ (v / lv)) <= lv + m))


def _integrator_class():
    import drjit as dr
    import mitsuba as mi

    def _p3(a):
        return mi.Point3f(*[float(z) for z in a])

    def _v3(a):
        return mi.Vector3f(*[float(z) for z in a])

    class PumpupCaustic(mi.SamplingIntegrator):
        """Path tracer plus mirror-image sampling through a planar near-mirror, one-sample MIS (module docstring)."""

        def __init__(self, props):
            mi.SamplingIntegrator.__init__(self, props)
            self.max_depth = int(props.get("max_depth", 6))
            self.mirror_id = str(props.get("mirror", "plate"))
            self.mirror_n = float(props.get("mirror_n", 5000.0))
            self.k_scale = float(props.get("k_scale", K_SCALE))
            self.technique_b = bool(props.get("technique_b", True))
            self.margin = float(props.get("margin", 3.0))
            self.technique_c = bool(props.get("technique_c", True))
            if self.max_depth < 1:
                raise ValueError(f"pumpup_caustic: max_depth must be an integer >= 1, got {self.max_depth}")
            if not self.margin >= 0.0:
                raise ValueError(f"pumpup_caustic: margin must be >= 0, got {self.margin}")
            if not (self.mirror_n > 0.0 and self.k_scale > 0.0):
                raise ValueError("pumpup_caustic: mirror_n and k_scale must be > 0, got "
                                 f"{self.mirror_n} and {self.k_scale}")

        # ---- the scene's pieces (Python-side, once per render) ------------------------------------
        def _mirror_shapes(self, scene):
            want = [w.strip() for w in self.mirror_id.split(",") if w.strip()]
            shapes = list(scene.shapes())
            if "*" in want:
                out = [s for s in shapes if "-" + s.id() not in want]
            else:
                out = [s for s in shapes if s.id() in want]
                if len(out) != len(want):
                    raise ValueError("pumpup_caustic: mirror must name shapes of the scene (comma-separated ids, "
                                     f"or '*' and '-id' to exclude), got {self.mirror_id!r}")
            return out

        @staticmethod
        def _faces(shape):
            """The planar rectangles of a shape: a ``rectangle``, or a mesh's faces grouped by plane."""
            params = mi.traverse(shape)

            def vec(a):
                return np.array([float(v) for v in a], dtype=np.float64)

            if "vertex_positions" not in params:  # a rectangle: [-1, 1]^2 at z = 0, normal +z, then to_world
                m = np.array(params["to_world"].matrix, dtype=np.float64).reshape(4, 4)
                c = m[:3, 3]
                u, v = m[:3, 0], m[:3, 1]
                return [(c, u, v)]
            pos = np.array(params["vertex_positions"], dtype=np.float64).reshape(-1, 3)
            tri = np.array(params["faces"], dtype=np.int64).reshape(-1, 3)
            nrm = np.cross(pos[tri[:, 1]] - pos[tri[:, 0]], pos[tri[:, 2]] - pos[tri[:, 0]])
            nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
            off = np.einsum("ij,ij->i", nrm, pos[tri[:, 0]])
            groups: list = []  # (plane key, vertex indices): triangles of one plane that share vertices
            for i in range(len(tri)):
                key = tuple(np.round(np.r_[nrm[i], off[i]], 4))
                idx = set(tri[i].tolist())
                for g in groups:
                    if g[0] == key and g[1] & idx:
                        g[1].update(idx)
                        break
                else:
                    groups.append((key, idx))
            out = []
            for key, idx in groups:
                pts = np.unique(np.round(pos[sorted(idx)], 5), axis=0)
                if len(pts) != 4:
                    raise ValueError("pumpup_caustic: a mirror mesh must be made of planar rectangles")
                a = pts[0]
                far = int(np.argmax(np.linalg.norm(pts - a, axis=1)))
                b, e = [pts[j] for j in range(1, 4) if j != far]
                u, v = (b - a) / 2.0, (e - a) / 2.0
                if abs(u @ v) > 1e-4 * (u @ u + v @ v):
                    raise ValueError("pumpup_caustic: a mirror mesh must be made of planar rectangles")
                n = np.cross(u, v)
                if n @ np.array(key[:3]) < 0:
                    u, v = v, u
                out.append(((a + pts[far]) / 2.0, u, v))
            return out

        def _setup(self, scene):
            """Per point light: (emitter, position, faces in front of it, technique C's pairs (f1, f2, l')),
            and the mirror shapes; kept for the scene's next call in the scalar variants (which call ``sample``
            per ray; the JIT variants trace it once per render).
            """
            scalar = mi.variant().startswith("scalar")
            if scalar and getattr(self, "_cache", (None,))[0] is scene:
                return self._cache[1]
            mirrors = self._mirror_shapes(scene)
            faces, plain = [], []
            for si, shape in enumerate(mirrors):
                for c, u, v in self._faces(shape):
                    n = np.cross(u, v)
                    n /= np.linalg.norm(n)
                    faces.append((mi.ShapePtr(shape), c, n, u, v))
                    plain.append((si, c, n, u, v))
            points = self._points([s for s in scene.shapes() if all(s is not m for m in mirrors)])
            lights = []
            for e in scene.emitters():
                if e.is_environment():
                    continue
                if not mi.has_flag(e.flags(), mi.EmitterFlags.DeltaPosition):
                    raise ValueError("pumpup_caustic: only point lights and one environment are supported")
                pos = mi.traverse(e)["position"]
                lpos = np.array([float(dr.slice(pos[i])) if dr.width(pos[i]) else float(pos[i]) for i in range(3)])
                pairs = []
                if self.technique_c and self.max_depth >= 4:
                    for i1, i2 in mirror_pairs(plain, lpos, points, self.k_scale * self.mirror_n, self.margin):
                        c2, n2 = plain[i2][1], plain[i2][2]
                        pairs.append((faces[i1], faces[i2], lpos - 2.0 * float((lpos - c2) @ n2) * n2))
                lights.append((e, lpos, [f for f in faces if (lpos - f[1]) @ f[2] > 1e-6], pairs))
            out = (lights, [mi.ShapePtr(m) for m in mirrors])
            if scalar:
                self._cache = (scene, out)
            return out

        @staticmethod
        def _points(shapes, grid=48):
            """A grid of points over the bounding boxes of ``shapes`` (one layer along a flat extent), (P, 3)."""
            out = []
            for shape in shapes:
                box = shape.bbox()
                lo = np.array([float(dr.slice(box.min[i])) if dr.width(box.min[i]) else float(box.min[i])
                               for i in range(3)])
                hi = np.array([float(dr.slice(box.max[i])) if dr.width(box.max[i]) else float(box.max[i])
                               for i in range(3)])
                axes = [np.linspace(lo[i], hi[i], grid) if hi[i] - lo[i] > 1e-6 else np.array([lo[i]])
                        for i in range(3)]
                out.append(np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3))
            return np.concatenate(out) if out else np.zeros((0, 3))

        # ---- technique B's lobe about the specular direction towards a light's mirror image ------
        def _lobe(self, x, light, face, active):
            """d0, k and whether the lobe exists at vertex x for a light at ``light`` and a mirror ``face``."""
            return self._lobe_full(x, light, face, active)[:3]

        def _lobe_full(self, x, light, face, active):
            """:meth:`_lobe` and the specular point s and |x - s|."""
            _, c, n, u, v = face
            side_l = float((light - c) @ n)
            side_x = dr.dot(x - _p3(c), _v3(n))
            lp = light - 2.0 * side_l * n  # the light's mirror image
            t = side_x / (side_x + side_l)
            s = x + t * (_p3(lp) - x)  # where x -> l' crosses the face's plane
            sc = s - _p3(c)
            d = s - x
            dist_xs = dr.norm(d)
            dist_sl = dr.norm(_p3(light) - s)
            d0 = d / dr.maximum(dist_xs, 1e-12)
            r = dist_xs / dr.maximum(dist_sl, 1e-12)
            k = self.k_scale * self.mirror_n * dr.square(1.0 + r)
            # s may lie just outside the face while the lobe still reaches it: accept s within the margin
            # m = margin |x - s| sqrt(2 / k) / cos (the lobe's footprint on the plane, module docstring)
            cos_s = dr.abs(dr.dot(d0, _v3(n)))
            m = self.margin * dist_xs * dr.sqrt(2.0 / k) / dr.maximum(cos_s, 0.05)
            lu, lv = float(np.linalg.norm(u)), float(np.linalg.norm(v))
            ok = (active & (side_x > 1e-4) & (dr.abs(dr.dot(sc, _v3(u / lu))) <= lu + m)
                  & (dr.abs(dr.dot(sc, _v3(v / lv))) <= lv + m))
            return d0, k, ok, s, dist_xs

        def _lobe_pair(self, x, image, f1, f2, active):
            """Technique C's lobe at x for a pair (f1, f2): about x -> s1, s1 on f1's plane where x -> p1 -> l'
            reflects (l' = ``image``, the light's image in f2's plane), with the test that s1 -> l' crosses f2's
            plane on f2 within the margin m (dist_xs + |s1 - s2|) sqrt(2 / k) / cos2: d0, k, ok.
            """
            d0, k, ok, s1, dist_xs = self._lobe_full(x, image, f1, active)
            _, c2, n2, u2, v2 = f2
            side1 = dr.dot(s1 - _p3(c2), _v3(n2))
            side_lp = float((image - c2) @ n2)
            t = side1 / dr.maximum(side1 - side_lp, 1e-12)
            e = _p3(image) - s1
            s2 = s1 + t * e
            s2c = s2 - _p3(c2)
            cos2 = dr.abs(dr.dot(e, _v3(n2))) / dr.maximum(dr.norm(e), 1e-12)
            m = self.margin * (dist_xs + dr.norm(s2 - s1)) * dr.sqrt(2.0 / k) / dr.maximum(cos2, 0.05)
            lu, lv = float(np.linalg.norm(u2)), float(np.linalg.norm(v2))
            ok &= ((side1 > 1e-4) & (dr.abs(dr.dot(s2c, _v3(u2 / lu))) <= lu + m)
                   & (dr.abs(dr.dot(s2c, _v3(v2 / lv))) <= lv + m))
            return d0, k, ok

        @staticmethod
        def _on_face(si, face):
            """Whether the hit ``si`` lies on ``face`` (its shape, its plane, inside it)."""
            ptr, c, n, u, v = face
            pc = si.p - _p3(c)
            size = math.sqrt(float(u @ u + v @ v))
            return ((si.shape == ptr) & (dr.abs(dr.dot(pc, _v3(n))) < 1e-4 * size)
                    & (dr.abs(dr.dot(pc, _v3(u))) <= 1.0001 * float(u @ u))
                    & (dr.abs(dr.dot(pc, _v3(v))) <= 1.0001 * float(v @ v)))

        @staticmethod
        def _mix_pdf(a, p_bsdf, q_c):
            """The continuation's pdf a p_bsdf + (1 - a) q_C (module docstring)."""
            return a * p_bsdf + (1.0 - a) * q_c

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
            f = bsdf.eval(ctx, si, si.to_local(ds.d), vis)
            return dr.select(vis, f * le, 0.0)

        # ---- the estimator ------------------------------------------------------------------------
        def sample(self, scene, sampler, ray, medium=None, active=True):
            lights, mirror_ptrs = self._setup(scene)
            env = scene.environment()
            ctx = mi.BSDFContext()
            ray = mi.Ray3f(ray)
            active = mi.Bool(active)
            L = mi.Spectrum(0.0)
            beta = mi.Spectrum(1.0)
            prev_pdf = mi.Float(0.0)
            prev_mis = mi.Bool(False)  # technique B ran at the previous vertex
            prev_lobes: dict = {}  # technique B's lobes there, per light: (d0, k, ok) per face
            any_pairs = any(pairs for *_, pairs in lights)
            for depth in range(self.max_depth):
                si = scene.ray_intersect(ray, active)
                escaped = active & ~si.is_valid()
                if env is not None:
                    L += dr.select(escaped, beta * env.eval(si, escaped), 0.0)
                active &= si.is_valid()
                if depth + 1 >= self.max_depth:
                    break
                bsdf = si.bsdf(ray)
                # technique C's lobes (x -> f1 -> f2 -> l), where they apply: x not on a mirror, a BSDF without
                # a delta component, and room for the two bounces and next-event estimation (depth + 3 edges)
                c_lobes = []
                a = mi.Float(1.0)
                if any_pairs and depth + 3 < self.max_depth:
                    use_c = active & ~mi.has_flag(bsdf.flags(), mi.BSDFFlags.Delta)
                    for ptr in mirror_ptrs:
                        use_c &= si.shape != ptr
                    count_c = mi.Float(0.0)
                    for em, pos, faces, pairs in lights:
                        for f1, f2, image in pairs:
                            c_lobes.append(self._lobe_pair(si.p, image, f1, f2, use_c))
                            count_c += dr.select(c_lobes[-1][2], 1.0, 0.0)
                    a = dr.select(count_c > 0.0, 1.0 - C_SHARE, 1.0)

                def q_c(w):
                    """Technique C's pdf of direction w: the uniform mixture of the valid lobes."""
                    q = mi.Float(0.0)
                    for d0, k, ok in c_lobes:
                        q += self._lobe_pdf(w, d0, k, ok)
                    return q / dr.maximum(count_c, 1.0)

                # next-event estimation to each point light; at a mirror face reached by a continuation from a
                # vertex where technique B ran, weighted w_A = p_x / (p_x + q_f / N) (balance heuristic)
                for li, (em, pos, faces, _) in enumerate(lights):
                    c = self._nee(scene, ctx, si, bsdf, em, active)
                    if li in prev_lobes:  # (absent where B did not run at the previous vertex: w_A = 1)
                        count, q_sel = mi.Float(0.0), mi.Float(0.0)
                        for (d0, k, ok), face in zip(prev_lobes[li], faces):
                            ok = ok & prev_mis & active
                            count += dr.select(ok, 1.0, 0.0)
                            hit = ok & self._on_face(si, face)
                            q_sel += dr.select(hit, self._lobe_pdf(ray.d, d0, k, hit), 0.0)
                        q = q_sel / dr.maximum(count, 1.0)
                        c *= dr.select(q > 0.0, prev_pdf / dr.maximum(prev_pdf + q, 1e-30), 1.0)
                    L += beta * c
                # technique B: x -> p (a mirror face) -> light through the light's image in that face's plane
                lobes_here = {}
                if self.technique_b and depth + 2 < self.max_depth:
                    for li, (em, pos, faces, _) in enumerate(lights):
                        if not faces:
                            continue
                        lobes = lobes_here[li] = [self._lobe(si.p, pos, face, active) for face in faces]
                        count = mi.Float(0.0)
                        for _, _, ok in lobes:
                            count += dr.select(ok, 1.0, 0.0)
                        pick = dr.floor(sampler.next_1d(active) * count)  # one valid face, uniformly
                        run = mi.Float(0.0)
                        d0, k, sel = mi.Vector3f(0.0, 0.0, 1.0), mi.Float(1.0), mi.Bool(False)
                        chosen = []
                        for (d0_f, k_f, ok), face in zip(lobes, faces):
                            this = ok & (run == pick)
                            run += dr.select(ok, 1.0, 0.0)
                            d0 = dr.select(this, d0_f, d0)
                            k = dr.select(this, k_f, k)
                            sel |= this
                            chosen.append((this, face))
                        w = self._lobe_sample(d0, k, sampler.next_2d(sel))
                        q = self._lobe_pdf(w, d0, k, sel) / dr.maximum(count, 1.0)
                        fx, px = bsdf.eval_pdf(ctx, si, si.to_local(w), sel)
                        if c_lobes:  # the continuation's pdf p_x = a p_bsdf + (1 - a) q_C
                            px = self._mix_pdf(a, px, q_c(w))
                        ok = sel & (q > 0.0) & (dr.max(fx) > 0.0)
                        ray_b = si.spawn_ray(w)
                        sp = scene.ray_intersect(ray_b, ok)
                        on = mi.Bool(False)
                        for this, face in chosen:
                            on |= this & self._on_face(sp, face)
                        ok &= sp.is_valid() & on
                        bsdf_p = sp.bsdf(ray_b)
                        c = self._nee(scene, ctx, sp, bsdf_p, em, ok)
                        L += dr.select(ok, beta * fx * c / dr.maximum(q + px, 1e-30), 0.0)  # f/q * q/(q+p_x)
                # the continuation: BSDF sampling, or (probability 1 - a) technique C's mixture of lobes
                bs, wt = bsdf.sample(ctx, si, sampler.next_1d(active), sampler.next_2d(active), active)
                wo = si.to_world(bs.wo)
                if c_lobes:
                    take_c = (sampler.next_1d(active) >= a) & active
                    pick = dr.floor(sampler.next_1d(take_c) * count_c)  # one valid lobe, uniformly
                    run = mi.Float(0.0)
                    d0, k = mi.Vector3f(0.0, 0.0, 1.0), mi.Float(1.0)
                    for d0_j, k_j, ok in c_lobes:
                        this = ok & (run == pick)
                        run += dr.select(ok, 1.0, 0.0)
                        d0 = dr.select(this, d0_j, d0)
                        k = dr.select(this, k_j, k)
                    w_c = self._lobe_sample(d0, k, sampler.next_2d(take_c))
                    fc, pc = bsdf.eval_pdf(ctx, si, si.to_local(w_c), take_c)
                    wo = dr.select(take_c, w_c, wo)
                    f_cos = dr.select(take_c, fc, wt * bs.pdf)  # Mitsuba's weight is f cos / p_bsdf
                    p_bsdf = dr.select(take_c, pc, bs.pdf)
                    p_mix = self._mix_pdf(a, p_bsdf, q_c(wo))  # exact for either component's w
                    active &= p_mix > 0.0
                    beta *= dr.select(active, f_cos / dr.maximum(p_mix, 1e-30), 0.0)
                    prev_pdf = mi.Float(p_mix)
                else:
                    active &= bs.pdf > 0.0
                    beta *= dr.select(active, wt, 0.0)
                    prev_pdf = mi.Float(bs.pdf)
                prev_mis = active & (depth + 2 < self.max_depth)
                prev_lobes = lobes_here
                ray = si.spawn_ray(wo)
            return L, mi.Bool(True), []

        def aov_names(self):
            return []

        def to_string(self):
            return (f"PumpupCaustic[max_depth={self.max_depth}, mirror={self.mirror_id!r}, n={self.mirror_n}, "
                    f"k_scale={self.k_scale}, technique_b={self.technique_b}, technique_c={self.technique_c}, "
                    f"margin={self.margin}]")

    return PumpupCaustic


def register() -> None:
    """Register the ``pumpup_caustic`` integrator for the current Mitsuba variant (idempotent)."""
    import mitsuba as mi

    v = mi.variant()
    if v not in _CLASSES:
        _CLASSES[v] = _integrator_class()
    cls = _CLASSES[v]
    mi.register_integrator("pumpup_caustic", lambda props: cls(props))
