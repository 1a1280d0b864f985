"""Tests of pumpup.testing.chi2_test: correct samplers pass, wrong pdfs fail, the false-positive
rate is what alpha says, Sidak's correction is applied, bad input is refused clearly.

The samplers here are written from scratch in this file (independent of pumpup.sampling).
"""

import math

import numpy as np
import pytest
from scipy import integrate, stats

import pumpup
from pumpup.testing import Chi2Result, _pearson, _pool, chi2_test, plot, sidak_level

# ----------------------------------------------------------------------------------------
# samplers and pdfs (N = (0, 0, 1); wi towards the light, wo towards the viewer)
# ----------------------------------------------------------------------------------------


def unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def direction(theta_deg, phi_deg=0.0):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)])


def frame(axis):
    """Orthonormal s, t with s x t = axis (Duff et al. 2017)."""
    x, y, z = axis
    sign = math.copysign(1.0, z)
    a = -1.0 / (sign + z)
    b = x * y * a
    return np.array([1 + sign * x * x * a, sign * b, -sign * x]), np.array([b, sign + y * y * a, -y])


def around(axis, cos_a, phi):
    s, t = frame(axis)
    sin_a = np.sqrt(np.maximum(0.0, 1 - cos_a**2))
    d = (sin_a * np.cos(phi))[:, None] * s + (sin_a * np.sin(phi))[:, None] * t + cos_a[:, None] * axis
    return unit(d)


def uniform_sample(wo, n, rng):
    z = 1.0 - rng.random(n)  # (0, 1]
    phi = 2 * np.pi * rng.random(n)
    r = np.sqrt(np.maximum(0.0, 1 - z * z))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1), np.full(n, 1 / (2 * np.pi))


def uniform_pdf(wi, wo):
    return np.where(wi[..., 2] > 0, 1 / (2 * np.pi), 0.0)


def cosine_sample(wo, n, rng):
    u = rng.random(n)
    z = np.sqrt(1.0 - u)  # (0, 1]
    phi = 2 * np.pi * rng.random(n)
    r = np.sqrt(u)
    wi = np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)
    return wi, z / np.pi


def cosine_pdf(wi, wo):
    return np.maximum(wi[..., 2], 0.0) / np.pi


def mirror(wo):
    return np.array([-wo[0], -wo[1], wo[2]])


def phong_sampler(n_exp, drop_rejected=False, pdf_exp=None):
    """cos^n lobe around the mirror direction, rejection below the horizon.

    drop_rejected: the classic bug -- redraw until n directions are accepted.
    pdf_exp: report the normalised density of a different exponent (a wrong pdf).
    """
    m = n_exp if pdf_exp is None else pdf_exp

    def draw(wo, n, rng):
        r = mirror(wo)
        cos_a = (1.0 - rng.random(n)) ** (1.0 / (n_exp + 1))  # 000 eq. 20
        wi = around(r, cos_a, 2 * np.pi * rng.random(n))
        c = np.clip(wi @ r, 0.0, 1.0)
        p = (m + 1) / (2 * np.pi) * c**m
        return wi, p

    def sample(wo, n, rng):
        if drop_rejected:
            out, pdfs, have = [], [], 0
            while have < n:
                wi, p = draw(wo, n, rng)
                ok = wi[:, 2] > 0
                out.append(wi[ok])
                pdfs.append(p[ok])
                have += int(ok.sum())
            return np.concatenate(out)[:n], np.concatenate(pdfs)[:n]
        wi, p = draw(wo, n, rng)
        below = wi[:, 2] <= 0
        wi[below] = 0.0
        p[below] = 0.0
        return wi, p

    return sample


def phong_pdf(n_exp):
    def pdf(wi, wo):
        c = wi @ mirror(wo)
        ok = (wi[..., 2] > 0) & (c > 0)
        return np.where(ok, (n_exp + 1) / (2 * np.pi) * np.maximum(c, 0.0) ** n_exp, 0.0)

    return pdf


def beckmann_d(cos_h, m):
    c2 = cos_h * cos_h
    tan2 = (1 - c2) / c2
    return np.exp(-tan2 / (m * m)) / (np.pi * m * m * c2 * c2)


