"""Exact sphere images (pumpup.render): pixels recomputed by hand, the furnace, writers, bad input."""

import math

import numpy as np
import pytest

import pumpup
import pumpup.render as R
from pumpup.cli import main


def _pixel(size, i, j):
    """World normal, tangent and bitangent of pixel (i, j), written out from the module docstring."""
    x = -1.0 + (2 * j + 1) / size
    y = 1.0 - (2 * i + 1) / size
    z = math.sqrt(1.0 - x * x - y * y)
    n = np.array([x, y, z])
    h = math.hypot(x, z)
    t = np.array([z / h, 0.0, -x / h])  # y_w x N, normalised
    b = np.cross(n, t)
    return n, t, b


def _local(w, n, t, b):
    return np.array([w @ t, w @ b, w @ n])


PIXELS = [(7, 9), (3, 12), (12, 4), (8, 8), (1, 8)]  # on the sphere of a 17 x 17 image


def test_geometry_frame_is_orthonormal_and_the_world_axes_at_the_centre():
    g = R.geometry(17)
    for a in (g.normal, g.tangent, g.bitangent):
        assert np.allclose(np.einsum("ij,ij->i", a, a), 1.0, atol=1e-15)
    assert np.abs(np.einsum("ij,ij->i", g.normal, g.tangent)).max() < 1e-15
    assert np.abs(np.einsum("ij,ij->i", g.normal, g.bitangent)).max() < 1e-15
    # right-handed: T x B = N
    assert np.allclose(np.cross(g.tangent, g.bitangent), g.normal, atol=1e-15)
    centre = np.flatnonzero(g.mask.ravel()).tolist().index(8 * 17 + 8)
    assert np.array_equal(g.normal[centre], [0.0, 0.0, 1.0])
    assert np.array_equal(g.tangent[centre], [1.0, 0.0, 0.0]) and np.allclose(g.bitangent[centre], [0, 1, 0])
    # the mask is the pixel centres strictly inside the unit circle
    c = -1 + (2 * np.arange(17) + 1) / 17
    assert np.array_equal(g.mask, c[None, :] ** 2 + c[:, None] ** 2 < 1)


@pytest.mark.parametrize("phi", [0.0, 30.0, 80.0, 120.0])
def test_phong_pixels_by_hand(phi):
    n_exp = 20.0
    c = (n_exp + 2) / (2 * math.pi)
    im = R.sphere({"type": "phong", "n": n_exp}, light_deg=phi, size=17, irradiance=2.5)
    lw = np.array([math.sin(math.radians(phi)), 0.0, math.cos(math.radians(phi))])
    for i, j in PIXELS:
        n, t, b = _pixel(17, i, j)
        L = _local(lw, n, t, b)
        V = _local(np.array([0.0, 0.0, 1.0]), n, t, b)
        cos_l = L[2]
        R_ = 2 * L[2] * np.array([0, 0, 1.0]) - L  # mirror of L about N = (0, 0, 1)
        rv = R_ @ V
        f = c * max(rv, 0.0) ** n_exp if cos_l > 0 else 0.0  # 000 eq. 5
        expect = 2.5 * f * max(cos_l, 0.0)
        got = im.radiance[i, j]
        assert abs(got - expect) <= 1e-12 * max(abs(expect), 1e-300), (i, j, got, expect)
    assert im.radiance[~im.mask].max() == 0.0 and im.error is None


def test_anisotropic_ward_pixels_by_hand_fix_the_tangent():
    """ward_aniso's a_x runs along T (the parallels): a hand computation in that frame agrees to 1e-12,
    and one in the frame turned by 90 degrees does not."""
    ax, ay = 0.1, 0.3
    im = R.sphere({"type": "ward_aniso", "ax": ax, "ay": ay}, light_deg=30.0, size=17)
    lw = np.array([0.5, 0.0, math.sqrt(3) / 2])

    def ward(L, V):
        h = L + V
        e = (h[0] / h[2] / ax) ** 2 + (h[1] / h[2] / ay) ** 2
        return math.exp(-e) / (4 * math.pi * ax * ay * math.sqrt(L[2] * V[2]))

    seen_difference = False
    for i, j in [(7, 9), (6, 10), (9, 7), (8, 9)]:
        n, t, b = _pixel(17, i, j)
        L, V = _local(lw, n, t, b), _local(np.array([0.0, 0.0, 1.0]), n, t, b)
        expect = ward(L, V) * L[2]
        assert abs(im.radiance[i, j] - expect) <= 1e-12 * expect
        turned = ward(_local(lw, n, b, -t), _local(np.array([0.0, 0.0, 1.0]), n, b, -t)) * L[2]
        seen_difference |= abs(turned - expect) > 1e-3 * expect
    assert seen_difference


