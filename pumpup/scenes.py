"""Path-traced scenes of the papers in Mitsuba 3, through the ``pumpup`` plugin (issue 18, item 2).

Each scene renders the same geometry, lights and samples twice (or four times) with the original
model and with its stretched or pumped version, side by side:

``000-fig8``
    000 Fig. 8, left: "a golden Beethoven (n = 4) with a copper sphere (n = 40) and a copper
    pyramid (n = 150) on a silver mirror (n = 5000)".  Here a gold sphere (n = 4) stands for the
    head and a cube for the pyramid.  Original: reciprocal Phong (000 eq. 5); new: stretched Phong
    (000 eq. 7 with Fresnel: 000 eq. 28), both times the measured metal's F(Theta_min) per RGB channel.
``000-fig9``
    000 Fig. 9: plastic spheres of one hue and different lightness and saturation, with
    (a_s, n) = (0.04, 169), (0.065, 64), (0.09, 9), (0.13, 3), on a plastic plate.  Original:
    Lambert + a_s x reciprocal Phong; new: 000 eq. 30 (``plastic``: Lambert + a_s x stretched
    Phong, Fresnel 1).
``001-fig8``
    001 Fig. 8: "a golden tank with aluminum, silver, copper and golden pyramids", reciprocal
    Phong (top) against Phong pumped up once (bottom), n = 20 (left) and n = 5000 (right), both times the
    measured metal's F(Theta_min) per RGB channel (the pumped one keeps the colour).  Here
    a gold cube with four small cubes (turned 45 degrees) on a grey Lambert plate.
``000-fig10``
    000 Fig. 10: "two ceramic teapots. Again, the diffuse component is dominant, the n exponents are 100
    and 20" (000 eq. 30, as Fig. 9).  The paper prints no a_s: here a_s = 0.04, the normal-incidence
    reflectance of a glaze of refractive index 1.5.  The teapots are built here (:func:`teapot_mesh`: a
    body of revolution, a knob, a spout and a handle), not Newell's patches.  Original: Lambert + a_s x
    reciprocal Phong; new: 000 eq. 30, on Fig. 9's plastic plate.

Metals: measured gold, silver, copper and aluminium (:mod:`pumpup.spectral.optical`: Johnson & Christy 1972
for Au, Ag, Cu; Rakic 1995 for Al), one complex index n + i k per RGB channel, the measured one at
:data:`pumpup.spectral.RGB_WAVELENGTHS` (630, 532, 465 nm), so each channel is a real conductor's
Fresnel factor F(Theta_min) (000 eq. 28: 0 <= F <= 1, F -> 1 at grazing).  Each panel kind is a
list of three per-channel specs (the ``pumpup`` plugin's RGB form):

* "stretched": ``metal`` (000 eq. 28, the stretched Phong lobe times F(Theta_min)), equal to
  ``SpectralMetal(material, n, wavelengths="rgb")`` channel by channel;
* "phong": ``fresnel`` over reciprocal Phong (000 eq. 5) -- the same F(Theta_min) on the original lobe;
* "pumped": ``fresnel`` over ``pumped(phong)`` (001 eq. 16, 20, one g1 level): the colour-keeping
  pumped metal (:class:`pumpup.spectral.SpectralPumpedLobe`'s construction: the F = 1 lobe pumped,
  then F per channel) with 001 Fig. 8's lobe, reciprocal Phong, so that the two rows of that figure
  differ by the pumping alone.  Pumping the metal per channel would divide out its colour (g
  divides by each channel's own albedo: pumped gold is white).

The sRGB of the 8-wavelength spectral F0 (``pumpup.spectral.to_srgb``) is not used as the channel
value: gold's red is 1.032, outside [0, 1], which no Fresnel factor reaches; the three measured
indices give F0 = (0.942, 0.704, 0.404) for gold against (1.032, 0.732, 0.362) from the spectrum.
:data:`F0` (Hoffman 2010) is kept for reference only; the scenes do not use it.

Lights: a constant sky (Mitsuba ``constant`` emitter; the papers' "sky-light") plus point lights,
path tracing (``path``, max_depth 6) with Mitsuba's MIS (000 Fig. 8 and 001 Fig. 8: ``pumpup_caustic``,
the same path tracer plus sampling towards point lights seen through one or two near-mirrors,
:data:`INTEGRATOR`); the plugin samples each lobe with pumpup's strategies.  A colour factor or a sum of
pumpup models (Lambert + Phong lobe) is the small BSDF plugin ``pumpup_mix`` defined here: f = sum_i w_i f_i
(w_i RGB), sampled by choosing component i with probability proportional to the mean of w_i and evaluating the
mixture pdf.

Imports Mitsuba only inside functions: ``import pumpup.scenes`` works without it, and
:func:`render_scene` then raises ImportError naming the ``render`` extra.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time

import numpy as np

__all__ = ["SCENES", "F0", "METALS", "metal_index", "check_scene", "panels", "render_scene", "render_panel",
           "integrator_name", "write_scene", "teapot_mesh", "TEAPOTS"]

#: normal-incidence reflectance of metals, linear RGB (Hoffman 2010 / Real-Time Rendering 3rd ed., Table 7.3);
#: the scenes used it before the measured metals (:data:`METALS`); kept for comparison only
F0 = {
    "gold": (1.000, 0.766, 0.336),
    "silver": (0.972, 0.960, 0.915),
    "copper": (0.955, 0.638, 0.538),
    "aluminium": (0.913, 0.922, 0.924),
}

SCENES = {
    "000-fig8": "000 Fig. 8 (left): gold, copper sphere and cube on a silver near-mirror plate (n = 5000); "
                "reciprocal Phong | stretched Phong",
    "000-fig9": "000 Fig. 9: plastic spheres (a_s, n) = (0.04, 169), (0.065, 64), (0.09, 9), (0.13, 3); "
                "Lambert + Phong lobe | 000 eq. 30",
    "001-fig8": "001 Fig. 8: gold cube with aluminium, silver, copper, gold cubes; reciprocal Phong | pumped once, "
                "n = 20 and 5000",
    "000-fig10": "000 Fig. 10: ceramic teapots, n = 100 (left) and 20 (right), a_s = 0.04; "
                 "Lambert + a_s Phong | 000 eq. 30",
}

#: the plastic spheres of 000 Fig. 9: (a_s, n) and a diffuse colour of one hue (orange), different lightness
#: and saturation, each with max(r, g, b) <= 1 - a_s (000 after eq. 30)
PLASTICS = [
    ((0.04, 169.0), (0.80, 0.42, 0.12)),
    ((0.065, 64.0), (0.60, 0.40, 0.25)),
    ((0.09, 9.0), (0.45, 0.22, 0.05)),
    ((0.13, 3.0), (0.75, 0.55, 0.38)),
]


#: the ceramic teapots of 000 Fig. 10: (a_s, n) and a diffuse glaze colour, max(r, g, b) <= 1 - a_s (000 after
#: eq. 30); the paper gives n = 100 and 20 and no a_s (0.04: the Fresnel reflectance of index 1.5 at normal incidence)
TEAPOTS = [
    ((0.04, 100.0), (0.82, 0.78, 0.68)),
    ((0.04, 20.0), (0.18, 0.32, 0.66)),
]


def check_scene(name) -> str:
    """``name`` if it is a known scene, else a ValueError listing them (one line)."""
    if name not in SCENES:
        raise ValueError(f"unknown scene {name!r}; choose one of {', '.join(SCENES)}")
    return name


# --------------------------------------------------------------------------------------------
# Materials as pumpup specs (plain data: no Mitsuba needed)
# --------------------------------------------------------------------------------------------


def _phong(n, c=None):
    s = {"type": "phong", "n": float(n)}
    if c is not None:
        s["c"] = float(c)
    return s


#: the radiance of the scenes' constant sky (linear sRGB)
SKY = (0.55, 0.62, 0.75)

#: the scenes' metals: colour name -> :mod:`pumpup.spectral.optical` material
METALS = {"gold": "Au", "silver": "Ag", "copper": "Cu", "aluminium": "Al"}


def metal_index(colour) -> tuple[list, list]:
    """(eta, k) per RGB channel of a scene metal: its measured index at ``spectral.RGB_WAVELENGTHS``."""
    from .spectral import RGB_WAVELENGTHS, optical

    eta, k = optical.constants(METALS[colour], list(RGB_WAVELENGTHS))
    return [float(x) for x in eta], [float(x) for x in k]


def metal(colour, n, kind):
    """The measured metal ``colour`` (a :data:`METALS` key) with exponent n, one spec per RGB channel:
    ``kind`` "phong" (F(Theta_min) x reciprocal Phong, 000 eq. 5), "stretched" (000 eq. 28) or "pumped"
    (F(Theta_min) x Phong pumped once with g1, 001 eq. 20; the colour-keeping pumped metal).  A
    ``pumpup_mix`` material: [(rgb weight, [3 specs])].
    """
    if kind not in ("phong", "stretched", "pumped"):
        raise ValueError(f"kind must be 'phong', 'stretched' or 'pumped', got {kind!r}")
    eta, k = metal_index(colour)
    base = _phong(n)
    if kind == "stretched":
        specs = [{"type": "metal", "n": float(n), "eta": e, "k": kk} for e, kk in zip(eta, k)]  # 000 eq. 28
    else:
        lobe = base if kind == "phong" else {"type": "pumped", "base": base, "g": "g1", "levels": 1}
        specs = [{"type": "fresnel", "base": lobe, "eta": e, "k": kk} for e, kk in zip(eta, k)]  # F(Theta_min) x lobe
    return [((1.0, 1.0, 1.0), specs)]


def plastic(rgb, a_s, n, kind):
    """000 Fig. 9's plastic: "phong" = Lambert(rgb) + a_s x reciprocal Phong; "stretched" = 000 eq. 30."""
    if kind == "phong":  # c = a_s (n + 2) / (2 pi): the normalised reciprocal Phong lobe scaled by a_s
        return [(tuple(rgb), {"type": "lambert", "albedo": 1.0}),
                ((1.0, 1.0, 1.0), _phong(n, a_s * (n + 2.0) / (2.0 * math.pi)))]
    return [((1.0, 1.0, 1.0), [{"type": "plastic", "n": float(n), "ad": float(c), "a_s": float(a_s)} for c in rgb])]


