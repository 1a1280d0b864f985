"""The numbers the documentation quotes come from the code or from generated files (docs/_ext/pumpup_numbers.py).

Fast checks: every ``{pumpup-value}`` key and ``{pumpup-table}`` name a page uses is registered; every registered
table is generated from its stored file and is a Markdown table; every fast value computes; every number typed in
a page or the README that ``QUOTES`` lists is still there, word for word, and equals its fresh computation rounded
to the digits it is printed with.  Values and quotes marked slow (more than a few seconds) run under ``-m slow``.
"""

import importlib.util
import math
import os
import re
import sys

import helpers
import numpy as np
import pytest

ROOT = str(helpers.ROOT)
DOCS = os.path.join(ROOT, "docs")
sys.path.insert(0, os.path.join(DOCS, "_ext"))
import pumpup_numbers as N  # noqa: E402

#: a number as the pages print it: 0.0642, 1e-8, 3.2e-7, 670,000 is not one (no thousands separators are checked)
NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?:e[+-]?\d+)?(?!\w|\.\d)")


def _pages() -> list[str]:
    out = []
    for folder, dirs, files in os.walk(DOCS):
        dirs[:] = [d for d in dirs if d not in ("_build", "gallery", "generated")]
        out += [os.path.join(folder, f) for f in files if f.endswith(".md")]
    return sorted(out)


def _used(pattern: str) -> dict[str, list[str]]:
    used: dict[str, list[str]] = {}
    for path in _pages():
        text = re.sub(r"(`{2,}).*?\1", "", open(path).read())  # inline code spans show the syntax, literally
        for key in re.findall(pattern, text):
            used.setdefault(key, []).append(os.path.relpath(path, ROOT))
    return used


def test_every_value_and_table_a_page_uses_is_registered():
    values = _used(r"\{pumpup-value\}`([^`]+)`")
    tables = _used(r"```\{pumpup-table\}\s+(\S+)")
    assert values and tables, "no page uses the role or the directive: the pattern is wrong"
    assert not {k: v for k, v in values.items() if k not in N.VALUES}
    assert not {k: v for k, v in tables.items() if k not in N.TABLES}
    unused = set(N.VALUES) - set(values)
    assert not unused, f"registered but quoted nowhere: {sorted(unused)}"


@pytest.mark.parametrize("name", sorted(N.TABLES))
def test_generated_tables_come_from_the_stored_files(name):
    text = N.TABLES[name]()
    blocks = re.findall(r"(?:^\|.*\n?)+", text, re.M)  # each run of table rows
    assert blocks, text[:300]
    for block in blocks:
        rows = block.strip().splitlines()
        cells = [len(re.findall(r"(?<!\\)\|", ln)) for ln in rows]
        assert len(rows) >= 3 and re.match(r"^\|(---\|)+$", rows[1]), block[:300]
        assert len(set(cells)) == 1, block[:300]


def test_fitting_table_is_the_scripts_own_output():
    """The page's table is what ``fitting_study.py --table`` prints from the same records."""
    fs = N._script("fitting_study")
    recs = list(N.fitting_records())
    sub = [r for r in recs if abs(r["mu_min"] - 0.05) < 1e-9 and not r.get("plausible", False)]
    assert fs.table(sub) in N.TABLES["fitting-study"]()
    assert "ggx a=0.1 F=1 | 0.992 / 0.906" in N.TABLES["fitting-study"]()  # a cell the study recorded


@pytest.mark.parametrize("key", sorted(k for k, v in N.VALUES.items() if not v.slow))
def test_fast_values_compute(key):
    text = N.VALUES[key].text()
    assert text and "nan" not in text and "inf" not in text


@pytest.mark.slow
@pytest.mark.parametrize("key", sorted(k for k, v in N.VALUES.items() if v.slow) or ["none"])
def test_slow_values_compute(key):
    if key == "none":
        pytest.skip("no slow value is registered")
    assert N.VALUES[key].text()


def _check_quote(q: N.Quote):
    text = open(os.path.join(ROOT, q.page)).read()
    assert q.text in text, f"{q.page} no longer says {q.text!r}: update docs/_ext/pumpup_numbers.py"
    typed = NUMBER.findall(q.text)
    fresh = q.compute()
    fresh = [float(x) for x in (fresh if isinstance(fresh, (tuple, list)) else np.ravel(fresh))]
    assert len(typed) == len(fresh), (typed, fresh)
    for t, f in zip(typed, fresh):
        value = float(t)
        if "e" in t.lower():  # scientific: half a unit of the last shown significant digit
            mantissa = t.lower().split("e")[0]
            digits = len(mantissa.split(".")[1]) if "." in mantissa else 0
            half = 0.5 * 10.0 ** (math.floor(math.log10(abs(value))) - digits) if value else 0.5
        else:
            digits = len(t.split(".")[1]) if "." in t else 0
            half = 0.5 * 10.0 ** -digits
        tol = half * (1 + 1e-9) + q.rtol * abs(f)
        assert abs(f - value) <= tol, f"{q.page}: {t} typed, {f!r} computed (tolerance {tol:g}) in {q.text!r}"


