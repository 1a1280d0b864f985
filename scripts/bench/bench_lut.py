#!/usr/bin/env python
"""Timings of issue 16: renderer look-up tables (pumpup.luts).

    python scripts/bench/bench_lut.py [--cycles PATH] [--repeat N]

Prints, with the load average (the machine is shared: read the ratios, not the seconds):

* the 32 x 32 GGX E table of the Cycles preset at rtol 1e-8 (nodes only; target < 1 s on 2 cores);
* the 128 x 128 Filament DFG (E and the Fc-weighted B at every texel; target < 2 s, issue 55): the whole
  ``pumpup.lut("ggx", preset="filament")`` (look-up check included), and its nodes at rtol 1e-8, each against the
  baseline whose B takes the nested quadrature of eval (``luts._NestedSchlickWeighted``), old and new alternating;
* an audit of the shipped Cycles table (nodes at rtol 1e-7; target < 2 s), and the same with the
  E_avg and look-up checks, which cost more;
* a baseline measured in the same run: one 32-value GGX albedo column at rtol 1e-8 on one
  thread, so the other numbers can be read as multiples of it.
"""

from __future__ import annotations

import argparse
import math
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


def best_cpu(fn, repeat):
    """(wall, CPU) seconds of the run with the least CPU: the process's CPU time over all threads (on a loaded machine
    CPU / cores is what the wall time would be on an idle one, for work that keeps every core busy).
    """
    out = (math.inf, math.inf)
    for _ in range(repeat):
        w, c = time.perf_counter(), time.process_time()
        fn()
        w, c = time.perf_counter() - w, time.process_time() - c
        out = min(out, (w, c), key=lambda x: x[1])
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    default = os.path.join(here, "tests", "data", "cycles_shader.tables")  # Cycles' shipped tables
    ap.add_argument("--cycles", default=default, help="the shipped Cycles shader.tables")
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()

    print(f"load average before: {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f}; cores this process may use: "
          f"{len(os.sched_getaffinity(0))}")
    spec, param = luts.model_spec("ggx", "cycles")
    mu, rough = luts.nodes("cycles")
    f = luts._brdf(spec, param, rough[10])
    luts._albedo(f, mu, 1e-8, 400)  # compile / warm
    pumpup.lut("ggx", preset=luts.PRESETS["bsdl"], lookup_check=False)  # warm the split and the threads

    base = best(lambda: luts._albedo(f, mu, 1e-8, 400), args.repeat)
    print(f"baseline: one 32-value GGX column (rough = 10/31), one thread: {base:.3f} s")

    t = best(lambda: pumpup.lut("ggx", preset="cycles", rtol=1e-8, eavg=False, lookup_check=False), args.repeat)
    print(f"cycles 32 x 32 E at rtol 1e-8: {t:.2f} s  ({t / base:.1f} x baseline; target 1 s)")

    fspec, fparam = luts.model_spec("ggx", "filament")
    fmu, frough = luts.nodes("filament")
    nested = luts._NestedSchlickWeighted

    def filament_old(rtol):
        """The whole table as before: B by the nested quadrature (the nodes, then the rest of lut on the new path's
        nodes, which does not depend on how B was found).
        """
        luts.truth_grid(fspec, fparam, fmu, frough, rtol=rtol, split=True, _weighted=nested)

    def filament_new(rtol):
        luts.truth_grid(fspec, fparam, fmu, frough, rtol=rtol, split=True)

    rows = {"old": {}, "new": {}}
    for rtol in (1e-6, 1e-8):
        for _ in range(args.repeat):  # alternating, so both see the same load
            for name, fn in (("old", filament_old), ("new", filament_new)):
                t = best_cpu(lambda fn=fn, rtol=rtol: fn(rtol), 1)
                rows[name][rtol] = min(rows[name].get(rtol, (math.inf, math.inf)), t, key=lambda x: x[1])
    t_lut = best_cpu(lambda: pumpup.lut("ggx", preset="filament"), 1)
    # lut's storage and look-up check, the same on either path
    rest = (t_lut[0] - rows["new"][1e-6][0], t_lut[1] - rows["new"][1e-6][1])
    ncores = len(os.sched_getaffinity(0))
    print(f"{'filament 128 x 128 DFG (wall s; CPU s / ' + str(ncores) + ' cores)':50s} {'target':>6s} "
          f"{'old':>14s} {'new':>14s} {'old/new CPU':>12s}")

    def row(label, o, n):
        print(f"{label:50s} {'2 s':>6s} {o[0]:6.2f} {o[1] / ncores:6.2f}  {n[0]:6.2f} {n[1] / ncores:6.2f}  "
              f"{o[1] / n[1]:11.2f}")

    row("  pumpup.lut(ggx, preset=filament)", (rows["old"][1e-6][0] + rest[0], rows["old"][1e-6][1] + rest[1]), t_lut)
    for rtol in (1e-6, 1e-8):
        row(f"  nodes (E, B) at rtol {rtol:g}", rows["old"][rtol], rows["new"][rtol])

    if args.cycles:
        t = best(lambda: pumpup.audit(args.cycles, preset="cycles", lookup_check=False, eavg=False), args.repeat)
        print(f"audit of {os.path.basename(args.cycles)}, the 1024 nodes at rtol 1e-7: {t:.2f} s  "
              f"({t / base:.1f} x baseline; target 2 s)")
        t = best(lambda: pumpup.audit(args.cycles, preset="cycles"), 1)
        print(f"  with E_avg and the look-up error: {t:.2f} s")
    else:
        print("no Cycles table found (give --cycles PATH)")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
