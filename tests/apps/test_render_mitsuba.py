"""End-to-end check (issue 18 item 3): the furnace sphere path-traced by Mitsuba 3 with the ``pumpup``
plugin agrees per pixel with pumpup's exact furnace image, within the Monte Carlo noise.

The scene: a unit sphere with the plugin's BSDF under Mitsuba's ``constant`` emitter (radiance 1),
seen by an ``orthographic`` sensor whose film covers the square [-1, 1]^2, i.e. render.py's framing
(pixel (i, j) covers x in [-1 + 2j/size, -1 + 2(j+1)/size], likewise y; the sphere touches the
edges).  Mitsuba's integrator is ``moment`` around ``path`` (max_depth 2: the sphere is convex, its
reflected rays see only the sky; emitters hidden so the background is 0), with a ``box`` pixel
filter, so each pixel is the mean of its samples drawn uniformly over the pixel's area, and the
moment integrator's second AOV is the mean of their squares: per pixel the sample variance
s^2 = (m2 - m^2) N / (N - 1) and the standard error s / sqrt(N).  (Mitsuba's colour AOVs are
CIE XYZ; the Y channel of a grey value is the value, of the squared one its square.)

The exact pixel is the area average of the furnace image over the same square: a(mu_V) at
mu_V = sqrt(1 - x^2 - y^2), 0 off the sphere, averaged over K x K sub-pixel midpoints, with
a(mu) from the albedo table ``pumpup.render.furnace`` uses (``render.furnace_table``; checked
equal to ``render.furnace`` at the pixel centres).  The sub-pixel quadrature error, estimated as
the difference between K and 2K, is required to be below a tenth of the standard error at every
pixel, so the z-score z = (mitsuba - exact) / SE measures the renderer alone.

A wrong model (Phong n = 20 rendered, Phong n = 30 as the reference) is shown to fail the same
criterion, so the check has power.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

mi = pytest.importorskip("mitsuba")
pytest.importorskip("drjit")
pm = pytest.importorskip("pumpup.mitsuba")

import pumpup  # noqa: E402
import pumpup.render as R  # noqa: E402

LLVM = "llvm_ad_rgb"
LLVM_OK, LLVM_WHY = pm.probe(LLVM)
#: image size and samples per pixel: default suite, -m slow; scalar (Python plugin calls per sample) is slower, and
#: 16 x 16 at 128 samples is the least that still tells GGX alpha 0.3 from 0.35 (test_wrong_model_is_detected)
if LLVM_OK:
    VARIANT, FAST, SLOW = LLVM, (24, 512), (48, 2048)
else:  # pragma: no cover - depends on the machine's libLLVM
    VARIANT, FAST, SLOW = "scalar_rgb", (16, 128), (24, 512)

#: looser albedo tables than the pumping operator's (bound about 1e-5, far below the Monte Carlo
#: noise of 1e-3 - 1e-2 per pixel): about 2.5 x cheaper to build
TABLE = {"rtol": 1e-6, "interp_tol": 1e-5}
Z_MAX = 4.0
#: largest accepted fraction of sphere pixels beyond Z_MAX: a Gaussian gives 6e-5, Student's t with
#: N - 1 >= 31 degrees of freedom (the variance is estimated) at most 4e-4; 1 % allows a few outliers
#: of the heavy-tailed pixels at the rim
FRACTION_MAX = 0.01

MODELS = {
    "phong": {"type": "phong", "n": 20},
    "stretched_phong": {"type": "stretched_phong", "n": 20},
    "pumped_phong": {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g1", "levels": 1},
    "ggx": {"type": "ggx", "alpha": 0.3},
}


def mitsuba_furnace(spec, size: int, spp: int, seed: int):
    """Mitsuba's furnace sphere: (mean, standard error) per pixel, (size, size) each."""
    pm.register(VARIANT)
    scene = pm.load_dict({
        "type": "scene",
        "integrator": {"type": "moment", "nested": {"type": "path", "max_depth": 2, "hide_emitters": True}},
        "sensor": {"type": "orthographic",
                   "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]),
                   "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"},
                            "pixel_format": "rgb"},
                   "sampler": {"type": "independent", "sample_count": spp}},
        "sphere": {"type": "sphere", "bsdf": pm.bsdf_dict(spec)},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}},
    })
    names = ["R", "G", "B"] + list(scene.integrator().aov_names())
    img = np.array(mi.render(scene, seed=seed), dtype=np.float64)
    mean, m2 = img[..., names.index("nested.Y")], img[..., names.index("m2_nested.Y")]
    assert np.allclose(mean, img[..., 1], rtol=1e-5, atol=1e-6)  # the AOV is the image's own mean
    var = np.maximum(m2 - mean * mean, 0.0) * spp / (spp - 1)
    return mean, np.sqrt(var / spp)


def exact_pixels(spec, size: int, k: int):
    """Area average of the exact furnace image over each pixel, K x K midpoints per pixel: (size, size)."""
    t = (np.arange(size * k) + 0.5) / (size * k)  # sub-pixel midpoints in [0, 1]
    c = -1.0 + 2.0 * t
    cc = np.sort(c * c)
    j = np.searchsorted(cc, 1.0 - cc) - 1  # the largest y^2 with x^2 + y^2 < 1, for each x^2
    r2_max = float(np.max(np.where(j >= 0, cc + cc[np.maximum(j, 0)], 0.0)))
    mu_min = math.sqrt(1.0 - r2_max) * (1 - 1e-9)  # the smallest mu_V of a midpoint on the sphere
    table, bound, _ = R.furnace_table(spec, mu_min, **TABLE)
    out = np.zeros((size, size))
    x = c[None, :]
    for i in range(size):  # one row of pixels at a time: size x k^2 sub-pixels
        y = -c[i * k:(i + 1) * k, None]
        r2 = x * x + y * y
        on = r2 < 1.0
        sub = np.zeros(r2.shape)
        sub[on] = table(np.sqrt(1.0 - r2[on]))  # 000 eq. 2: the furnace radiance is the albedo at mu_V
        out[i] = sub.reshape(k, size, k).mean(axis=(0, 2))
    return out, bound


