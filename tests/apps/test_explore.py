"""pumpup.explore without a browser: the views equal pumpup's API, bad input is refused, the CLI checks arguments."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import threading

import numpy as np
import pytest

import pumpup
from pumpup.core import SpecError
from pumpup.explore import compute as C

PHONG = {"type": "phong", "n": 20}


def test_views_equal_pumpups_api():
    r = C.compute({"specs": ["phong:n=20"], "theta_i": 40.0, "pump": {"on": True, "g": "g2", "levels": 2},
                   "kulla_conty": True})
    m = r["models"][0]
    f = pumpup.load(PHONG)
    mu = np.asarray(m["albedo"]["mu"])
    a, err = pumpup.albedo(f, mu, return_error=True)
    np.testing.assert_array_equal(m["albedo"]["a"], a)
    np.testing.assert_array_equal(m["albedo"]["err"], err)
    assert m["mean_albedo"] == pumpup.mean_albedo(f)
    c, theta = pumpup.max_constant(f)
    assert m["max_constant"] == {"name": "c", "value": c, "theta": theta}
    # the lobe: f_r(wi, wo) cos(theta_o) in the plane of incidence, the mirror direction at +theta_i
    t = np.radians(np.asarray(m["lobe"]["theta_o"]))
    wo = np.stack([-np.sin(t), np.zeros_like(t), np.cos(t)], axis=-1)
    wi = np.array([math.sin(math.radians(40.0)), 0.0, math.cos(math.radians(40.0))])
    np.testing.assert_array_equal(m["lobe"]["value"], f.eval(wi, wo) * np.cos(t))
    k = int(np.argmax(np.asarray(m["lobe"]["value"]) / np.cos(t)))
    assert m["lobe"]["theta_o"][k] == 40.0  # f_r of Phong peaks at the mirror direction, a point of the curve
    # the overlays are pumpup.pump and pumpup.compensate of the same model
    g = pumpup.pump(f, g="g2", levels=2)
    np.testing.assert_array_equal(m["overlays"]["pumped"]["albedo"]["a"], pumpup.albedo(g, mu))
    kc = pumpup.compensate(f, method="kulla_conty")
    assert m["overlays"]["kulla_conty"]["mean_albedo"] == pumpup.mean_albedo(kc)
    # the furnace image: pumpup.albedo at every pixel's mu_V, within pumpup.render.furnace's bound of its image
    g = pumpup.render.geometry(C.FURNACE_SIZE)
    got = np.frombuffer(__import__("base64").b64decode(m["furnace"]["data"]), "<f8").reshape(g.mask.shape)
    a_px, err_px = pumpup.albedo(f, g.view[:, 2], return_error=True)
    np.testing.assert_array_equal(got[g.mask], a_px)
    assert not got[~g.mask].any() and m["furnace"]["bound"] == err_px.max()
    im = pumpup.render.furnace(f, size=C.FURNACE_SIZE)
    assert np.abs(got - im.radiance).max() <= im.error + err_px.max()
    json.dumps(r, allow_nan=False)  # what the server sends


def test_furnace_of_a_non_reciprocal_model_is_pumpups_furnace():
    f = pumpup.compensate(pumpup.load("lambert:albedo=0.5"), method="scale")
    assert not f.reciprocal
    m = C.furnace_image(f)
    im = pumpup.render.furnace(f, size=C.FURNACE_SIZE)
    assert m["method"] == "pumpup.render.furnace" and m["bound"] == im.error
    np.testing.assert_array_equal(np.frombuffer(__import__("base64").b64decode(m["data"]), "<f8"), im.radiance.ravel())
    with pytest.raises(SpecError, match="anisotropic"):
        C.furnace_image(pumpup.load("ward_aniso:ax=0.1,ay=0.3"))


def test_above_one_is_where_albedo_minus_error_exceeds_one():
    r = C.compute({"specs": ['{"type": "phong", "n": 20, "c": 6}']})
    alb = r["models"][0]["albedo"]
    a, e, th = map(np.asarray, (alb["a"], alb["err"], alb["theta"]))
    over = th[a - e > 1]
    assert over.size and alb["above_one"][0][0] == over.min() and alb["above_one"][-1][1] == over.max()
    assert C.compute({"specs": ["lambert:albedo=0.5"]})["models"][0]["albedo"]["above_one"] == []


def test_slice_is_fr_at_rusinkiewicz_angles():
    f = pumpup.load("ward:m=0.2")
    s = C.slice_image(f, n=8)
    img = np.frombuffer(__import__("base64").b64decode(s["data"]), "<f8").reshape(8, 8)
    th, td = math.radians(s["axis"][3]), math.radians(s["axis"][5])
    h = np.array([math.sin(th), 0.0, math.cos(th)])
    # wi, wo: mirror images of each other about h, at theta_d from it, phi_d = 90 degrees (perpendicular to the
    # plane of h and N)
    y = np.array([0.0, 1.0, 0.0])
    wi = math.cos(td) * h + math.sin(td) * y
    wo = math.cos(td) * h - math.sin(td) * y
    assert img[5, 3] == pytest.approx(float(f.eval(wi, wo)), rel=1e-12)


@pytest.mark.parametrize("spec, words", [
    ("function:name=x", "wraps Python code"),
    ('{"type": "pumped", "base": {"type": "function", "name": "f"}}', "wraps Python code"),
    ("/etc/passwd", "unknown model type"),
    ('{"type": "metal", "material": "Au", "n": 20}', "spectral"),
    ("phong:n=-1", "outside its allowed range"),
    ("phong:n=" + "1" * 5000, "at most"),
    ("", "empty"),
    ('{"type": "phong", "n": 20', "not valid JSON"),
])
def test_only_registry_specs_are_accepted(spec, words):
    with pytest.raises(SpecError, match=words):
        C.compute({"specs": [spec]})


@pytest.mark.parametrize("state, words", [
    ({"specs": []}, "1 to 4"),
    ({"specs": ["phong:n=1"] * 5}, "1 to 4"),
    ({"specs": ["phong:n=1"], "theta_i": 95}, "theta_i"),
    ({"specs": ["phong:n=1"], "theta_i": "x"}, "theta_i"),
    ({"specs": ["phong:n=1"], "pump": {"on": True, "levels": 6}}, "levels"),
    ({"specs": ["phong:n=1"], "pump": {"on": True, "g": "g3"}}, "g1"),
    ({"specs": ["phong:n=1", "phong:n=-2"]}, "model 2"),
])
def test_bad_state_names_the_entry(state, words):
    with pytest.raises(SpecError, match=words):
        C.compute(state)


def test_a_newer_request_cancels_and_a_deadline_stops():
    with pytest.raises(C.Cancelled):
        C.compute({"specs": ["phong:n=3"]}, cancel=lambda: True)
    with pytest.raises(C.TimeLimit):
        C.compute({"specs": ["phong:n=3"]}, deadline=0.0)
    # a heavy request (a 5-level pumping of a new model) stops soon after its time limit
    import time

    t0 = time.monotonic()
    with pytest.raises(C.TimeLimit, match="time limit"):
        C.compute({"specs": ["stretched_phong:n=37.25"], "pump": {"on": True, "g": "g2", "levels": 5}},
                  deadline=t0 + 0.05)
    assert time.monotonic() - t0 < 5.0


def test_catalog_has_registry_ranges_and_log_sliders():
    cat = {m["type"]: m for m in C.model_catalog()}
    assert "function" not in cat and set(cat) <= set(pumpup.registry())
    n = next(p for p in cat["phong"]["params"] if p["name"] == "n")
    assert n["slider"]["log"] and n["range"] == pumpup.registry()["phong"].params["n"].range_text()
    alpha = next(p for p in cat["ggx"]["params"] if p["name"] == "alpha")
    assert alpha["slider"]["log"] and alpha["slider"]["lo"] >= pumpup.registry()["ggx"].params["alpha"].lo
    albedo = next(p for p in cat["lambert"]["params"] if p["name"] == "albedo")
    assert not albedo["slider"]["log"] and (albedo["slider"]["lo"], albedo["slider"]["hi"]) == (0.0, 1.0)
    for m in cat.values():
        pumpup.load(m["example"])


def run_cli(*args, timeout=60):
    return subprocess.run([sys.executable, "-m", "pumpup.cli", "explore", *args], capture_output=True, text=True,
                          timeout=timeout)


@pytest.mark.parametrize("args, words", [
    (["phong:n=-1", "--no-browser"], "outside its allowed range"),
    (["--port", "70000", "--no-browser"], "--port"),
    (["--time-limit", "0", "--no-browser"], "--time-limit"),
    (["a", "b", "c", "d", "e", "--no-browser"], "at most 4"),
])
def test_cli_refuses_bad_arguments_with_one_line(args, words):
    pytest.importorskip("starlette")
    r = run_cli(*args)
    assert r.returncode == 2 and words in r.stderr and len(r.stderr.strip().splitlines()) == 1, r.stderr


def test_another_host_warns_in_one_line(capsys):
    pytest.importorskip("uvicorn")
    from pumpup import explore

    stop = threading.Event()
    urls = []
    explore.serve(["lambert"], host="0.0.0.0", port=0, open_browser=False, stop=stop,
                  ready=lambda u: (urls.append(u), stop.set()))
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "warning" in err[0] and "0.0.0.0" in err[0]
    assert urls and urls[0].startswith("http://0.0.0.0:")


def test_default_host_is_local_and_silent(capsys):
    pytest.importorskip("uvicorn")
    import inspect

    from pumpup import explore

    assert inspect.signature(explore.serve).parameters["host"].default == "127.0.0.1"
    stop = threading.Event()
    explore.serve(None, port=0, open_browser=False, stop=stop, ready=lambda u: stop.set())
    assert capsys.readouterr().err == ""


def test_the_lines_shown_reproduce_the_view(tmp_path, monkeypatch, capsys):
    import shlex

    from pumpup import cli

    r = C.compute({"specs": ["phong:n=20"], "theta_i": 50, "pump": {"on": True, "g": "g2", "levels": 2}})
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(r["lines"]["python"], scope)  # the Python lines run as shown
    assert scope["f"] == pumpup.load(PHONG) and scope["p"] == pumpup.pump(PHONG, g="g2", levels=2)
    for line in r["lines"]["cli"].splitlines():
        args = shlex.split(line)
        assert args[0] == "pumpup"
        if args[1] != "explore":
            assert cli.main(args[1:]) in (0, None), line
    assert "50.0" in capsys.readouterr().out  # pumpup albedo ... --theta 50


def test_pumpups_warnings_reach_the_page():
    m = C.compute({"specs": ["ward:m=0.05"]})["models"][0]
    assert m["max_constant"]["value"] == 0.0
    assert any("unbounded" in note for note in m["notes"]), m["notes"]


def test_lobe_surface_is_f_cos_over_the_hemisphere():
    f = pumpup.load("ward:m=0.2")
    r = C.compute({"specs": ["ward:m=0.2"], "theta_i": 35.0, "lobe3d": True})["models"][0]["lobe3d"]
    v = np.frombuffer(__import__("base64").b64decode(r["data"]), "<f8").reshape(len(r["theta"]), len(r["phi"]))
    t, p = np.radians(r["theta"][7]), np.radians(r["phi"][40])
    wo = np.array([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])
    wi = np.array([np.sin(np.radians(35.0)), 0.0, np.cos(np.radians(35.0))])
    assert v[7, 40] == float(f.eval(wi, wo)) * np.cos(t)
    assert "lobe3d" not in C.compute({"specs": ["ward:m=0.2"]})["models"][0]


def test_first_answer_imports_neither_scipy_linalg_nor_scipy_optimize():
    """The server's first answer loads numba's registries without scipy.linalg (load_numba_registries) and computes
    max_constant without scipy.optimize; afterwards a kernel that calls BLAS still compiles and runs, through the real
    scipy.linalg.cython_blas."""
    pytest.importorskip("starlette")
    code = """
import sys
from pumpup.explore import compute as C, server
server.load_numba_registries()
r = C.compute({"specs": ["phong:n=20"]})
assert r["models"][0]["max_constant"]["value"] > 0
print([m for m in ("scipy.linalg", "scipy.optimize") if m in sys.modules])
import numba, numpy as np
dot = numba.njit(lambda a, b: np.dot(a, b))
print(dot(np.arange(3.0), np.arange(3.0)), hasattr(sys.modules["scipy.linalg.cython_blas"], "__pyx_capi__"))
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split("\n")[:2] == ["[]", "5.0 True"], r.stdout