def beckmann_sampler(m, jacobian=True):
    def sample(wo, n, rng):
        tan2 = -m * m * np.log(1.0 - rng.random(n))  # Walter et al. 2007 eq. 28
        cos_h = 1 / np.sqrt(1 + tan2)
        h = around(np.array([0.0, 0.0, 1.0]), cos_h, 2 * np.pi * rng.random(n))
        woh = h @ wo
        wi = unit(2 * woh[:, None] * h - wo)
        p = beckmann_d(cos_h, m) * cos_h
        if jacobian:
            p = p / (4 * woh)
        bad = (wi[:, 2] <= 0) | (woh <= 0)
        wi[bad] = 0.0
        p[bad] = 0.0
        return wi, p

    return sample


def beckmann_pdf(m, jacobian=True):
    def pdf(wi, wo):
        s = wi + wo
        h = s / np.maximum(np.linalg.norm(s, axis=-1, keepdims=True), 1e-300)
        cos_h = h[..., 2]
        woh = h @ wo
        ok = (wi[..., 2] > 0) & (woh > 0) & (cos_h > 0)
        ch = np.where(ok, cos_h, 1.0)
        p = beckmann_d(ch, m) * ch
        if jacobian:
            p = p / (4 * np.where(ok, woh, 1.0))
        return np.where(ok, p, 0.0)

    return pdf


WOS = np.array([direction(0), direction(40, 30), direction(80, -100)])
FAST = {"n_samples": 100_000, "n_theta": 32, "n_phi": 64}

# ----------------------------------------------------------------------------------------
# correct samplers pass
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "name, sample, pdf, wo",
    [
        ("uniform", uniform_sample, uniform_pdf, WOS),
        ("cosine", cosine_sample, cosine_pdf, WOS),
        ("phong n=20", phong_sampler(20), phong_pdf(20), WOS),
        ("phong n=3 grazing", phong_sampler(3), phong_pdf(3), np.array([direction(70), direction(85, 45)])),
        ("beckmann m=0.3", beckmann_sampler(0.3), beckmann_pdf(0.3), WOS),
        ("beckmann m=0.05", beckmann_sampler(0.05), beckmann_pdf(0.05), WOS[:2]),
    ],
)
def test_correct_samplers_pass(name, sample, pdf, wo):
    # A fixed seed can be unlucky: for Beckmann m=0.05 at these settings, 600 seeds gave
    # 9 p-values below 0.01 (1.5 %), the smallest 1.3e-5 (seed 1; Pearson's statistic
    # with few cells has a heavier extreme tail than chi2).  Seed 2 is not chosen per case.
    r = chi2_test(sample, pdf, wo, seed=2, **FAST)
    assert r, str(r)
    assert r.passed and all(r.passed_each)
    assert np.all(r.p_values >= r.significance)
    assert np.all(r.pdf_mismatches == 0)
    assert np.all(r.dofs > 30)
    # every sample is accounted for: in a bin or in the rejected cell
    assert np.all(r.observed.sum(axis=(1, 2)) + r.observed_rejected == r.n_samples)
    # (the rejected cell's expectation is clipped at 0, so allow the quadrature's rounding above 1)
    np.testing.assert_allclose(r.expected.sum(axis=(1, 2)) + r.expected_rejected, r.n_samples, atol=1e-3)
    assert np.all(r.pdf_integral <= 1 + 1e-9)


def test_rejected_samples_are_counted_not_renormalised():
    """At grazing incidence a quarter of the Phong n=3 lobe is below the horizon: the pdf
    integrates to ~0.75, and the rejected cell is checked against n (1 - integral)."""
    r = chi2_test(phong_sampler(3), phong_pdf(3), direction(80), seed=2, **FAST)
    assert r, str(r)
    assert 0.6 < r.pdf_integral[0] < 0.9
    e, o = r.expected_rejected[0], r.observed_rejected[0]
    assert e > 0.1 * r.n_samples
    assert abs(o - e) < 4 * math.sqrt(e)


def phong_horizon_fraction(n_exp, theta_o_deg):
    """Independent 1-D quadrature: the fraction of the cos^n lobe around the mirror direction
    that lies above the horizon (the integral of the Phong pdf over the sphere)."""
    rz = math.cos(math.radians(theta_o_deg))
    st = math.sqrt(1 - rz * rz)

    def f(a):
        # lobe coordinates: z = cos a rz + sin a cos phi st > 0 on an arc of phi
        if st == 0:
            frac = 1.0 if rz > 0 else 0.0
        else:
            x = -math.cos(a) * rz / (math.sin(a) * st) if math.sin(a) > 0 else -math.inf
            frac = math.acos(min(1.0, max(-1.0, x))) / math.pi
        return (n_exp + 1) * math.cos(a) ** n_exp * math.sin(a) * frac

    kink = math.pi / 2 - math.radians(theta_o_deg)  # the lobe starts to be cut
    val, _ = integrate.quad(f, 0, math.pi / 2, points=[kink], epsabs=1e-13, epsrel=1e-12, limit=200)
    return val


