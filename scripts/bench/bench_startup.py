"""The first minute, measured: import, --help, reproduce, and the cold and warm first call of every
command in the README, each beside its target.

    python scripts/bench/bench_startup.py              # everything (about 10 minutes on 2 cores)
    python scripts/bench/bench_startup.py --quick      # import, --help and the baseline only
    python scripts/bench/bench_startup.py --repeat 5   # more runs of the short measurements (their minimum is shown)

Times are of whole processes: CPU (user + system, from the kernel's accounting of the child) and wall.
The baseline, measured in the same run, is ``python -c "import numpy"``: the ratio column says how many
numpy imports each measurement costs.  A cold call runs with an empty numba cache (``NUMBA_CACHE_DIR`` set
to a new directory), as on a new machine; the warm call is the next process with the same cache.
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(cmd: list[str] | str, cwd: str, env: dict | None = None) -> tuple[float, float, int]:
    """(CPU seconds, wall seconds, status) of one process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run(cmd, cwd=cwd, env=env, shell=isinstance(cmd, str), stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, wall, r.returncode


def best(cmd, cwd, repeat, env=None):
    runs = [run(cmd, cwd, env) for _ in range(repeat)]
    return min(r[0] for r in runs), min(r[1] for r in runs), max(r[2] for r in runs)


def readme_commands() -> list[str]:
    """The commands of the README's fenced bash blocks, without the install and test-suite lines."""
    text = open(os.path.join(ROOT, "README.md")).read()
    out = []
    for block in re.findall(r"^```bash[ \t]*\n(.*?)^```", text, re.S | re.M):
        for line in re.sub(r"\s*\\\n\s*", " ", block).splitlines():
            line = line.split(" #")[0].strip()
            for part in line.split("&&"):
                part = part.strip()
                if part and not part.startswith(("pip install", "python -m pytest", "#")):
                    out.append(part)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="import, --help and the baseline only")
    ap.add_argument("--repeat", type=int, default=3, help="runs of each short measurement (default 3)")
    args = ap.parse_args()
    py = sys.executable
    pumpup = [py, "-m", "pumpup.cli"]
    rows = []
    base_cpu, base_wall, _ = best([py, "-c", "import numpy"], ROOT, args.repeat)
    rows.append(("baseline: python -c 'import numpy'", base_cpu, base_wall, "", 0))
    for what, cmd, target in (("import pumpup", [py, "-c", "import pumpup"], "< 0.3 s CPU"),
                              ("pumpup --help", pumpup + ["--help"], "< 0.3 s CPU")):
        cpu, wall, rc = best(cmd, ROOT, args.repeat)
        rows.append((what, cpu, wall, target, rc))
    if not args.quick:
        with tempfile.TemporaryDirectory() as tmp:
            cache = os.path.join(tmp, "numba-cache")
            env = dict(os.environ, NUMBA_CACHE_DIR=cache, MPLBACKEND="Agg")
            run(pumpup + ["warmup", "--quiet"], tmp, env)  # reproduce's own time, not its compile
            cpu, wall, rc = run(pumpup + ["reproduce", "--out", os.path.join(tmp, "reproduced")], tmp, env)
            rows.append(("pumpup reproduce (kernels cached)", cpu, wall, "< 10 s", rc))
            shutil.rmtree(cache)
            cpu, wall, rc = run(pumpup + ["warmup", "--quiet"], tmp, env)
            rows.append(("pumpup warmup, cold (every kernel)", cpu, wall, "", rc))
            cpu, wall, rc = run(pumpup + ["warmup", "--quiet"], tmp, env)
            rows.append(("pumpup warmup, warm", cpu, wall, "", rc))
            for name in os.listdir(ROOT):  # the README's relative paths resolve as in a clone
                if name != ".git":
                    os.symlink(os.path.join(ROOT, name), os.path.join(tmp, name))
            shim = os.path.join(tmp, "bin")
            os.makedirs(shim)
            with open(os.path.join(shim, "pumpup"), "w") as fh:
                fh.write(f"#!/bin/sh\nexec {py} -m pumpup.cli \"$@\"\n")
            os.chmod(os.path.join(shim, "pumpup"), 0o755)
            env["PATH"] = shim + os.pathsep + env["PATH"]
            env["PYTHONPATH"] = ROOT
            for cmd in readme_commands():
                if cmd == "pumpup reproduce":
                    continue
                shutil.rmtree(cache, ignore_errors=True)
                cold = run(cmd, tmp, env)
                warm = run(cmd, tmp, env)
                rows.append((f"{cmd[:70]} (cold)", cold[0], cold[1], "told once, then computes", cold[2]))
                rows.append((f"{cmd[:70]} (warm)", warm[0], warm[1], "cached kernels", warm[2]))
    width = max(len(r[0]) for r in rows)
    print(f"{'measurement':{width}s}  {'CPU [s]':>8s}  {'wall [s]':>8s}  {'x numpy':>8s}  target")
    for what, cpu, wall, target, rc in rows:
        flag = "" if rc == 0 else f"  (exit status {rc})"
        print(f"{what:{width}s}  {cpu:8.2f}  {wall:8.2f}  {cpu / base_cpu:8.1f}  {target}{flag}")


if __name__ == "__main__":
    main()
