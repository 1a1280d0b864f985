"""Screenshots of ``pumpup explore`` for the docs (docs/_static/explore/*.png), taken in headless chromium.

    python scripts/make/explore_screenshots.py [--out docs/_static/explore]

Needs the ``explore`` extra, playwright and Debian's chromium.  The server runs in a thread of this process on a free
port; every picture is the page as a user sees it.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import threading
import urllib.parse

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, ROOT)  # this checkout's pumpup

from pumpup import explore  # noqa: E402

PUMPED = json.dumps({"type": "pumped", "base": {"type": "phong", "n": 20}, "g": "g2", "levels": 3})
SHOTS = {
    # file stem -> (URL query, element to capture or None for the whole page)
    "overview": ({"s": "phong:n=20", "pump": "g2:3", "kc": "1", "ti": "60"}, None),
    "compare": ({"s": ["phong:n=20", "stretched_phong:n=20", PUMPED, "ggx:alpha=0.3"], "ti": "60", "log": "1"}, None),
    "lobe": ({"s": ["phong:n=20", "stretched_phong:n=20"], "ti": "60", "pump": "g2:3"}, "#lobe"),
    "albedo": ({"s": ["phong:n=20", "ggx:alpha=0.5"], "pump": "g2:3", "kc": "1"}, "#albedo"),
    "spheres": ({"s": ["phong:n=20", "ggx:alpha=0.3", '{"type": "phong", "n": 20, "c": 6}'], "light": "40",
                 "laz": "30"}, "#spheres"),
    "slice": ({"s": ["phong:n=20", "ggx:alpha=0.3"], "log": "1"}, ".slice-row"),
}


def main(argv=None) -> int:
    """Save the screenshots (one line per file written)."""
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "_static", "explore"))
    args = ap.parse_args(argv)
    from playwright.sync_api import sync_playwright

    os.makedirs(args.out, exist_ok=True)
    stop, ready, urls = threading.Event(), threading.Event(), []
    t = threading.Thread(target=explore.serve, kwargs=dict(port=0, open_browser=False, stop=stop,
                                                         ready=lambda u: (urls.append(u), ready.set())), daemon=True)
    t.start()
    ready.wait(60)
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=shutil.which("chromium"),
                                        args=["--use-angle=swiftshader", "--enable-unsafe-swiftshader"])
            page = browser.new_page(viewport={"width": 1500, "height": 1150})
            for stem, (query, selector) in SHOTS.items():
                page.goto(urls[0] + "?" + urllib.parse.urlencode(query, doseq=True))
                page.wait_for_function("window.explore && window.explore.ready", timeout=300_000)
                page.wait_for_timeout(300)
                path = os.path.join(args.out, f"{stem}.png")
                (page.locator(selector) if selector else page).screenshot(path=path)
                print(path)
            # a bad spec: one message, the views keep the last good answer
            page.goto(urls[0] + "?s=phong:n=20")
            page.wait_for_function("window.explore && window.explore.ready", timeout=300_000)
            page.fill("#spec-text", "phong:n=-5")
            page.press("#spec-text", "Enter")
            page.wait_for_function("window.explore.drawnId === window.explore.sent")
            path = os.path.join(args.out, "bad-input.png")
            page.screenshot(path=path, clip={"x": 0, "y": 0, "width": 1500, "height": 420})
            print(path)
            browser.close()
    finally:
        stop.set()
        t.join(10)
    return 0


if __name__ == "__main__":
    sys.exit(main())
