"""The explorer's web server: a Starlette application served by uvicorn, everything offline.

Routes
------
``GET /``
    The page (``static/index.html``), its script and style (``/static/...``) and plotly.js (which the page loads
    for the 3-D lobe only), served from the installed ``plotly`` package (``plotly/package_data/plotly.min.js``):
    nothing is fetched from elsewhere.
``GET /api/models``
    The registered models and their parameters (:func:`pumpup.explore.compute.model_catalog`).
``WS /ws``
    One connection per browser tab, holding that tab's state only.  The page sends ``{"id": n, "state": {...}}``;
    the server answers ``{"id": n, "ok": true, "result": {...}, "ms": ...}`` or ``{"id": n, "ok": false, "error":
    "one line"}``.  A newer message supersedes the computation still running for the same tab (it stops at its next
    view and answers ``{"id": n, "cancelled": true}``); each computation has a time bound.
``GET /download/{kind}?spec=...``
    ``spec.json``, ``albedo.nc`` (``pumpup.tabulate`` written by ``pumpup.write_table`` to a temporary directory
    that is removed once the bytes are read), ``shader.glsl`` and ``shader.brdf`` (``pumpup.shader``, targets
    glsl-es and brdf-explorer), ``mitsuba.json`` (``pumpup.mitsuba.bsdf_dict``) and ``lut?preset=...`` (a
    renderer's table, ``pumpup.lut`` written by ``pumpup.luts.write_lut``, for the models with a roughness).  The
    server writes no other file.  Requests must name this machine in their Host header (or the host given to
    ``--host``).
"""

from __future__ import annotations

import asyncio
import contextlib
import importlib.util
import json
import os
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from importlib import resources
from typing import Any

from ..core import SpecError
from . import compute as C

#: seconds one computation may take before the page is told so and its work is stopped at the next view
TIME_LIMIT = 60.0
#: threads that compute (the numba kernels hold the GIL for short calls; two keep one tab from blocking the rest)
WORKERS = 2
#: the model the page opens with when the command names none
DEFAULT_SPEC = "phong:n=20"

_STATIC = resources.files(__package__) / "static"


def plotly_js_path() -> str:
    """The path of plotly.min.js inside the installed ``plotly`` package, found without importing the package (an
    ImportError naming the extra if it is not installed).
    """
    spec = importlib.util.find_spec("plotly")
    if spec is None or not spec.origin:
        raise ImportError("pumpup explore needs the 'explore' extra: pip install 'pumpup[explore]'")
    path = os.path.join(os.path.dirname(spec.origin), "package_data", "plotly.min.js")
    if not os.path.exists(path):
        raise ImportError(f"the installed plotly package has no bundled plotly.min.js at {path}")
    return path


def load_numba_registries() -> None:
    """Load numba's CPU lowering registries (what its first compile or cache load does) without importing
    ``scipy.linalg``.

    numba.np.arraymath, one of those registries, checks at import that BLAS is there by importing
    ``scipy.linalg.cython_blas``, which imports all of ``scipy.linalg`` (0.3 to 0.5 s, most of it scipy's array-API
    layer importing ``numpy.f2py``).  pumpup's kernels call no BLAS.  Where scipy ships ``cython_blas`` (the check
    would pass), the check is answered by an empty placeholder module for the time of that one import, and the
    placeholder is removed before anything else can see it; numba imports the real module when a kernel that uses BLAS
    is compiled or run.  Call it before any numba kernel runs and while no other thread imports scipy (the explorer
    calls it first thing in its first computation); once the registries are loaded it does nothing.
    """
    import sys
    import types

    name = "scipy.linalg.cython_blas"
    if "numba.np.arraymath" in sys.modules or name in sys.modules:
        return
    spec = importlib.util.find_spec("scipy")
    if spec is None or not spec.submodule_search_locations:
        return
    folders = [os.path.join(p, "linalg") for p in spec.submodule_search_locations]
    if not any(f.startswith("cython_blas.") and f.endswith((".so", ".pyd"))
               for d in folders if os.path.isdir(d) for f in os.listdir(d)):
        return  # no BLAS from scipy: numba's own check says so
    placeholder = types.ModuleType(name)
    sys.modules[name] = placeholder
    try:
        import numba.np.arraymath  # noqa: F401
    finally:
        if sys.modules.get(name) is placeholder:
            del sys.modules[name]


