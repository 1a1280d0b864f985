"""Every command line error exits with status 2 and one line on stderr, before any long work
(issue 13, items 9 and 14); Ctrl-C prints one line and exits with 130."""

import argparse
import importlib
import os
import signal
import subprocess
import sys
import time

import pytest
from helpers import default_sigint

import pumpup
from pumpup import cli


@pytest.fixture
def no_work(monkeypatch):
    """Any computation fails the test: the errors must come first."""
    def refuse(*a, **k):
        raise AssertionError("the command computed before checking its arguments")

    monkeypatch.setattr(pumpup, "tabulate", refuse)
    monkeypatch.setattr(pumpup, "pump", refuse)
    monkeypatch.setattr(pumpup, "sweep", refuse)
    div = importlib.import_module("pumpup.divergence")  # (pumpup.divergence is also the function's name)

    monkeypatch.setattr(div, "analysis_dataset", refuse)
    monkeypatch.setattr(div, "divergence", refuse)


def run(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(argv)
    err = capsys.readouterr().err
    return exc.value.code, err


CASES = [
    (["table", "phong:n=20", "--out", "nodir/x.nc"], "directory .* does not exist"),
    (["pump", "phong:n=20", "--out", "nodir/x.nc"], "directory .* does not exist"),
    (["sweep", "stretched_phong", "--param", "n=1,2", "--out", "nodir/x.nc"], "directory .* does not exist"),
    (["divergence", "all", "--tables", "nodir"], "--tables nodir: directory does not exist"),
    (["divergence", "ward:m=-0.1"], r"parameter 'm' = -0.1 is outside its allowed range \[1e-06, 1000\]"),
    (["divergence", "ward:m=0.1", "--mu-min", "0"], r"--mu-min must be a number in \(0, 1\)"),
    (["mc", "phong:n=20", "--n", "99999999999999999999"], r"--n must be an integer in \[1, 1e\+08\]"),
    (["albedo", "phong:n=20", "--theta", "100"], r"theta must be in \[0, 90\) degrees"),
    (["albedo", "phong:n=20", "--theta", "-30"], r"--theta -30: .*\[0, 90\)"),
    (["albedo", "phong:n=20", "--rtol", "0"], r"rtol must be a finite number in \(0, 1\]"),
    (["albedo", "phong:n"], "must look like name=value"),
    (["albedo", "nope:n=1"], "unknown model type"),
    (["pump", "phong:n=20", "--levels", "0"], r"levels must be an integer in \[1, 64\]"),
    (["check", "phong:n=20,c=1e999"], "'c' must be finite"),
    (["albedo", "--mu", "x", "phong:n=2"], "invalid float value"),  # argparse's own: status 2 too
]


@pytest.mark.parametrize("argv, match", CASES, ids=[" ".join(c[0][:2]) + str(i) for i, c in enumerate(CASES)])
def test_user_errors_exit_2_with_one_line(argv, match, capsys, no_work, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # outside the repository: no tables/ here
    code, err = run(argv, capsys)
    assert code == 2, err
    lines = [ln for ln in err.splitlines() if ln.strip() and not ln.startswith("usage:")]
    assert len(lines) == 1, err
    import re

    assert re.search(match, lines[0]), lines[0]


def test_divergence_all_outside_the_repository_fails_first(capsys, no_work, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, err = run(["divergence", "all"], capsys)
    assert code == 2 and "--tables tables: directory does not exist" in err


def test_errors_of_a_real_process_and_ctrl_c(tmp_path):
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.dirname(os.path.abspath(pumpup.__file__))))
    r = subprocess.run([sys.executable, "-m", "pumpup.cli", "table", "phong:n=20", "--out", "nodir/x.nc"],
                       capture_output=True, text=True, cwd=tmp_path, env=env, timeout=120)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "does not exist" in r.stderr
    # Ctrl-C in the middle of a long computation: one line, status 130
    p = subprocess.Popen([sys.executable, "-m", "pumpup.cli", "divergence", "all", "--tables", ".", "--figures", "."],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path, env=env,
                         preexec_fn=default_sigint)
    deadline = time.time() + 120
    while time.time() < deadline and p.poll() is None and _cpu_seconds(p.pid) < 4.0:
        time.sleep(0.2)  # until it is computing (imports take about 1 s of CPU)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 130, err
    assert err.strip() == "pumpup: interrupted", err


def _cpu_seconds(pid):
    try:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        time.sleep(6)
        return 1e9


def _actions(parser):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                for a in sub._actions:
                    yield name, a


def test_every_option_has_help_with_its_default():
    for name, a in _actions(cli.build_parser()):
        if isinstance(a, argparse._HelpAction):
            continue
        assert a.help, f"{name} {a.dest} has no help"
        if a.option_strings:
            assert "default" in a.help or "required" in a.help, f"{name} {a.option_strings}: {a.help!r}"
            if a.default not in (None, False):
                import re

                stated = re.search(r"default:? ([^)]*)", a.help).group(1).split()[0]
                if isinstance(a.default, (int, float)):
                    assert float(stated) == a.default, (name, a.option_strings, a.help)
                else:
                    assert stated == str(a.default), (name, a.option_strings, a.help)


def test_models_shows_ranges_defaults_and_meanings(capsys):
    assert cli.main(["models"]) == 0
    out = capsys.readouterr().out
    assert "``" not in out and ":func:" not in out and ":class:" not in out
    lines = out.splitlines()
    phong = lines.index(next(ln for ln in lines if ln.startswith("phong:")))
    n, c = lines[phong + 1].split(), lines[phong + 2].split()
    assert n[:4] == ["n", "[0,", "1e+06]", "required"] and "exponent" in lines[phong + 1]
    assert c[:3] == ["c", "[0,", "inf)"] and "(n + 2) / (2 pi)" in lines[phong + 2]
    assert "scale [1/sr]" in lines[phong + 2]
    # aligned: every parameter line has its range, default and meaning in the same columns
    header = lines[0]
    cols = [header.index(w) for w in ("range", "default", "meaning")]
    for name, cls in pumpup.registry().items():
        i = lines.index(next(ln for ln in lines if ln.startswith(name + ":")))
        for k, (pname, p) in enumerate(cls.params.items()):
            ln = lines[i + 1 + k]
            assert ln.split()[0] == pname
            assert ln[cols[0] - 1] == " " and ln[cols[1] - 1] == " " and ln[cols[2] - 1] == " "
            assert ln[cols[0]:].startswith(p.range_text() if p.kind in ("float", "int", "floats") or p.choices
                                           else p.kind)
