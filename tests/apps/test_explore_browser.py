"""pumpup explore in a real browser: Debian's chromium, headless, driven by Playwright.

The server runs in a thread of this process on a free port.  Where chromium or Playwright is missing the tests skip,
except under CI=true, where they fail (CI installs both: .ci/run).
"""

from __future__ import annotations

import base64
import json
import os
import shutil
import tempfile
import threading

import numpy as np
import pytest

import pumpup
from pumpup.explore import compute as C

CI = os.environ.get("CI") == "true"
#: chromium's flags: WebGL 2 on the CPU (SwiftShader) where there is no GPU
CHROMIUM_ARGS = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]
#: milliseconds to wait for a page to be drawn (the first computation of a model compiles its kernels when numba's
#: cache is cold)
WAIT_MS = 180_000


def _need(what: str, ok: bool) -> None:
    if not ok:
        if CI:
            pytest.fail(f"{what} is missing, and CI=true: .ci/run must install it")
        pytest.skip(f"{what} is not installed")


@pytest.fixture(scope="module")
def chromium():
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _need("playwright (pip, the test extra)", False)
    for mod in ("starlette", "uvicorn", "plotly"):
        try:
            __import__(mod)
        except ImportError:
            _need(f"{mod} (the explore extra)", False)
    exe = shutil.which("chromium")
    _need("chromium (apt)", exe is not None)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=exe, args=CHROMIUM_ARGS)
        context = browser.new_context(viewport={"width": 1400, "height": 1000})
        yield context
        browser.close()


@pytest.fixture(scope="module")
def server():
    from pumpup import explore

    C.compute({"specs": ["phong:n=20"], "kulla_conty": True})  # numba's kernels, compiled before the clock runs
    stop, urls = threading.Event(), []
    ready = threading.Event()
    t = threading.Thread(target=explore.serve, kwargs=dict(
        specs=["phong:n=20"], port=0, open_browser=False, stop=stop,
        ready=lambda u: (urls.append(u), ready.set())), daemon=True)
    t.start()
    assert ready.wait(60), "the server did not start"
    yield urls[0]
    stop.set()
    t.join(10)


@pytest.fixture(autouse=True)
def close_tabs(request):
    yield
    if "chromium" in request.fixturenames:
        for page in request.getfixturevalue("chromium").pages:
            page.close()


class Page:
    """A tab, its console errors, and a wait for its next drawing."""

    def __init__(self, context, url: str, wait: bool = True):
        self.page = context.new_page()
        self.errors: list[str] = []
        self.page.on("console", lambda m: self.errors.append(m.text) if m.type == "error" else None)
        self.page.on("pageerror", lambda e: self.errors.append(str(e)))
        self.page.goto(url, wait_until="commit")
        if wait:
            self.ready()

    def ready(self) -> Page:
        self.page.wait_for_function("window.explore && window.explore.ready", timeout=WAIT_MS)
        return self

    def drawn(self) -> int:
        return self.page.evaluate("window.explore.drawn")

    def wait_answer(self) -> None:
        """Wait until the answer to the newest request is drawn (or shown as an error)."""
        self.page.wait_for_function("window.explore.drawnId === window.explore.sent", timeout=WAIT_MS)

    def slide(self, selector: str, value) -> None:
        self.page.evaluate("([s, v]) => { const e = document.querySelector(s); e.value = v; "
                           "e.dispatchEvent(new Event('input', {bubbles: true})); }", [selector, value])

    def result(self) -> dict:
        return self.page.evaluate("window.explore.result")

    def cell(self, row: int, cls: str) -> float:
        return float(self.page.get_attribute(f"#numbers tbody tr[data-row='{row}'] td.{cls}", "data-value"))


