"""pumpup.caustics (the ``pumpup_caustic`` Mitsuba integrator): its lobe samples what its pdf says, bad input,
technique C's face pairs, and renders of 000 Fig. 8 and 001 Fig. 8 whose means agree with Mitsuba's ``path`` and
with the integrator's own variants (techniques B and C off, C off, the lobes 16 x wider or narrower) within their
standard errors, and a wrong weight that the comparison catches."""

from __future__ import annotations

import math
import os
import sys

import helpers
import numpy as np
import pytest

mi = pytest.importorskip("mitsuba")
pm = pytest.importorskip("pumpup.mitsuba")
LLVM_OK, LLVM_WHY = pm.probe("llvm_ad_rgb")
pytestmark = pytest.mark.skipif(not LLVM_OK, reason=f"llvm_ad_rgb unusable here: {LLVM_WHY}")

ROOT = str(helpers.ROOT)
sys.path.insert(0, os.path.join(ROOT, "scripts", "make"))


@pytest.fixture(scope="module")
def S():
    import pumpup.scenes as scenes

    scenes._mitsuba("llvm_ad_rgb")
    return scenes


def _cls(S):
    from pumpup import caustics

    return caustics._CLASSES[mi.variant()]


@pytest.mark.parametrize("k", [30.0, 5000.0, 80000.0])
def test_lobe_samples_follow_its_pdf(S, k):
    """cos^k lobe about a tilted axis, 2^18 samples: the fraction inside a cap of angle t0 is 1 - cos^(k+1) t0,
    and the mean of 1/q over the cap's samples is its solid angle 2 pi (1 - cos t0), within 4 standard errors."""
    import drjit as dr

    C = _cls(S)
    n = 1 << 18
    rng = np.random.default_rng(1)
    u = mi.Point2f(rng.random(n, dtype=np.float32), rng.random(n, dtype=np.float32))
    d0 = dr.normalize(mi.Vector3f(0.3, -0.8, 0.5))
    kk = mi.Float(k)
    w = C._lobe_sample(d0, kk, u)
    q = np.array(C._lobe_pdf(w, d0, kk, mi.Bool(True)), dtype=np.float64)
    assert np.allclose(np.array(dr.norm(w)), 1.0, atol=1e-6)
    t0 = 1.5 / math.sqrt(k)  # about 1.06 standard deviations of the angle
    cos = np.array(dr.dot(w, d0), dtype=np.float64)
    om = 0.5 * np.array(dr.squared_norm(w - d0), dtype=np.float64)  # 1 - cos, accurate
    inside = om < 1 - math.cos(t0)
    p = 1 - math.exp((k + 1) * math.log(math.cos(t0)))
    assert abs(inside.mean() - p) < 4 * math.sqrt(p * (1 - p) / n)
    g = np.where(inside, 1.0 / q, 0.0)
    cap = 2 * math.pi * (1 - math.cos(t0))
    assert abs(g.mean() - cap) < 4 * g.std() / math.sqrt(n)
    assert np.all(cos > 0)


def test_mirror_faces_of_rectangles_and_cubes(S):
    """A rectangle is one face; two cubes that Mitsuba merges into one mesh (same BSDF) are 12 faces, each a
    rectangle of the cube's half size, centred on its face, its normal pointing outwards."""
    T = mi.ScalarTransform4f
    bsdf = {"type": "diffuse"}
    cubes = [((0.0, 0.5, 0.0), 0.5, 0.0), ((2.0, 0.3, 1.0), 0.3, 45.0)]
    d = {"type": "scene", "plate": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90) @ T().scale(3.2)}}
    for i, (c, h, turn) in enumerate(cubes):
        d[f"c{i}"] = {"type": "cube", "bsdf": bsdf,
                      "to_world": T().translate(list(c)) @ T().rotate([0, 1, 0], turn) @ T().scale(h)}
    scene = mi.load_dict(d)
    C = _cls(S)
    faces = [f for shape in scene.shapes() for f in C._faces(shape)]
    assert len(faces) == 13
    plate = [f for f in faces if abs(f[0][1]) < 1e-6 and np.linalg.norm(f[1]) > 3]
    assert len(plate) == 1 and np.allclose(np.cross(plate[0][1], plate[0][2]) / 3.2 ** 2, [0, 1, 0], atol=1e-6)
    for c, u, v in faces:
        if np.linalg.norm(u) > 3:
            continue
        n = np.cross(u, v)
        n /= np.linalg.norm(n)
        owner = [(np.array(cc), h) for cc, h, _ in cubes if np.linalg.norm(c - cc) < h * 1.01]
        assert len(owner) == 1
        cc, h = owner[0]
        assert np.linalg.norm(u) == pytest.approx(h, rel=1e-5) and np.linalg.norm(v) == pytest.approx(h, rel=1e-5)
        assert abs(u @ v) < 1e-6 and (c - cc) @ n == pytest.approx(h, rel=1e-5)