def panels(name) -> list:
    """The panels of a scene: a list of rows, each a list of (label, {object name: material}).

    A material is a list of (rgb weight, pumpup spec or list of 3 specs) for ``pumpup_mix``.
    """
    check_scene(name)
    if name == "000-fig8":
        out = []
        for kind, lab in (("phong", "reciprocal Phong (000 eq. 5)"), ("stretched", "stretched Phong (000 eq. 7)")):
            out.append((lab, {"head": metal("gold", 4, kind), "sphere": metal("copper", 40, kind),
                              "cube": metal("copper", 150, kind), "plate": metal("silver", 5000, kind)}))
        return [out]
    if name == "000-fig9":
        out = []
        for kind, lab in (("phong", "Lambert + a_s Phong (000 eq. 5)"), ("stretched", "plastic, 000 eq. 30")):
            mats = {f"s{i}": plastic(rgb, a_s, n, kind) for i, ((a_s, n), rgb) in enumerate(PLASTICS)}
            mats["plate"] = plastic((0.45, 0.45, 0.50), 0.04, 20.0, kind)
            out.append((lab, mats))
        return [out]
    if name == "000-fig10":
        out = []
        for kind, lab in (("phong", "Lambert + a_s Phong (000 eq. 5)"), ("stretched", "plastic, 000 eq. 30")):
            mats = {f"t{i}": plastic(rgb, a_s, n, kind) for i, ((a_s, n), rgb) in enumerate(TEAPOTS)}
            mats["plate"] = plastic((0.45, 0.45, 0.50), 0.04, 20.0, kind)
            out.append((lab, mats))
        return [out]
    rows = []
    for kind, lab in (("phong", "reciprocal Phong"), ("pumped", "pumped once (g1)")):
        row = []
        for n in (20, 5000):
            row.append((f"{lab}, n = {n}", {
                "tank": metal("gold", n, kind), "p0": metal("aluminium", n, kind), "p1": metal("silver", n, kind),
                "p2": metal("copper", n, kind), "p3": metal("gold", n, kind),
                "plate": [((0.5, 0.5, 0.5), {"type": "lambert", "albedo": 1.0})]}))
        rows.append(row)
    return rows