def test_slider_shows_pumpups_numbers(chromium, server):
    p = Page(chromium, server + "?s=phong:n=20&ti=30")
    check_furnace(p)
    p.slide("#param-n", 700)
    p.wait_answer()
    r = p.result()
    spec = r["models"][0]["input"]
    assert spec["type"] == "phong" and spec["n"] != 20 and set(spec) == {"type", "n"}
    f = pumpup.load(spec)
    assert p.cell(0, "mean-albedo") == pumpup.mean_albedo(f)
    c, theta = pumpup.max_constant(f)
    assert p.cell(0, "max-constant") == c
    alb = r["models"][0]["albedo"]
    a, err = pumpup.albedo(f, np.asarray(alb["mu"]), return_error=True)
    np.testing.assert_array_equal(alb["a"], a)
    np.testing.assert_array_equal(alb["err"], err)
    # the field beside the slider shows the value sent, and the URL carries it
    assert float(p.page.input_value("#field-n")) == spec["n"]
    assert f"n%3D{spec['n']:g}" in p.page.url or f"n={spec['n']:g}" in p.page.url
    # the incidence slider moves the lobe: the page's lobe is f cos at the new angle
    p.slide("#theta-i", 60)
    p.wait_answer()
    lobe = p.result()["models"][0]["lobe"]
    np.testing.assert_array_equal(lobe["value"], C.lobe_curve(f, 60.0)["value"])
    # a newer slider value supersedes the one still being computed: the last one is drawn
    n0 = p.drawn()
    p.page.evaluate("""() => { const e = document.querySelector('#theta-i');
        for (const v of [11, 22, 33, 44, 55]) { e.value = v; e.dispatchEvent(new Event('input')); } }""")
    p.wait_answer()
    assert p.result()["state"]["theta_i"] == 55
    assert p.drawn() - n0 <= 5  # older answers are dropped (cancelled on the server or ignored by the page)
    assert p.errors == []


def test_bad_input_shows_one_message_and_the_server_keeps_serving(chromium, server):
    p = Page(chromium, server + "?s=lambert:albedo=0.5&3d=1")
    assert p.page.is_visible("#lobe3d-view")  # the 3-D lobe, drawn without a console error
    p.page.fill("#spec-text", "phong:n=-5")
    p.page.press("#spec-text", "Enter")
    p.wait_answer()
    msg = p.page.text_content("#message")
    assert p.page.is_visible("#message") and "'n' = -5 is outside its allowed range [0, 1e+06]" in msg
    assert "\n" not in msg.strip()
    # the views keep the last good state: a slider move after the error computes lambert again
    p.slide("#theta-i", 40)
    p.wait_answer()
    assert not p.page.is_visible("#message") and p.result()["models"][0]["input"] == {"type": "lambert", "albedo": 0.5}
    for bad in ("function:name=x", "/etc/passwd", '{"type": "ggx", "alpha": "x"}'):
        p.page.fill("#spec-text", bad)
        p.page.press("#spec-text", "Enter")
        p.wait_answer()
        assert p.page.is_visible("#message"), bad
    # a malformed message on the socket is answered, not fatal
    answer = p.page.evaluate("""() => new Promise((ok) => {
        const ws = new WebSocket(`ws://${location.host}/ws`);
        ws.onopen = () => ws.send("not json");
        ws.onmessage = (e) => { ok(JSON.parse(e.data)); ws.close(); };
    })""")
    assert answer["ok"] is False and "bad message" in answer["error"]
    p.page.fill("#spec-text", "ggx:alpha=0.2")
    p.page.press("#spec-text", "Enter")
    p.wait_answer()
    assert not p.page.is_visible("#message")
    assert p.result()["models"][0]["input"] == {"type": "ggx", "alpha": 0.2}
    page = p.page.request.get(server)  # and the server still serves new pages
    assert page.ok and "pumpup explore" in page.text()
    assert p.errors == []


def test_ten_tabs_do_not_share_state(chromium, server):
    tabs = [Page(chromium, server + f"?s=phong:n={k + 1}&ti={10 + k}", wait=False) for k in range(10)]
    for t in tabs:  # the ten tabs load at once
        t.ready()
    for k, t in enumerate(tabs):
        r = t.result()
        assert r["models"][0]["input"]["n"] == k + 1 and r["state"]["theta_i"] == 10 + k
    before = [t.drawn() for t in tabs]
    tabs[3].slide("#theta-i", 75)
    tabs[3].slide("#param-n", 500)
    tabs[3].wait_answer()
    for k, t in enumerate(tabs):
        r = t.result()
        if k == 3:
            assert r["state"]["theta_i"] == 75 and r["models"][0]["input"]["n"] != 4
        else:
            assert t.drawn() == before[k]
            assert r["models"][0]["input"]["n"] == k + 1 and r["state"]["theta_i"] == 10 + k
        assert t.errors == []
        t.page.close()


