"""Parameter sweeps: albedo tables over a grid of model parameters, run in chunks on dask.

``pumpup.sweep(spec, {"n": [...], "p": [...]}, mu=...)`` tabulates, for every cell of the
parameter grid, the directional albedo a(mu) (000 eq. 2) with its error, the mean albedo
(000 eq. 33) and the maximum constant (000 Tables 2 and 4), optionally after pumping the
cell's model up (001 sec. 3).  Each cell is one pure, deterministic computation: exactly
:func:`pumpup.tabulate`, :func:`pumpup.mean_albedo` and :func:`pumpup.max_albedo` of the
cell's model, whatever scheduler runs it and however the grid is chunked.

Chunks run through dask: the local threaded, multiprocessing or synchronous scheduler, or a
``dask.distributed`` cluster (``client=`` or ``scheduler="tcp://host:8786"``).  With
``out=``, every finished chunk is saved at once, atomically, as a part file in the
directory ``<out>.parts/`` beside a manifest of the sweep's definition; a sweep started
again with the same definition loads the finished parts and computes only the rest.  When
all chunks are done the parts are merged into ``out`` (netCDF, or a zarr store if ``out``
ends in ``.zarr``), written atomically, and the parts directory is removed.

dask is imported inside the functions, so ``import pumpup`` stays fast.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import shutil
import sys
import tempfile
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ._version import __version__
from .core import BRDF, SpecError, budget, load
from .engine.cubature import DEFAULT_ATOL, DEFAULT_RTOL, check_mu

if TYPE_CHECKING:
    import xarray as xr
    from numpy.typing import ArrayLike

__all__ = ["SWEEP_KIND", "default_mu", "dimension_name", "sweep"]

SWEEP_KIND = "pumpup albedo sweep"
#: scheduler names that select dask's local schedulers (anything else is a cluster address)
LOCAL_SCHEDULERS = ("threads", "processes", "synchronous")
#: keyword arguments of :func:`pumpup.pump` that ``pump=`` may hold
PUMP_KEYS = ("g", "levels", "force")
#: tolerances of the per-cell mean albedo and albedo maximum (the defaults of those functions)
MEAN_RTOL = 1e-9
MAX_RTOL = 1e-11
MAX_MU_MIN = 1e-6
#: default number of cells of a chunk along the last swept parameter
DEFAULT_CHUNK = 8
_PART_VARS = ("albedo", "albedo_error", "mean_albedo", "mean_albedo_error", "max_constant",
              "max_constant_error", "max_albedo_theta", "max_albedo_mu")


def default_mu(n: int = 257) -> np.ndarray:
    """``n`` values of mu = cos(theta_i), theta_i uniform in [0, 90) degrees, increasing.

    theta_k = k 90 / n degrees for k = 0 ... n - 1; mu is computed as sin(90 deg - theta_k)
    so that it keeps its digits near grazing incidence.

    Examples
    --------
    >>> mu = default_mu(4)
    >>> mu.round(6).tolist()
    [0.382683, 0.707107, 0.92388, 1.0]
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise ValueError(f"default_mu: n must be an integer >= 2, got {n!r}")
    k = np.arange(1, n + 1)
    return np.sin(k * (np.pi / 2) / n)


# --------------------------------------------------------------------------------------------
# Input checks
# --------------------------------------------------------------------------------------------


def _plain(value: Any) -> Any:
    """A numpy scalar as the Python number (specs are plain JSON)."""
    return value.item() if isinstance(value, np.generic) else value


def _check_params(spec: dict, params: Mapping[str, Sequence]) -> dict[str, list]:
    if not isinstance(params, Mapping) or len(params) == 0:
        raise SpecError("sweep: params must be a non-empty dict {parameter name: list of values}")
    from .core import _REGISTRY, _ensure_models

    _ensure_models()

    name = spec.get("type")
    if not isinstance(name, str) or name not in _REGISTRY:
        raise SpecError(f"unknown model type {name!r}; known types: {', '.join(_REGISTRY)}")
    cls = _REGISTRY[name]
    out: dict[str, list] = {}
    for key, values in params.items():
        if key not in cls.params:
            raise SpecError(f"sweep: {name} has no parameter {key!r}; its parameters: {', '.join(cls.params)}")
        if cls.params[key].kind == "spec":
            raise SpecError(f"sweep: {name} parameter {key!r} is a nested model spec and cannot be swept")
        if isinstance(values, (str, bytes)) or not isinstance(values, (Sequence, np.ndarray)):
            raise SpecError(f"sweep: the values of {key!r} must be a list, got {values!r}")
        values = [_plain(v) for v in np.asarray(values, dtype=object).ravel()] if len(values) else []
        if len(values) == 0:
            raise SpecError(f"sweep: the list of values of {key!r} is empty")
        if len(set(map(repr, values))) != len(values):
            raise SpecError(f"sweep: the values of {key!r} repeat: {values!r}")
        for v in values:  # the model's own Param check: names the parameter and its range
            cls.params[key].check(name, key, v)
        out[key] = values
    return out


