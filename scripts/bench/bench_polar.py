"""The 1-D routes of frames 0-5 (pumpup/engine/outer_rule.py) against their baselines and a floor, same run.

Rows (257-point tables, mu uniform in theta over [0, 89.99] degrees, rtol 1e-10, thread CPU time, best of ``--rounds``
rounds in which every path runs once, alternating, so that they share the machine's load):

* issue 55's floor row: Phong n = 20 by the ``lobe`` route against a compiled fixed Gauss-Legendre rule with no error
  estimate on the same pieces (the engine's breakpoints and substitutions, :func:`pumpup.engine.outer_rule._pieces`),
  of the fewest points per piece whose values all lie within 1e-10 of the engine's at rtol 1e-14 (found first); the
  target is at most 2 x that floor;
* issue 49's row: Ashikhmin-Shirley nu = nv = 10, rs = 0.5 (``half_arc``), target under 20 ms;
* the other models of frames 0-5 in ``scripts/bench/bench_revisions.py``.

"old" is the same code with ``lobe_fresnel_gauss=False`` (Ashikhmin-Shirley's arcs by the adaptive 7/15 rule instead
of their closed form, frame 5's arcs by that rule instead of Gauss-Legendre pieces) and ``decay_estimate=False`` (the
``lobe`` route's closed forms by QUADPACK's estimate alone, without the one from the decay of the rule's coefficients);
the other rows show that nothing else moved.  The values of old and new must agree within their summed estimates.

    PYTHONPATH=. python scripts/bench/bench_polar.py [--rounds 15]
"""

import argparse
import math
import os
import time

import numpy as np
from numba import njit

import pumpup
from pumpup.engine import outer_rule as _outer
from pumpup.engine import polar as _polar
from pumpup.engine import routes as _routes
from pumpup.engine.hint_view import kernel_view
from pumpup.engine.lobe_frame import _k_closed

MU = np.sin(np.radians(90.0 - np.linspace(0.0, 89.99, 257)))
RTOL = 1e-10

SPECS = {
    "phong n=20": ({"type": "phong", "n": 20}, "2 x the floor"),
    "ashikhmin_shirley n=10 rs=0.5": ({"type": "ashikhmin_shirley", "nu": 10, "nv": 10, "rs": 0.5}, "< 20 ms"),
    "stretched_phong n=20": ({"type": "stretched_phong", "n": 20}, ""),
    "stretched_phong n=5000": ({"type": "stretched_phong", "n": 5000}, ""),
    "retro n=10": ({"type": "retro", "n": 10}, ""),
    "blinn n=50": ({"type": "blinn", "n": 50}, ""),
    "ward m=0.2": ({"type": "ward", "m": 0.2}, ""),
    "cook_torrance m=0.3": ({"type": "cook_torrance", "m": 0.3}, ""),
    "metal n=20 Au-like": ({"type": "metal", "n": 20, "eta": 0.2, "k": 3.0}, ""),
}


@njit(cache=True, nogil=True)
def _floor(n, p, mu_arr, x, wx, mp, out):  # pragma: no cover - compiled
    """Frame 0's integral by the fixed rule (``x``, ``wx`` on [0, 1]) on every piece, no estimate."""
    cap = _outer.PIECES_CAP
    kinds = np.empty(cap, np.int64)
    sms = np.empty(cap, np.int64)
    v0 = np.empty(cap)
    w = np.empty(cap)
    v1 = np.empty(cap)
    for q in range(mu_arr.shape[0]):
        mu = mu_arr[q]
        s = math.sqrt((1.0 - mu) * (1.0 + mu))
        k, c2, _ = _outer._pieces(0, 0, n, p, mu, s, kinds, sms, v0, w, v1, mp)
        tot = 0.0
        for i in range(k):
            if w[i] <= 0.0:
                continue
            for j in range(x.shape[0]):
                u, um, sa, fac = _outer._u_at(kinds[i], sms[i], n, v0[i], w[i], v1[i], x[j])
                tot += wx[j] * _k_closed(p, mu, c2, u, um, sa)[0] * fac
        out[q] = tot


