"""Benchmark of the exact images (pumpup.render): a 256 x 256 sphere and a furnace image.

    python scripts/bench/bench_render.py [--size 256] [--repeat 7]

Targets (issue 18): a sphere image under 0.1 s for the Phong family (one evaluation per
pixel), a furnace image under 0.2 s (one albedo table plus a look-up per pixel).  Timings
are best of ``--repeat``; the machine is shared, so every line also gives a ratio to a
baseline measured in the same run: for spheres, the model's bare kernel on the same pixel
directions (what is left is geometry and writing the image); for furnaces, one
``pumpup.albedo`` value at the table's tolerance (so the ratio counts albedo evaluations).
A furnace's first image in a session builds the albedo table (adaptive, down to mu = 1e-8)
and measures reciprocity and isotropy; later images of the same model (any size) only look
up: both are timed.
The load average is printed first.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))  # this checkout's pumpup

import pumpup  # noqa: E402
import pumpup.render as R  # noqa: E402


def best(fn, repeat):
    t = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        t.append(time.perf_counter() - t0)
    return min(t)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--repeat", type=int, default=7)
    args = ap.parse_args(argv)
    print(f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f} "
          f"on {os.cpu_count()} cores; size {args.size}")
    g = R.geometry(args.size)
    wi = g.to_local(R.light_direction(30.0))
    print(f"{'sphere, Phi_L = 30':38s} {'time [s]':>9s} {'bare kernel [s]':>16s} {'ratio':>6s}")
    for spec in ({"type": "phong", "n": 20}, {"type": "stretched_phong", "n": 20}, {"type": "phong_shader", "n": 20},
                 {"type": "blinn", "n": 20}, {"type": "ggx", "alpha": 0.3},
                 {"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g1", "levels": 3}):
        f = pumpup.load(spec)
        R.sphere(f, 30.0, args.size)  # compile / build tables outside the timing
        t = best(lambda: R.sphere(f, 30.0, args.size), args.repeat)
        t0 = best(lambda: f._eval(wi, g.view), args.repeat)
        print(f"{R.label(spec):38s} {t:9.4f} {t0:16.4f} {t / t0:6.1f}")
    R._GEOMETRY.clear()
    t_geo = best(lambda: (R._GEOMETRY.clear(), R.geometry(args.size)), 3)
    print(f"{'(geometry of a new size, once)':38s} {t_geo:9.4f}")

    print(f"\n{'furnace':34s} {'first [s]':>9s} {'again [s]':>9s} {'look-up [s]':>11s} {'nodes':>5s} "
          f"{'one albedo [s]':>14s} {'first / one':>11s}")
    pm = sys.modules["pumpup.operators.pumping"]
    for spec in ({"type": "lambert", "albedo": 0.8}, {"type": "phong", "n": 20}, {"type": "stretched_phong", "n": 20},
                 {"type": "ggx", "alpha": 0.3}):
        f = pumpup.load(spec)
        R.furnace(f, 16)  # compile outside the timing

        def fresh():  # forget the table and the reciprocity verdict: the first image of a session
            pm._TABLES.clear()
            R._TABLES.clear()
            R._TRANSPOSED.clear()
            R.furnace(f, args.size)

        t_first = best(fresh, max(1, args.repeat // 3))
        t_again = best(lambda: R.furnace(f, args.size), args.repeat)
        table, _, _ = R.furnace_table(f, float(g.view[:, 2].min()))
        t_look = best(lambda: table(g.view[:, 2]), args.repeat)
        t_one = best(lambda: pumpup.albedo(f, 0.5, rtol=1e-9), args.repeat)
        print(f"{R.label(spec):34s} {t_first:9.4f} {t_again:9.4f} {t_look:11.4f} {len(table.mu):5d} {t_one:14.5f} "
              f"{t_first / t_one:11.0f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
