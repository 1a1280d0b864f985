"""Every ```python and ```bash block of README.md and of the documentation's Markdown pages (docs/) runs.

The python blocks of one document run in order as ONE script (a file, as a user would save them; the
processes scheduler of the sweep example then needs its main guard) in a fresh process: every page
stands on its own, as a reader who opens it sees it.  The bash blocks of one document
run line by line, in order, in one process of their own: each ``pumpup ARGS`` line as this checkout's
``pumpup.cli.main(ARGS)``, the others through bash (``DOCUMENT_RUNNER``).  Both run in a scratch
directory that mirrors the repository root (a symlink to every top-level entry but .git), so
the examples read what they would read from the root while the files they write (tables,
sweeps) do not land in the checkout.

The README's first block holds the install commands.  Of each line, the ``pip install ...``
part is skipped (it would reinstall the package); the rest runs, except what is listed in
EXPENSIVE with the reason.  A block added to the README later is run by these tests unchanged.
"""

import os
import re
import shlex
import subprocess
import sys
import textwrap

import helpers
import pytest

ROOT = str(helpers.ROOT)
README = os.path.join(ROOT, "README.md")
DOCS = os.path.join(ROOT, "docs")
#: folders of docs/ that hold generated pages or a page's data, not pages (docs/conf.py's exclude_patterns)
GENERATED = ("_build", "gallery", "reference/generated", "reference/modules", "examples")


def _not_a_page_folder(rel: str) -> bool:
    """Whether docs/``rel`` holds no pages: a generated folder, or a user-guide page's own data folder."""
    parts = rel.split(os.sep)
    generated = any(rel == g or rel.startswith(g + os.sep) for g in GENERATED)
    return generated or (len(parts) > 1 and parts[0] == "user-guide")


def doc_pages() -> list[str]:
    """Every Markdown page of the documentation site (docs/), sorted; a page added later is run unchanged."""
    out = []
    for folder, dirs, files in os.walk(DOCS):
        rel = os.path.relpath(folder, DOCS)
        if rel != "." and _not_a_page_folder(rel):
            dirs[:] = []
            continue
        out += [os.path.join(folder, name) for name in files if name.endswith(".md")]
    return sorted(out)


#: the documents whose examples run: the README, then every page of the site
DOCUMENTS = [README, *doc_pages()]

#: commands of the README's bash blocks that the default suite does not run, with the reason
EXPENSIVE = {
    "python -m pytest -q": "the test suite itself: CI runs it (.ci/run), a test cannot run it inside itself",
    "pumpup reproduce": "about 10 s, and it rewrites every table: run by test_expensive_bash_commands (-m slow)",
    "pumpup render scene 000-fig8 --spp 64 --size 256 --variant auto --out scenes":
        "a path-traced scene, minutes: run by test_expensive_bash_commands (-m slow)",
}
EXPENSIVE.update({
    "python -m pytest -q -m slow": "the slow test suite itself: a test cannot run it inside itself",
    "python -m sphinx -W -b html docs docs/_build/html":
        "the documentation build, minutes: tests/project/test_docs.py builds it (-m slow) and .ci/run",
})
EXPENSIVE.update({
    "pumpup explore phong:n=20 ggx:alpha=0.3":
        "a server that runs until Ctrl-C: tests/apps/test_explore_browser.py starts it and drives it in chromium",
})
#: commands that are never run by a test, even with -m slow
NEVER = {"python -m pytest -q", "python -m pytest -q -m slow", "python -m sphinx -W -b html docs docs/_build/html",
         "pumpup explore phong:n=20 ggx:alpha=0.3"}


def blocks(text=None):
    """(language, code, line number) of every fenced python or bash block of ``text``, or (language, code,
    "FILE line N") of every document's."""
    if text is None:
        return [(lang, code, f"{os.path.relpath(path, ROOT)} line {line}") for path in DOCUMENTS
                for lang, code, line in blocks(open(path).read())]
    out = []
    for m in re.finditer(r"^```(python|bash)[ \t]*\n(.*?)^```", text, re.S | re.M):
        out.append((m.group(1), m.group(2), text[:m.start()].count("\n") + 1))
    return out


def bash_commands(text=None):
    """The commands of the bash blocks: lines (joined at a trailing backslash), comments dropped,
    split at '&&', without the 'pip install' parts."""
    out = []
    for lang, code, line in blocks(text):
        if lang != "bash":
            continue
        for ln in re.sub(r"\s*\\\n\s*", " ", code).splitlines():
            ln = ln.split(" #")[0].strip()
            if not ln or ln.startswith("#"):
                continue
            for part in ln.split("&&"):
                part = part.strip()
                if part and not part.startswith("pip install"):
                    out.append((part, line))
    return out