# --------------------------------------------------------------------------------------------
# Mitsuba (imported only here)
# --------------------------------------------------------------------------------------------


def _mitsuba(variant="auto"):
    """Import pumpup.mitsuba and register the plugins for ``variant`` ("auto": llvm if its probe passes)."""
    try:
        import pumpup.mitsuba as pm
    except ImportError:
        raise ImportError("path-traced scenes need Mitsuba 3: install the render extra, "
                          "pip install -e \".[render]\" (or pip install \"pumpup[render]\")") from None
    if variant not in (None, "auto") and not str(variant).endswith("_rgb"):
        raise ValueError("variant must be 'auto' or an RGB Mitsuba variant (scalar_rgb, llvm_ad_rgb, ...), got "
                         f"{variant!r}")
    v = pm.register(None if variant in (None, "auto") else variant)
    if not v.endswith("_rgb"):  # an earlier mi.set_variant of a mono or spectral variant
        v = pm.register("llvm_ad_rgb")
    _register_mix(pm)
    from . import caustics

    caustics.register()
    return pm, v


_MIX: dict = {}


def _register_mix(pm):
    import drjit as dr
    import mitsuba as mi

    variant = mi.variant()
    if variant not in _MIX:
        jit = not variant.startswith("scalar")

        class PumpupMix(mi.BSDF):
            """f = sum_i w_i f_i for pumpup BSDFs f_i and RGB weights w_i (see the module docstring)."""

            def __init__(self, props):
                mi.BSDF.__init__(self, props)
                comps = json.loads(props["components"])
                if not comps:
                    raise ValueError("pumpup_mix: needs at least one component")
                self.weights = [mi.Color3f(*[float(x) for x in w]) for w, _ in comps]
                self.bsdfs = [mi.load_dict(pm.bsdf_dict(s)) for _, s in comps]
                m = np.array([max(float(np.mean(w)), 1e-6) for w, _ in comps])
                self.prob = [float(x) for x in m / m.sum()]  # Python floats: numpy scalars would force evaluation
                flags = 0
                for b in self.bsdfs:
                    flags |= int(b.flags())
                self.m_flags = flags
                self.m_components = [flags]
                self.desc = props["components"]

            def _eval_pdf(self, ctx, si, wo, active):
                val, pdf = mi.Color3f(0.0), mi.Float(0.0)
                for w, p, b in zip(self.weights, self.prob, self.bsdfs):
                    e, q = b.eval_pdf(ctx, si, wo, active)
                    val = val + w * e
                    pdf = pdf + p * q
                return val, pdf

            def eval(self, ctx, si, wo, active=True):
                return self._eval_pdf(ctx, si, wo, active)[0]

            def pdf(self, ctx, si, wo, active=True):
                return self._eval_pdf(ctx, si, wo, active)[1]

            def eval_pdf(self, ctx, si, wo, active=True):
                return self._eval_pdf(ctx, si, wo, active)

            def sample(self, ctx, si, sample1, sample2, active=True):
                if len(self.bsdfs) == 1:
                    bs, wt = self.bsdfs[0].sample(ctx, si, sample1, sample2, active)
                    return bs, wt * self.weights[0]
                acc, bs = 0.0, None
                for i, (p, b) in enumerate(zip(self.prob, self.bsdfs)):
                    last = i == len(self.bsdfs) - 1
                    pick = (sample1 >= acc) if last else ((sample1 >= acc) & (sample1 < acc + p))
                    u = dr.clip((sample1 - acc) / p, 0.0, 0.99999994)  # reuse the selection sample
                    bi, _ = b.sample(ctx, si, u, sample2, active)
                    if bs is None:
                        bs = bi
                    elif jit:
                        bs = dr.select(pick, bi, bs)
                    elif pick:
                        bs = bi
                    acc += p
                val, pdf = self._eval_pdf(ctx, si, bs.wo, active)
                ok = (pdf > 0.0) & active & (bs.pdf > 0.0)
                wt = val / dr.maximum(pdf, 1e-30)
                bs.pdf = dr.select(ok, pdf, 0.0) if jit else (pdf if ok else mi.Float(0.0))
                return bs, (dr.select(ok, wt, 0.0) if jit else (wt if ok else mi.Color3f(0.0)))

            def to_string(self):
                return f"PumpupMix[{self.desc}]"

            def traverse(self, callback):
                pass

        _MIX[variant] = PumpupMix
    cls = _MIX[variant]
    mi.register_bsdf("pumpup_mix", lambda props: cls(props))


