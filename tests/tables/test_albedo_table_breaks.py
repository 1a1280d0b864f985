"""An albedo table split at the kinks of the albedo (AlbedoTable's breaks, tabulate(breaks=...)): a pumped level's table
has them where a level below changes its g's form (Pumped.albedo_kinks)."""

import numpy as np
import pytest

import pumpup
from pumpup.operators import pumping
from pumpup.tables import AlbedoTable, nondecreasing
from pumpup.tables.validate import TableError


def _kinked(mu):
    lx = np.log(mu)
    # a kink at mu = 0.6, quadratic in log(mu) on either side
    return 0.3 + 0.2 * np.abs(lx - np.log(0.6)) + 0.01 * lx**2


def test_a_split_spline_follows_a_kink_the_whole_one_rounds_off():
    mu = np.unique(np.concatenate([np.geomspace(1e-3, 1.0, 40), [0.6]]))
    v = _kinked(mu)
    x = np.geomspace(1e-3, 1.0, 2001)
    split = AlbedoTable(mu, v, np.zeros_like(v), breaks=[0.6])
    whole = AlbedoTable(mu, v, np.zeros_like(v))
    assert split.breaks == (0.6,) and split.degree == 5
    assert np.max(np.abs(split(x) - _kinked(x))) < 1e-13 and np.max(np.abs(whole(x) - _kinked(x))) > 1e-4
    assert split(np.array([0.6]))[0] == pytest.approx(_kinked(0.6), abs=1e-15)  # continuous at the break


def test_breaks_must_be_nodes():
    mu = np.geomspace(1e-3, 1.0, 12)
    with pytest.raises(ValueError, match="breaks must be nodes"):
        AlbedoTable(mu, mu, 0 * mu, breaks=[0.5])


def test_short_pieces_take_lower_degrees():
    mu = np.array([0.01, 0.1, 0.2, 0.3, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0])
    t = AlbedoTable(mu, np.sqrt(mu), 0 * mu, breaks=[0.2])  # 3 nodes below the break: a cubic there
    assert t.degree == 5 and t._spline.c.shape[0] == 6
    np.testing.assert_allclose(t(mu), np.sqrt(mu), rtol=0, atol=1e-15)


def test_monotone_check_sees_a_fall_before_a_break():
    """A split spline is only C0 at a break: a piece that falls into it, with no turn of its slope inside, shows it at
    its right end only (the check once looked at the breakpoints, where the piece to the right is evaluated)."""
    mu = np.geomspace(0.1, 1.0, 15)
    lx, b = np.log(mu), mu[7]
    rise = np.where(lx <= lx[7], lx, lx[7] + 3.0 * (lx - lx[7]))  # increasing, a kink at b
    assert AlbedoTable(mu, rise, 0 * mu, breaks=[b]).is_increasing()
    peak = 0.5 * (lx[6] + lx[7])  # below b a parabola (reproduced exactly) that turns down between the last nodes
    fall = np.where(lx <= lx[7], -((lx - peak) ** 2), -((lx[7] - peak) ** 2) + 3.0 * (lx - lx[7]))
    t = AlbedoTable(mu, fall, 0 * mu, breaks=[b])
    d1 = t._spline.derivative()
    assert np.all(d1(t._spline.x) >= 0)  # every breakpoint, as the check once saw them
    assert not nondecreasing(t._spline)


def test_tabulate_refuses_bad_breaks():
    f = pumpup.load({"type": "lambert"})
    for bad in ([1.5], [float("nan")], [1e-9]):
        with pytest.raises(ValueError, match=r"breaks must lie in \(mu_min, 1\)"):
            pumpup.tabulate(f, breaks=bad, progress=False)
    with pytest.raises(ValueError, match=r"breaks must be numbers in \(mu_min, 1\)"):
        pumpup.tabulate(f, breaks=["a"], progress=False)
    with pytest.raises(ValueError, match="breaks need an adaptive grid"):
        pumpup.tabulate(f, mu=[0.5, 1.0], breaks=[0.5], progress=False)


def test_a_pumped_level_is_tabulated_split_at_the_level_below_kinks(tmp_path):
    """2-level g2 pumped GGX alpha 0.1: level 1's bound crosses the diagonal at v = 0.98814, a kink of the level-2
    table's albedo.  Split there the table needs about half the nodes (the whole spline's grid bunched towards it:
    241 nodes before), and the 1-D path about two thirds of the evaluations (1448 per mu before)."""
    p = pumpup.pump({"type": "ggx", "alpha": 0.1, "shadowing": "correlated"}, g="g2", levels=2)
    kinks = p.base.albedo_kinks(*pumping.grid_interior())
    assert any(abs(k - 0.98814) < 1e-5 for k in kinks)
    t = p.table()
    assert set(kinks) <= set(t.breaks) | {k for k in kinks if k <= t.mu[0]}
    whole = pumpup.tabulate(p.base, rtol=pumping.TABLE_RTOL, interp_tol=pumping.TABLE_INTERP_TOL, progress=False)
    assert len(t.mu) < 0.6 * whole.sizes["mu"]
    assert t.interp_error <= pumping.TABLE_INTERP_TOL
    near = 0.98814369 * (1.0 + np.linspace(-1e-3, 1e-3, 41))  # about the break: the bound holds (001 eq. 17's g >= a)
    a = pumpup.albedo(p.base, near, rtol=1e-12)
    assert np.all(p.lookup().upper(near) >= a) and np.max(np.abs(t(near) - a)) <= t.margin
    path = tmp_path / "ggx_g2.nc"
    pumpup.save_pumped(p, path)
    q = pumpup.load_pumped(path)
    assert q.table().breaks == t.breaks
    mu = np.array([1.0, 0.99, 0.98814, 0.9, 0.5, 0.1])
    np.testing.assert_array_equal(pumpup.albedo(q, mu), pumpup.albedo(p, mu))