def test_bad_mirror_is_one_line(S):
    label, mats = S.panels("000-fig8")[0][0]
    d = S._scene_dict("000-fig8", mats, 8, 1)
    for integ, words in (({"type": "pumpup_caustic", "mirror": "nope"},
                          "mirror must name shapes of the scene (comma-separated ids, or '*' and '-id' to "
                          "exclude), got 'nope'"),
                         ({"type": "pumpup_caustic", "k_scale": 0.0}, "mirror_n and k_scale must be > 0"),
                         ({"type": "pumpup_caustic", "margin": -1.0}, "margin must be >= 0, got -1.0")):
        d["integrator"] = integ
        with pytest.raises(Exception) as e:
            mi.render(mi.load_dict(d))
        chain, x = [], e.value
        while x is not None:
            chain.append(str(x))
            x = x.__cause__ or x.__context__
        assert any(words in m for m in chain), chain


def _check(size, spp, passes, pairs, zmax, rough=None, scene="000-fig8", names=None):
    import caustic_check as C

    S = C.S
    setup = C.SETUP[scene]
    i, j = setup["panels"][0]
    label, mats = S.panels(scene)[i][j]
    integ = {k: C.scene_integrator(scene, k, rough or 5000) for k in C.INTEGRATORS if names is None or k in names}
    if rough is not None:  # rougher mirrors: Mitsuba's path converges too, the comparison is tight
        mats = C.rougher(scene, mats, rough)
    masks = C.regions(scene, mats, size)
    assert masks["plate"].sum() > 0.2 * size * size and masks["sky"].sum() > 0.2 * size * size
    ys = {k: C.passes(scene, mats, integ[k], size, spp, passes, 1000 * j)[0] for j, k in enumerate(C.INTEGRATORS)
          if k in integ}
    res = C.compare(ys, {k: m for k, m in masks.items() if m.sum() >= 4})
    for region, r in res.items():
        for pair in pairs:
            assert abs(r["z"][pair]) < zmax, (region, pair, r)
    return res


#: the pairs of integrators (scripts/make/caustic_check.py's INTEGRATORS) whose means the small renders compare
PAIRS = ["path vs caustic, B off", "path vs caustic", "caustic, B off vs caustic", "caustic vs caustic, k / 16",
         "caustic vs caustic, k x 16", "caustic, C off vs caustic", "path vs caustic, C off"]


def test_means_agree_small_render(S):
    """000 Fig. 8 with a plate of n = 300 (not 5000: there Mitsuba's path needs far more samples to converge),
    24 x 24, 6 passes x 64 spp of each integrator: per region (all, sky, each object, plate), pumpup_caustic
    with its mirror-image technique agrees with its lobe 16 x wider and narrower, with technique B off and
    with Mitsuba's path, and B off with path, within 4 combined standard errors."""
    res = _check(24, 64, 6, PAIRS, 4.0, rough=300)
    assert res["all"]["caustic"]["se"] < res["all"]["caustic, B off"]["se"]  # and it is less noisy


#: the pairs of the fast test on 001 Fig. 8 (four integrators; each kernel of pumpup_caustic with technique C
#: compiles for seconds): technique C on against off and against Mitsuba's path, and C's lobes 16 x narrower
CUBES_PAIRS = ["path vs caustic", "caustic, C off vs caustic", "caustic vs caustic, k x 16", "path vs caustic, C off"]


def test_means_agree_small_render_cubes(S):
    """001 Fig. 8's reciprocal Phong panel with its five cubes at n = 300 (the near-mirrors are the cubes'
    faces), 20 x 20, 5 passes x 48 spp: pumpup_caustic with technique C (two faces) agrees per region with C off,
    with its lobes 16 x narrower and with Mitsuba's path, within 4 combined standard errors (every pair of PAIRS:
    the slow test below)."""
    _check(20, 48, 5, CUBES_PAIRS, 4.0, rough=300, scene="001-fig8",
           names=("path", "caustic", "caustic, C off", "caustic, k x 16"))