def _bsdf(material) -> dict:
    return {"type": "pumpup_mix", "components": json.dumps([[list(w), s] for w, s in material])}


def _scene_dict(name, mats, size, spp):
    import mitsuba as mi

    T = mi.ScalarTransform4f

    def sphere(mat, x, z, r):
        return {"type": "sphere", "center": [x, r, z], "radius": r, "bsdf": _bsdf(mat)}

    def cube(mat, x, z, h, turn):
        return {"type": "cube", "bsdf": _bsdf(mat),
                "to_world": T().translate([x, h, z]) @ T().rotate([0, 1, 0], turn) @ T().scale(h)}

    d = {"type": "scene",
         "integrator": dict(INTEGRATOR.get(name, PATH)),
         "sensor": {"type": "perspective", "fov": 32,
                    "to_world": T().look_at(origin=[0, 2.4, 7.0], target=[0, 0.45, 0], up=[0, 1, 0]),
                    "film": {"type": "hdrfilm", "width": size, "height": size, "pixel_format": "rgb",
                             "rfilter": {"type": "box"}},
                    "sampler": {"type": "independent", "sample_count": spp}},
         "sky": {"type": "constant", "radiance": {"type": "rgb", "value": list(SKY)}},
         "key": {"type": "point", "position": [3.0, 5.0, 4.0], "intensity": {"type": "rgb", "value": 40.0}},
         "fill": {"type": "point", "position": [-4.0, 3.5, 1.5], "intensity": {"type": "rgb", "value": 14.0}},
         "plate": {"type": "rectangle", "bsdf": _bsdf(mats["plate"]),
                   "to_world": T().rotate([1, 0, 0], -90) @ T().scale(3.2)}}
    if name == "000-fig8":
        d["head"] = sphere(mats["head"], -0.9, -0.3, 0.75)
        d["sphere"] = sphere(mats["sphere"], 1.3, 0.9, 0.45)
        d["cube"] = cube(mats["cube"], 0.5, -1.3, 0.42, 30)
    elif name == "000-fig10":
        path = _teapot_ply()
        for i, (x, z, turn) in enumerate(((-1.05, -0.7, -25.0), (0.95, 0.75, -150.0))):
            d[f"t{i}"] = {"type": "ply", "filename": path, "bsdf": _bsdf(mats[f"t{i}"]),
                          "to_world": T().translate([x, 0.0, z]) @ T().rotate([0, 1, 0], turn) @ T().scale(0.68)}
    elif name == "000-fig9":
        for i in range(4):
            d[f"s{i}"] = sphere(mats[f"s{i}"], -1.5 + 1.0 * i, 0.4 * (i % 2), 0.45)
    else:
        d["tank"] = cube(mats["tank"], 0.0, -0.6, 0.6, 20)
        for i, (x, z) in enumerate(((-1.45, 0.9), (-0.5, 1.5), (0.5, 1.5), (1.45, 0.9))):
            d[f"p{i}"] = cube(mats[f"p{i}"], x, z, 0.3, 45)
    return d