def _check_pump(pump: Mapping | None) -> dict | None:
    if pump is None:
        return None
    if not isinstance(pump, Mapping):
        raise SpecError(f"sweep: pump must be a dict like {{'g': 'g2', 'levels': 2}} or None, got {pump!r}")
    unknown = sorted(set(pump) - set(PUMP_KEYS))
    if unknown:
        raise SpecError(f"sweep: unknown pump option(s) {', '.join(map(repr, unknown))}; allowed: "
                        f"{', '.join(PUMP_KEYS)}")
    out = {"g": "g1", "levels": 1, **{k: _plain(v) for k, v in pump.items()}}
    if out["g"] not in ("g1", "g2"):
        raise SpecError(f"sweep: pump g must be 'g1' or 'g2', got {out['g']!r}")
    lv = out["levels"]
    if isinstance(lv, bool) or not isinstance(lv, int) or lv < 1:
        raise SpecError(f"sweep: pump levels must be an integer >= 1, got {lv!r}")
    return out


def _chunk_shape(names: list[str], shape: tuple[int, ...], chunks) -> tuple[int, ...]:
    if chunks is None:
        return (1,) * (len(shape) - 1) + (min(shape[-1], DEFAULT_CHUNK),)
    if isinstance(chunks, (int, np.integer)) and not isinstance(chunks, bool):
        chunks = {names[-1]: int(chunks)}
    if not isinstance(chunks, Mapping):
        raise TypeError(f"sweep: chunks must be None, an int or a dict {{parameter: cells}}, got {chunks!r}")
    unknown = sorted(set(chunks) - set(names))
    if unknown:
        raise ValueError(f"sweep: chunks names {', '.join(map(repr, unknown))}, which are not swept "
                         f"({', '.join(names)})")
    out = []
    for name, n in zip(names, shape):
        c = chunks.get(name, 1 if name != names[-1] else min(n, DEFAULT_CHUNK))
        if isinstance(c, bool) or not isinstance(c, (int, np.integer)) or c < 1:
            raise ValueError(f"sweep: chunks[{name!r}] must be an integer >= 1, got {c!r}")
        out.append(min(int(c), n))
    return tuple(out)


# --------------------------------------------------------------------------------------------
# One cell, one chunk (these run on the workers)
# --------------------------------------------------------------------------------------------


def cell_model(spec: dict, pump: dict | None) -> BRDF:
    """The model of one cell: ``load(spec)``, pumped with ``pump`` if given."""
    f = load(spec)
    if pump:
        from .operators.pumping import pump as pump_fn

        f = pump_fn(f, **pump)
    return f


def _cell(spec: dict, pump: dict | None, mu: np.ndarray, opts: dict) -> dict[str, Any]:
    """Everything the sweep stores for one cell: a pure function of its arguments."""
    from .operators.pumping import _TABLES, Pumped, _key
    from .tables import max_albedo, mean_albedo, tabulate

    f = cell_model(spec, pump)
    ds = tabulate(f, mu=mu, rtol=opts["rtol"], atol=opts["atol"], progress=False)
    out: dict[str, Any] = {"albedo": ds["albedo"].values, "albedo_error": ds["albedo_error"].values}
    if opts["mean"]:
        out["mean_albedo"], out["mean_albedo_error"] = mean_albedo(f, rtol=MEAN_RTOL, return_error=True)
    if opts["maximum"]:
        m = max_albedo(f, mu_min=MAX_MU_MIN, rtol=MAX_RTOL)
        out.update(max_constant=m.constant, max_constant_error=m.constant_error,
                   max_albedo_theta=m.theta_deg, max_albedo_mu=m.mu)
    # the pumping operator caches the albedo table of every base for the session; no other
    # cell has this cell's bases, so drop them (a long sweep would otherwise grow in memory;
    # the levels of f keep their own references while f lives)
    cur = f
    while isinstance(cur, Pumped):
        _TABLES.pop(_key(cur.base), None)
        cur = cur.base
    return out