@pytest.mark.slow
def test_means_agree_small_render_cubes_every_pair(S):
    """As test_means_agree_small_render_cubes, every pair of PAIRS (technique B off, C off, the lobes 16 x wider
    and narrower, path), 24 x 24, 6 passes x 64 spp."""
    _check(24, 64, 6, PAIRS, 4.0, rough=300, scene="001-fig8")


def test_wrong_continuation_weight_is_caught(S, monkeypatch):
    """The comparison above can fail: with the continuation weighted f cos / p_bsdf although technique C sampled
    the direction (the mixture's pdf replaced by the BSDF's), technique C on and off disagree by more than 4
    combined standard errors on 001 Fig. 8's plate at n = 300, 20 x 20, 5 passes x 48 spp (C's share of the
    continuation raised to 1/2, to make the error plain: z = 35 here; 6.9 at the default share)."""
    from pumpup import caustics

    cls = _cls(S)
    monkeypatch.setattr(cls, "_mix_pdf", staticmethod(lambda a, p_bsdf, q_c: p_bsdf))
    monkeypatch.setattr(caustics, "C_SHARE", 0.5)
    res = _check(20, 48, 5, [], 4.0, rough=300, scene="001-fig8", names=("caustic, C off", "caustic"))
    assert abs(res["plate"]["z"]["caustic, C off vs caustic"]) > 4.0, res["plate"]


def _rect(x, turn, grey, y=1.0, half=0.5):
    """A mirror rectangle facing +x (turn 90) or -x (turn -90) at x, centred at height y (a BSDF of its own:
    Mitsuba merges shapes of equal BSDFs into one mesh)."""
    T = mi.ScalarTransform4f
    return {"type": "rectangle", "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": grey}},
            "to_world": T().translate([x, y, 0.0]) @ T().rotate([0, 1, 0], turn) @ T().scale([half, half, 1.0])}


def test_pair_pruning_on_a_tiny_scene(S):
    """Two facing mirrors A (x = -1, facing +x) and B (x = +1, facing -x), y in [0.5, 1.5], above a floor (y = 0),
    a light at (0, 1.5, 0), and a mirror E at x = 3 facing away: technique C keeps exactly the pairs (A, B) and
    (B, A). Unfolded, floor -> A -> B -> light reflects on A from floor points with x >= 0.5 only, floor -> B ->
    A -> light from x <= -0.5: without a margin, from floor points with x in [-2, -0.6] only (B, A) is kept, from
    x in [-0.4, 0.4] none; with the margin, from x in [1.1, 2] (behind A's plane) only (A, B). At vertices on
    the floor, the integrator's Dr.Jit test and lobe agree with the numpy twin the pruning uses."""
    from pumpup import caustics

    T = mi.ScalarTransform4f
    scene = mi.load_dict({
        "type": "scene", "floor": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90) @ T().scale(2.0)},
        "A": _rect(-1.0, 90, 0.2), "B": _rect(1.0, -90, 0.3), "E": _rect(3.0, 90, 0.4),
        "light": {"type": "point", "position": [0.0, 1.5, 0.0]},
        "integrator": {"type": "pumpup_caustic", "mirror": "A,B,E"}})
    integ = scene.integrator()
    (lights, mirrors) = integ._setup(scene)
    assert len(lights) == 1 and len(mirrors) == 3
    em, pos, faces, pairs = lights[0]
    ids = {}
    for f in faces:
        ids[id(f)] = [s.id() for s in scene.shapes() if mi.ShapePtr(s) == f[0]][0]
    assert sorted((ids[id(f1)], ids[id(f2)]) for f1, f2, _ in pairs) == [("A", "B"), ("B", "A")]
    # the image of the light in f2's plane
    for f1, f2, image in pairs:
        assert np.allclose(image, [2.0, 1.5, 0.0] if ids[id(f2)] == "B" else [-2.0, 1.5, 0.0], atol=1e-6)
    plain = [(i, f[1], f[2], f[3], f[4]) for i, f in enumerate(faces)]
    kn = integ.k_scale * integ.mirror_n

    def grid(lo, hi):
        x, z = np.meshgrid(np.linspace(lo, hi, 15), np.linspace(-2, 2, 15))
        return np.stack([x.ravel(), np.zeros(x.size), z.ravel()], axis=1)

    name = {i: ids[id(f)] for i, f in enumerate(faces)}
    assert [(name[a], name[b]) for a, b in caustics.mirror_pairs(plain, pos, grid(-2, -0.6), kn, 0.0)] == [("B", "A")]
    assert [(name[a], name[b]) for a, b in caustics.mirror_pairs(plain, pos, grid(1.1, 2), kn, 3.0)] == [("A", "B")]
    assert caustics.mirror_pairs(plain, pos, grid(-0.4, 0.4), kn, 0.0) == []
    # Dr.Jit's test at vertices on the floor against the numpy twin, with the integrator's margin
    pts = grid(-2, 2)
    x = mi.Point3f(*[mi.Float(pts[:, i].astype(np.float32)) for i in range(3)])
    for f1, f2, image in pairs:
        d0, k, ok = integ._lobe_pair(x, image, f1, f2, mi.Bool(True))
        s1, k_np, ok1 = caustics._lobe_np(pts, image, f1[1:], kn, integ.margin)
        ok_np = ok1 & caustics._second_face_np(pts, s1, k_np, image, f2[1:], integ.margin)
        assert ok_np.sum() >= 10 and np.array_equal(np.array(ok), ok_np)
        assert np.allclose(np.array(k), k_np, rtol=1e-4)
        d_np = (s1 - pts) / np.linalg.norm(s1 - pts, axis=1, keepdims=True)
        assert np.allclose(np.stack([np.array(d0[i]) for i in range(3)], axis=1), d_np, atol=1e-5)