#: Mitsuba's path tracer, the integrator of the scenes without a near-mirror plate
PATH = {"type": "path", "max_depth": 6}
#: the scenes rendered otherwise: 000 Fig. 8 and 001 Fig. 8 by ``pumpup_caustic`` (:mod:`pumpup.caustics`), the
#: same path tracer plus sampling towards point lights seen through one or two planar near-mirrors (000: the
#: silver plate, n = 5000; 001: the faces of the cubes, n = 5000 in two of its panels), combined by MIS:
#: unbiased, and without the caustics' fireflies of ``path``
INTEGRATOR = {"000-fig8": {"type": "pumpup_caustic", "max_depth": 6, "mirror": "plate", "mirror_n": 5000.0},
              "001-fig8": {"type": "pumpup_caustic", "max_depth": 6, "mirror": "*,-plate", "mirror_n": 5000.0}}


def integrator_name(name) -> str:
    """The Mitsuba integrator a scene renders with (``path`` or ``pumpup_caustic``)."""
    return INTEGRATOR.get(check_scene(name), PATH)["type"]


def _revolve(r, y, n_phi):
    """A surface of revolution about +y of the profile (r[k], y[k]), r[0] = r[-1] = 0 (the poles, bottom first):
    vertices and faces, counter-clockwise seen from outside.
    """
    phi = np.linspace(0.0, 2.0 * np.pi, n_phi, endpoint=False)
    m = len(r) - 2
    rings = [np.stack([r[k] * np.cos(phi), np.full(n_phi, y[k]), -r[k] * np.sin(phi)], axis=1) for k in range(1, m + 1)]
    v = np.concatenate([[[0.0, y[0], 0.0]], *rings, [[0.0, y[-1], 0.0]]])
    i = np.arange(n_phi)
    j = (i + 1) % n_phi
    f = [np.stack([np.zeros(n_phi, int), 1 + j, 1 + i], axis=1)]
    for k in range(m - 1):
        a, b = 1 + k * n_phi + i, 1 + k * n_phi + j
        f += [np.stack([a, b, b + n_phi], axis=1), np.stack([a, b + n_phi, a + n_phi], axis=1)]
    a, b = 1 + (m - 1) * n_phi + i, 1 + (m - 1) * n_phi + j
    f.append(np.stack([a, b, np.full(n_phi, 1 + m * n_phi)], axis=1))
    return v, np.concatenate(f)


