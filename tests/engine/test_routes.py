"""The albedo engine's routing table (pumpup/engine/routes.py): printed, and every registered model's examples take the
routes it says, as recorded from the engine's own calls; :func:`~pumpup.engine.routes.using` restores the choice it
changed."""

import helpers
import numpy as np
import pytest

import pumpup
from pumpup.engine import cubature, nested, polar, routes, slope
from pumpup.engine.routes import current, using

MU = np.array([1.0, 0.7, 0.3, 0.2, 0.05, 1e-4])
EXAMPLES = [(name, params) for name, cls in pumpup.registry().items() for params in cls.examples]


def test_the_table_prints_every_route(capsys):
    text = routes.describe()
    print(text)
    for route in routes.ROUTES:
        assert route in text, route
    assert set(r.route for r in routes.RULES) <= set(routes.ONE_D_ROUTES)
    # (a header, slope, lobe_axis, the rules, nested, cubature)
    assert capsys.readouterr().out.count("\n") == len(routes.RULES) + 5


def _recorded(f, mu, monkeypatch, phi=None):
    """The routes pumpup.albedo takes for ``f`` at ``mu``, as (term index, route, sorted mu) from the engine's calls."""
    seen = []
    term = {"i": 0}
    run, integrate, group, slope_albedo, axis = (polar.run, nested.integrate, cubature._integrate_group,
                                                 slope.slope_albedo, polar.axis_albedo)

    def rec(name, values):
        seen.append((term["i"], name, tuple(sorted(np.asarray(values, dtype=float).tolist()))))

    inside_axis = {"on": False}

    def run_recorded(route, hint, m, *a, **k):
        if not inside_axis["on"]:  # (the lobe_axis route runs the lobe route about its axis: recorded as lobe_axis)
            rec(route, m)
        return run(route, hint, m, *a, **k)

    def axis_recorded(n, nu, *a, **k):
        rec("lobe_axis", MU_NOW["mu"])
        inside_axis["on"] = True
        try:
            return axis(n, nu, *a, **k)
        finally:
            inside_axis["on"] = False

    monkeypatch.setattr(polar, "run", run_recorded)
    monkeypatch.setattr(nested, "integrate", lambda t, g, *a, **k: (rec("nested", g.mu), integrate(t, g, *a, **k))[1])
    monkeypatch.setattr(cubature, "_integrate_group",
                        lambda t, g, *a, **k: (rec("cubature", g.mu), group(t, g, *a, **k))[1])
    monkeypatch.setattr(slope, "slope_albedo", lambda t, m, *a, **k: (rec("slope", m), slope_albedo(t, m, *a, **k))[1])
    monkeypatch.setattr(polar, "axis_albedo", axis_recorded)
    out = []
    for i, (_, t) in enumerate(f.albedo_terms()):
        term["i"] = i
        MU_NOW["mu"] = mu
        before = len(seen)
        pumpup.albedo(t, mu, rtol=1e-6, phi=0.0 if phi is None else phi)
        out += seen[before:]
    return sorted(out)


MU_NOW = {"mu": None}


def _planned(f, mu, phi=None):
    out = []
    for i, (_, t) in enumerate(f.albedo_terms()):
        for route, idx, _ in routes.plan(t, mu, phi):
            out.append((i, route, tuple(sorted(mu[idx].tolist()))))
    return sorted(out)


@pytest.mark.parametrize("name,params", EXAMPLES, ids=[f"{n}-{i}" for i, (n, _) in enumerate(EXAMPLES)])
def test_every_example_takes_the_routes_of_the_table(name, params, monkeypatch):
    import warnings

    f = pumpup.load({"type": name, **params})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        got = _recorded(f, MU, monkeypatch)
    # the nested and 2-D engines are called once per lobe group: merge the calls of one route per term
    merged = {}
    for i, route, m in got:
        merged.setdefault((i, route), set()).update(m)
    planned = {}
    for i, route, m in _planned(f, MU):
        planned.setdefault((i, route), set()).update(m)
    assert merged == planned, (name, params)