#: a pixel is tested when the chance that all its samples miss the sphere, (1 - coverage)^spp, is below this: a
#: rim pixel that the sphere barely touches may otherwise get no hit at all (zero sample variance, no z-score), as
#: the scalar variant's 32 samples per pixel do
MISS_ALL_MAX = 1e-6


def coverage(size: int, k: int) -> np.ndarray:
    """The fraction of each pixel's area on the sphere, from K x K sub-pixel midpoints: (size, size)."""
    c = -1.0 + 2.0 * (np.arange(size * k) + 0.5) / (size * k)
    on = (c[:, None] ** 2 + c[None, :] ** 2) < 1.0
    return on.reshape(size, k, size, k).mean(axis=(1, 3))


def zscores(spec_rendered, spec_exact, size, spp, seed=7, k=32):
    mean, se = mitsuba_furnace(spec_rendered, size, spp, seed)
    ex, bound = exact_pixels(spec_exact, size, k)
    ex2, _ = exact_pixels(spec_exact, size, 2 * k)
    covered = (ex2 > 0) & ((1.0 - coverage(size, 2 * k)) ** spp < MISS_ALL_MAX)
    quad = np.abs(ex2 - ex)
    return mean, se, ex2, quad, bound, covered


def check_furnace(spec, size, spp, k=32):
    mean, se, ex, quad, bound, covered = zscores(spec, spec, size, spp, k=k)
    # the reference is the image pumpup.render.furnace draws, at the pixel centres
    im = R.furnace(spec, size, **TABLE)
    table, _, _ = R.furnace_table(spec, float(im.radiance[im.mask].min()) * 0.5, **TABLE)
    np.testing.assert_allclose(im.radiance[im.mask], table(R.geometry(size).view[:, 2]), rtol=0, atol=1e-15)
    # background: no sample can reach the sphere
    assert np.all(mean[coverage(size, 2 * k) == 0.0] == 0.0)
    assert np.all(se[covered] > 0.0), "a pixel on the sphere with zero sample variance"
    assert np.all(quad[covered] + bound < 0.1 * se[covered]), (
        f"reference quadrature error {float(quad.max()):.2g} not below 0.1 x the standard error")
    z = (mean - ex)[covered] / se[covered]
    frac = float(np.mean(np.abs(z) > Z_MAX))
    return z, frac


def failures(z) -> list:
    """The criteria a z-score map must meet; the list of those it fails."""
    out = []
    frac = float(np.mean(np.abs(z) > Z_MAX))
    if frac > FRACTION_MAX:
        out.append(f"{frac:.1%} of {z.size} pixels beyond {Z_MAX} sigma (max |z| {abs(z).max():.2f})")
    # the noise is what the variance says: z has mean ~0 (no bias) and spread ~1 over the sphere's pixels
    if abs(float(z.mean())) > 4.0 / math.sqrt(z.size) + 0.05:
        out.append(f"mean z {z.mean():+.3f} (bias)")
    if not 0.8 < float(z.std()) < 1.25:
        out.append(f"std of z {z.std():.3f}")
    return out


@pytest.mark.parametrize("name", list(MODELS))
def test_furnace_sphere_matches_exact(name):
    z, _ = check_furnace(MODELS[name], *FAST)
    assert not failures(z), f"{name}: " + "; ".join(failures(z))


def test_wrong_model_is_detected():
    """GGX alpha = 0.3 rendered, the exact furnace of alpha = 0.35 as reference (albedo 1.8-5 % lower): rejected;
    and Phong against once-pumped Phong (the papers' effect): most pixels beyond 4 sigma."""
    mean, se, ex, quad, bound, covered = zscores(MODELS["ggx"], {"type": "ggx", "alpha": 0.35}, *FAST)
    assert failures((mean - ex)[covered] / se[covered])
    mean, se, ex, quad, bound, covered = zscores(MODELS["phong"], MODELS["pumped_phong"], *FAST)
    assert float(np.mean(np.abs((mean - ex)[covered] / se[covered]) > Z_MAX)) > 0.5


@pytest.mark.slow
@pytest.mark.parametrize("name", list(MODELS))
def test_furnace_sphere_matches_exact_large(name):
    z, _ = check_furnace(MODELS[name], *SLOW, k=64)
    assert not failures(z), f"{name}: " + "; ".join(failures(z))


if __name__ == "__main__":  # print the z statistics
    import sys

    big = "--slow" in sys.argv
    for name, spec in MODELS.items():
        z, frac = check_furnace(spec, *(SLOW if big else FAST), k=64 if big else 32)
        print(f"{name:16s} pixels {z.size:5d}  beyond 4 sigma {frac:.3%}  mean z {z.mean():+.3f}  std z {z.std():.3f}"
              f"  max |z| {abs(z).max():.2f}")
    _ = pumpup