def _tube(path, radius, n_phi):
    """A tube of radius ``radius[k]`` along a curve ``path`` (k, 3) in the x-y plane, closed by a flat disc at each
    end (an open end would show the tube's inside, black under a one-sided BSDF): vertices and faces,
    counter-clockwise seen from outside.
    """
    t = np.gradient(path, axis=0)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    z = np.array([0.0, 0.0, 1.0])
    nrm = np.cross(t, z)
    phi = np.linspace(0.0, 2.0 * np.pi, n_phi, endpoint=False)
    v = path[:, None, :] + radius[:, None, None] * (np.cos(phi)[None, :, None] * nrm[:, None, :]
                                                    + np.sin(phi)[None, :, None] * z)
    i = np.arange(n_phi)
    j = (i + 1) % n_phi
    f = []
    for k in range(len(path) - 1):
        a, b = k * n_phi + i, k * n_phi + j
        f += [np.stack([a, b + n_phi, b], axis=1), np.stack([a, a + n_phi, b + n_phi], axis=1)]
    k_last = (len(path) - 1) * n_phi
    first, last = len(path) * n_phi, len(path) * n_phi + 1  # the discs' centres: the path's ends
    f += [np.stack([np.full(n_phi, first), i, j], axis=1),  # facing back along the path at its start
          np.stack([np.full(n_phi, last), k_last + j, k_last + i], axis=1)]  # facing forward at its end
    return np.concatenate([v.reshape(-1, 3), path[[0, -1]]]), np.concatenate(f)


