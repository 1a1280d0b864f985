"""Benchmark: ``pumpup_caustic`` on 001 Fig. 8's n = 5000 panels with its two-mirror technique C on, against
the same integrator with C off, measured in the same run.

    python scripts/bench/bench_caustic.py [--size 256] [--spp 64] [--rounds 3]

Per panel it renders once with each setting to compile the kernels (Dr.Jit caches them; the seconds of that
first render are printed as "cold"), then ``--rounds`` rounds of C off and C on, alternating, each render
converted to an array inside the timing (Dr.Jit evaluates lazily).  Prints the median wall and process CPU
seconds per setting, the ratio C on / C off, the fireflies of each render (``make_scenes.fireflies``) and the
load average (the machine is shared).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, ROOT)  # this checkout's pumpup
sys.path.insert(0, os.path.join(ROOT, "scripts", "make"))

import numpy as np  # noqa: E402
from make_scenes import LUMINANCE, fireflies  # noqa: E402

import pumpup.scenes as S  # noqa: E402


def main(argv=None) -> int:
    """Render, time and print (module docstring); returns the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args(argv)
    S.check_args("001-fig8", a.spp, a.size, "auto")
    if a.rounds < 1:
        raise SystemExit("--rounds must be >= 1")
    _, variant = S._mitsuba("auto")
    import mitsuba as mi

    rows = S.panels("001-fig8")
    for label, mats in (rows[0][1], rows[1][1]):
        scenes = {}
        for c in (False, True):
            d = S._scene_dict("001-fig8", mats, a.size, a.spp)
            d["integrator"] = dict(S.INTEGRATOR["001-fig8"], technique_c=c)
            scenes[c] = mi.load_dict(d)

        def run(c, seed):
            t, cpu = time.perf_counter(), time.process_time()
            y = np.array(mi.render(scenes[c], seed=seed), dtype=np.float64)[..., :3] @ LUMINANCE
            return time.perf_counter() - t, time.process_time() - cpu, fireflies(y)

        cold = {c: run(c, 1)[0] for c in (False, True)}
        res: dict = {False: [], True: []}
        for r in range(a.rounds):
            for c in (False, True):
                res[c].append(run(c, 100 + r))
        wall = {c: statistics.median(x[0] for x in res[c]) for c in res}
        cpu = {c: statistics.median(x[1] for x in res[c]) for c in res}
        for c in (False, True):
            print(f"{label}, C {'on ' if c else 'off'}: cold {cold[c]:.1f} s, warm {wall[c]:.2f} s wall, "
                  f"{cpu[c]:.2f} s CPU; fireflies {[x[2] for x in res[c]]}")
        print(f"{label}: C on / C off = {wall[True] / wall[False]:.2f} (wall), {cpu[True] / cpu[False]:.2f} (CPU); "
              f"{variant}, {a.size} x {a.size}, {a.spp} spp; load {os.getloadavg()[0]:.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
