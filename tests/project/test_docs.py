"""The documentation site (docs/) covers the package and builds clean.

Fast checks: every public name of ``pumpup.__all__`` appears in the API reference, every module with an ``__all__``
has a reference page that lists each of its names, every subcommand and option of the command line appears in the
generated CLI reference, and the user guide picks up every page of docs/user-guide/.  (The code blocks of the
pages run in tests/project/test_readme.py.)

The slow check builds the site as CI does (``sphinx -W``: warnings are errors; the gallery runs), checks every
internal link, anchor and image of the built HTML, and loads every page in headless Chromium (Debian's
``chromium``, driven by Playwright) asserting no console error and no image that failed to load.
"""

import argparse
import html.parser
import importlib
import os
import pkgutil
import re
import shutil
import subprocess
import sys
import urllib.parse

import helpers
import pytest

import pumpup

ROOT = str(helpers.ROOT)
DOCS = os.path.join(ROOT, "docs")
sys.path.insert(0, os.path.join(DOCS, "_ext"))
import pumpup_docs  # noqa: E402


def test_api_reference_lists_every_public_name():
    text = open(os.path.join(DOCS, "reference", "api.rst")).read()
    listed = set(re.findall(r"^ {3}(\w+)\s*$", text, re.M))  # autosummary entries
    modules = set(re.findall(r"^``(\w+)``\s+:mod:`([\w.]+)`", text, re.M))  # the table of modules exported by name
    missing = []
    for name in pumpup.__all__:
        if name == "__version__":
            ok = "``__version__``" in text
        elif name in pumpup._PUBLIC and pumpup._PUBLIC[name][1] is None:
            ok = (name, f"pumpup.{pumpup._PUBLIC[name][0]}") in modules
        else:
            ok = name in listed
        if not ok:
            missing.append(name)
    assert not missing, f"public names missing from docs/reference/api.rst: {missing}"
    assert not listed - set(pumpup.__all__) - {"nosignatures"}, "api.rst lists names that are not public"