def test_compare_shares_axes_and_downloads(chromium, server):
    p = Page(chromium, server + "?s=phong:n=20&s=stretched_phong:n=20&s=ggx:alpha=0.3&kc=1")
    r = p.result()
    assert [m["input"]["type"] for m in r["models"]] == ["phong", "stretched_phong", "ggx"]
    assert p.page.locator("#spheres .sphere-pair").count() == 3
    # the three image slices share one colour axis: each panel's pixels are its values on the scale from 0 to the
    # largest value of all three, which the colour bar shows (a panel on a scale of its own would reach the top
    # colour at its own maximum, which is below half the shared one for at least one of them)
    datas = [np.frombuffer(base64.b64decode(m["slice"]["data"]), "<f8") for m in r["models"]]
    top = max(float(d.max()) for d in datas)
    assert min(float(d.max()) for d in datas) < 0.5 * top
    assert float(p.page.get_attribute("#slice-scale", "data-cmax")) == top
    assert float(p.page.get_attribute("#slice-scale", "data-cmin")) == 0.0
    for i, d in enumerate(datas):
        n = r["models"][i]["slice"]["n"]
        px = np.array(p.page.evaluate(f"""() => Array.from(document.getElementById('slice-{i}').getContext('2d')
            .getImageData(0, 0, {n}, {n}).data)""")).reshape(n, n, 4)[::-1]  # canvas rows from the top: theta_d up
        want = p.page.evaluate("([v, top]) => v.map((x) => window.explore.viridis(x, 0, top))", [d.tolist(), top])
        np.testing.assert_array_equal(px[..., :3].reshape(-1, 3), np.array(want), err_msg=f"panel {i}")
        assert (px[..., 3] == 255).all()
    spec = json.dumps({"type": "ggx", "alpha": 0.3})
    got = p.page.request.get(server + "download/spec.json", params={"spec": spec})
    assert got.ok and json.loads(got.body()) == pumpup.load(spec).spec
    got = p.page.request.get(server + "download/mitsuba.json", params={"spec": spec})
    assert got.ok and json.loads(json.loads(got.body())["spec"]) == pumpup.load(spec).spec
    got = p.page.request.get(server + "download/albedo.nc", params={"spec": spec})
    assert got.ok and "albedo.nc" in got.headers["content-disposition"]
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "a.nc")
        with open(path, "wb") as fh:
            fh.write(got.body())
        ds = pumpup.open_table(path)
        ref = pumpup.tabulate(pumpup.load(spec), progress=False)
        np.testing.assert_array_equal(ds["albedo"].values, ref["albedo"].values)
    bad = p.page.request.get(server + "download/albedo.nc", params={"spec": "function:name=x"})
    assert bad.status == 400 and "wraps Python code" in bad.text()
    import importlib.util

    if importlib.util.find_spec("pumpup.shaders") is not None:
        from pumpup import shaders

        for kind, target in (("shader.glsl", "glsl-es"), ("shader.brdf", "brdf-explorer")):
            got = p.page.request.get(server + "download/" + kind, params={"spec": spec})
            assert got.ok and got.text() == shaders.shader(pumpup.load(spec).spec, target=target), kind
    got = p.page.request.get(server + "download/lut", params={"spec": spec, "preset": "cycles"}, timeout=120_000)
    assert got.ok and "table_ggx_E" in got.text()
    from pumpup import luts

    with tempfile.TemporaryDirectory() as tmp:  # the same file as pumpup.lut("ggx", preset="cycles") writes
        with open(luts.write_lut(pumpup.lut("ggx", preset="cycles"), os.path.join(tmp, "t.h"))) as fh:
            assert got.text() == fh.read()
    bad = p.page.request.get(server + "download/lut", params={"spec": "phong:n=2", "preset": "cycles"})
    assert bad.status == 400 and "roughness" in bad.text()
    # a request naming another host (a page elsewhere reaching this one through DNS) is refused
    foreign = p.page.request.get(server + "api/models", headers={"Host": "attacker.example"})
    assert foreign.status == 400
    assert p.errors == []