def _run_chunk(specs: list[dict], pump: dict | None, mu: np.ndarray, opts: dict) -> dict[str, np.ndarray]:
    """The cells of one chunk, one after the other; arrays with a leading cell axis."""
    cells = [_cell(s, pump, mu, opts) for s in specs]
    return {k: np.array([c[k] for c in cells], dtype=np.float64) for k in cells[0]}


# --------------------------------------------------------------------------------------------
# Part files: one per finished chunk, written atomically
# --------------------------------------------------------------------------------------------


def _part_name(block: tuple[int, ...]) -> str:
    return "chunk-" + "-".join(map(str, block)) + ".npz"


def _write_atomic(directory: str, name: str, write) -> None:
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix="-" + name, dir=directory)
    try:
        with os.fdopen(fd, "wb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, os.path.join(directory, name))
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _save_part(directory: str, block: tuple[int, ...], arrays: dict[str, np.ndarray]) -> None:
    _write_atomic(directory, _part_name(block), lambda fh: np.savez(fh, **arrays))


def _load_part(directory: str, block: tuple[int, ...], n_cells: int) -> dict[str, np.ndarray] | None:
    """A finished chunk's arrays, or None if it is missing or unreadable (then it is recomputed)."""
    path = os.path.join(directory, _part_name(block))
    if not os.path.exists(path):
        return None
    try:
        with np.load(path) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError, EOFError):
        return None
    if not arrays or any(a.shape[0] != n_cells for a in arrays.values()):
        return None
    return arrays


class SweepError(ValueError):
    """A sweep cannot write its output: another sweep is running into it, or it holds another sweep."""