def test_a_file_whose_breaks_are_not_nodes_is_refused(tmp_path):
    ds = pumpup.tabulate(pumpup.load({"type": "phong", "n": 5}), mu=np.geomspace(0.01, 1.0, 9), progress=False)
    path = tmp_path / "t.nc"
    for breaks in (0.5, np.array([ds["mu"].values[3], 0.5])):  # one (written as a number) and two
        ds.attrs["interpolation_breaks"] = breaks
        pumpup.write_table(ds, path)
        with pytest.raises(TableError, match="interpolation_breaks"):
            pumpup.open_table(path)
    ds.attrs["interpolation_breaks"] = float(ds["mu"].values[3])  # a node: read back, the digest matches
    pumpup.write_table(ds, path)
    assert pumpup.AlbedoTable.from_dataset(pumpup.open_table(path)).breaks == (float(ds["mu"].values[3]),)


def test_a_g1_level_albedo_has_a_kink_where_its_bound_equals_the_bound_at_the_normal():
    """GGX alpha 0.5's albedo falls from mu = 1 and rises again at grazing, so the bound u(v) of its g1 pumping equals
    u(1) at v = 0.4788: there the set of wo with u(N.wo) > u(v) is born at the normal, and the level's albedo has a
    jump of its second derivative (measured here: second differences +0.099 on one side, -0.258 on the other) that no
    cut of g marks.  ``Pumped._kink_normal`` finds it and ``albedo_kinks`` splits the table above it there.  With g2 and
    u(1) <= 1, g at wo = N is max(u(v), 1): no such kink."""
    f = pumpup.pump({"type": "ggx", "alpha": 0.5}, g="g1", levels=1)
    (v0,) = f._kink_normal()
    assert abs(float(f.lookup().upper(v0)) - float(f.lookup().upper(1.0))) < 1e-12
    h = 2e-3
    a = pumpup.albedo(f, v0 + h * np.arange(-6, 7), rtol=1e-13)
    d2 = np.diff(a, 2) / h**2
    left, right = d2[:4], d2[-4:]  # the second differences that do not straddle v0
    assert np.ptp(left) < 0.01 and np.ptp(right) < 0.05 and left.min() - right.max() > 0.3, d2
    assert v0 in pumpup.pump({"type": "ggx", "alpha": 0.5}, g="g1",
                             levels=2).base.albedo_kinks(*pumping.grid_interior())
    assert pumpup.pump({"type": "ggx", "alpha": 0.5}, g="g2", levels=1)._kink_normal() == []


def test_two_level_g1_pumped_ward_at_normal_incidence_bounds_its_error():
    """Rough Ward (m = 0.885, found by ``scripts/studies/fuzz_engines.py --two-d``): before its level-2 table was split
    at the level-1 kink v = 0.0605 (u(v) = u(1), above), the table bunched 37 nodes between 0.05 and 0.07 and rounded
    the kink off over 1e-4 in theta_o, and the nested engine was 1.6e-12 off at mu = 1 with an estimate of 8.1e-13 (rtol
    1e-10).  Reference: at normal incidence the albedo is a 1-D integral over theta_o (scipy's quad, split at every
    level's cut)."""
    from scipy.integrate import quad

    f = pumpup.load({"type": "pumped", "base": {"type": "ward", "m": 0.885}, "g": "g1", "levels": 2})
    assert len(f.table().breaks) == 1
    # the compiled bound takes the spline at the first node itself, as AlbedoTable.upper: with the power law there (its
    # margin 24 on 651) level 1's albedo at exactly mu0 = 1e-8 was 3.6 % below its limit, and level 2's table bisected
    # towards its first node (725 nodes, 504 within 1e-9 of 1e-8; 13 s for the two tables, now ~1 s)
    low = f.base.table()
    mu0 = np.array([low.mu[0]])
    assert f.base.lookup().upper(mu0)[0] == low.upper(mu0)[0]
    assert f.table().mu[1] > 2.0 * f.table().mu[0] and len(f.table().mu) < 200
    wi = np.array([0.0, 0.0, 1.0])

    def ring(th):
        return float(f.eval(wi, np.array([np.sin(th), 0.0, np.cos(th)]))) * np.cos(th) * np.sin(th) * 2 * np.pi

    cuts = sorted(np.arccos(u) for u in (*f.lobe(1.0).levels, *f.table_kinks()) if 0 < u < 1)
    ends = [0.0, *cuts, np.pi / 2]
    ref = sum(quad(ring, lo, hi, epsabs=1e-17, epsrel=1e-13, limit=400)[0] for lo, hi in zip(ends[:-1], ends[1:]))
    for rtol in (1e-8, 1e-10, 1e-11):
        a, e = pumpup.albedo(f, 1.0, rtol=rtol, return_error=True)
        assert abs(float(a) - ref) <= float(e) + 1e-13, (rtol, float(a) - ref, float(e))