@pytest.mark.parametrize("n_exp, theta", [(3, 80.0), (20, 75.0), (1, 50.0)])
def test_pdf_integral_matches_independent_quadrature(n_exp, theta):
    r = chi2_test(phong_sampler(n_exp), phong_pdf(n_exp), direction(theta, 20), seed=3, n_samples=10_000,
                  n_theta=32, n_phi=64)
    ref = phong_horizon_fraction(n_exp, theta)
    assert ref < 0.99
    # the total quadrature bias must be small beside one sample in n_samples
    assert abs(r.pdf_integral[0] - ref) < 1e-7, (r.pdf_integral[0], ref)
    assert r.integration_error[0] < 1e-5


# ----------------------------------------------------------------------------------------
# wrong pdfs fail
# ----------------------------------------------------------------------------------------


def test_cosine_sampler_with_uniform_pdf_fails():
    def sample(wo, n, rng):
        wi, _ = cosine_sample(wo, n, rng)
        return wi, np.full(n, 1 / (2 * np.pi))

    r = chi2_test(sample, uniform_pdf, direction(30), seed=4, **FAST)
    assert not r
    assert r.p_values[0] < 1e-12
    assert r.pdf_mismatches[0] == 0  # consistent, so only the statistic can catch it
    assert any("rejected the null hypothesis" in m for m in r.messages[0])


def test_phong_exponent_off_by_one_fails():
    """Directions from cos^20, density reported (consistently) as the normalised cos^21."""
    r = chi2_test(phong_sampler(20, pdf_exp=21), phong_pdf(21), direction(30), seed=5, **FAST)
    assert not r
    assert r.pdf_mismatches[0] == 0
    assert r.p_values[0] < 1e-6
    # and with the correct exponent, same seed, it passes
    assert chi2_test(phong_sampler(20), phong_pdf(20), direction(30), seed=5, **FAST)


def test_inconsistent_sample_pdf_is_reported():
    """The sampler reports the cos^21 density while pdf() is cos^20: a common bug."""
    r = chi2_test(phong_sampler(20, pdf_exp=21), phong_pdf(20), direction(30), seed=6, **FAST)
    assert not r
    assert r.pdf_mismatches[0] > 0.9 * r.n_samples
    assert any("differs from pdf(wi, wo)" in m for m in r.messages[0])


def test_missing_half_vector_jacobian_fails():
    r = chi2_test(beckmann_sampler(0.3, jacobian=False), beckmann_pdf(0.3, jacobian=False), direction(40),
                  seed=7, **FAST)
    assert not r
    assert r.pdf_mismatches[0] == 0
    assert r.p_values[0] < 1e-12


def test_dropping_rejected_samples_fails():
    """Redrawing rejected directions renormalises the lobe behind the pdf's back."""
    r = chi2_test(phong_sampler(3, drop_rejected=True), phong_pdf(3), direction(80), seed=8, **FAST)
    assert not r
    assert r.observed_rejected[0] == 0
    assert r.expected_rejected[0] > 0.1 * r.n_samples
    assert r.p_values[0] < 1e-12
    assert r.pdf_mismatches[0] == 0


def test_dropping_rejected_samples_at_small_rejection_rate_fails():
    """The same bug where only ~1.5 % of draws are rejected (Phong n=20 at 60 degrees)."""
    wo = direction(60)
    assert 0.005 < 1 - phong_horizon_fraction(20, 60) < 0.03
    r = chi2_test(phong_sampler(20, drop_rejected=True), phong_pdf(20), wo, seed=9, **FAST)
    assert not r, str(r)
    assert chi2_test(phong_sampler(20), phong_pdf(20), wo, seed=9, **FAST)


def test_pdf_integrating_above_one_fails():
    def sample(wo, n, rng):
        wi, p = cosine_sample(wo, n, rng)
        return wi, 2 * p

    r = chi2_test(sample, lambda wi, wo: 2 * cosine_pdf(wi, wo), direction(0), seed=10, n_samples=20_000,
                  n_theta=16, n_phi=32)
    assert not r
    assert r.pdf_integral[0] == pytest.approx(2.0, rel=1e-9)
    assert any("integrates to 2.000000" in m for m in r.messages[0])


