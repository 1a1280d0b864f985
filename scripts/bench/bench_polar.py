"""The 1-D path (pumpup/engine/polar.py) against a previous version of it, in the same run (issue 14).

Loads ``pumpup/engine/polar.py`` as it was at a git revision (default 2a636a4: before issue 14's
calibrated estimate, one first interval per piece and the allocation-free pieces) beside the
current one, and times ``albedo_1d`` on the Phong family's 257-point tables (mu uniform in theta)
at rtol 1e-10, interleaved, best of 40 each; prints both, the ratio, the evaluations per mu, and
whether the values agree within the summed error estimates.

    PYTHONPATH=. python scripts/bench/bench_polar.py [REVISION]
"""

import importlib.util
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

import pumpup
from pumpup.engine import polar as _polar

SPECS = [{"type": "phong", "n": 20}, {"type": "stretched_phong", "n": 20},
         {"type": "stretched_phong", "n": 20, "p": 0.0}, {"type": "retro", "n": 10}]


def previous(rev):
    root = pathlib.Path(__file__).resolve().parents[2]
    for where in ("pumpup/engine/polar.py", "pumpup/_polar.py"):  # (its path before the layered packages)
        r = subprocess.run(["git", "-C", str(root), "show", f"{rev}:{where}"], capture_output=True, text=True)
        if r.returncode == 0:
            break
    r.check_returncode()
    src = r.stdout
    path = pathlib.Path(tempfile.mkdtemp()) / "_polar_previous.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("pumpup._polar_previous", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["pumpup._polar_previous"] = mod
    spec.loader.exec_module(mod)
    return mod


def main():
    rev = sys.argv[1] if len(sys.argv) > 1 else "2a636a4"
    old = previous(rev)
    mu = np.cos(np.linspace(0, np.pi / 2, 258)[:-1])
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; 257-point tables at rtol 1e-10, "
          f"albedo_1d, best of 40 (interleaved); previous = pumpup/engine/polar.py at {rev}")
    for s in SPECS:
        term = pumpup.load(s).albedo_terms()[0][1]
        mods = {"previous": old, "now": _polar}
        for mod in mods.values():
            mod.albedo_1d(term, mu, 1e-10, 1e-14, 20000)  # compile / load
        best, res = dict.fromkeys(mods, np.inf), {}
        for _ in range(40):
            for name, mod in mods.items():
                t = time.perf_counter()
                res[name] = mod.albedo_1d(term, mu, 1e-10, 1e-14, 20000)
                best[name] = min(best[name], time.perf_counter() - t)
        (vb, eb), (va, ea) = res["previous"][:2], res["now"][:2]
        agree = bool(np.all(np.abs(va - vb) <= ea + eb))
        print(f"{s!s:48s} previous {best['previous'] * 1e3:5.2f} ms ({res['previous'][3].mean():3.0f} ev/mu)  "
              f"now {best['now'] * 1e3:5.2f} ms ({res['now'][3].mean():3.0f} ev/mu)  ratio "
              f"{best['previous'] / best['now']:4.2f}  agree within summed errors: {agree} "
              f"(max |diff| {np.max(np.abs(va - vb)):.1g})", flush=True)
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