#: what the table says, written out by hand for the families (one model each, and the operators' factors)
EXPECTED = [
    ({"type": "lambert"}, {"closed"}),
    ({"type": "phong", "n": 20}, {"lobe"}),
    ({"type": "blinn", "n": 20}, {"half"}),
    ({"type": "ward", "m": 0.2}, {"ward"}),
    ({"type": "cook_torrance", "m": 0.3}, {"vcavity"}),
    ({"type": "cook_torrance", "m": 0.3, "ior": 1.5}, {"half_arc"}),
    ({"type": "ggx", "alpha": 0.3}, {"normal"}),
    ({"type": "ggx", "alpha": 0.3, "ior": 1.5}, {"normal", "half_arc"}),
    ({"type": "ggx", "alpha": 1.5}, {"nested"}),
    ({"type": "beckmann", "alpha": 0.3, "g1": "walter", "shadowing": "correlated", "ior": 1.5}, {"nested"}),
    ({"type": "schlick", "r": 0.2}, {"normal"}),
    ({"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}, {"lobe_normal"}),
    ({"type": "metal", "n": 5, "eta": 0.2, "k": 3.0}, {"lobe_fresnel"}),
    ({"type": "metal", "n": 20, "eta": 0.6}, {"nested"}),
    ({"type": "pumped", "base": {"type": "phong", "n": 20}}, {"pumped_lobe"}),
    ({"type": "pumped", "base": {"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}}, {"pumped_lobe"}),
    ({"type": "pumped", "base": {"type": "ggx", "alpha": 0.3}}, {"normal"}),
    ({"type": "pumped", "base": {"type": "ggx", "alpha": 0.3, "ior": 1.5}}, {"normal", "nested"}),
    ({"type": "pumped", "base": {"type": "blinn", "n": 16}}, {"nested"}),
    ({"type": "fresnel", "base": {"type": "ggx", "alpha": 0.3}, "eta": 0.2, "k": 3.0}, {"normal"}),
    ({"type": "fresnel", "base": {"type": "blinn", "n": 20}, "eta": 0.2, "k": 3.0}, {"nested"}),
    ({"type": "scaled", "base": {"type": "ggx", "alpha": 0.3}, "f0": 1.0}, {"normal"}),
    ({"type": "scaled", "base": {"type": "phong", "n": 5}, "f0": 1.0}, {"nested"}),
    ({"type": "ward_aniso", "ax": 0.1, "ay": 0.3}, {"slope"}),
    ({"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rs": 0.5}, {"half_arc"}),
    ({"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rs": 0.5, "rd": 0.5}, {"half_arc", "closed"}),
    ({"type": "ashikhmin_shirley", "nu": 10, "nv": 100, "rs": 0.5}, {"nested"}),
]


@pytest.mark.parametrize("spec,expected", EXPECTED, ids=[str(i) for i in range(len(EXPECTED))])
def test_the_families_routes_written_out(spec, expected):
    f = pumpup.load(spec)
    got = {r for (_, t) in f.albedo_terms() for r, _, _ in routes.plan(t, MU)}
    assert got == expected, (spec, got)


def test_engine_argument_leaves_routes_out():
    f = pumpup.load({"type": "ggx", "alpha": 0.3})
    assert {r for r, _, _ in routes.plan(f, MU, choice=routes.Choice(engine="nested"))} == {"nested"}
    assert {r for r, _, _ in routes.plan(f, MU, choice=routes.Choice(engine="2d"))} == {"cubature"}
    assert {r for r, _, _ in routes.plan(f, MU, choice=routes.Choice(without=frozenset({"normal"})))} == {"half_arc"}
    a = pumpup.albedo(f, MU, rtol=1e-10)
    for engine in ("1d", "nested", "2d"):
        b, e = pumpup.albedo(f, MU, rtol=1e-10, return_error=True, engine=engine)
        assert np.all(np.abs(a - b) <= 1e-10 * a + e), engine
    with pytest.raises(ValueError, match="no 1-D route"):
        pumpup.albedo(pumpup.load({"type": "ggx", "alpha": 1.5}), 0.5, engine="1d")


def test_using_restores_the_choice():
    assert current().engine == "auto" and not current().without
    with pytest.raises(RuntimeError), helpers.two_d_only():
        assert current().engine == "2d"
        with helpers.without_nested():
            assert current().engine == "2d" and current().without == {"nested"}
        assert not current().without
        raise RuntimeError
    assert current().engine == "auto" and not current().without
    with pytest.raises(ValueError, match="engine must be one of"):
        pumpup.albedo(pumpup.load({"type": "phong", "n": 2}), 0.5, engine="3d")
    with pytest.raises(ValueError, match="unknown routes"):
        with using(without={"frame6"}):
            pass
