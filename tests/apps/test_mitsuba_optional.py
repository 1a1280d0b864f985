"""pumpup without Mitsuba: ``import pumpup`` does not import it, and ``pumpup.mitsuba`` names the extra to
install (these run whether or not mitsuba is installed; the bridge itself is tested in test_mitsuba.py)."""

from __future__ import annotations

import os
import subprocess
import sys

import helpers

ROOT = str(helpers.ROOT)


def _run(code):
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env, timeout=300)


def test_import_pumpup_does_not_import_mitsuba():
    r = _run("import sys, pumpup; print('mitsuba' in sys.modules, 'drjit' in sys.modules)")
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["False", "False"]


def test_missing_mitsuba_gives_an_import_error_naming_the_extra():
    r = _run("import sys; sys.modules['mitsuba'] = None; sys.modules['drjit'] = None\n"
             "import pumpup\n"
             "try:\n    import pumpup.mitsuba\nexcept ImportError as e:\n    print('IMPORTERROR', e)\n")
    assert r.returncode == 0, r.stderr
    assert "IMPORTERROR" in r.stdout and 'pip install -e ".[render]"' in r.stdout