def teapot_mesh(n=48) -> tuple[np.ndarray, np.ndarray]:
    """A teapot as a triangle mesh: (vertices (V, 3), faces (F, 3) counter-clockwise seen from outside).

    Standing on y = 0, 1.48 high, the spout towards +x: a body of revolution (a superellipse profile, radius 1), a
    knob, a spout (a tapering tube along a quadratic Bezier curve) and a handle (a tube along an arc).  The parts
    interpenetrate; a path tracer needs no more.  ``n`` sets the tessellation.
    """
    s = np.linspace(0.0, np.pi, n)
    e = 2.6  # superellipse exponent: a round pot with a broad base
    r_body = np.abs(np.sin(s)) ** (2 / e)
    cs = np.cos(s)
    y_body = 0.62 * (1.0 + np.sign(cs) * np.abs(cs) ** (2 / e))[::-1]  # bottom pole first
    u = np.linspace(0.0, np.pi, max(n // 2, 4))
    t = np.linspace(0.0, 1.0, n)
    p0, p1, p2 = np.array([0.75, 0.45, 0.0]), np.array([1.35, 0.55, 0.0]), np.array([1.55, 1.15, 0.0])
    spout = ((1 - t) ** 2)[:, None] * p0 + (2 * t * (1 - t))[:, None] * p1 + (t ** 2)[:, None] * p2
    a = np.linspace(-0.55 * np.pi, 0.55 * np.pi, n)
    handle = np.stack([-0.92 - 0.42 * np.cos(a), 0.68 + 0.36 * np.sin(a), np.zeros_like(a)], axis=1)
    parts = [_revolve(r_body, y_body, 2 * n),
             _revolve(0.13 * np.sin(u), 1.22 + 0.13 * (1.0 - np.cos(u)), n),  # the knob
             _tube(spout, 0.20 - 0.11 * t, max(n // 2, 4)),
             _tube(handle, np.full(n, 0.075), max(n // 3, 4))]
    vs, fs, off = [], [], 0
    for v, f in parts:
        vs.append(v)
        fs.append(f + off)
        off += len(v)
    return np.concatenate(vs), np.concatenate(fs).astype(np.int64)


_PLY: dict = {}


def _teapot_ply() -> str:
    """:func:`teapot_mesh` as a binary PLY file in a temporary folder (written once per process)."""
    if "path" not in _PLY or not os.path.exists(_PLY["path"]):
        import tempfile

        v, f = teapot_mesh()
        head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\nproperty float x\n"
                f"property float y\nproperty float z\nelement face {len(f)}\n"
                "property list uchar int vertex_indices\nend_header\n").encode()
        faces = np.zeros(len(f), dtype=[("n", "u1"), ("i", "<i4", (3,))])
        faces["n"] = 3
        faces["i"] = f
        path = os.path.join(tempfile.mkdtemp(prefix="pumpup-teapot-"), "teapot.ply")
        with open(path, "wb") as fh:
            fh.write(head + v.astype("<f4").tobytes() + faces.tobytes())
        _PLY["path"] = path
    return _PLY["path"]


def check_args(name, spp, size, variant):
    """Check every argument before any work (one-line ValueError naming it)."""
    from .render import check_size

    check_scene(name)
    if isinstance(spp, bool) or not isinstance(spp, (int, np.integer)) or not 1 <= int(spp) <= 1 << 20:
        raise ValueError(f"spp must be an integer number of samples per pixel in [1, {1 << 20}], got {spp!r}")
    size = check_size(size)
    if variant not in ("auto", None) and not isinstance(variant, str):
        raise ValueError(f"variant must be 'auto' or a Mitsuba variant name, got {variant!r}")
    return name, int(spp), size


def render_panel(name, mats, size, spp, *, passes=4, seed=0, report=None):
    """One panel: (size, size, 3) linear RGB radiance, the mean of ``passes`` renders with different seeds."""
    import mitsuba as mi

    passes = max(1, min(int(passes), spp))
    scene = _load(name, mats, size, spp // passes)
    acc = None
    for k in range(passes):
        img = np.array(mi.render(scene, seed=seed + k), dtype=np.float64)[..., :3]
        acc = img if acc is None else acc + img
        if report:
            report(k + 1, passes)
    extra = spp - passes * (spp // passes)
    if extra:  # samples per pixel not divisible by the passes: one more pass with the rest, weighted
        scene = _load(name, mats, size, extra)
        img = np.array(mi.render(scene, seed=seed + passes), dtype=np.float64)[..., :3]
        return (acc * (spp // passes) + img * extra) / spp
    return acc / passes


def _load(name, mats, size, spp):
    import mitsuba as mi

    return mi.load_dict(_scene_dict(name, mats, size, spp))


def render_scene(name, spp=64, size=256, variant="auto", *, progress=True, out=sys.stderr):
    """Render every panel of a scene: (variant, rows of (label, image), seconds per panel).

    Same geometry, lights, seed and samples in every panel.  Prints the variant and progress on ``out``.
    """
    name, spp, size = check_args(name, spp, size, variant)
    pm, v = _mitsuba(variant)
    print(f"pumpup render scene {name}: Mitsuba variant {v}, {size} x {size}, {spp} spp", file=out, flush=True)
    rows, times = [], []
    layout = panels(name)
    total = sum(len(r) for r in layout)
    done = 0
    for row in layout:
        r = []
        for label, mats in row:
            t = time.perf_counter()

            def report(k, n, label=label, t=t, done=done):
                if progress:
                    print(f"  panel {done + 1}/{total} ({label}): pass {k}/{n}, {time.perf_counter() - t:.1f} s",
                          file=out, flush=True)

            img = render_panel(name, mats, size, spp, report=report)
            times.append(time.perf_counter() - t)
            r.append((label, img))
            done += 1
        rows.append(r)
    return v, rows, times


def write_scene(name, rows, out_dir, *, exposure=0.0, variant="", spp=0, exr=True):
    """Write each panel as linear EXR (R, G, B; unless ``exr`` is False) and the side-by-side PNG ``NAME.png``
    (radiance x 2^exposure, sRGB transfer, clipped at 1); returns the paths.
    """
    from matplotlib.figure import Figure

    from .render import _atomic, srgb

    os.makedirs(out_dir, exist_ok=True)
    paths = []
    import OpenEXR

    for i, row in enumerate(rows if exr else []):
        for j, (label, img) in enumerate(row):
            p = os.path.join(out_dir, f"{name}_{i}{j}.exr")
            ch = {k: np.ascontiguousarray(img[..., c], dtype=np.float32) for c, k in enumerate("RGB")}
            header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
                      "pumpup_scene": name, "pumpup_panel": label, "pumpup_variant": variant,
                      "pumpup_spp": str(spp)}
            with _atomic(p) as tmp:
                with OpenEXR.File(header, ch) as f:
                    f.write(tmp)
            paths.append(p)
    n_rows, n_cols = len(rows), max(len(r) for r in rows)
    height = 3.5 * n_rows + 0.75  # inches: each panel 3.2 and its title 0.3, the suptitle and the footer
    fig = Figure(figsize=(3.2 * n_cols, height))
    axes = fig.subplots(n_rows, n_cols, squeeze=False, gridspec_kw={
        "left": 0.02, "right": 0.98, "bottom": 0.3 / height, "top": 1 - 0.75 / height, "wspace": 0.06,
        "hspace": 0.3 / 3.2})  # hspace: a fraction of a panel's height, room for the title of the row below
    for i, row in enumerate(rows):
        for j, (label, img) in enumerate(row):
            ax = axes[i][j]
            ax.imshow(srgb(img * 2.0 ** exposure), interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(label, fontsize=8)
    fig.suptitle(SCENES[name], fontsize=7.5)
    fig.text(0.5, 0.005, f"Mitsuba 3 {variant}, {integrator_name(name)}, {spp} spp; tone map: radiance x "
             f"2^{exposure:g}, sRGB transfer, clipped at 1", ha="center", va="bottom", fontsize=6.5)
    p = os.path.join(out_dir, f"{name}.png")
    with _atomic(p) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    paths.append(p)
    return paths