def test_the_parsers_see_every_block():
    text = textwrap.dedent('''\
        # x
        ```bash
        pip install -e . && pumpup reproduce
        pip install -e ".[test]" && python -m pytest -q   # CI
        pumpup models \\
            --help
        ```
        ```python
        x = 1
        ```
        ```text
        not code
        ```
    ''')
    assert [b[0] for b in blocks(text)] == ["bash", "python"]
    assert [c for c, _ in bash_commands(text)] == ["pumpup reproduce", "python -m pytest -q", "pumpup models --help"]
    assert len(blocks()) >= 5 and any(lang == "bash" for lang, _, _ in blocks())


def clone_entries() -> list[str]:
    """The top-level entries a fresh clone has: those git tracks (every entry but .git outside a git checkout)."""
    try:
        r = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, timeout=60)
    except OSError:
        r = None
    if r is None or r.returncode != 0 or not r.stdout.strip():
        return [name for name in os.listdir(ROOT) if name != ".git"]
    return sorted({line.split("/", 1)[0] for line in r.stdout.splitlines()})


def make_workspace(base) -> tuple:
    """A scratch directory under ``base`` that mirrors the repository root, and a PATH on which ``pumpup`` is
    this checkout's command line."""
    work = base / "root"
    work.mkdir(parents=True)
    for name in clone_entries():
        os.symlink(os.path.join(ROOT, name), work / name)
    bindir = base / "bin"
    bindir.mkdir()
    shim = bindir / "pumpup"
    shim.write_text(f"#!/bin/sh\nexec {shlex.quote(sys.executable)} -m pumpup.cli \"$@\"\n")
    shim.chmod(0o755)
    env = dict(os.environ, PYTHONPATH=ROOT, PATH=f"{bindir}{os.pathsep}{os.environ['PATH']}", MPLBACKEND="Agg")
    env.pop("PYTHONSTARTUP", None)
    return work, env


@pytest.fixture
def workspace(tmp_path):
    """A scratch directory that mirrors the repository root, with ``pumpup`` on its PATH."""
    return make_workspace(tmp_path)


def python_script(path) -> str:
    """The python blocks of one document as one script, each block headed by its line number."""
    rel = os.path.relpath(path, ROOT)
    return "\n".join(f"# --- {rel} line {line}\n{code}" for lang, code, line in blocks(open(path).read())
                     if lang == "python")


def test_every_page_is_found():
    names = {os.path.relpath(p, ROOT) for p in DOCUMENTS}
    assert {"README.md", "docs/getting-started.md", "docs/user-guide/albedo.md"} <= names
    assert not any("_build" in n or n.startswith("docs/gallery") for n in names)


@pytest.mark.parametrize("path", [p for p in DOCUMENTS if python_script(p)], ids=lambda p: os.path.relpath(p, ROOT))
def test_python_blocks_run_as_one_script(workspace, path):
    work, env = workspace
    script = work / "doc_examples.py"
    script.write_text(python_script(path))
    r = subprocess.run([sys.executable, str(script)], cwd=work, env=env, capture_output=True, text=True,
                       timeout=900)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "Traceback" not in r.stderr


def commands_by_document() -> dict[str, list[tuple[str, str]]]:
    """The bash commands the default suite runs, grouped by document in order; a command repeated within one
    document runs once there (the second run would see the same files and print the same)."""
    out: dict[str, list[tuple[str, str]]] = {}
    for cmd, line in bash_commands():
        if cmd in EXPENSIVE:
            continue
        doc = line.rsplit(" line ", 1)[0]
        if cmd not in (c for c, _ in out.get(doc, [])):
            out.setdefault(doc, []).append((cmd, line))
    return out


def test_commands_by_document_keeps_every_command():
    by_doc = commands_by_document()
    assert {cmd for cmd, _ in bash_commands() if cmd not in EXPENSIVE} == {c for cmds in by_doc.values()
                                                                            for c, _ in cmds}
    assert "README.md" in by_doc and "docs/user-guide/files.md" in by_doc


