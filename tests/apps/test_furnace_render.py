"""Furnace renders read along rings (pumpup.furnace_render): the ring statistics on synthetic renders, and, under
``-m slow``, Cycles (needs bpy, an optional extra: skipped without it) and Mitsuba 3 against the prediction.
"""

import importlib.util
import os
import re

import helpers
import numpy as np
import pytest

import pumpup
from pumpup import furnace_render as fr

CYCLES_TABLES = str(helpers.DATA / "cycles_shader.tables")


def _synthetic(truth, res=96, noise=0.01, seed=3, extent=1.025):
    """An orthographic image of the unit sphere whose pixels are the truth averaged over their footprint plus
    independent Gaussian noise; coverage and mean normal as a renderer's passes give them."""
    rng = np.random.default_rng(seed)
    sub = (np.arange(8) + 0.5) / 8
    idx = np.arange(res)
    x = ((idx[None, :, None, None] + sub[None, None, None, :]) / res * 2 - 1) * extent
    y = ((idx[:, None, None, None] + sub[None, None, :, None]) / res * 2 - 1) * extent
    r2 = x * x + y * y
    hit = r2 < 1
    mu = np.sqrt(np.clip(1 - r2, 0, 1))
    alpha = hit.mean(axis=(2, 3))
    with np.errstate(invalid="ignore", divide="ignore"):
        mean_mu = np.where(hit, mu, 0).sum(axis=(2, 3)) / hit.sum(axis=(2, 3))
        value = np.where(hit, truth(mu), 0).sum(axis=(2, 3)) / hit.sum(axis=(2, 3))
    return {"value": value + noise * rng.standard_normal(value.shape), "alpha": alpha, "mu": mean_mu}


def test_rings_recover_a_curved_truth_and_catch_a_bias():
    def truth(m):
        return 0.7 + 0.3 * np.sqrt(m)  # curved in mu, as E is: the pixel footprint matters near the rim

    img = _synthetic(truth)
    table = fr.rings(img, truth)
    assert len(table) >= 9 and all(r["geometry"] < 0.02 for r in table)
    ok, z = fr.compare_rings(table)
    assert ok, z
    # the standard error is the noise over sqrt(n)
    assert table[-1]["se"] == pytest.approx(0.01 / np.sqrt(table[-1]["n"]), rel=0.15)
    # predicting at the pixel's mean normal instead of over its footprint is biased near the rim
    near_rim = fr.rings(_synthetic(truth, noise=1e-4), truth, extent=None)[0]
    assert abs(near_rim["difference"]) > 3 * near_rim["se"]
    # a prediction off by a bias of 10 standard errors is caught
    biased = fr.rings(img, lambda m: truth(m) + 10 * table[-1]["se"])
    assert not fr.compare_rings(biased)[0]


def test_rings_over_seeds_hold_an_error_shared_by_pixels():
    """Noise shared by every pixel of a render (what a sampling pattern common to the pixels gives) is invisible in
    the pixel scatter and visible across renders."""
    def truth(m):
        return 0.7 + 0.3 * np.sqrt(m)

    rng = np.random.default_rng(7)
    renders = []
    for k in range(12):
        img = _synthetic(truth, res=64, noise=1e-3, seed=k)
        img["value"] = img["value"] + 5e-3 * rng.standard_normal()  # one error for the whole render
        renders.append(img)
    one = fr.rings(renders[0], truth)
    many = fr.rings(renders, truth)
    assert 3 * max(r["se"] for r in one) < min(r["se"] for r in many)
    assert fr.compare_rings(many)[0]


def _scale(r):
    def predict(mu):
        return pumpup.furnace_prediction("cycles", "scale", path=CYCLES_TABLES, mu=mu, roughness=[r])[
            "furnace"].values[:, 0]
    return predict


def _none(conventions, r):
    def predict(mu):
        return pumpup.furnace_prediction(conventions, "none", mu=mu, roughness=[r])["furnace"].values[:, 0]
    return predict


@pytest.mark.slow
def test_cycles_rings_agree_with_the_prediction():
    if importlib.util.find_spec("bpy") is None:  # an optional extra, not installed by CI
        pytest.skip("bpy is not installed (pip install --no-deps \"bpy>=5,<6\")")
    r = 0.5
    edges = np.linspace(0.1, 1.0, 6)
    multi = [fr.render_cycles(r, "MULTI_GGX", resolution=64, spp=16, seed=1 + k) for k in range(16)]
    ok, z = fr.compare_rings(fr.rings(multi, _scale(r), edges))
    assert ok, f"Multiscatter GGX rings off the 1/E_lookup prediction by {z:.2f} standard errors"
    single = [fr.render_cycles(r, "GGX", resolution=64, spp=16, seed=1 + k) for k in range(16)]
    ok, z = fr.compare_rings(fr.rings(single, _none("cycles", r), edges))
    assert ok, f"GGX rings off E by {z:.2f} standard errors"
    # the comparison can fail: the uncompensated lobe is far from the compensated prediction
    assert not fr.compare_rings(fr.rings(single, _scale(r), edges))[0]


@pytest.mark.slow
def test_mitsuba_roughconductor_rings_are_E():
    pytest.importorskip("mitsuba")
    r = 0.5
    edges = np.linspace(0.1, 1.0, 6)
    imgs = [fr.render_mitsuba(r * r, resolution=64, spp=16, seed=1 + k) for k in range(16)]
    ok, z = fr.compare_rings(fr.rings(imgs, _none("mitsuba", r), edges, min_alpha=0.999))
    assert ok, f"roughconductor rings off E by {z:.2f} standard errors"
    # correlated Smith differs
    assert not fr.compare_rings(fr.rings(imgs, _none("cycles", r), edges, min_alpha=0.999))[0]


def test_docs_examples_are_the_shipped_files():
    """The page's generated preset examples are the shipped conventions files (rerun
    scripts/studies/renderer_tables_doc.py after editing one)."""
    from pumpup import conventions as cv

    page = (helpers.ROOT / "docs" / "user-guide" / "renderer-tables.md").read_text()
    blocks = re.findall(r"`pumpup/data/conventions/([\w-]+\.toml)`\):\n\n```toml\n(.*?)\n```", page, re.S)
    assert {b[0] for b in blocks} == set(cv.PRESET_FILES.values())
    for fname, text in blocks:
        with open(os.path.join(cv.PRESET_DIR, fname)) as fh:
            assert fh.read().rstrip("\n") == text