def test_shader_diffuse_term_is_in_the_radiance():
    """Lewis's eq. 4 with L_d = 1: E = pi, kd = (1 - ks)/pi, ks = k_s / pi gives (1 - k_s)(N.S) + k_s F_s."""
    ks = 0.4
    im = R.sphere({"type": "phong_shader", "n": 10, "ks": ks / math.pi, "kd": (1 - ks) / math.pi},
                  light_deg=60.0, size=17, irradiance=math.pi)
    lw = np.array([math.sin(math.pi / 3), 0.0, 0.5])
    for i, j in PIXELS:
        n, t, b = _pixel(17, i, j)
        L, V = _local(lw, n, t, b), _local(np.array([0.0, 0.0, 1.0]), n, t, b)
        if L[2] <= 0:
            assert im.radiance[i, j] == 0
            continue
        rv = (2 * L[2] * np.array([0, 0, 1.0]) - L) @ V
        expect = (1 - ks) * L[2] + ks * max(rv, 0.0) ** 10  # 002 eq. 4, 5
        assert abs(im.radiance[i, j] - expect) <= 1e-12 * expect


def test_lambert_furnace_is_rho_everywhere():
    for rho in (1.0, 0.37):
        im = R.furnace({"type": "lambert", "albedo": rho}, size=33)
        vals = im.radiance[im.mask]
        assert vals.size == np.count_nonzero(im.mask) > 700
        assert np.abs(vals - rho).max() <= 1e-12
        assert im.error <= 1e-12 and np.all(im.radiance[~im.mask] == 0)
    own = R.furnace({"type": "lambert", "albedo": 0.37}, size=9, rtol=1e-8, interp_tol=1e-6)  # not pump's table
    assert own.params["rtol"] == 1e-8 and np.abs(own.radiance[own.mask] - 0.37).max() <= 1e-12


def test_phong_furnace_pixels_are_the_albedo_within_the_stated_bound():
    f = pumpup.load({"type": "phong", "n": 20})
    im = R.furnace(f, size=17)
    g = R.geometry(17)
    mu = g.view[:, 2]
    a, e = pumpup.albedo(f, mu, return_error=True, rtol=1e-12)
    diff = np.abs(im.radiance[im.mask] - a)
    assert np.all(diff <= im.error + e), (diff.max(), im.error)
    assert im.error < 1e-6
    # by hand: the centre pixel sees mu_V = 1, where reciprocal Phong reflects exactly 1; the rim is dark
    assert abs(im.radiance[8, 8] - 1.0) <= im.error
    assert im.radiance[im.mask].min() < 0.35


def _phong_shader_furnace_reference(n, ks, kd, mu_v):
    """integral of f(L, V) (N.L) d omega_L for Phong's shader = kd pi + ks integral (R_L.V)_+^n d omega_L,
    by scipy dblquad in spherical coordinates about N (independent of pumpup's engine)."""
    from scipy.integrate import dblquad

    sv = math.sqrt(1 - mu_v * mu_v)

    def g(phi, theta):
        st, ct = math.sin(theta), math.cos(theta)
        # (R_L . V) = 2 (N.L)(N.V) - L.V with V = (sv, 0, mu_v)
        rv = 2 * ct * mu_v - (st * math.cos(phi) * sv + ct * mu_v)
        return (max(rv, 0.0) ** n) * st

    val, err = dblquad(g, 0, math.pi / 2, 0, 2 * math.pi, epsabs=1e-13, epsrel=1e-12)
    return kd * math.pi + ks * val