def check_furnace(p: Page) -> None:
    """The furnace sphere of phong:n=20 on the page is pumpup.render.furnace's image, tone-mapped as pumpup does."""
    m = p.result()["models"][0]
    g = pumpup.render.geometry(C.FURNACE_SIZE)
    got = np.frombuffer(base64.b64decode(m["furnace"]["data"]), "<f8").reshape(g.mask.shape)
    np.testing.assert_array_equal(got[g.mask], pumpup.albedo(pumpup.load("phong:n=20"), g.view[:, 2]))
    # the canvas shows them with pumpup.render's tone map (exposure 0)
    k = C.FURNACE_SIZE // 2
    for i, j in ((k, k), (k, 3), (5, k), (0, 0)):
        pixel = p.page.evaluate(f"""() => Array.from(document.getElementById('furnace-0').getContext('2d')
            .getImageData({j}, {i}, 1, 1).data)""")
        expect = np.round(pumpup.render.srgb(got[i, j]) * 255) if g.mask[i, j] else None
        assert pixel[:3] == ([expect] * 3 if expect is not None else
                             [round(c * 255) for c in pumpup.render.BACKGROUND]), (i, j)


#: float32's machine epsilon
EPS32 = float(np.finfo(np.float32).eps)


def sphere_pixels(p: Page, spec: str, size: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """The lit sphere of ``spec`` read back from WebGL (float32 target) and pumpup.render.sphere's image."""
    p.page.fill("#spec-text", spec)
    p.page.press("#spec-text", "Enter")
    p.wait_answer()
    m = p.result()["models"][0]
    assert m["shader"] and "glsl" in m["shader"], m["shader"]
    got = np.array(p.page.evaluate(f"window.explore.sphereRadiance(0, {size})")).reshape(size, size)
    ref = pumpup.render.sphere(spec, light_deg=30, azimuth_deg=20, size=size).radiance
    return got, ref


def need_shaders() -> None:
    import importlib.util

    if importlib.util.find_spec("pumpup.shaders") is None:
        pytest.skip("this pumpup has no shader export (pumpup.shader); the page shows pumpup.render.sphere instead")


def test_lit_sphere_pixels_match_eval(chromium, server):
    need_shaders()
    p = Page(chromium, server + "?s=lambert&light=30&laz=20")
    assert p.page.text_content("#sphere-source") == "(WebGL 2, pumpup.shader GLSL)"
    check_sphere(p, (("phong:n=20", 20),))
    assert p.errors == []


@pytest.mark.slow
def test_lit_sphere_pixels_match_eval_more_models(chromium, server):
    need_shaders()
    p = Page(chromium, server + "?s=lambert&light=30&laz=20")
    check_sphere(p, (("ggx:alpha=0.3", 1), ("lambert:albedo=0.5", 1), ("stretched_phong:n=100", 100)))
    # a pumped chain: the shader rounds down by its own float32 bound, so its value is never above pumpup's
    got, ref = sphere_pixels(p, json.dumps({"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2",
                                            "levels": 2}))
    bright = ref > 0.1 * ref.max()
    assert np.all(got <= ref * (1 + EPS32)) and np.all(got[bright] >= ref[bright] * (1 - 1e-3))
    assert p.errors == []


def check_sphere(p: Page, cases) -> None:
    """WebGL's lit sphere equals pumpup.render.sphere to float32 rounding for each (spec, lobe exponent)."""
    for spec, n in cases:
        got, ref = sphere_pixels(p, spec)
        # float32 rounding: the pixel's frame and the light in float32 (a few ulps of each cosine), amplified by the
        # lobe's exponent n; relative to the image's peak (near the terminator N.L cancels) and, on the bright part,
        # to the pixel itself
        peak = ref.max()
        assert np.all(np.abs(got - ref) <= 8 * EPS32 * (1 + n) * peak), (spec, np.abs(got - ref).max() / peak)
        bright = ref > 0.1 * peak
        rel = np.abs(got - ref)[bright] / ref[bright]
        assert rel.max() <= 8 * EPS32 * (1 + n), (spec, rel.max())
