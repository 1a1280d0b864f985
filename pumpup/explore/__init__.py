"""``pumpup explore``: look at a BRDF, its albedo, and what pumping and compensation do to it, live in the browser.

A local web application (Starlette served by uvicorn; the plots drawn on the page's own canvases; plotly.js from the
installed ``plotly`` package for the 3-D lobe; the lit sphere in WebGL 2): nothing is fetched from the network at run
time.  Needs the ``explore`` extra
(``pip install 'pumpup[explore]'``).

>>> from pumpup.explore import compute
>>> r = compute.compute({"specs": ["lambert:albedo=0.5"], "theta_i": 30})
>>> round(r["models"][0]["mean_albedo"], 12)
0.5

The views are computed by :mod:`pumpup.explore.compute` (plain pumpup calls, testable without a browser) and served
by :mod:`pumpup.explore.server`.
"""

from __future__ import annotations

import socket
import sys
import threading
from collections.abc import Callable

__all__ = ["LOCAL_HOSTS", "bind", "serve"]

#: hosts that only this machine reaches: any other host gets a warning
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")
DEFAULT_PORT = 8765


def bind(host: str = "127.0.0.1", port: int = DEFAULT_PORT) -> socket.socket:
    """A listening TCP socket on ``host``:``port`` (port 0: a free one); an OSError naming the port if it is taken."""
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise ValueError(f"--port must be an integer in [0, 65535], got {port!r}")
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    sock = socket.socket(family, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
    except OSError as exc:
        sock.close()
        raise OSError(f"cannot listen on {host}:{port} ({exc.strerror}); pass --port 0 for a free port") from None
    sock.listen(128)
    sock.setblocking(False)
    return sock


def serve(specs: list[str] | None = None, *, host: str = "127.0.0.1", port: int = DEFAULT_PORT,
          open_browser: bool = True, time_limit: float | None = None, ready: Callable[[str], None] | None = None,
          stop: threading.Event | None = None) -> None:
    """Serve the explorer until Ctrl-C (or until ``stop`` is set).

    Parameters
    ----------
    specs : list of str, optional
        One to four model specs the page opens with (short or JSON form); checked before the server starts.
    host : str
        The address to listen on; by default 127.0.0.1 (this machine only).  Any other host prints a one-line
        warning on stderr: every machine that reaches it can use the explorer.
    port : int
        The port (0: a free port; the URL printed says which).
    open_browser : bool
        Open the page in the default web browser.
    time_limit : float, optional
        Seconds one computation may take (default :data:`pumpup.explore.server.TIME_LIMIT`).
    ready : callable, optional
        Called with the page's URL once the server listens (by default the URL is printed).
    stop : threading.Event, optional
        Set it to stop the server (for tests and embedding).
    """
    import asyncio

    from . import server

    sock = bind(host, port)
    # the specs are checked before anything is served (a bad one: an error and no URL); once uvicorn runs, the page's
    # first answer computes in the server's threads while the page loads
    try:
        app = server.create_app(specs, time_limit=server.TIME_LIMIT if time_limit is None else float(time_limit),
                                allowed_hosts=None if host in LOCAL_HOSTS else ["*"])
    except BaseException:
        sock.close()
        raise
    if host not in LOCAL_HOSTS:
        print(f"pumpup explore: warning: listening on {host}, so other machines that reach it can use the explorer",
              file=sys.stderr)
    import uvicorn

    actual = sock.getsockname()[1]
    shown = f"[{host}]" if ":" in host else host
    url = f"http://{shown}:{actual}/"
    config = uvicorn.Config(app, log_level="warning", ws="websockets-sansio", lifespan="on")
    srv = uvicorn.Server(config)

    async def run() -> None:
        task = asyncio.create_task(srv.serve(sockets=[sock]))
        while not srv.started and not task.done():
            await asyncio.sleep(0.01)
        if srv.started:
            (ready or (lambda u: print(f"pumpup explore: {u} (Ctrl-C stops it)", flush=True)))(url)
            if open_browser:
                import webbrowser

                webbrowser.open(url)
        while stop is not None and not task.done():
            if stop.is_set():
                srv.should_exit = True
                break
            await asyncio.sleep(0.05)
        await task

    try:
        asyncio.run(run())
    finally:
        sock.close()
