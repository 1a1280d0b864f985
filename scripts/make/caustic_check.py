"""Check that pumpup's caustic integrator is unbiased, and measure what it does to the fireflies.

    python scripts/make/caustic_check.py [--scene 000-fig8] [--size 64] [--spp 256] [--passes 32]
                                         [--fireflies-size 256] [--fireflies-spp 64 256]
                                         [--reference-spp 1024] [--rough-plate 300] [--out figures]

Renders a panel of ``--scene`` (000 Fig. 8: the reciprocal Phong one; 001 Fig. 8: reciprocal Phong, n = 5000;
:data:`SETUP`) with Mitsuba's ``path`` (max_depth 6), with ``pumpup_caustic`` without its mirror-image techniques
(the plain path tracer), without its two-mirror technique C and with both (:data:`INTEGRATORS`), ``--passes`` times
each at ``--spp`` samples per pixel and independent seeds. Per region of the image (the pixels whose centre sees the
sky, each shape, all pixels, and the 2 % of pixels where 8 more passes of the path tracer spread most: the caustics'
fireflies) it prints the mean luminance of each integrator (also ``pumpup_caustic`` with its lobes' exponent k
divided and multiplied by 16: the weights of the techniques change, an unbiased combination keeps the mean) with its
standard error (from the spread of the passes) and the z-score of each difference. The same again with rougher
mirrors (``--rough-plate``, n = 300), where ``path`` makes no caustic fireflies and the comparison is tight. Then it
renders the scene's near-mirror panels (n = 5000) at ``--fireflies-size`` and each of ``--fireflies-spp`` with
``path`` and with ``pumpup_caustic`` (for 001 Fig. 8 also without technique C; two seeds each) and prints the
fireflies (``make_scenes.fireflies``), those of them that are not fireflies of a ``pumpup_caustic`` render at
``--reference-spp`` (noise, not bright features of the converged image), and the render times. Writes
``OUT/caustic_check.json`` (000 Fig. 8) or ``OUT/caustic_check_SCENE.json``; the documentation quotes them. About 5
minutes for 000 Fig. 8 on a free 2-core machine, more for 001 Fig. 8.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402
from make_scenes import LUMINANCE, firefly_mask  # noqa: E402
from stored_json import write  # noqa: E402

import pumpup.scenes as S  # noqa: E402
from pumpup.caustics import K_SCALE  # noqa: E402

#: per scene: the panels checked (row, column; the first is compared per region), the integrator's ``mirror``,
#: the near-mirrors' metals (made rougher for the second comparison), and whether paths reflect a light through
#: two mirrors of different shapes (technique C applies: its fireflies are counted with C off too)
SETUP = {"000-fig8": {"panels": [(0, 0), (0, 1)], "mirror": "plate", "metals": {"plate": "silver"},
                     "two_mirror": False},
         "001-fig8": {"panels": [(0, 1), (1, 1)], "mirror": "*,-plate",
                      "metals": {"tank": "gold", "p0": "aluminium", "p1": "silver", "p2": "copper", "p3": "gold"},
                     "two_mirror": True}}
#: the integrators compared: Mitsuba's path tracer, pumpup_caustic without its mirror-image techniques (B and
#: C: the plain path tracer), without the two-mirror technique C, with both, and with the techniques' lobes 16 x
#: wider and narrower (k / 16, k x 16; the MIS weights and the continuation's pdf change, the expectation must not)
INTEGRATORS = {"path": {"type": "path", "max_depth": 6},
               "caustic, B off": {"type": "pumpup_caustic", "max_depth": 6, "technique_b": False,
                                  "technique_c": False},
               "caustic, C off": {"type": "pumpup_caustic", "max_depth": 6, "technique_c": False},
               "caustic": {"type": "pumpup_caustic", "max_depth": 6},
               "caustic, k / 16": {"type": "pumpup_caustic", "max_depth": 6, "k_scale": K_SCALE / 16},
               "caustic, k x 16": {"type": "pumpup_caustic", "max_depth": 6, "k_scale": K_SCALE * 16}}


def regions(scene: str, mats: dict, size: int) -> dict:
    """Boolean masks (size, size) of the pixels whose centre sees the sky or each shape (by its id), and all."""
    import mitsuba as mi

    sc = mi.load_dict(S._scene_dict(scene, mats, size, 1))
    sensor = sc.sensors()[0]
    j, i = np.meshgrid(np.arange(size), np.arange(size))  # row i, column j
    pos = mi.Point2f((j.ravel() + 0.5) / size, (i.ravel() + 0.5) / size)
    ray, _ = sensor.sample_ray(0.0, 0.5, pos, mi.Point2f(0.5, 0.5))
    si = sc.ray_intersect(ray)
    out = {"all": np.ones((size, size), bool), "sky": ~np.array(si.is_valid()).reshape(size, size)}
    for shape in sc.shapes():
        out[shape.id()] = np.array((si.shape == mi.ShapePtr(shape)) & si.is_valid()).reshape(size, size)
    return out


def passes(scene: str, mats: dict, integrator: dict, size: int, spp: int, n: int, seed0: int):
    """(n, size, size) luminance of n independent renders, and the seconds they took."""
    import mitsuba as mi

    d = S._scene_dict(scene, mats, size, spp)
    d["integrator"] = dict(integrator)
    sc = mi.load_dict(d)
    t = time.perf_counter()
    y = np.stack([np.array(mi.render(sc, seed=seed0 + k), dtype=np.float64)[..., :3] @ LUMINANCE for k in range(n)])
    return y, time.perf_counter() - t


def compare(ys: dict, masks: dict) -> dict:
    """Per region: each integrator's mean and standard error over its passes, and the z-scores of the
    differences (each pair).
    """
    out = {}
    keys = list(ys)
    for rn, m in masks.items():
        r = {}
        stats = {}
        for k in keys:
            per = ys[k][:, m].mean(axis=1)
            stats[k] = (float(per.mean()), float(per.std(ddof=1) / np.sqrt(len(per))))
            r[k] = {"mean": stats[k][0], "se": stats[k][1]}
        z = {}
        for i, a in enumerate(keys):
            for b in keys[i + 1:]:
                (ma, sa), (mb, sb) = stats[a], stats[b]
                z[f"{a} vs {b}"] = (ma - mb) / max(np.hypot(sa, sb), 1e-300)
        r["z"] = z
        r["pixels"] = int(m.sum())
        out[rn] = r
    return out


def scene_integrator(scene: str, key: str, n: float = 5000.0) -> dict:
    """The integrator ``key`` of :data:`INTEGRATORS` for ``scene``: pumpup_caustic with the scene's mirrors, of
    exponent ``n``.
    """
    integ = dict(INTEGRATORS[key])
    if integ["type"] == "pumpup_caustic":
        integ.update(mirror=SETUP[scene]["mirror"], mirror_n=float(n))
    return integ


def rougher(scene: str, mats: dict, n: float) -> dict:
    """A panel's materials with the scene's near-mirrors made Phong metals of exponent ``n``."""
    return dict(mats, **{o: S.metal(metal, n, "phong") for o, metal in SETUP[scene]["metals"].items()})


def main(argv=None) -> int:
    """Measure, print and write ``caustic_check.json``; returns the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="000-fig8", choices=sorted(SETUP))
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--passes", type=int, default=32)
    ap.add_argument("--fireflies-size", type=int, default=256)
    ap.add_argument("--fireflies-spp", type=int, nargs="+", default=[64, 256])
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--rough-plate", type=int, default=300)
    ap.add_argument("--out", default="figures")
    a = ap.parse_args(argv)
    S.check_args(a.scene, a.spp, a.size, "auto")
    for spp in a.fireflies_spp:
        S.check_args(a.scene, spp, a.fireflies_size, "auto")
    S.check_args(a.scene, a.reference_spp, a.fireflies_size, "auto")
    if a.passes < 2:
        raise SystemExit("--passes must be >= 2 (the standard errors come from the spread of the passes)")
    _, variant = S._mitsuba("auto")
    setup = SETUP[a.scene]
    rows = S.panels(a.scene)
    chosen = [rows[i][j] for i, j in setup["panels"]]
    label, mats = chosen[0]

    def integrator(k, n=5000.0):
        return scene_integrator(a.scene, k, n)

    masks = regions(a.scene, mats, a.size)
    cmp = {}
    for plate_n in (5000, a.rough_plate):  # the scene's plate, and a rougher one where path converges too
        pm = mats if plate_n == 5000 else rougher(a.scene, mats, plate_n)
        ys, secs = {}, {}
        for j, k in enumerate(INTEGRATORS):
            ys[k], secs[k] = passes(a.scene, pm, integrator(k, plate_n), a.size, a.spp, a.passes, 1000 * j)
        m = dict(masks)
        # path's fireflies: from passes of their own (selecting them on the compared passes would bias path up)
        sd = passes(a.scene, pm, integrator("path"), a.size, a.spp, 8, 90000)[0].std(axis=0, ddof=1)
        m["path's fireflies"] = sd >= np.percentile(sd, 98)
        cmp[plate_n] = compare(ys, m)
        print(f"plate n = {plate_n}: seconds " + ", ".join(f"{k} {v:.1f}" for k, v in secs.items()))
        for rn, r in cmp[plate_n].items():
            print(f"{rn:18s} ({r['pixels']:5d} px) " + "; ".join(f"{k} {r[k]['mean']:.5f} +- {r[k]['se']:.5f}"
                                                              for k in INTEGRATORS)
                  + " | z " + ", ".join(f"{v:+.2f}" for v in r["z"].values()), flush=True)
    ff = {}
    for plabel, pmats in chosen:
        ref, s_ref = passes(a.scene, pmats, integrator("caustic"), a.fireflies_size, a.reference_spp, 1, 11)
        ref_mask = firefly_mask(ref[0])
        ff[plabel] = {"reference": {"spp": a.reference_spp, "fireflies": int(ref_mask.sum()), "seconds": s_ref}}
        print(f"{plabel}: caustic at {a.reference_spp} spp: fireflies {int(ref_mask.sum())} in {s_ref:.1f} s",
              flush=True)
        for spp in a.fireflies_spp:
            for k in ("path", "caustic, C off", "caustic") if setup["two_mirror"] else ("path", "caustic"):
                r = {"fireflies": [], "noise": [], "seconds": []}
                for seed in (7, 8):
                    y, sec = passes(a.scene, pmats, integrator(k), a.fireflies_size, spp, 1, seed)
                    m = firefly_mask(y[0])
                    r["fireflies"].append(int(m.sum()))
                    r["noise"].append(int((m & ~ref_mask).sum()))
                    r["seconds"].append(sec)
                ff[plabel][f"{k}, {spp} spp"] = r
                print(f"{plabel}: {k}, {spp} spp: fireflies {r['fireflies']} (not at {a.reference_spp} spp: "
                      f"{r['noise']}) in " + ", ".join(f"{x:.1f}" for x in r["seconds"]) + " s", flush=True)
    out = {"scene": a.scene, "panel": label, "variant": variant, "size": a.size, "spp": a.spp, "passes": a.passes,
           "rough_plate": a.rough_plate,
           "regions": cmp[5000], "regions_rough_plate": cmp[a.rough_plate],
           "fireflies_size": a.fireflies_size, "fireflies_spp": a.fireflies_spp,
           "reference_spp": a.reference_spp, "fireflies": ff, "load": os.getloadavg()[0]}
    path = os.path.join(a.out, "caustic_check.json" if a.scene == "000-fig8" else f"caustic_check_{a.scene}.json")
    write(path, out, sort_keys=True)
    print("wrote", path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