def test_non_reciprocal_furnace_integrates_over_the_light():
    """Phong's shader (002 eq. 8) is not reciprocal: its furnace radiance is integral f(L, V) N.L dL, which
    differs from its albedo a(mu_V); at the centre it is (n+2)/(n+1) in closed form."""
    n = 5.0
    spec = {"type": "phong_shader", "n": n, "kd": 0.05}
    im = R.furnace(spec, size=17)
    assert im.params["transposed"]
    ks = (n + 2) / (2 * math.pi)
    assert abs(im.radiance[8, 8] - (0.05 * math.pi + ks * 2 * math.pi / (n + 1))) <= im.error + 1e-14
    g = R.geometry(17)
    k = np.flatnonzero(g.mask.ravel()).tolist().index(3 * 17 + 12)
    mu_v = float(g.view[k, 2])
    ref = _phong_shader_furnace_reference(n, ks, 0.05, mu_v)
    assert abs(im.radiance[3, 12] - ref) <= im.error + 1e-10
    # the albedo (integral over V) is a different number there: the transposition matters
    assert abs(float(pumpup.albedo(pumpup.load(spec), mu_v)) - ref) > 1e-3


def test_furnace_refuses_anisotropic_models():
    with pytest.raises(pumpup.SpecError, match="anisotropic"):
        R.furnace({"type": "ward_aniso", "ax": 0.1, "ay": 0.3}, size=8)


@pytest.mark.parametrize("kw, match", [
    ({"light_deg": 180}, r"\[0, 180\)"), ({"light_deg": -1e-9}, r"\[0, 180\)"), ({"light_deg": float("nan")}, "180"),
    ({"size": 7}, ">= 8"), ({"size": 8.5}, ">= 8"), ({"size": True}, ">= 8"), ({"size": 10**6}, "<= 4096"),
    ({"irradiance": 0.0}, "irradiance"), ({"azimuth_deg": float("inf")}, "azimuth"),
])
def test_bad_input_is_one_clear_error(kw, match):
    args = {"light_deg": 0.0, "size": 16, **kw}
    with pytest.raises(ValueError, match=match):
        R.sphere({"type": "phong", "n": 2}, **args)


def test_furnace_bad_size():
    with pytest.raises(ValueError, match=">= 8"):
        R.furnace({"type": "lambert"}, size=4)


def test_exr_round_trip(tmp_path):
    im = R.sphere({"type": "blinn", "n": 30}, light_deg=30, size=24)
    p = R.write_exr(tmp_path / "a.exr", im)
    rad, mask, header = R.read_exr(p)
    assert rad.dtype == np.float32 and np.array_equal(rad, im.radiance.astype(np.float32))
    assert np.array_equal(mask, im.mask)
    assert pumpup.load(header["pumpup_spec"]) == pumpup.load({"type": "blinn", "n": 30})
    fu = R.furnace({"type": "lambert", "albedo": 0.5}, size=8)
    rad, mask, header = R.read_exr(R.write_exr(tmp_path / "f.exr", fu))
    assert np.all(rad[mask] == np.float32(0.5)) and float(header["pumpup_error_bound"]) == fu.error
    (tmp_path / "bad.exr").write_bytes(b"not an exr")
    with pytest.raises(ValueError, match="not a readable OpenEXR"):
        R.read_exr(tmp_path / "bad.exr")
    assert sorted(x.name for x in tmp_path.iterdir()) == ["a.exr", "bad.exr", "f.exr"]  # no temporaries left


def test_png_tone_map_and_clipping(tmp_path):
    import matplotlib.image as mimage
    from PIL import Image as PILImage

    im = R.sphere({"type": "phong", "n": 20}, light_deg=0, size=32)  # peak c = 3.5: clipped at exposure 0
    rgb, clipped = R.tone_map(im, exposure=0.0)
    assert clipped.any() and np.all(rgb[clipped] == R.CLIP_COLOUR)
    assert np.all(im.radiance[clipped] > 1) and np.all(im.radiance[im.mask & ~clipped] <= 1)
    rgb2, clipped2 = R.tone_map(im, exposure=-2.0)  # x 1/4: the peak 3.43 fits
    assert not clipped2.any()
    k = np.unravel_index(np.argmax(im.radiance), im.radiance.shape)
    v = im.radiance[k] / 4
    assert abs(rgb2[k][0] - (1.055 * v ** (1 / 2.4) - 0.055)) < 1e-12  # the sRGB transfer function
    assert np.all(rgb2[~im.mask] == R.BACKGROUND)
    p = R.write_png(tmp_path / "a.png", im, exposure=-2.0)
    back = mimage.imread(p)
    assert back.shape[:2] == (32, 32)
    assert np.abs(back[..., :3] - rgb2).max() <= 0.5 / 255 + 1e-6
    text = PILImage.open(p).text
    assert "sRGB" in text["Description"] and "-2" in text["Description"]
    assert text["pumpup_clipped_pixels"] == "0"