def test_margin_keeps_the_mean(S):
    """001 Fig. 8's reciprocal Phong panel, cubes at n = 300, 20 x 20, 5 passes x 48 spp, technique C off (its
    pairs take the same margin; the fast cubes test checks C at the default one): technique B with specular points
    only on the faces (margin 0) and with a margin 4 x the default agree per region within 4 combined standard
    errors (the margin changes both MIS weights, not the expectation)."""
    import caustic_check as C

    setup = C.SETUP["001-fig8"]
    i, j = setup["panels"][0]
    label, mats = C.S.panels("001-fig8")[i][j]
    mats = C.rougher("001-fig8", mats, 300)
    masks = C.regions("001-fig8", mats, 20)
    ys = {}
    for k, m in enumerate((0.0, 12.0)):
        integ = dict(C.scene_integrator("001-fig8", "caustic, C off", 300), margin=m)
        ys[m] = C.passes("001-fig8", mats, integ, 20, 48, 5, 500 * k)[0]
    res = C.compare(ys, {k: m for k, m in masks.items() if m.sum() >= 4})
    for region, r in res.items():
        for pair, z in r["z"].items():
            assert abs(z) < 4.0, (region, pair, r)


@pytest.mark.slow
def test_means_agree_and_fireflies_drop(S):
    """64 x 64, 16 passes x 256 spp: every pair of integrators agrees within 4 combined standard errors per
    region; at 256 x 256 and 64 spp the fireflies of 000 Fig. 8's left panel drop at least 10 x; at 256 x 256
    and 256 spp, 001 Fig. 8's pumped n = 5000 panel keeps at most 5 fireflies with technique C, at least 4 x
    fewer than without it (the paths through two cube faces)."""
    import caustic_check as C

    res = _check(64, 256, 16, [], 4.0)
    for region, r in res.items():
        assert all(abs(z) < 4.0 for z in r["z"].values()), (region, r)
    from make_scenes import fireflies

    label, mats = C.S.panels("000-fig8")[0][0]
    y_path = C.passes("000-fig8", mats, C.INTEGRATORS["path"], 256, 64, 1, 7)[0][0]
    y_new = C.passes("000-fig8", mats, C.INTEGRATORS["caustic"], 256, 64, 1, 7)[0][0]
    assert fireflies(y_new) * 10 <= fireflies(y_path)
    i, j = C.SETUP["001-fig8"]["panels"][1]
    label, mats = C.S.panels("001-fig8")[i][j]
    count = {}
    for k in ("caustic, C off", "caustic"):
        integ = dict(C.INTEGRATORS[k], mirror=C.SETUP["001-fig8"]["mirror"], mirror_n=5000.0)
        count[k] = fireflies(C.passes("001-fig8", mats, integ, 256, 256, 1, 7)[0][0])
    assert count["caustic"] <= 5 and count["caustic"] * 4 <= count["caustic, C off"], (label, count)
