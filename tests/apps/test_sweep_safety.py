"""Sweeps that share an output, fail to start, or are killed (issue 13, item 11)."""

import fcntl
import os
import signal
import subprocess
import sys
import textwrap
import time

import helpers
import pytest

import pumpup

sw = sys.modules["pumpup.sweeps"]
A = dict(spec={"type": "lambert"}, params={"albedo": [0.25, 0.5]}, mu=[0.5, 1.0], scheduler="synchronous",
         mean=False, maximum=False, progress=False)


def test_a_running_sweep_locks_its_output(tmp_path):
    out = tmp_path / "s.nc"
    parts = tmp_path / "s.nc.parts"
    parts.mkdir()
    fd = os.open(parts, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)  # as a sweep in another process holds it
    try:
        with pytest.raises(sw.SweepError, match="another sweep is running into"):
            pumpup.sweep(**A, out=out)
    finally:
        os.close(fd)
    ds = pumpup.sweep(**A, out=out)  # free again
    assert out.exists() and not parts.exists() and ds["albedo"].shape == (2, 2)


def test_a_sweep_that_never_started_leaves_nothing(tmp_path, monkeypatch):
    out = tmp_path / "s.nc"

    def unreachable(*a, **k):
        raise OSError("sweep: cannot reach the dask scheduler at 'tcp://nowhere:8786'")

    monkeypatch.setattr(sw, "_run_local", unreachable)
    with pytest.raises(OSError, match="cannot reach"):
        pumpup.sweep(**A, out=out)
    assert os.listdir(tmp_path) == []  # no manifest to refuse the next sweep
    monkeypatch.undo()
    pumpup.sweep(**{**A, "mu": [0.25, 1.0]}, out=out)  # a different sweep runs
    assert out.exists()


def test_a_different_sweep_does_not_overwrite_a_result(tmp_path):
    out = tmp_path / "s.nc"
    first = pumpup.sweep(**A, out=out)
    before = out.read_bytes()
    with pytest.raises(sw.SweepError, match="different sweep.*overwrite=True"):
        pumpup.sweep(**{**A, "mu": [0.3, 1.0]}, out=out)
    assert out.read_bytes() == before
    pumpup.sweep(**A, out=out)  # the same sweep again: allowed, the same numbers
    assert pumpup.open_table(out)["albedo"].values.tolist() == first["albedo"].values.tolist()
    pumpup.sweep(**{**A, "mu": [0.3, 1.0]}, out=out, overwrite=True)
    assert pumpup.open_table(out)["mu"].values.tolist() == [0.3, 1.0]
    other = tmp_path / "other.nc"
    other.write_bytes(b"my thesis")
    with pytest.raises(sw.SweepError, match="not a result of this sweep"):
        pumpup.sweep(**A, out=other)
    assert other.read_bytes() == b"my thesis"
    from pumpup.cli import main

    with pytest.raises(SystemExit) as exc:
        main(["sweep", "lambert", "--param", "albedo=0.1,0.2", "--mu", "1", "--no-mean", "--no-maximum",
              "--out", str(out), "--serial"])
    assert exc.value.code == 2
    assert main(["sweep", "lambert", "--param", "albedo=0.1,0.2", "--mu", "1", "--no-mean", "--no-maximum",
                 "--out", str(out), "--serial", "--overwrite"]) == 0


def _children(pid):
    out = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as fh:
                    fields = fh.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid and fields[0] != "Z":
                out.append(int(d))
    return out


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_killing_a_process_sweep_ends_its_workers(tmp_path):
    root = str(helpers.ROOT)
    script = tmp_path / "s.py"
    script.write_text(textwrap.dedent(f"""
        import pumpup
        if __name__ == "__main__":
            pumpup.sweep({{"type": "stretched_phong"}}, {{"n": [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]}},
                         mu=[1.0, 0.5], scheduler="processes", workers=2, chunks=1, progress=False,
                         out={str(tmp_path / "x.nc")!r})
    """))
    p = subprocess.Popen([sys.executable, str(script)], env=dict(os.environ, PYTHONPATH=root), cwd=tmp_path)
    try:
        deadline = time.time() + 120
        while len(_children(p.pid)) < 2 and time.time() < deadline and p.poll() is None:
            time.sleep(0.2)
        workers = _children(p.pid)
        assert len(workers) >= 2, "the workers did not start"
        time.sleep(1.0)  # let them import pumpup and set their parent-death signal
    finally:
        p.kill()
        p.wait()
    deadline = time.time() + 30
    alive = workers
    while alive and time.time() < deadline:
        time.sleep(0.2)
        alive = [w for w in alive if os.path.exists(f"/proc/{w}")
                 and open(f"/proc/{w}/stat").read().rsplit(")", 1)[1].split()[0] != "Z"]
    for w in alive:
        os.kill(w, signal.SIGKILL)
    assert not alive, f"workers {alive} outlived the killed sweep"