def test_samples_where_the_pdf_is_zero_fail():
    """A few samples leak below the horizon; the pdf (rightly) says none can be there."""

    def sample(wo, n, rng):
        wi, p = cosine_sample(wo, n, rng)
        wi[:3, 2] *= -1
        return wi, p

    r = chi2_test(sample, cosine_pdf, direction(0), seed=11, n_samples=20_000, n_theta=16, n_phi=32,
                  pdf_rtol=None)
    assert not r
    assert any("samples where none are expected" in m and "3 samples in 3 bins" in m for m in r.messages[0])
    # pbrt's lenient rule tolerates a few
    r = chi2_test(sample, cosine_pdf, direction(0), seed=11, n_samples=20_000, n_theta=16, n_phi=32,
                  pdf_rtol=None, max_zero_bin_samples=3)
    assert not any("none are expected" in m for m in r.messages[0])


def test_rejections_with_a_pdf_that_integrates_to_one_fail():
    def sample(wo, n, rng):
        wi, p = cosine_sample(wo, n, rng)
        wi[:10] = 0.0
        p[:10] = 0.0
        return wi, p

    r = chi2_test(sample, cosine_pdf, direction(0), seed=12, n_samples=20_000, n_theta=16, n_phi=32)
    assert not r
    assert any("10 rejected samples although the pdf integrates" in m for m in r.messages[0])


def test_malformed_samples_are_reported():
    def sample(wo, n, rng):
        wi, p = cosine_sample(wo, n, rng)
        wi[0] = 0.0  # rejected, but with a pdf
        wi[1] *= 1.01  # not a unit vector
        p[2] = np.nan
        return wi, p

    r = chi2_test(sample, cosine_pdf, direction(0), seed=13, n_samples=5_000, n_theta=8, n_phi=16)
    assert not r
    text = "\n".join(r.messages[0])
    assert "1 rejected samples (wi = 0) have a nonzero pdf value" in text
    assert "1 sampled directions are not unit vectors" in text
    assert "1 samples have a non-finite direction or pdf value" in text


def test_negative_pdf_is_reported():
    r = chi2_test(cosine_sample, lambda wi, wo: cosine_pdf(wi, wo) - 0.01 * (wi[..., 2] < 0), direction(0),
                  seed=14, n_samples=5_000, n_theta=8, n_phi=16)
    assert not r
    assert any("negative or non-finite values at quadrature nodes" in m for m in r.messages[0])


# ----------------------------------------------------------------------------------------
# Sidak correction
# ----------------------------------------------------------------------------------------


def test_sidak_level():
    assert sidak_level(0.01, 1) == pytest.approx(0.01, rel=1e-15)
    for k in (2, 3, 5, 20):
        lv = sidak_level(0.01, k)
        assert (1 - lv) ** k == pytest.approx(0.99, rel=1e-14)
        assert 0.01 / k < lv < 0.01  # between Bonferroni and no correction
    assert sidak_level(1e-12, 4) == pytest.approx(2.5e-13, rel=1e-6)  # no cancellation


def test_sidak_correction_is_applied():
    wos = np.array([direction(10), direction(35, 60), direction(60, 200), direction(75, 300)])
    kw = {"seed": 15, "n_samples": 20_000, "n_theta": 16, "n_phi": 32}
    r = chi2_test(phong_sampler(10), phong_pdf(10), wos, alpha=0.01, **kw)
    k = len(wos)
    assert r.significance == pytest.approx(1 - 0.99 ** (1 / k), rel=1e-12)
    assert r.p_value == pytest.approx(1 - (1 - r.p_values.min()) ** k, rel=1e-9)
    p_min = r.p_values.min()
    assert 0 < p_min < 1
    # an alpha whose Sidak level lies just below p_min although alpha itself is above it:
    # the corrected test accepts, so the correction was applied...
    alpha = 1 - (1 - 0.9 * p_min) ** k
    assert alpha > p_min
    r2 = chi2_test(phong_sampler(10), phong_pdf(10), wos, alpha=alpha, **kw)
    np.testing.assert_array_equal(r2.p_values, r.p_values)  # same seed, same draws
    assert r2.passed
    # ...and one whose Sidak level is just above p_min rejects
    r3 = chi2_test(phong_sampler(10), phong_pdf(10), wos, alpha=1 - (1 - 1.1 * p_min) ** k, **kw)
    assert not r3.passed
    assert r3.passed_each.sum() == k - 1
    # a single direction at that alpha is tested at alpha itself
    j = int(np.argmin(r.p_values))
    single = chi2_test(phong_sampler(10), phong_pdf(10), wos[j], alpha=alpha, **kw)
    assert single.significance == alpha