class _Parts:
    """The parts directory ``<out>.parts/`` of a sweep, locked (flock on the directory itself) for as
    long as the sweep runs, so that two sweeps to one ``out`` never run at once.  The manifest
    ``sweep.json`` is written with the first finished chunk (a sweep that never started, say its
    scheduler was unreachable, leaves nothing behind); an existing manifest must match.
    """

    def __init__(self, out: str, definition: dict, overwrite: bool = False):
        import fcntl

        self.directory = directory = os.fspath(out) + ".parts"
        parent = os.path.dirname(os.path.abspath(directory))
        if not os.path.isdir(parent):
            raise OSError(f"cannot write {out!r}: directory {parent!r} does not exist")
        self.text = json.dumps(definition, sort_keys=True, indent=1)
        self.created = not os.path.isdir(directory)
        os.makedirs(directory, exist_ok=True)
        self.fd = os.open(directory, os.O_RDONLY)
        try:
            fcntl.flock(self.fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(self.fd)
            raise SweepError(f"another sweep is running into {os.fspath(out)!r} (its parts directory "
                             f"{directory!r} is locked); wait for it, or write to another file") from None
        if not os.path.isdir(directory) or not os.path.samestat(os.fstat(self.fd), os.stat(directory)):
            self.close()  # the sweep that held it finished and removed it meanwhile: start afresh
            return self.__init__(out, definition, overwrite)
        self.manifest = os.path.join(directory, "sweep.json")
        self.saved = 0
        if os.path.exists(self.manifest):
            with open(self.manifest) as fh:
                old = fh.read()
            if old != self.text:
                if not overwrite:
                    self.close()
                    raise ValueError(
                        f"{directory!r} holds the parts of a different sweep (its manifest sweep.json differs from "
                        "this one's spec, parameters, mu, pump or options); delete that directory to start afresh, "
                        "write this sweep to another file, or pass overwrite=True (--overwrite)"
                    )
                for name in os.listdir(directory):  # overwrite: that sweep's parts go
                    os.unlink(os.path.join(directory, name))

    def save(self, block, arrays) -> None:
        if self.saved == 0 and not os.path.exists(self.manifest):
            _write_atomic(self.directory, "sweep.json", lambda fh: fh.write(self.text.encode()))
        _save_part(self.directory, block, arrays)
        self.saved += 1

    def close(self, remove: bool = False) -> None:
        if remove:
            shutil.rmtree(self.directory, ignore_errors=True)
        if self.fd is not None:
            os.close(self.fd)  # releases the lock
            self.fd = None

    def abandon(self) -> None:
        """After a failure: release the lock; remove the directory if this sweep made it and
        saved nothing into it.
        """
        empty = self.created and self.saved == 0 and not any(n.startswith("chunk-") for n in os.listdir(self.directory))
        self.close(remove=empty)


def definition_digest(definition: dict) -> str:
    """SHA-256 of what defines a sweep's result (spec, parameters, mu, pump, options): stored in
    the result's attribute ``sweep_definition_sha256``.
    """
    import hashlib

    def canon(v):  # 1 and 1.0 are the same parameter value
        if isinstance(v, dict):
            return {k: canon(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [canon(x) for x in v]
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            return float(v)
        return v

    keys = ("spec", "params", "mu", "pump", "options")
    text = json.dumps({k: canon(definition[k]) for k in keys}, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()


def _check_existing_output(out: str, digest: str, overwrite: bool):
    """Refuse to replace a result of a different sweep (or a file that is not one) unless ``overwrite``; the finished
    result of this very sweep in a netCDF file (validated by :func:`pumpup.open_table`, checksums and digest), or None.
    """
    out = os.fspath(out)
    if not os.path.exists(out) or overwrite:
        return None
    ds = None
    try:
        if out.rstrip("/").endswith(".zarr"):
            import xarray as xr

            with xr.open_zarr(out) as ds:
                attrs = dict(ds.attrs)
        else:
            from .tables import open_table

            ds = open_table(out)
            attrs = ds.attrs
    except Exception:  # unreadable: not ours to replace silently
        attrs = {}
    if attrs.get("sweep_definition_sha256") == digest:
        return ds  # (a zarr store, which carries no digest, is computed again)
    what = ("the result of a different sweep" if attrs.get("pumpup_kind") == SWEEP_KIND
            else "something that is not a result of this sweep")
    raise SweepError(f"{out!r} exists and holds {what}; pass overwrite=True (--overwrite) to replace it, "
                     "or write to another file")


# --------------------------------------------------------------------------------------------
# Running the chunks
# --------------------------------------------------------------------------------------------


def _progress_bar(total: int, progress: bool | None):
    from tqdm.auto import tqdm

    show = sys.stderr.isatty() if progress is None else progress
    return tqdm(total=total, desc="sweep", unit="cell", disable=not show)


def warm_kernels(f: BRDF) -> None:
    """Compile (or load from numba's cache) the kernels that the cells of a threaded sweep use, on
    this thread, before the threads start: numba's lazily compiled ufuncs, asked for the same
    signature by two threads at once, compile it twice and warn ("Compilation requested for
    previously compiled argument types"), once per sweep.  One value of the innermost base's
    albedo runs every kernel of the engine and the model (a pumped chain's own kernel compiles
    under numba's lock).
    """
    from .engine.cubature import albedo
    from .operators.pumping import Pumped

    base = f
    while isinstance(base, Pumped):
        base = base.base
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a warm-up value: its accuracy does not matter
        albedo(base, 1.0, rtol=1e-3, atol=1e-3)


def _run_local(tasks, scheduler: str, workers: int | None, on_done) -> None:
    """Run the chunks with a local dask scheduler; ``on_done`` sees each result in this process."""
    import uuid

    import dask
    from dask.callbacks import Callback, normalize_callback

    run = uuid.uuid4().hex  # keys of this run only, even beside other dask work in this process
    keys = {}
    delayed = []
    for k, (block, args) in enumerate(tasks):
        key = f"pumpup-sweep-{run}-chunk-{k}"
        keys[key] = block
        delayed.append(dask.delayed(_run_chunk, pure=True)(*args, dask_key_name=key))

    class Saver(Callback):
        def _posttask(self, key, result, dsk, state, worker_id):
            if key in keys:
                on_done(keys[key], result)

    kw = {} if scheduler == "synchronous" or workers is None else {"num_workers": workers}
    # each result is placed (and saved) as it arrives; the callback is local to this computation.
    # chunksize=1: one chunk per dispatch (dask's process scheduler batches 6 ready tasks per
    # worker by default, which ran a sweep of two chunks on one process)
    if scheduler != "processes":
        dask.compute(*delayed, scheduler=scheduler, callbacks=[normalize_callback(Saver())], chunksize=1, **kw)
        return
    # our own pool of worker processes, so that they end with the sweep: terminated if it fails or
    # is interrupted, and (Linux) sent SIGTERM by the kernel if this process is killed
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    pool = ProcessPoolExecutor(workers or os.cpu_count() or 1, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_worker_init, initargs=(os.getpid(),))
    try:
        dask.compute(*delayed, scheduler="processes", pool=pool, callbacks=[normalize_callback(Saver())],
                     chunksize=1)
    except BaseException:
        procs = list(getattr(pool, "_processes", {}).values())
        pool.shutdown(wait=False, cancel_futures=True)
        for proc in procs:
            if proc.is_alive():
                proc.terminate()
        for proc in procs:
            proc.join(5)
        raise
    pool.shutdown(wait=True)


def _worker_init(parent: int) -> None:  # pragma: no cover - runs in the workers
    """In each worker process: ask the kernel (Linux prctl PR_SET_PDEATHSIG) for SIGTERM when the
    sweep's process dies, so that a killed sweep leaves no workers behind; ignore SIGINT (Ctrl-C
    goes to the sweep, which ends the workers).
    """
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        return
    if os.getppid() != parent:  # the sweep died before prctl took effect
        os._exit(1)


def _run_distributed(tasks, client, address: str | None, on_done) -> None:
    """Run the chunks on a dask.distributed cluster; results are saved here as they complete."""
    from distributed import Client, as_completed

    own = client is None
    if own:
        try:
            client = Client(address, timeout="20s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise OSError(f"sweep: cannot reach the dask scheduler at {address!r}: {exc}") from None
    futures = {}
    try:
        for block, args in tasks:
            futures[client.submit(_run_chunk, *args, pure=False)] = block
        for fut in as_completed(list(futures)):
            result = fut.result()  # raises the worker's exception here
            on_done(futures.pop(fut), result)
            fut.release()
    finally:
        if futures:
            client.cancel(list(futures))
        if own:
            client.close()


# --------------------------------------------------------------------------------------------
# The public function
# --------------------------------------------------------------------------------------------


def sweep(spec: dict | str, params: Mapping[str, Sequence], mu: ArrayLike | None = None, *, pump: Mapping | None = None,
          client: Any = None, scheduler: str | None = None, workers: int | None = None,
          chunks: int | Mapping[str, int] | None = None, out: str | os.PathLike | None = None,
          rtol: float = DEFAULT_RTOL, atol: float = DEFAULT_ATOL, mean: bool = True, maximum: bool = True,
          progress: bool | None = None, overwrite: bool = False, max_seconds: float | None = None) -> xr.Dataset:
    """Albedo tables over a grid of model parameters, computed in chunks through dask.

    Cell (v_1, ..., v_k) of the grid is the model ``pumpup.load(spec | {p_1: v_1, ...})``
    (pumped with ``pumpup.pump(model, **pump)`` if ``pump`` is given).  For each cell the
    sweep stores exactly what :func:`pumpup.tabulate` (on the grid ``mu``),
    :func:`pumpup.mean_albedo` and :func:`pumpup.max_albedo` return for that model: the
    values do not depend on the scheduler, the number of workers or the chunking.

    Parameters
    ----------
    spec : dict or str
        The base model spec (or its JSON).  Parameters not given take the model's defaults
        *per cell*: sweeping ``n`` of ``stretched_phong`` without a ``c`` gives each cell
        its own c = (n + 2) / (2 pi).
    params : dict
        ``{name: list of values}``, one grid dimension per entry, in this order.  Names must
        be parameters of ``spec["type"]``; values are checked by the model's own parameter
        ranges before anything runs.  Swept values replace those in ``spec``.
    mu : array_like, optional
        cos(theta_i) in (0, 1]; sorted and made unique as by :func:`pumpup.tabulate`.
        Default: :func:`default_mu` (257 values, theta uniform in [0, 90) degrees).
    pump : dict, optional
        Options of :func:`pumpup.pump`, e.g. ``{"g": "g2", "levels": 2}``: each cell's model
        is pumped up first (001 sec. 3).
    client : dask.distributed.Client, optional
        Run on this cluster (left open afterwards).
    scheduler : str, optional
        ``"threads"`` (default), ``"processes"`` or ``"synchronous"`` for dask's local
        schedulers, or the address of a ``dask.distributed`` scheduler
        (``"tcp://host:8786"``), to which the sweep connects and which it leaves running.
        The engine's compiled kernels release the GIL but its Python between them does not,
        and each cell's table already runs on ``pumpup.tables.THREADS`` threads: use
        ``"processes"`` (from a script, under ``if __name__ == "__main__":``, since the
        workers are spawned) or a cluster for large sweeps.  Cluster workers need pumpup
        installed; results come back to this process, which writes the parts and ``out``.
    workers : int, optional
        Threads or processes of the local scheduler (default: dask's, one per core).
    chunks : int or dict, optional
        Cells of a chunk along each swept parameter, ``{name: count}`` (missing names: 1,
        except the last parameter: 8); an int is the count along the last parameter.
        A chunk is the unit of work, of saving and of resuming.
    out : path, optional
        Write the result here (netCDF; a zarr store if the name ends in ``.zarr``) and keep
        finished chunks in ``<out>.parts/`` until the end, so that an interrupted sweep run
        again with the same arguments resumes where it stopped.  The parts directory
        remembers the sweep's definition; a different sweep is refused, not mixed in.  A
        netCDF ``out`` that holds the finished result of the same sweep is read back
        (validated) instead of computed again.
    rtol, atol : float
        Quadrature tolerances of the albedo values (see :func:`pumpup.albedo`).
    mean : bool
        Compute the mean albedo of every cell (000 eq. 33; rtol 1e-9).  For pumped models
        this is the dearest part of a cell.
    maximum : bool
        Compute the maximum constant and the angle of the albedo maximum of every cell
        (000 Tables 2 and 4; scanned down to mu = 1e-6, rtol 1e-11).
    progress : bool, optional
        Show a progress bar over cells (default: when stderr is a terminal).
    overwrite : bool
        Replace ``out`` (and discard the parts in ``<out>.parts/``) when they belong to a different
        sweep; without it such a sweep is refused before it computes.  With it, a finished result of
        the same sweep is computed again and replaced (by the same numbers).
    max_seconds : float, optional
        A time budget: past it, the sweep stops with :class:`pumpup.core.budget.BudgetExceeded` (a
        TimeoutError): at once on the synchronous scheduler, else when the next chunk finishes; with
        ``out``, the finished chunks are kept and a new run resumes from them.  None: no bound.

    Returns
    -------
    xarray.Dataset
        Dimensions: the swept parameters, in order, then ``mu`` (a parameter named like a data
        variable, Lambert's ``albedo``, gets the dimension ``lambert_albedo``).  Data variables:
        ``albedo`` and ``albedo_error`` (params..., mu); if ``mean``, ``mean_albedo`` and
        ``mean_albedo_error``; if ``maximum``, ``max_constant``, ``max_constant_error``,
        ``max_albedo_theta`` [degree] and ``max_albedo_mu``.  Coordinates: the swept values,
        ``mu`` and ``theta`` [degree].  Attributes: ``spec`` (JSON of the base spec without
        the swept parameters), ``swept_parameters`` (JSON list), ``pump`` (JSON),
        ``method``, ``rtol``, ``atol``, ``mean_albedo_rtol``, ``max_albedo_rtol``,
        ``pumpup_version``.

    Raises
    ------
    SpecError
        An unknown model or parameter name, a value outside the parameter's range, an empty
        or repeating list of values, or bad pump options.
    ValueError
        mu outside (0, 1], bad chunks, or parts of a different sweep at ``out``.

    References
    ----------
    000: L. Neumann, A. Neumann, L. Szirmay-Kalos, Compact Metallic Reflectance Models (1999).
    001: the same authors, Analysis and Pumping of the Albedo Function (1998).

    Examples
    --------
    >>> import pumpup
    >>> ds = pumpup.sweep({"type": "lambert"}, {"albedo": [0.25, 0.5]}, mu=[0.5, 1.0],
    ...                   scheduler="synchronous", maximum=False)
    >>> ds["albedo"].dims, ds["albedo"].values.round(12).tolist()
    (('lambert_albedo', 'mu'), [[0.25, 0.25], [0.5, 0.5]])
    """
    from .core import check_tolerance, parse_spec

    if isinstance(spec, str):  # JSON or the short form "stretched_phong:p=0.5" (or just a type name)
        spec = parse_spec(spec)
    if not isinstance(spec, Mapping) or "type" not in spec:
        raise SpecError(f"sweep: spec must be a dict with a 'type' key, got {spec!r}")
    spec = {k: _plain(v) for k, v in spec.items()}
    rtol = check_tolerance("sweep", "rtol", rtol)
    atol = check_tolerance("sweep", "atol", atol, hi=math.inf, zero=True)
    values = _check_params(spec, params)
    names = list(values)
    pump = _check_pump(pump)
    grid = np.unique(check_mu(np.atleast_1d(default_mu() if mu is None else mu)).ravel())
    if grid.size == 0:
        raise ValueError("sweep: mu is empty; give at least one value in (0, 1]")
    if client is not None and scheduler is not None:
        raise ValueError("sweep: give client= or scheduler=, not both")
    if scheduler is not None and (not isinstance(scheduler, str)
                                  or (scheduler not in LOCAL_SCHEDULERS and ":" not in scheduler)):
        raise ValueError(f"sweep: scheduler must be one of {', '.join(map(repr, LOCAL_SCHEDULERS))} or the address "
                         f"of a dask.distributed scheduler such as 'tcp://host:8786', got {scheduler!r}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"sweep: workers must be an integer >= 1, got {workers!r}")
    budget.check_max_seconds("sweep", max_seconds)
    shape = tuple(len(values[n]) for n in names)
    cshape = _chunk_shape(names, shape, chunks)
    base = {k: v for k, v in spec.items() if k not in values}

    # every cell's spec, checked up front (cross-parameter checks too) so no worker fails on input
    def cell_spec(index):
        return {**spec, **{n: values[n][i] for n, i in zip(names, index)}}

    for index in itertools.product(*(range(s) for s in shape)):
        load(cell_spec(index))
    first = cell_spec((0,) * len(shape))
    if pump:
        cell_model(first, pump)  # pump's own checks (e.g. a non-reciprocal base) before anything runs

    opts = {"rtol": float(rtol), "atol": float(atol), "mean": bool(mean), "maximum": bool(maximum)}
    blocks = list(itertools.product(*(range(math.ceil(s / c)) for s, c in zip(shape, cshape))))

    def block_slices(block):
        return tuple(slice(b * c, min((b + 1) * c, s)) for b, c, s in zip(block, cshape, shape))

    def block_cells(block):
        return list(itertools.product(*(range(sl.start, sl.stop) for sl in block_slices(block))))

    n_mu = grid.size
    arrays = {k: np.full(shape + ((n_mu,) if k.startswith("albedo") else ()), np.nan) for k in _PART_VARS}

    def place(block, result):
        sl = block_slices(block)
        bshape = tuple(s.stop - s.start for s in sl)
        for k, v in result.items():
            arrays[k][sl] = v.reshape(bshape + v.shape[1:])

    definition = {"spec": spec, "params": values, "mu": [float(m) for m in grid], "pump": pump,
                  "options": opts, "chunks": list(cshape), "pumpup_version": __version__}
    digest = definition_digest(definition)
    parts = None
    todo = list(blocks)
    if out is not None:
        finished = _check_existing_output(out, digest, overwrite)
        if finished is not None:  # this sweep ran to the end before: its result, not a second run
            return finished
        parts = _Parts(out, definition, overwrite)
        todo = []
        for block in blocks:
            res = _load_part(parts.directory, block, len(block_cells(block)))
            if res is None:
                todo.append(block)
            else:
                place(block, res)

    try:
        tasks = [(block, ([cell_spec(i) for i in block_cells(block)], pump, grid, opts)) for block in todo]
        total = sum(len(block_cells(b)) for b in todo)
        done = [0]
        with _progress_bar(total, progress) as bar, budget.time_budget("sweep", max_seconds):
            def on_done(block, result):
                if parts is not None:
                    parts.save(block, result)
                place(block, result)
                bar.update(len(block_cells(block)))
                done[0] += len(block_cells(block))
                budget.check(f"{done[0]} of {total} cells were done"
                             + (" (the finished chunks are kept: a new run resumes)" if parts is not None else ""))

            if tasks:
                if client is not None or (scheduler is not None and scheduler not in LOCAL_SCHEDULERS):
                    _run_distributed(tasks, client, scheduler, on_done)
                else:
                    if (scheduler or "threads") == "threads":
                        warm_kernels(cell_model(first, pump))
                    _run_local(tasks, scheduler or "threads", workers, on_done)

        ds = _dataset(spec, base, names, values, grid, pump, opts, arrays)
        ds.attrs["sweep_definition_sha256"] = digest
        if out is not None:
            _write_output(ds, out)
    except BaseException:
        if parts is not None:
            parts.abandon()
        raise
    if parts is not None:
        parts.close(remove=True)
    return ds


def dimension_name(model: str, name: str) -> str:
    """The dimension of a swept parameter: its name, or ``model_name`` where that is also the
    name of a data variable (Lambert's ``albedo`` becomes ``lambert_albedo``).

    Examples
    --------
    >>> dimension_name("phong", "n"), dimension_name("lambert", "albedo")
    ('n', 'lambert_albedo')
    """
    return f"{model}_{name}" if name in _PART_VARS or name in ("mu", "theta") else name


def _dataset(spec, base, names, values, grid, pump, opts, arrays):
    import xarray as xr

    from .core import _REGISTRY
    from .tables import METHOD

    cls = _REGISTRY[spec["type"]]
    dims = tuple(dimension_name(spec["type"], n) for n in names)
    adims = dims + ("mu",)
    data = {
        "albedo": (adims, arrays["albedo"], {
            "long_name": "directional albedo a(mu)", "units": "1",
            "definition": "integral of f_r(wi, wo) cos(theta_o) d omega_o (000 eq. 2)"}),
        "albedo_error": (adims, arrays["albedo_error"], {
            "long_name": "estimated absolute quadrature error of albedo", "units": "1"}),
    }
    if opts["mean"]:
        data["mean_albedo"] = (dims, arrays["mean_albedo"], {
            "long_name": "mean albedo 2 * integral_0^1 a(mu) mu dmu (000 eq. 33)", "units": "1"})
        data["mean_albedo_error"] = (dims, arrays["mean_albedo_error"], {
            "long_name": "estimated absolute error of mean_albedo", "units": "1"})
    if opts["maximum"]:
        data["max_constant"] = (dims, arrays["max_constant"], {
            "long_name": "maximum constant: 1 / max over mu of the albedo with the model's constant set to 1 "
                         "(000 Tables 2 and 4)", "units": "1"})
        data["max_constant_error"] = (dims, arrays["max_constant_error"], {
            "long_name": "propagated error of max_constant", "units": "1"})
        data["max_albedo_theta"] = (dims, arrays["max_albedo_theta"], {
            "long_name": "incidence angle theta_i of the albedo maximum", "units": "degree"})
        data["max_albedo_mu"] = (dims, arrays["max_albedo_mu"], {
            "long_name": "cos(theta_i) of the albedo maximum", "units": "1"})
    coords = {
        "mu": ("mu", grid, {"long_name": "cosine of the incidence angle, cos(theta_i)", "units": "1"}),
        "theta": ("mu", np.degrees(np.arccos(grid)), {"long_name": "incidence angle theta_i", "units": "degree"}),
    }
    for n, d in zip(names, dims):
        p = cls.params[n]
        coords[d] = (d, np.asarray(values[n]),
                     {"parameter": n, "long_name": f"{spec['type']} parameter {n}" + (f": {p.doc}" if p.doc else ""),
                      "valid_range": p.range_text()})
    return xr.Dataset(data, coords=coords, attrs={
        "title": f"Directional albedo of {spec['type']} over {', '.join(names)}"
                 + (f", pumped ({pump['g']}, {pump['levels']} levels)" if pump else ""),
        "pumpup_kind": SWEEP_KIND,
        "spec": json.dumps(base, sort_keys=True),
        "model": spec["type"],
        "swept_parameters": json.dumps(names),
        "swept_dimensions": json.dumps(list(dims)),
        "cell_spec": "spec with the swept parameters set to the cell's coordinates; model defaults per cell",
        "pump": json.dumps(pump, sort_keys=True),
        "method": METHOD,
        "rtol": opts["rtol"],
        "atol": opts["atol"],
        "mean_albedo_rtol": MEAN_RTOL if opts["mean"] else "not computed",
        "max_albedo_rtol": MAX_RTOL if opts["maximum"] else "not computed",
        "max_albedo_mu_min": MAX_MU_MIN if opts["maximum"] else "not computed",
        "grid": "given",
        "pumpup_version": __version__,
    })


def _write_output(ds, out) -> None:
    """A netCDF file (atomic rename of a temporary file) or a zarr store (atomic rename of a temporary directory)."""
    from .tables import write_table

    out = os.fspath(out)
    if not out.rstrip("/").endswith(".zarr"):
        write_table(ds, out)
        return
    out = out.rstrip("/")
    parent = os.path.dirname(os.path.abspath(out))
    tmp = tempfile.mkdtemp(prefix=".tmp-", suffix=".zarr", dir=parent)
    try:
        ds.to_zarr(tmp, mode="w", zarr_format=2, consolidated=True)  # format 2: every zarr and xarray reads it
        if os.path.exists(out):
            old = tempfile.mkdtemp(prefix=".old-", dir=parent)
            os.replace(out, os.path.join(old, "store"))
            os.replace(tmp, out)
            shutil.rmtree(old, ignore_errors=True)
        else:
            os.replace(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
