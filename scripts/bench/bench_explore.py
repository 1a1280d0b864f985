"""Benchmark of ``pumpup explore`` in headless chromium: slider release to every view redrawn, and page-ready time.

    python scripts/bench/bench_explore.py [--moves 20] [--cases phong,ggx,...]

Targets (issue 54): from a slider release to every view redrawn (lobe, albedo with its table, spheres, slice), over
20 moves: the Phong family under 100 ms, every other built-in model under 300 ms, a 3-level pumped model under
500 ms (median; max under 3x the median); the page ready under 2 s after the command with a warm kernel cache.

A move sets a parameter's slider to a new value and fires its ``input`` and ``change`` events (the release); the
time runs until the page has drawn the answer to that value and the browser has painted a frame.  Every move gives a
new parameter value (no cache hit).  The machine is shared, so every case also prints the baseline measured in the
same run: ``pumpup.explore.compute.compute`` of the same states called in this process (pumpup's own work); the
ratio is what the server, the socket and the drawing add.  ``server ms`` is the server's time for the request (its
queue included) and ``draw ms`` the page's plotting and WebGL time, both medians.  Needs the ``explore`` extra,
playwright and Debian's chromium.  The load average is printed first.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, ROOT)  # this checkout's pumpup

from pumpup.explore import compute as C  # noqa: E402

#: case name -> (URL query, slider id, slider positions to cycle through (0..1000), target ms)
CASES = {
    "phong": ("s=phong:n=20", "param-n", 100),
    "stretched_phong": ("s=stretched_phong:n=20", "param-n", 100),
    "blinn": ("s=blinn:n=20", "param-n", 300),
    "ward": ("s=ward:m=0.1", "param-m", 300),
    "ggx": ("s=ggx:alpha=0.2", "param-alpha", 300),
    "beckmann": ("s=beckmann:alpha=0.2", "param-alpha", 300),
    "cook_torrance": ("s=cook_torrance:m=0.2", "param-m", 300),
    "schlick": ("s=schlick:r=0.3", "param-r", 300),
    "lambert": ("s=lambert:albedo=0.5", "param-albedo", 300),
    "pumped phong g2 x3": ("s=phong:n=20&pump=g2:3", "param-n", 500),
}

MOVE_JS = """async ([id, v]) => {
  const e = document.getElementById(id);
  e.focus();  // as under the user's pointer: the page does not rebuild the control being dragged
  const before = window.explore.sent;
  const t0 = performance.now();
  e.value = v;
  e.dispatchEvent(new Event('input', {bubbles: true}));
  e.dispatchEvent(new Event('change', {bubbles: true}));
  const want = window.explore.sent;
  if (want === before) return -1;
  while (window.explore.drawnId !== want) await new Promise((r) => setTimeout(r, 1));
  await new Promise((r) => requestAnimationFrame(() => r()));
  const d = window.explore.drawMs;
  return [performance.now() - t0, window.explore.serverMs, d.lobe + d.albedo + d.spheres + d.slice + d.lobe3d];
}"""


def positions(moves: int) -> list[int]:
    """Slider positions (of 1000): every move a new value, around the middle of the range."""
    return [400 + 9 * k if k % 2 == 0 else 600 - 9 * k for k in range(moves)]


def baseline(page, query: str, slider: str, moves: int) -> list[float]:
    """The time of pumpup's own work for the states the page sent: compute() in this process [ms]."""
    states = page.evaluate("window.__states")
    out = []
    for st in states[-moves:]:
        t0 = time.perf_counter()
        C.compute(st)
        out.append(1e3 * (time.perf_counter() - t0))
    return out


def main(argv=None) -> int:
    """Print the page-ready time and, per case, the slider-to-redrawn times beside pumpup's own."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--moves", type=int, default=20)
    ap.add_argument("--cases", default=",".join(CASES))
    args = ap.parse_args(argv)
    from playwright.sync_api import sync_playwright

    print(f"load average: {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} cores")
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    # warm numba's cache for the cases (the target is for a warm kernel cache)
    subprocess.run([sys.executable, "-m", "pumpup.cli", "warmup", "--quiet"], env=env, check=True)
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=shutil.which("chromium"),
                                    args=["--use-angle=swiftshader", "--enable-unsafe-swiftshader"])
        context = browser.new_context(viewport={"width": 1400, "height": 1000})
        page = context.new_page()
        # page ready: from the command's start to the first answer drawn
        t0 = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-m", "pumpup.cli", "explore", "phong:n=20", "--port", "0",
                                 "--no-browser"], stdout=subprocess.PIPE, text=True, env=env)
        try:
            line = proc.stdout.readline()
            url = line.split()[2]
            t_listen = time.perf_counter() - t0
            page.goto(url)
            page.wait_for_function("window.explore && window.explore.ready", timeout=120_000)
            t_ready = time.perf_counter() - t0
            print(f"page ready {t_ready:.2f} s after the command (server listening after {t_listen:.2f} s; "
                  "target < 2 s)")
            print(f"{'case':22s} {'median ms':>10s} {'max ms':>8s} {'target':>7s} {'max/med':>8s} "
                  f"{'pumpup ms':>10s} {'ratio':>6s} {'server ms':>9s} {'draw ms':>8s}")
            for name in args.cases.split(","):
                query, slider, target = CASES[name]
                page.goto(url + "?" + query)
                page.wait_for_function("window.explore && window.explore.ready", timeout=120_000)
                page.evaluate("""() => { window.__states = []; const send = WebSocket.prototype.send;
                    WebSocket.prototype.send = function (m) { try { window.__states.push(JSON.parse(m).state); }
                    catch (e) {} return send.call(this, m); }; }""")
                times, server, drawing = [], [], []
                for v in positions(args.moves):
                    ms = page.evaluate(MOVE_JS, [slider, v])
                    if ms != -1:
                        times.append(ms[0])
                        server.append(ms[1])
                        drawing.append(ms[2])
                err = page.evaluate("document.getElementById('message').hidden")
                base = baseline(page, query, slider, len(times))
                med, mx, bmed = statistics.median(times), max(times), statistics.median(base)
                flag = "" if med < target and mx < 3 * med else "  MISSED"
                print(f"{name:22s} {med:10.1f} {mx:8.1f} {target:7d} {mx / med:8.2f} {bmed:10.1f} "
                      f"{med / bmed:6.2f} {statistics.median(server):9.1f} {statistics.median(drawing):8.1f}"
                      f"{flag}{'' if err else '  (error shown)'}")
        finally:
            proc.terminate()
            proc.wait(10)
        browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