# ----------------------------------------------------------------------------------------
# the false-positive rate
# ----------------------------------------------------------------------------------------


def test_p_values_of_a_correct_sampler_are_uniform():
    """100 seeds of a correct sampler with rejection (Phong n=5 at 70 degrees): the p-values
    must look uniform (KS test) and about 1 % of them fall below 0.01."""
    wo = direction(70, 10)
    pv = np.array([
        chi2_test(phong_sampler(5), phong_pdf(5), wo, seed=1000 + s, n_samples=5_000, n_theta=8, n_phi=16).p_values[0]
        for s in range(100)
    ])
    ks = stats.kstest(pv, "uniform")
    assert ks.pvalue > 0.01, (ks, np.sort(pv))
    # P(5 or more of 100 below 0.01 | rate 1 %) = 0.003
    assert (pv < 0.01).sum() <= 4
    assert 1 <= (pv < 0.1).sum() <= 20  # binomial(100, 0.1): 1-20 has probability > 0.999
    assert 0.3 < np.mean(pv) < 0.7


# ----------------------------------------------------------------------------------------
# bad input
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"wo": [0.0, 0.0, 1.1]}, r"wo must be unit vectors.*norm 1\.1"),
        ({"wo": [[0.0, 0.0, 1.0], [0.0, 0.6, 0.6]]}, r"wo\[1\] has norm"),
        ({"wo": [0.0, 1.0]}, "wo must be a unit 3-vector"),
        ({"wo": [np.nan, 0.0, 1.0]}, "wo must be finite"),
        ({"n_samples": 0}, "n_samples must be an integer >= 1"),
        ({"n_samples": 1.5}, "n_samples must be an integer >= 1"),
        ({"alpha": 0.0}, r"alpha must be a significance level in \(0, 1\)"),
        ({"alpha": 1.0}, r"alpha must be a significance level in \(0, 1\)"),
        ({"alpha": -0.1}, r"alpha must be a significance level in \(0, 1\)"),
        ({"n_theta": 15}, "n_theta must be even"),
        ({"n_phi": 0}, "n_phi must be an integer >= 1"),
        ({"min_expected": 0}, "min_expected must be > 0"),
    ],
)
def test_bad_input_is_refused(kwargs, match):
    args = {"wo": [0.0, 0.0, 1.0], "n_samples": 100}
    args.update(kwargs)
    wo = args.pop("wo")
    with pytest.raises(ValueError, match=match):
        chi2_test(cosine_sample, cosine_pdf, wo, **args)


def test_sampler_returning_too_few_samples_is_refused():
    def sample(wo, n, rng):  # drops its rejected samples instead of returning them
        wi, p = phong_sampler(3)(wo, n, rng)
        keep = p > 0
        return wi[keep], p[keep]

    with pytest.raises(ValueError, match=r"wi of shape \(n, 3\).*n = 1000"):
        chi2_test(sample, phong_pdf(3), direction(80), n_samples=1000)


def test_pdf_that_does_not_broadcast_is_refused():
    with pytest.raises(ValueError, match="pdf"):
        chi2_test(cosine_sample, lambda wi, wo: np.ones(3), direction(0), n_samples=100)


# ----------------------------------------------------------------------------------------
# the result object, speed, the pooling, the plot
# ----------------------------------------------------------------------------------------


def test_result_and_speed():
    """1e6 samples at the default resolution (64 x 128 bins)."""
    r = chi2_test(cosine_sample, cosine_pdf, direction(20), seed=16)
    assert isinstance(r, Chi2Result)
    assert r and bool(r) is True
    assert r.observed.shape == r.expected.shape == (1, 64, 128)
    assert r.observed.sum() == 1_000_000
    assert r.observed[0, :32].sum() == 0 and r.expected[0, :32].sum() == 0  # below the horizon
    assert r.p_value == r.p_values[0] and r.statistic == r.statistics[0] and r.dof == r.dofs[0]
    assert r.dof == 64 * 128 // 2 - 1 + (1 if r.expected_rejected[0] > 0 else 0) - r.pooled_in[0] + r.pooled_out[0]
    text = str(r)
    assert "PASSED" in text and "p = " in text and "dof = " in text
    assert r.timings["bin"] < 1.0, r.timings
    assert r.timings["integrate"] < 2.0, r.timings