FAST = [q for q in N.QUOTES if not q.slow]
SLOW = [q for q in N.QUOTES if q.slow]


@pytest.mark.parametrize("q", FAST, ids=[f"{q.page}:{q.text[:30]}" for q in FAST])
def test_typed_numbers_match_a_fresh_computation(q):
    _check_quote(q)


@pytest.mark.slow
@pytest.mark.parametrize("q", SLOW, ids=[f"{q.page}:{q.text[:30]}" for q in SLOW])
def test_typed_numbers_match_a_fresh_computation_slow(q):
    _check_quote(q)


def test_the_check_rejects_a_wrong_number():
    q = N.Quote("README.md", "| 3.8 | 3.7098", lambda: (3.8, 3.7093))
    with pytest.raises(AssertionError, match="3.7098 typed"):
        _check_quote(q)


@pytest.mark.slow
def test_the_stored_warp_search_is_what_the_code_finds():
    """``tables/lut_warps.json`` (the renderer-tables page's warp table) is what ``scripts/make/lut_warps.py``
    computes now: the same candidates, their worst look-up errors to 1e-6 relative."""
    fresh = N._script("lut_warps").run()
    stored = N.lut_warps()
    assert [d["mu_min"] for d in fresh["domains"]] == [d["mu_min"] for d in stored["domains"]]
    for f, s in zip(fresh["domains"], stored["domains"]):
        assert [(c["p"], c["q"]) for c in f["candidates"]] == [(c["p"], c["q"]) for c in s["candidates"]]
        np.testing.assert_allclose([c["max_abs"] for c in f["candidates"]], [c["max_abs"] for c in s["candidates"]],
                                   rtol=1e-6)


#: the generated sections of docs/user-guide/renderer-tables.md (scripts/studies/renderer_tables_doc.py); the
#: audit and the energy study take seconds, so they run under -m slow
_RT_SECTIONS = [("presets", False), ("furnace", False), ("cycles-audit", True), ("energy", True)]


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if slow else n for n, slow in _RT_SECTIONS])
def test_renderer_tables_sections_are_what_the_script_writes(name):
    """Each ``<!-- generated:NAME -->`` section of the renderer-tables page is what ``renderer_tables_doc.py``
    writes now (the furnace section: the summary ``furnace_cycles.py`` stored beside the page)."""
    doc = N._script("renderer_tables_doc", "studies")
    text = open(doc.PAGE).read()
    body = {"presets": doc.presets_section, "furnace": lambda: doc.furnace_section(doc.PAGE),
            "cycles-audit": doc.audit_section, "energy": doc.energy_section}[name]()
    assert body is not None, f"{name}: nothing to compare with"
    assert doc.replace(text, name, body) == text, \
        f"the {name} section of {doc.PAGE} is stale: run python scripts/studies/renderer_tables_doc.py --only {name}"


@pytest.mark.slow
@pytest.mark.parametrize("script, stored", [("he_torrance_fig5", "he_torrance_fig5.json"),
                                            ("metal_colours", "metal_colours.json"),
                                            ("pumped_colours", "pumped_colours.json"),
                                            ("mitsuba_measurements", "mitsuba_measurements.json")])
def test_the_stored_study_is_what_the_code_computes(script, stored):
    """The stored results the He-Torrance, spectral and Mitsuba pages' tables are generated from are what their
    scripts compute now (a minute or a few each): the same tables, to the digits they print.  The Mitsuba
    measurements need the render extra (skipped without it, except in CI) and run in the variant stored."""
    module = N._script(script)
    data = N._json(stored)
    if script == "mitsuba_measurements":
        if importlib.util.find_spec("mitsuba") is None:
            if os.environ.get("CI") == "true":
                pytest.fail("mitsuba is not installed: CI must install the render extra")
            pytest.skip("mitsuba is not installed (pip install -e '.[render]')")
        fresh = module.run(variant=data["variant"])
        assert fresh["variant"] == data["variant"], f"{data['variant']} is not usable here: {fresh['variant']} ran"
        for key in ("default_count", "fine_count"):  # the chi-square cell the page quotes, to the digits it prints
            assert round(fresh["chi2_horizon"][key]) == round(data["chi2_horizon"][key])
        assert fresh["chi2_horizon"]["passes"] == data["chi2_horizon"]["passes"]
    else:
        fresh = module.run()
    assert module.markdown(fresh) == module.markdown(data)