#: runs one document's commands in order in one Python process (argv[1]: a JSON list of [command, line]): a plain
#: ``pumpup ARGS`` (no shell syntax) as ``pumpup.cli.main(ARGS)``, what the ``pumpup`` script runs, so that the
#: interpreter and pumpup's imports start once per document; any other command through bash.  Prints the first
#: failure as JSON on the last line of stdout, or null.
DOCUMENT_RUNNER = r"""
import contextlib, io, json, shlex, subprocess, sys

def run(cmd):
    argv = shlex.split(cmd)
    plain = argv and argv[0] == "pumpup" and not any(c in cmd for c in "|&;<>$`()")
    if not plain:
        r = subprocess.run(["bash", "-c", cmd], capture_output=True, text=True, timeout=900)
        return r.returncode, r.stderr
    from pumpup.cli import main
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        try:
            code = main(argv[1:])
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) or exc.code is None else (print(exc.code, file=err) or 1)
    return code or 0, err.getvalue()

failure = None
for cmd, line in json.loads(sys.argv[1]):
    code, err = run(cmd)
    if code != 0:
        failure = f"{line}: {cmd} (exit {code})\n{err[-2000:]}"
        break
print(json.dumps(failure))
"""


def test_document_runner_reports_a_failing_command(tmp_path):
    """The runner of test_bash_blocks_run fails on a pumpup command that fails, and on a bash command that does."""
    import json

    work, env = make_workspace(tmp_path)
    for cmds, expect in ([["pumpup models", "a 1"], ["pumpup albedo phong:n=-1 --mu 1", "a 2"]], "a 2"), \
                        ([["pumpup models", "b 1"], ["true && false", "b 2"]], "b 2"), \
                        ([["pumpup models", "c 1"], ["ls > /dev/null", "c 2"]], None):
        r = subprocess.run([sys.executable, "-c", DOCUMENT_RUNNER, json.dumps(cmds)], cwd=work, env=env,
                           capture_output=True, text=True, timeout=300)
        failure = json.loads(r.stdout.splitlines()[-1])
        assert (failure is None) if expect is None else failure.startswith(expect + ": "), (failure, r.stderr)


def test_bash_blocks_run(tmp_path):
    """Each document's commands run in order in a workspace of the document's own (a command may read what an
    earlier one of its page wrote), in one process per document (DOCUMENT_RUNNER); the documents run side by side,
    one per core."""
    import json
    from concurrent.futures import ThreadPoolExecutor

    by_doc = commands_by_document()

    def run_document(index_and_doc):
        index, doc = index_and_doc
        work, env = make_workspace(tmp_path / f"doc{index}")
        r = subprocess.run([sys.executable, "-c", DOCUMENT_RUNNER, json.dumps(by_doc[doc])], cwd=work, env=env,
                           capture_output=True, text=True, timeout=1800)
        lines = r.stdout.splitlines()
        if r.returncode != 0 or not lines:
            return [f"{doc}: the runner failed\n{r.stderr[-2000:]}"]
        failure = json.loads(lines[-1])
        return [failure] if failure else []

    with ThreadPoolExecutor(max(1, min(2, os.cpu_count() or 1))) as pool:
        failures = [f for fs in pool.map(run_document, enumerate(by_doc)) for f in fs]
    assert not failures, "\n".join(failures)
    assert sum(map(len, by_doc.values())) >= 1


@pytest.mark.slow
def test_expensive_bash_commands(workspace):
    work, env = workspace
    os.unlink(work / "tables")  # reproduce writes tables/: here, not into the checkout
    for cmd, line in bash_commands():
        if cmd in EXPENSIVE and cmd not in NEVER:
            r = subprocess.run(["bash", "-c", cmd], cwd=work, env=env, capture_output=True, text=True, timeout=3600)
            assert r.returncode == 0, f"{line}: {cmd}\n{r.stderr[-2000:]}"


def test_expensive_list_names_real_commands():
    """EXPENSIVE may only excuse commands that are in the README (no stale excuses)."""
    cmds = {c for c, _ in bash_commands()}
    assert set(EXPENSIVE) <= cmds, set(EXPENSIVE) - cmds


def test_readme_claims_match_the_code():
    """Item 16: the README's word on the GIL and on where 'divergence all' writes."""
    from pumpup.cli import build_parser
    from pumpup.engine.cubature import _geometry_kernel
    from pumpup.engine.lobe_geometry import accumulate

    text = "".join(open(path).read() for path in DOCUMENTS)
    assert "hold the GIL" not in text and "kernels release the GIL" in text
    for kernel in (_geometry_kernel, accumulate):
        assert kernel.targetoptions.get("nogil") is True
    args = build_parser().parse_args(["divergence", "all"])
    assert f"`{args.tables}/divergence.nc` and `{args.figures}/divergence.png`" in text
