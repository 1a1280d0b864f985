"""Benchmark of ``pumpup explore`` in headless chromium: slider release to every view redrawn, and page-ready time.

    python scripts/bench/bench_explore.py [--moves 20] [--cases phong,ggx,...] [--baseline DIR] [--ready-runs N]
                                          [--no-bytecode] [--swiftshader-compositing]

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

The views are the lobe, the albedo plot with its table of numbers, the spheres and the image slice (and the 3-D lobe
when it is on); the page updates its status line, URL, download links and code lines in the same task, so the same
frame shows them.

The browser is Debian's chromium, headless, with its own defaults: on a machine without a usable GPU (as this
benchmark's machines are) it composites and rasterises the page in software and runs WebGL 2 on SwiftShader, which
chrome://gpu reports as "Compositing: Software only" and "WebGL: Software only" (the first line printed says what
it found); on a machine with a GPU it uses the GPU.  ``--swiftshader-compositing`` starts it with
``--use-angle=swiftshader --enable-unsafe-swiftshader`` instead (as the browser tests do), which makes chromium take
SwiftShader for a GPU and composite every frame of the whole page through it: a configuration no user's browser
runs by itself, whose frames cost tens of milliseconds on a loaded CPU.

Before measuring, each checkout's kernels are compiled (``pumpup warmup``) and its Python modules byte-compiled
(``compileall``), as an installed or once-run pumpup has them; ``--no-bytecode`` removes the bytecode instead and sets
PYTHONDONTWRITEBYTECODE, so that every start compiles pumpup's modules from source (about 0.5 s of CPU).

``--baseline DIR`` runs a second explorer from another checkout (``git archive main | tar -x -C DIR``) in the same
browser and alternates the two move by move and start by start, so that both see the same load; the last columns are
its median and max, the ratio new/old, and its server and drawing medians.
"""

from __future__ import annotations

import argparse
import os
import re
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


def gpu_status(browser) -> str:
    """How chromium composites and runs WebGL, as chrome://gpu reports it."""
    page = browser.new_page()
    try:
        page.goto("chrome://gpu")
        page.wait_for_function("document.querySelector('info-view')?.shadowRoot?.textContent.includes('Compositing:')",
                               timeout=10_000)
        text = page.evaluate("document.querySelector('info-view').shadowRoot.textContent")
    except Exception as exc:  # chrome://gpu's layout is chromium's, not an interface: say so rather than stop
        return f"chrome://gpu not read ({type(exc).__name__})"
    finally:
        page.close()
    found = {k: re.search(rf"{k}: ([^*]*?)(?:\*|$)", text) for k in ("Compositing", "WebGL")}
    return "; ".join(f"{k}: {m.group(1).strip().rstrip('.')}" for k, m in found.items() if m)


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


def start(root: str, browser, env: dict) -> tuple:
    """Start ``pumpup explore`` from the checkout ``root`` and load its page in a new browser context; the page-ready
    time is from the command's start to the first answer drawn (``window.explore.ready``).

    Returns (process, url, page, seconds until the server printed its URL, seconds until the page was ready).
    """
    env = dict(env, PYTHONPATH=root + os.pathsep + os.environ.get("PYTHONPATH", ""))
    context = browser.new_context(viewport={"width": 1400, "height": 1000})
    page = context.new_page()
    t0 = time.perf_counter()
    # run in the checkout: ``python -m`` puts the working directory first on sys.path, before PYTHONPATH
    proc = subprocess.Popen([sys.executable, "-m", "pumpup.cli", "explore", "phong:n=20", "--port", "0",
                             "--no-browser"], stdout=subprocess.PIPE, text=True, env=env, cwd=root)
    line = proc.stdout.readline()
    url = line.split()[2]
    t_listen = time.perf_counter() - t0
    page.goto(url)
    page.wait_for_function("window.explore && window.explore.ready", timeout=120_000)
    ready = time.perf_counter() - t0
    with open(os.path.join(root, "pumpup", "explore", "static", "app.js"), encoding="utf-8") as fh:
        if page.request.get(url + "static/app.js").text() != fh.read():
            raise SystemExit(f"the explorer started for {root} serves another checkout's page")
    return proc, url, page, t_listen, ready


def open_case(page, url: str, query: str) -> None:
    """Load a case's page and record the states it sends (for the baseline of pumpup's own work)."""
    page.goto(url + "?" + query)
    page.wait_for_function("window.explore && window.explore.ready", timeout=120_000)
    page.evaluate("""() => { window.__states = []; const send = WebSocket.prototype.send;
        WebSocket.prototype.send = function (m) { try { window.__states.push(JSON.parse(m).state); }
        catch (e) {} return send.call(this, m); }; }""")


def move(page, slider: str, v: int) -> list | None:
    """One slider move: [ms to every view redrawn, server ms, draw ms], or None if the page sent nothing."""
    ms = page.evaluate(MOVE_JS, [slider, v])
    return None if ms == -1 else ms