def floor_rule(hint):
    """(the floor as a function of no arguments, its points per piece, its mean points per mu)."""
    view = kernel_view(hint)
    n, p = float(view.n), float(view.p)
    mp = np.zeros(64)
    scale = np.asarray(view.scale(MU), dtype=float)
    ref = _polar.run("lobe", hint, MU, 1e-14, 0.0, 10000)[0] / scale
    out = np.empty(MU.size)
    for order in range(4, 41):
        x, wx = np.polynomial.legendre.leggauss(order)
        x, wx = 0.5 * (x + 1.0), 0.5 * wx
        _floor(n, p, MU, x, wx, mp, out)
        if np.all(np.abs(out - ref) <= RTOL * np.abs(ref)):
            break
    cap = _outer.PIECES_CAP
    kinds, sms = np.empty(cap, np.int64), np.empty(cap, np.int64)
    v0, w, v1 = np.empty(cap), np.empty(cap), np.empty(cap)
    live = []
    for m in MU:
        k = _outer._pieces(0, 0, n, p, m, math.sqrt((1 - m) * (1 + m)), kinds, sms, v0, w, v1, mp)[0]
        live.append(int(np.sum(w[:k] > 0)))
    pieces = float(np.mean(live))
    return (lambda: _floor(n, p, MU, x, wx, mp, out)), order, order * pieces


def main():
    """Print every row, old, new (and the floor) alternating."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=15)
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; 257-point tables at rtol {RTOL:g}, "
          f"thread CPU time, best of {args.rounds} alternating rounds")
    for name, (spec, target) in SPECS.items():
        f = pumpup.load(spec)
        hint = f.azimuth_hint()
        parts = [(r, m) for r, m in _routes.hint_routes(hint, MU, None)]
        if len(parts) != 1 or parts[0][0] not in _polar._FRAMES:
            print(f"{name:32s} not on frames 0-5 ({[r for r, _ in parts]}), skipped")
            continue
        route = parts[0][0]
        paths = {
            "old": lambda: _polar.run(route, hint, MU, RTOL, 0.0, 10000, lobe_fresnel_gauss=False,
                                      decay_estimate=False),
            "new": lambda: _polar.run(route, hint, MU, RTOL, 0.0, 10000),
        }
        floor_order = None
        if name == "phong n=20":
            paths["floor"], floor_order, floor_nodes = floor_rule(hint)
        res = {k: fn() for k, fn in paths.items()}  # (compiles / loads every kernel)
        best = dict.fromkeys(paths, math.inf)
        for r in range(args.rounds):
            for key in (list(paths) if r % 2 == 0 else list(paths)[::-1]):
                t = time.thread_time()
                out = paths[key]()
                best[key] = min(best[key], time.thread_time() - t)
                if key != "floor":
                    res[key] = out
        (vo, eo, _, evo), (vn, en, _, evn) = res["old"], res["new"]
        agree = bool(np.all(np.abs(vn - vo) <= eo + en))
        line = (f"{name:32s} {route:9s} old {best['old'] * 1e3:7.2f} ms ({evo.mean():5.1f} ev/mu)  new "
                f"{best['new'] * 1e3:7.2f} ms ({evn.mean():5.1f} ev/mu)  new/old {best['new'] / best['old']:4.2f}  "
                f"agree within summed errors: {agree}")
        if floor_order is not None:
            line += (f"\n{'':32s} floor: {floor_order}-point Gauss-Legendre per piece, {floor_nodes:.1f} nodes/mu, "
                     f"{best['floor'] * 1e3:.3f} ms; old {best['old'] / best['floor']:.2f} x, new "
                     f"{best['new'] / best['floor']:.2f} x the floor (target {target})")
        elif target:
            line += f"  (target {target})"
        print(line, flush=True)
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