def public_modules() -> list[str]:
    """Every module of the package that declares an ``__all__`` (its public names), found here independently."""
    out = []
    for info in pkgutil.walk_packages(pumpup.__path__, "pumpup."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        if getattr(importlib.import_module(info.name), "__all__", None):
            out.append(info.name)
    return out


def test_every_module_with_public_names_has_a_reference_page():
    documented = pumpup_docs.documented_modules()
    missing = [m for m in public_modules() if m not in documented and m not in pumpup_docs.EXCLUDED]
    assert not missing, f"modules with an __all__ and no reference page: {missing}"
    assert {"pumpup.core", "pumpup.engine.routes", "pumpup.luts", "pumpup.mitsuba"} <= set(documented)


@pytest.mark.parametrize("module", pumpup_docs.documented_modules())
def test_module_page_lists_every_name(module):
    text = pumpup_docs.module_page_rst(module)
    assert f".. automodule:: {module}" in text
    for name in getattr(importlib.import_module(module), "__all__", ()):
        assert re.search(rf"^ {{3}}{re.escape(name)}$", text, re.M), f"{module}.{name} not in its page"
        assert re.search(rf"^\.\. auto\w+:: {re.escape(name)}$", text, re.M), f"{module}.{name} not documented"


def subcommands(parser: argparse.ArgumentParser, path=()):
    """(path, parser) of every subcommand at every depth, found independently of the docs extension."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield (*path, name), sub
                yield from subcommands(sub, (*path, name))


def test_cli_reference_lists_every_subcommand_and_option():
    from pumpup.cli import build_parser

    parser = build_parser()
    text = pumpup_docs.cli_reference_rst(parser)
    found = list(subcommands(parser))
    assert len(found) >= 16 and ("render", "scene") in [p for p, _ in found]
    for path, sub in found:
        assert "``pumpup " + " ".join(path) + "``" in text, f"pumpup {' '.join(path)} missing"
        for action in sub._actions:
            for option in action.option_strings:
                assert option in text, f"pumpup {' '.join(path)} {option} missing"
    reference = open(os.path.join(DOCS, "reference", "cli.rst")).read()
    assert ".. pumpup-cli::" in reference  # the page is the generated one


def test_user_guide_globs_its_folder():
    text = open(os.path.join(DOCS, "user-guide", "index.md")).read()
    toctree = re.search(r"```\{toctree\}\n(.*?)```", text, re.S).group(1)
    assert ":glob:" in toctree and re.search(r"^\*$", toctree, re.M)
    listed = {ln.strip() for ln in toctree.splitlines() if ln.strip() and not ln.startswith(":")}
    for name in os.listdir(os.path.join(DOCS, "user-guide")):
        if name.endswith(".md") and name != "index.md":
            assert name[:-3] in listed or "*" in listed


def test_routing_table_directive_prints_the_code_table():
    from pumpup.engine.routes import ROUTES, describe

    text = pumpup_docs.routing_table_rst()
    assert describe().splitlines()[0] in text
    assert all(route in text for route in ROUTES)


def test_model_list_is_the_registry():
    from pumpup.core import registry

    text = pumpup_docs.model_list_rst()
    assert all(re.search(rf"^ {{3}}{name}: ", text, re.M) for name in registry())


def test_plain_text_math_is_kept_literal():
    assert pumpup_docs.plain_text_math("error |K - G| and r_- or ``|x|``") == r"error \|K - G\| and r\_- or ``|x|``"
    assert pumpup_docs.plain_text_math("| a | b |") == "| a | b |"  # a table row


# ------------------------------------------------------------------------------------------------------------------
# The build (CI: .ci/run runs it with CI=true, where a missing tool fails instead of skipping)
# ------------------------------------------------------------------------------------------------------------------


class _Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.images, self.ids = [], [], set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and a.get("href"):
            self.links.append(a["href"])
        if tag == "img" and a.get("src"):
            self.images.append(a["src"])
        if tag == "link" and a.get("href") and a.get("rel") in ("stylesheet", "icon"):
            self.links.append(a["href"])


def html_pages(outdir: str) -> list[str]:
    """The built pages: every .html file but the theme's templates and the copies Sphinx keeps (``_static``...)."""
    out = []
    for folder, dirs, files in os.walk(outdir):
        dirs[:] = [d for d in dirs if not d.startswith("_")]
        out += [os.path.join(folder, name) for name in files if name.endswith(".html")]
    return sorted(out)


def internal_problems(outdir: str) -> list[str]:
    """Every internal link, anchor or image of the built HTML under ``outdir`` that does not resolve."""
    pages = {}
    for path in html_pages(outdir):
        parser = _Links()
        parser.feed(open(path, encoding="utf-8").read())
        pages[os.path.normpath(path)] = parser
    problems = []
    for path, parser in pages.items():
        for kind, targets in (("link", parser.links), ("image", parser.images)):
            for target in targets:
                url = urllib.parse.urlsplit(target)
                if url.scheme or url.netloc or target.startswith(("mailto:", "javascript:")):
                    continue
                file = os.path.normpath(os.path.join(os.path.dirname(path), urllib.parse.unquote(url.path))) \
                    if url.path else path
                if os.path.isdir(file):
                    file = os.path.join(file, "index.html")
                if not os.path.exists(file):
                    problems.append(f"{os.path.relpath(path, outdir)}: {kind} {target} -> missing file")
                elif url.fragment and file in pages and urllib.parse.unquote(url.fragment) not in pages[file].ids:
                    problems.append(f"{os.path.relpath(path, outdir)}: {kind} {target} -> missing anchor")
    return problems


@pytest.fixture(scope="module")
def built_site(tmp_path_factory):
    pytest.importorskip("sphinx")
    outdir = str(tmp_path_factory.mktemp("html"))
    env = dict(os.environ, PYTHONPATH=ROOT, MPLBACKEND="Agg")
    r = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", "-q", DOCS, outdir],
                       cwd=ROOT, env=env, capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, (r.stdout + r.stderr)[-5000:]
    return outdir


@pytest.mark.slow
def test_docs_build_with_every_internal_link_and_image(built_site):
    pages = [p for p in os.listdir(os.path.join(built_site, "gallery")) if p.startswith("plot_") and
             p.endswith(".html")]
    assert len(pages) >= 10, pages  # the gallery ran
    for must in ("reference/cli.html", "reference/api.html", "engine/index.html", "user-guide/albedo.html"):
        assert os.path.exists(os.path.join(built_site, must)), must
    cli = open(os.path.join(built_site, "reference", "cli.html"), encoding="utf-8").read()
    from pumpup.cli import build_parser

    for path, _ in subcommands(build_parser()):  # a section (and its anchor) per subcommand
        assert f'id="cli-{"-".join(path)}"' in cli, path
    problems = internal_problems(built_site)
    assert not problems, "\n".join(problems[:50])


def chromium() -> str | None:
    path = shutil.which("chromium") or shutil.which("chromium-browser")
    if path is None and os.environ.get("CI") == "true":
        pytest.fail("chromium is not installed (Debian: apt-get install chromium); CI must not skip the browser check")
    return path


@pytest.mark.slow
def test_every_page_loads_in_chromium_without_errors(built_site):
    executable = chromium()
    if executable is None:
        pytest.skip("chromium is not installed")
    if os.environ.get("CI") == "true":
        from playwright.sync_api import sync_playwright
    else:
        sync_playwright = pytest.importorskip("playwright.sync_api").sync_playwright
    pages = html_pages(built_site)
    assert len(pages) > 50
    failures = []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=executable, args=["--no-sandbox"])
        page = browser.new_page()
        errors = []
        page.on("console", lambda msg: errors.append(msg.text) if msg.type == "error" else None)
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        for path in pages:
            errors.clear()
            page.goto("file://" + path, wait_until="load")
            broken = page.evaluate("Array.from(document.images).filter(i => !i.complete || i.naturalWidth === 0)"
                                   ".map(i => i.getAttribute('src'))")
            rel = os.path.relpath(path, built_site)
            if errors:
                failures.append(f"{rel}: console errors {errors[:3]}")
            if broken:
                failures.append(f"{rel}: images not loaded {broken[:3]}")
        browser.close()
    assert not failures, "\n".join(failures[:50])