def main(argv=None) -> int:
    """Print the page-ready time and, per case, the slider-to-redrawn times beside pumpup's own (and beside another
    checkout's, with ``--baseline``).
    """
    ap = argparse.ArgumentParser()
    ap.add_argument("--moves", type=int, default=20)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--baseline", metavar="DIR",
                    help="another checkout of pumpup (e.g. git worktree add DIR main, or git archive REV | tar -x "
                         "-C DIR): its explorer is measured too, alternating with this one's, move by move")
    ap.add_argument("--ready-runs", type=int, default=1,
                    help="page-ready measurements per checkout (alternating with --baseline); the median is printed")
    ap.add_argument("--no-bytecode", action="store_true",
                    help="remove pumpup's cached bytecode (__pycache__/*.pyc) of each checkout first and write none, "
                         "so that every start compiles pumpup's modules from source")
    ap.add_argument("--swiftshader-compositing", action="store_true",
                    help="start chromium with --use-angle=swiftshader --enable-unsafe-swiftshader, which composites "
                         "every frame through SwiftShader's GL as if it were a GPU, instead of chromium's own defaults "
                         "(on a machine without a GPU: software compositing, WebGL 2 on SwiftShader)")
    args = ap.parse_args(argv)
    if args.no_bytecode:
        os.environ["PYTHONDONTWRITEBYTECODE"] = "1"
    from playwright.sync_api import sync_playwright

    print(f"load average: {os.getloadavg()[0]:.2f} (1 min), {os.cpu_count()} cores")
    roots = {"new": ROOT}
    if args.baseline:
        roots["old"] = os.path.abspath(args.baseline)
    # warm numba's cache for the cases (the target is for a warm kernel cache), and Python's bytecode cache, which an
    # installed or once-imported pumpup has (unless PYTHONDONTWRITEBYTECODE is set, when every start compiles
    # pumpup's modules from source: --no-bytecode measures that)
    for root in roots.values():
        if args.no_bytecode:
            for folder, _, files in os.walk(os.path.join(root, "pumpup")):
                for name in files:
                    if name.endswith(".pyc"):
                        os.remove(os.path.join(folder, name))
        subprocess.run([sys.executable, "-m", "pumpup.cli", "warmup", "--quiet"], check=True, cwd=root,
                       env=dict(os.environ, PYTHONPATH=root + os.pathsep + os.environ.get("PYTHONPATH", "")))
        if not args.no_bytecode:
            subprocess.run([sys.executable, "-m", "compileall", "-q", os.path.join(root, "pumpup")], check=True)
    print(f"Python bytecode: {'compiled from source at every start (--no-bytecode)' if args.no_bytecode else 'cached'}"
          f"{' (PYTHONDONTWRITEBYTECODE is set)' if os.environ.get('PYTHONDONTWRITEBYTECODE') else ''}")
    with sync_playwright() as p:
        flags = ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"] if args.swiftshader_compositing else []
        browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=flags)
        print(f"chromium {browser.version}, {' '.join(flags) or 'its own defaults'}: {gpu_status(browser)}")
        running: dict[str, tuple] = {}
        try:
            ready: dict[str, list] = {k: [] for k in roots}
            listen: dict[str, list] = {k: [] for k in roots}
            for run in range(args.ready_runs):
                for key, root in roots.items():
                    if key in running:
                        running[key][0].terminate()
                        running[key][0].wait(10)
                        running[key][2].context.close()
                    running[key] = start(root, browser, os.environ)
                    listen[key].append(running[key][3])
                    ready[key].append(running[key][4])
            for key in roots:
                print(f"{key}: page ready {statistics.median(ready[key]):.2f} s after the command (server listening "
                      f"after {statistics.median(listen[key]):.2f} s; target < 2 s; median of "
                      f"{len(ready[key])}: {', '.join(f'{t:.2f}' for t in ready[key])})")
            print(f"{'case':22s} {'median ms':>10s} {'max ms':>8s} {'target':>7s} {'max/med':>8s} "
                  f"{'pumpup ms':>10s} {'ratio':>6s} {'server ms':>9s} {'draw ms':>8s}"
                  + (f" {'old med':>8s} {'old max':>8s} {'new/old':>8s} {'old srv':>8s} {'old draw':>8s}"
                     if args.baseline else ""))
            for name in args.cases.split(","):
                query, slider, target = CASES[name]
                for key in roots:
                    open_case(running[key][2], running[key][1], query)
                got: dict[str, list] = {k: [] for k in roots}
                for v in positions(args.moves):
                    for key in roots:  # alternating: both see the same load
                        ms = move(running[key][2], slider, v)
                        if ms is not None:
                            got[key].append(ms)
                page = running["new"][2]
                times = [m[0] for m in got["new"]]
                err = page.evaluate("document.getElementById('message').hidden")
                base = baseline(page, query, slider, len(times))
                med, mx, bmed = statistics.median(times), max(times), statistics.median(base)
                flag = "" if med < target and mx < 3 * med else "  MISSED"
                line = (f"{name:22s} {med:10.1f} {mx:8.1f} {target:7d} {mx / med:8.2f} {bmed:10.1f} "
                        f"{med / bmed:6.2f} {statistics.median(m[1] for m in got['new']):9.1f} "
                        f"{statistics.median(m[2] for m in got['new']):8.1f}")
                if args.baseline:
                    old = [m[0] for m in got["old"]]
                    line += (f" {statistics.median(old):8.1f} {max(old):8.1f} {med / statistics.median(old):8.2f}"
                             f" {statistics.median(m[1] for m in got['old']):8.1f}"
                             f" {statistics.median(m[2] for m in got['old']):8.1f}")
                print(line + flag + ("" if err else "  (error shown)"), flush=True)
        finally:
            for proc, *_ in running.values():
                proc.terminate()
                proc.wait(10)
            browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
