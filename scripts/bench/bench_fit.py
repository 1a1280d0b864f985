"""Benchmark: a one-parameter perceptual fit (stretched Phong n to GGX alpha = 0.1), target < 10 s.

Prints the wall time of the fit in a fresh process (first fit: numba's cached kernels load,
the target's tables are built) and again (second fit), beside a baseline measured in the
same run: the albedo of the target at 33 mu with rtol 1e-9; and the CPU time of the process,
which a shared machine's load inflates much less than the wall time.  Timings on a shared
machine are noisy; the load average is printed with them.

    python scripts/bench/bench_fit.py
"""

import os
import time

import numpy as np

import pumpup


def main():
    print(f"load average before: {os.getloadavg()}")
    target = pumpup.load({"type": "ggx", "alpha": 0.1})
    mu = np.cos(np.linspace(0.0, np.arccos(0.05), 33))
    times = {}
    for run in ("first", "second"):
        t0 = time.perf_counter()
        pumpup.albedo(target, mu, rtol=1e-9)
        base = time.perf_counter() - t0
        t0, c0 = time.perf_counter(), time.process_time()
        r = pumpup.fit(target, "stretched_phong", params={"n": (1, 1e4)})
        times[run] = time.perf_counter() - t0
        cpu = time.process_time() - c0
        print(f"{run} fit: {times[run]:.2f} s wall, {cpu:.2f} s CPU of this process ({r.evaluations} evaluations, {r.albedo_evaluations} with the albedo, "
              f"{r.exchanges} exchange rounds); baseline albedo(33 mu, rtol 1e-9) {base * 1e3:.0f} ms; "
              f"ratio {times[run] / base:.0f}")
    print(r)
    print(f"load average after: {os.getloadavg()}")
    print(f"verdict: {'under' if times['second'] < 10 else 'OVER'} 10 s (second fit {times['second']:.2f} s)")


if __name__ == "__main__":
    main()
