"""This checkout against another revision of pumpup, alternating in one run: 257-point albedo tables, eval and a sweep
cell, with the ratio new / old of each.

    python scripts/bench/bench_revisions.py 3b65c31            # against that commit (a temporary git worktree)
    python scripts/bench/bench_revisions.py 3b65c31 --rounds 5

Each round runs the workload once in each checkout, in separate processes, alternating which goes first; a process
warms every measurement up once (numba's cache, the pumping tables) and then takes the best of three.  The table shows
each measurement's best over the rounds and the ratio new / old; only the public API is used, so any two revisions
can be compared.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

#: the measurements: name -> spec (a 257-point table at rtol 1e-10) or a special kind
SPECS = {
    "phong n=20": {"type": "phong", "n": 20},
    "stretched_phong n=5000": {"type": "stretched_phong", "n": 5000},
    "blinn n=50": {"type": "blinn", "n": 50},
    "ward m=0.2": {"type": "ward", "m": 0.2},
    "cook_torrance m=0.3": {"type": "cook_torrance", "m": 0.3},
    "ggx alpha=0.3": {"type": "ggx", "alpha": 0.3},
    "beckmann alpha=0.2 ior=1.5": {"type": "beckmann", "alpha": 0.2, "ior": 1.5},
    "metal n=20 Au-like": {"type": "metal", "n": 20, "eta": 0.2, "k": 3.0},
    "ward_aniso 0.1/0.3": {"type": "ward_aniso", "ax": 0.1, "ay": 0.3},
    "pumped phong g2 x2": {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2", "levels": 2},
    "scaled ggx": {"type": "scaled", "base": {"type": "ggx", "alpha": 0.3}},
    "kulla_conty ggx": {"type": "kulla_conty", "base": {"type": "ggx", "alpha": 0.3}},
    "ashikhmin_shirley n=10 rs=0.5": {"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rs": 0.5},
    "fresnel(ggx) Au-like": {"type": "fresnel", "base": {"type": "ggx", "alpha": 0.3}, "eta": 0.2, "k": 3.0},
}

WORKLOAD = r'''
import json, sys, time
import numpy as np
import pumpup

specs = json.loads(sys.argv[1])
mu = np.sin(np.radians(90.0 - np.linspace(0.0, 89.99, 257)))  # theta uniform in [0, 90) degrees
out = {}


def best(fn, repeat=3):
    fn()  # warm-up: the kernels from numba's cache, a pumped or compensated model's tables
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


for name, spec in specs.items():
    f = pumpup.load(spec)
    out["table " + name] = best(lambda: pumpup.albedo(f, mu, rtol=1e-10))
rng = np.random.default_rng(1)
v = rng.normal(size=(2, 1_000_000, 3))
v[..., 2] = np.abs(v[..., 2])
v /= np.linalg.norm(v, axis=-1, keepdims=True)
for name in ("phong n=20", "ggx alpha=0.3"):
    f = pumpup.load(specs[name])
    out["eval 1e6 " + name] = best(lambda: f.eval(v[0], v[1]))
f = pumpup.load({"type": "stretched_phong", "n": 20, "p": 0.5})
out["sweep cell stretched_phong"] = best(lambda: (pumpup.albedo(f, mu, rtol=1e-10), pumpup.mean_albedo(f),
                                                  pumpup.max_constant(f)))
print(json.dumps(out))
'''


def run(checkout: str) -> dict:
    env = dict(os.environ, PYTHONPATH=checkout, NUMBA_NUM_THREADS="1", OMP_NUM_THREADS="1")
    r = subprocess.run([sys.executable, "-c", WORKLOAD, json.dumps(SPECS)], cwd=checkout, env=env,
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"the workload failed in {checkout}:\n{r.stderr[-3000:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("revision", help="the git revision to compare against (a commit, tag or branch)")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds (default 3)")
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        old = os.path.join(tmp, "old")
        subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", old, a.revision], check=True,
                       capture_output=True)
        try:
            new_best: dict = {}
            old_best: dict = {}
            for k in range(a.rounds):
                order = [(ROOT, new_best), (old, old_best)] if k % 2 == 0 else [(old, old_best), (ROOT, new_best)]
                for checkout, acc in order:
                    for key, t in run(checkout).items():
                        acc[key] = min(t, acc.get(key, float("inf")))
                print(f"round {k + 1} of {a.rounds} done", file=sys.stderr)
        finally:
            subprocess.run(["git", "-C", ROOT, "worktree", "remove", "--force", old], capture_output=True)
    width = max(len(k) for k in new_best)
    print(f"{'measurement':{width}s}  {'old [ms]':>9s}  {'new [ms]':>9s}  {'new/old':>7s}")
    for key in new_best:
        o, n = old_best[key] * 1e3, new_best[key] * 1e3
        print(f"{key:{width}s}  {o:9.2f}  {n:9.2f}  {n / o:7.3f}")


if __name__ == "__main__":
    main()
