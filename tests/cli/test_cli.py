"""The command line: a few real runs and clear errors."""

import subprocess
import sys

import pytest

from pumpup.cli import main, parse_spec


def test_parse_spec_short_and_json():
    assert parse_spec("phong:n=20,c=1") == {"type": "phong", "n": 20, "c": 1}
    assert parse_spec('{"type": "ward", "m": 0.1}') == {"type": "ward", "m": 0.1}
    with pytest.raises(SystemExit):
        parse_spec("phong:n")


def test_albedo_command(capsys):
    assert main(["albedo", "lambert:albedo=0.5", "--mu", "1", "0.25"]) == 0
    out = capsys.readouterr().out
    assert out.count("0.500000000000000") == 2


def test_models_lists_the_registry(capsys):
    main(["models"])
    out = capsys.readouterr().out
    for name in ("phong", "stretched_phong", "ward", "cook_torrance", "pumped"):
        assert name in out


def test_bad_spec_and_mu_are_clear_errors():
    with pytest.raises(SystemExit, match="unknown model type"):
        main(["albedo", "nope:n=1"])
    with pytest.raises(SystemExit, match=r"'n'.*\[0, 1e\+06\]"):  # MAX_EXPONENT (issue 13)
        main(["albedo", "phong:n=-1"])
    with pytest.raises(SystemExit, match="mu"):
        main(["albedo", "phong:n=1", "--mu", "0"])
    with pytest.raises(SystemExit, match="not reciprocal"):
        main(["pump", "phong_shader:n=3"])


def test_help_is_fast_and_works():
    r = subprocess.run([sys.executable, "-m", "pumpup.cli", "--help"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and "albedo" in r.stdout


def test_mc_command(capsys):
    """Monte Carlo beside quadrature; exit 0 when they agree within 4 standard errors, clear errors."""
    assert main(["mc", "stretched_phong:n=20", "--mu", "1", "0.05", "--n", "50000", "--seed", "3"]) == 0
    out = capsys.readouterr().out
    assert "phong lobe (mirror)(20)" in out and "(MC - q) / se" in out
    assert len(out.strip().splitlines()) == 4
    with pytest.raises(SystemExit, match="mu"):
        main(["mc", "phong:n=20", "--mu", "0"])
    with pytest.raises(SystemExit, match="--n"):
        main(["mc", "phong:n=20", "--n", "0"])


def test_check_says_a_diverging_albedo_has_no_maximum(capsys):
    assert main(["check", "ward:m=0.1"]) == 0
    out = capsys.readouterr().out
    assert "max albedo (constant set to 1): unbounded: a(mu) ~ mu^-0.5" in out and "maximum constant 0" in out
    assert main(["check", "phong:n=20"]) == 0
    import math

    # reciprocal Phong with c = 1 peaks at normal incidence, a(1) = 2 pi / (n + 2): its constant is (n + 2) / (2 pi)
    assert f"maximum constant {22 / (2 * math.pi):.9f}" in capsys.readouterr().out


def test_commands_read_saved_brdf_files(tmp_path, capsys):
    """A SPEC argument may be a file written by pump --out or compensate --out; another file gets one line."""
    pumped, comp, table = str(tmp_path / "p.nc"), str(tmp_path / "c.nc"), str(tmp_path / "t.nc")
    assert main(["pump", "phong:n=20", "--levels", "2", "--out", pumped]) == 0
    assert main(["compensate", "ggx:alpha=0.3", "--out", comp]) == 0
    capsys.readouterr()
    assert main(["albedo", pumped, "--mu", "1", "0.5"]) == 0
    out = capsys.readouterr().out
    import pumpup

    expected = pumpup.albedo(pumpup.pump("phong:n=20", levels=2), [1.0, 0.5])
    row = [line.split() for line in out.splitlines() if line.split()[:1] == ["0.5"]][0]
    assert abs(float(row[2]) - expected[1]) <= float(row[3]) and '"type": "pumped"' in out
    assert main(["albedo", comp, "--mu", "0.5"]) == 0
    assert '"type": "kulla_conty"' in capsys.readouterr().out
    assert main(["table", pumped, "--out", table]) == 0
    with pytest.raises(SystemExit, match="not a saved BRDF .pumpup albedo table."):
        main(["albedo", table])
    (tmp_path / "junk.nc").write_bytes(b"not netcdf")
    with pytest.raises(SystemExit, match="not a readable netCDF file"):
        main(["check", str(tmp_path / "junk.nc")])