class Session:
    """One tab's connection: the generation of its newest request (nothing else is kept between requests)."""

    def __init__(self) -> None:
        self.generation = 0


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


def create_app(initial_specs: list[str] | None = None, *, time_limit: float = TIME_LIMIT, workers: int = WORKERS,
               allowed_hosts: list[str] | None = None):
    """The Starlette application.

    Parameters
    ----------
    initial_specs : list of str, optional
        Specs the page opens with when its URL names none (checked here: a SpecError before the server starts).
    time_limit : float
        Seconds one computation may take.
    workers : int
        Threads that compute.
    allowed_hosts : list of str, optional
        Host names the requests may name (their ``Host`` header, so a web page elsewhere cannot reach a local server
        through a name that resolves to 127.0.0.1); by default this machine's names.
    """
    from starlette.applications import Starlette
    from starlette.responses import HTMLResponse, JSONResponse, PlainTextResponse, Response
    from starlette.routing import Route, WebSocketRoute
    from starlette.websockets import WebSocket, WebSocketDisconnect

    initial = []
    for s in initial_specs or []:
        initial.append(C.short_spec(C.check_spec(s).spec))
    if len(initial) > C.MAX_COMPARE:
        raise SpecError(f"pumpup explore: at most {C.MAX_COMPARE} specs, got {len(initial)}")
    plotly_path = plotly_js_path()  # (an ImportError before the server starts if plotly is missing)
    plotly_js: list[bytes] = []  # read on its first request (the 3-D lobe), then sent in one piece from memory
    pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="pumpup-explore")
    catalog: dict[str, Any] = {}

    lock = threading.Lock()
    compute_lock = threading.Lock()
    # the page's first request, computed while the page loads (numba's kernels load from its cache on first use):
    # the answer waits here for the page's identical first request
    first_state = {"specs": initial or [DEFAULT_SPEC]}
    prefetched: dict[str, Any] = {}

    def state_key(state: Any) -> str | None:
        try:
            return json.dumps(C.check_state(state), sort_keys=True, default=str)
        except (SpecError, ValueError, TypeError):
            return None

    def prefetch() -> None:
        with compute_lock:
            try:
                load_numba_registries()
                prefetched[state_key(first_state)] = C.compute(first_state, deadline=time.monotonic() + time_limit)
            except Exception:  # noqa: BLE001 - the page's own request reports any error
                pass


    def models() -> list:
        with lock:
            if "models" not in catalog:
                catalog["models"] = C.model_catalog()
            return catalog["models"]

    async def index(request):
        html = (_STATIC / "index.html").read_text(encoding="utf-8")
        boot = json.dumps({"initial": initial or [DEFAULT_SPEC], "time_limit": time_limit})
        return HTMLResponse(html.replace("/*BOOT*/{}", boot))

    async def static(request):
        name = request.path_params["name"]
        if name == "plotly.min.js":  # 4.8 MB that never changes while the server runs: the browser keeps it
            if not plotly_js:
                with open(plotly_path, "rb") as fh:
                    plotly_js.append(fh.read())
            return Response(plotly_js[0], media_type="text/javascript",
                            headers={"Cache-Control": "max-age=86400, immutable"})
        if name not in ("app.js", "app.css"):
            return PlainTextResponse("not found", status_code=404)
        media = "text/javascript" if name.endswith(".js") else "text/css"
        return Response((_STATIC / name).read_text(encoding="utf-8"), media_type=media)

    async def api_models(request):
        loop = asyncio.get_running_loop()
        return JSONResponse(await loop.run_in_executor(pool, models))

    async def ws(websocket: WebSocket):
        await websocket.accept()
        session = Session()
        loop = asyncio.get_running_loop()
        tasks: set = set()

        async def answer(msg_id: Any, state: Any, generation: int) -> None:
            t0 = time.monotonic()
            deadline = t0 + time_limit

            def work():
                with compute_lock:  # one computation at a time (the GIL and pumpup's warnings capture)
                    if prefetched:
                        done = prefetched.pop(state_key(state), None)
                        prefetched.clear()  # used once, by the first request only
                        if done is not None:
                            return done
                    return C.compute(state, cancel=lambda: session.generation != generation, deadline=deadline)

            try:
                result = await asyncio.wait_for(loop.run_in_executor(pool, work), timeout=time_limit + 1.0)
                reply = {"id": msg_id, "ok": True, "result": result, "ms": 1e3 * (time.monotonic() - t0)}
            except C.Cancelled:
                reply = {"id": msg_id, "cancelled": True}
            except (C.TimeLimit, asyncio.TimeoutError):
                reply = {"id": msg_id, "ok": False,
                         "error": f"the computation took longer than the time limit, {time_limit:g} s, and was "
                                  "stopped (pumpup explore --time-limit raises it; the first use of a model compiles "
                                  "its kernels: run 'pumpup warmup' once)"}
            except (SpecError, ValueError, TypeError, ArithmeticError) as exc:
                reply = {"id": msg_id, "ok": False, "error": _one_line(exc)}
            except Exception as exc:  # a bug in a view must not end the tab's connection
                reply = {"id": msg_id, "ok": False, "error": _one_line(f"internal error: {type(exc).__name__}: {exc}")}
            if session.generation != generation and "cancelled" not in reply:
                reply = {"id": msg_id, "cancelled": True}
            try:
                await websocket.send_text(json.dumps(reply, allow_nan=False, default=float))
            except (RuntimeError, WebSocketDisconnect):
                pass
            except ValueError as exc:  # a NaN or infinity in a view: say so rather than send invalid JSON
                await websocket.send_text(json.dumps({"id": msg_id, "ok": False,
                                                      "error": _one_line(f"a view holds a non-finite number: {exc}")}))

        try:
            while True:
                text = await websocket.receive_text()
                try:
                    msg = json.loads(text)
                    if not isinstance(msg, dict) or "state" not in msg:
                        raise ValueError("a message must be a JSON object with 'id' and 'state'")
                except ValueError as exc:
                    await websocket.send_text(json.dumps({"id": None, "ok": False,
                                                          "error": _one_line(f"bad message: {exc}")}))
                    continue
                session.generation += 1
                task = asyncio.create_task(answer(msg.get("id"), msg["state"], session.generation))
                tasks.add(task)
                task.add_done_callback(tasks.discard)
        except WebSocketDisconnect:
            session.generation += 1  # stop this tab's running work at its next view
            for t in tasks:
                t.cancel()

    async def download(request):
        kind = request.path_params["kind"]
        text = request.query_params.get("spec", "")
        loop = asyncio.get_running_loop()
        try:
            f = C.check_spec(text)
        except (SpecError, ValueError) as exc:
            return PlainTextResponse(_one_line(exc), status_code=400)
        stem = C.short_spec(f.spec).split(":")[0]
        if kind == "spec.json":
            body, media, name = json.dumps(f.spec, indent=2) + "\n", "application/json", f"{stem}.json"
        elif kind == "mitsuba.json":
            from .. import mitsuba as pm

            body, media, name = json.dumps(pm.bsdf_dict(f.spec), indent=2) + "\n", "application/json", \
                f"{stem}-mitsuba.json"
        elif kind in ("shader.glsl", "shader.brdf"):
            if importlib.util.find_spec("pumpup.shaders") is None:
                return PlainTextResponse("this pumpup has no shader export (pumpup.shader)", status_code=404)
            from .. import shaders

            target = "glsl-es" if kind == "shader.glsl" else "brdf-explorer"
            try:
                body = shaders.shader(f.spec, target=target)
            except (SpecError, ValueError) as exc:
                return PlainTextResponse(_one_line(exc), status_code=400)
            media, name = "text/plain", f"{stem}.{kind.split('.')[1]}"
        elif kind == "albedo.nc":
            def table() -> bytes:
                import pumpup

                ds = pumpup.tabulate(f, progress=False, max_seconds=time_limit)
                with tempfile.TemporaryDirectory(prefix="pumpup-explore-") as tmp:
                    path = pumpup.write_table(ds, os.path.join(tmp, "albedo.nc"))
                    with open(path, "rb") as fh:
                        return fh.read()

            try:
                body = await asyncio.wait_for(loop.run_in_executor(pool, table), timeout=time_limit)
            except (asyncio.TimeoutError, TimeoutError):  # pumpup's BudgetExceeded is a TimeoutError
                return PlainTextResponse(f"the table took longer than the time limit, {time_limit:g} s",
                                         status_code=503)
            except (SpecError, ValueError) as exc:
                return PlainTextResponse(_one_line(exc), status_code=400)
            media, name = "application/x-netcdf", f"{stem}-albedo.nc"
        elif kind == "lut":
            from .. import luts

            preset = request.query_params.get("preset", "cycles")
            ext = {"c": "h", "netcdf": "nc", "npy": "npy", "exr": "exr", "filament": "inc"}
            if preset not in luts.PRESETS:
                return PlainTextResponse(f"preset must be one of {', '.join(luts.PRESETS)}, got {preset!r}",
                                         status_code=400)
            if f.type not in luts.ROUGH_PARAM:
                return PlainTextResponse(f"a renderer's table is made over the roughness of "
                                         f"{', '.join(luts.ROUGH_PARAM)}; {f.type} has none", status_code=400)
            name = f"{stem}-{preset}.{ext.get(luts.PRESETS[preset].fmt, 'dat')}"

            # the table's axis sets the roughness; the preset sets the shadowing unless the spec gives one
            given = {k: v for k, v in C.parse_spec_any(text).items() if k != luts.ROUGH_PARAM[f.type]}

            def table() -> bytes:
                ds = luts.lut(given, preset=preset, max_seconds=time_limit)
                with tempfile.TemporaryDirectory(prefix="pumpup-explore-") as tmp:
                    path = luts.write_lut(ds, os.path.join(tmp, name))
                    with open(path, "rb") as fh:
                        return fh.read()

            try:
                body = await asyncio.wait_for(loop.run_in_executor(pool, table), timeout=time_limit + 1.0)
            except (asyncio.TimeoutError, TimeoutError):
                return PlainTextResponse(f"the table took longer than the time limit, {time_limit:g} s",
                                         status_code=503)
            except (SpecError, ValueError) as exc:
                return PlainTextResponse(_one_line(exc), status_code=400)
            media = "application/octet-stream"
        else:
            return PlainTextResponse(f"unknown download {kind!r}; one of spec.json, albedo.nc, lut, shader.glsl, "
                                     "shader.brdf, mitsuba.json", status_code=404)
        return Response(body, media_type=media, headers={"Content-Disposition": f'attachment; filename="{name}"'})

    async def favicon(request):
        return Response(status_code=204)

    routes = [Route("/", index), Route("/favicon.ico", favicon), Route("/static/{name}", static),
              Route("/api/models", api_models), WebSocketRoute("/ws", ws), Route("/download/{kind}", download)]

    @contextlib.asynccontextmanager
    async def lifespan(app):
        # once uvicorn runs (not before: the imports would slow its start), the first answer and the model list are
        # computed while the page loads
        pool.submit(prefetch)
        pool.submit(models)
        yield
        pool.shutdown(wait=False, cancel_futures=True)

    from starlette.middleware import Middleware
    from starlette.middleware.trustedhost import TrustedHostMiddleware

    hosts = allowed_hosts or ["127.0.0.1", "localhost", "[::1]", "::1"]
    return Starlette(routes=routes, lifespan=lifespan,
                     middleware=[Middleware(TrustedHostMiddleware, allowed_hosts=hosts)])
