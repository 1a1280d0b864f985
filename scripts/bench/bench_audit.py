#!/usr/bin/env python
"""Timings of issue 52: audits from a conventions description and furnace predictions.

    python scripts/bench/bench_audit.py [--cycles PATH] [--repeat N]

Prints, with the load average (the machine is shared: read the ratios, not the seconds):

* the audit of the shipped 32 x 32 Cycles table through its conventions file: nodes only, and with E_avg and the
  look-up error (target < 2 s);
* the furnace prediction over 32 roughnesses x 64 view cosines for the scale and Kulla-Conty methods (target < 1 s);
* a baseline measured in the same run: one 32-value GGX albedo column at rtol 1e-8 on one thread.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))

import pumpup  # noqa: E402
from pumpup import luts  # noqa: E402


def best(fn, repeat):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap.add_argument("--cycles", default=os.path.join(here, "tests", "data", "cycles_shader.tables"))
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f}; cores this process may use: "
          f"{len(os.sched_getaffinity(0))}")
    spec, param = luts.model_spec("ggx", "cycles")
    mu, rough = luts.nodes("cycles")
    f = luts._brdf(spec, param, rough[10])
    luts._albedo(f, mu, 1e-8, 400)  # compile / warm
    pumpup.audit(args.cycles, conventions="cycles")  # warm every path once
    pumpup.furnace_prediction("cycles", "kulla_conty", path=args.cycles)
    base = best(lambda: luts._albedo(f, mu, 1e-8, 400), args.repeat)
    print(f"baseline: one 32-value GGX column (rough = 10/31), one thread: {base:.3f} s")
    t = best(lambda: pumpup.audit(args.cycles, conventions="cycles", lookup_check=False, eavg=False), args.repeat)
    print(f"audit of the Cycles 32 x 32 table from its conventions, nodes: {t:.2f} s ({t / base:.1f} x baseline; "
          "target 2 s)")
    t = best(lambda: pumpup.audit(args.cycles, conventions="cycles"), args.repeat)
    print(f"  with E_avg and the look-up error: {t:.2f} s ({t / base:.1f} x baseline; target 2 s)")
    t0 = best(lambda: pumpup.audit(args.cycles, preset="cycles"), args.repeat)
    print(f"  the same through the preset: {t0:.2f} s (ratio conventions / preset {t / t0:.2f})")
    for method in ("scale", "kulla_conty"):
        t = best(lambda m=method: pumpup.furnace_prediction("cycles", m, path=args.cycles), args.repeat)
        print(f"furnace prediction ({method}), 32 roughnesses x 64 view cosines: {t:.2f} s ({t / base:.1f} x "
              "baseline; target 1 s)")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