def test_grid_figure_and_labels(tmp_path):
    ims = [[R.sphere({"type": "phong", "n": 5}, a, 16) for a in (0, 60)],
           [R.furnace({"type": "lambert", "albedo": 0.8}, 16), None]]
    p = R.grid_figure(ims, tmp_path / "g.png", row_labels=["a", "b"], col_labels=["0", "60"], title="t")
    assert (tmp_path / "g.png").stat().st_size > 1000 and p.endswith("g.png")
    assert R.label({"type": "pumped", "g": "g2", "levels": 2, "base": {"type": "blinn", "n": 20}}) == \
        "g2 x2 of blinn n=20"
    assert abs(math.cos(math.radians(10)) ** R.lewis_exponent(10) - 0.5) < 1e-14


def test_cli_render_sphere_and_furnace(tmp_path, capsys):
    out = tmp_path / "img"
    assert main(["render", "sphere", "phong:n=20", "lambert", "--light", "0,60", "--size", "16",
                 "--out", str(out)]) == 0
    names = sorted(x.name for x in out.iterdir())
    assert "sphere_grid.png" in names and "sphere_01_lambert_L60.exr" in names and len(names) == 9
    rad, mask, _ = R.read_exr(out / "sphere_00_phong_L60.exr")
    assert np.array_equal(rad, R.sphere({"type": "phong", "n": 20}, 60, 16).radiance.astype(np.float32))
    assert main(["render", "furnace", "lambert:albedo=0.25", "--size", "8", "--out", str(out)]) == 0
    rad, mask, _ = R.read_exr(out / "furnace_00_lambert.exr")
    assert np.all(rad[mask] == np.float32(0.25))
    assert "error bound" in capsys.readouterr().out


@pytest.mark.parametrize("argv, match", [
    (["sphere", "phong:n=2", "--light", "0,180"], r"--light .*\[0, 180\)"),
    (["sphere", "phong:n=2", "--light", "-5"], r"\[0, 180\)"),
    (["sphere", "phong:n=2", "--size", "7"], "--size must be .* >= 8"),
    (["sphere", "phong:n=2", "nope:n=1"], "SPEC 'nope:n=1' does not load: unknown model type"),
    (["sphere", "phong:n=-1"], r"'n' = -1 is outside"),
    (["furnace", "phong:n=2", "--size", "x"], "--size"),
    (["furnace", "ward_aniso:ax=0.1,ay=0.2"], "anisotropic"),
])
def test_cli_bad_input_one_line_status_2_nothing_written(tmp_path, capsys, argv, match):
    import re

    out = tmp_path / "never"
    assert main(["render", *argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(match, err), err
    assert not out.exists()


def test_furnace_clipping_allows_the_error_bound():
    mask = np.ones((8, 8), bool)
    rad = np.full((8, 8), 1.0 + 5e-8)
    rad[0, 0] = 1.0 + 3e-7
    im = R.Image(rad, mask, "furnace", {"type": "lambert"}, error=1e-7)
    _, clipped = R.tone_map(im)
    assert clipped.sum() == 1 and clipped[0, 0]  # above 1 + bound: more reflected than received
    im.error = None
    assert R.tone_map(im)[1].all()
    im.radiance[:] = 1.0 + 2e-16  # a light scaled so that the peak is 1, to rounding: not clipped
    assert not R.tone_map(im)[1].any()


@pytest.mark.parametrize("light", ["30", True, b"30"], ids=str)
def test_a_light_angle_given_as_text_or_a_bool_is_refused_in_one_line(light):
    from pumpup import render

    with pytest.raises(ValueError, match="light angle Phi_L must be a number of degrees"):
        render.sphere({"type": "lambert"}, light_deg=light, size=8)