def test_pooling_keeps_every_observation():
    rng = np.random.default_rng(17)
    for trial in range(20):
        e = rng.exponential(rng.uniform(0.5, 20), 300)
        e[:20] = 0.0
        o = rng.poisson(e).astype(float)
        o[:2] += 1  # samples in zero-expected cells end up in a pooled cell
        po, pe, pin, pout = _pool(o, e, 5.0)
        assert po.sum() == o.sum()
        assert pe.sum() == pytest.approx(e.sum(), rel=1e-12)
        assert np.all(pe >= 5.0)  # here there is always enough to pool
        assert pin == np.sum(e < 5.0) - 18  # the 18 empty zero-expected cells are dropped
        assert len(pe) == np.sum(e >= 5.0) + pout
        stat, dof, _, _ = _pearson(o, e, 5.0)
        assert dof == len(pe) - 1
        assert stat == pytest.approx(np.sum((po - pe) ** 2 / pe), rel=1e-12)
    # without pooling it is Pearson's statistic, as scipy computes it
    keep = e > 0
    stat, dof, pin, pout = _pearson(o[keep], e[keep], 1e-300)
    assert (pin, pout, dof) == (0, 0, keep.sum() - 1)
    e_scaled = e[keep] * o[keep].sum() / e[keep].sum()
    assert _pearson(o[keep], e_scaled, 1e-300)[0] == pytest.approx(stats.chisquare(o[keep], e_scaled).statistic,
                                                                 rel=1e-12)


def test_pooling_matches_a_hand_computation():
    o = np.array([0, 1, 2, 0, 3, 9, 12])
    e = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 10.0, 11.0])
    # the empty zero cell is dropped; lows 1, 2, 3 pool into (obs 3, exp 6); the remainder 4
    # is below 5 and joins that group: (obs 6, exp 10)
    stat, dof, pin, pout = _pearson(o, e, 5.0)
    assert (pin, pout) == (4, 1)
    assert dof == 2
    assert stat == pytest.approx((6 - 10) ** 2 / 10 + (9 - 10) ** 2 / 10 + (12 - 11) ** 2 / 11)
    # a lone remainder joins the smallest unpooled cell
    po, pe, pin, pout = _pool(np.array([1, 9, 12]), np.array([2.0, 10.0, 11.0]), 5.0)
    assert (pin, pout) == (1, 0)
    np.testing.assert_array_equal(po, [10, 12])
    np.testing.assert_array_equal(pe, [12.0, 11.0])
    # a sample where nothing is expected makes the statistic infinite if it cannot be pooled
    assert _pearson(np.array([1, 10]), np.array([0.0, 10.0]), 1e-300)[0] == pytest.approx(0.1)  # pooled
    assert _pearson(np.array([2]), np.array([0.0]), 5.0)[0] == np.inf


def test_plot_writes_a_figure(tmp_path):
    r = chi2_test(phong_sampler(20), phong_pdf(20), WOS, seed=18, n_samples=20_000, n_theta=16, n_phi=32)
    path = tmp_path / "chi2.png"
    plot(r, path)
    assert path.stat().st_size > 1000


def test_reachable_from_the_package():
    assert pumpup.testing.chi2_test is chi2_test


# ----------------------------------------------------------------------------------------
# the result's repr (issue 13, item 16)
# ----------------------------------------------------------------------------------------


def _result(passed, p):
    k = len(p)
    return Chi2Result(
        wo=np.tile([0.0, 0.0, 1.0], (k, 1)), p_values=np.array(p), statistics=np.full(k, 31.5),
        dofs=np.full(k, 40), alpha=0.01, significance=1 - 0.99 ** (1 / k), passed_each=np.full(k, passed),
        passed=passed, messages=[[] for _ in p], observed=np.ones((k, 64, 128), int),
        expected=np.ones((k, 64, 128)), observed_rejected=np.zeros(k), expected_rejected=np.zeros(k),
        pdf_integral=np.ones(k), integration_error=np.zeros(k), pdf_mismatches=np.zeros(k, int),
        pooled_in=np.zeros(k, int), pooled_out=np.zeros(k, int), n_samples=1_000_000, n_theta=64, n_phi=128)


def test_chi2_repr_shows_the_verdict_and_p_value():
    r = _result(True, [0.5, 0.2, 0.9])
    text = repr(r)
    assert text.startswith("<Chi2Result passed: p = 0.488")  # 1 - 0.8^3
    assert "array" not in text and len(text) < 250
    assert "FAILED" in repr(_result(False, [1e-6]))
