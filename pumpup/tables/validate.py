"""Validation of the files pumpup reads, and the checksums of the files it writes.

A file is checked when it is opened (:func:`pumpup.open_table`, :func:`pumpup.load_pumped`),
so that a damaged or edited file gives one clear :class:`TableError` naming the file and what
is wrong, never a KeyError, IndexError, JSONDecodeError or AttributeError from deep inside,
and never silently different numbers.  What is checked, for an albedo table:

* the variables ``albedo`` and ``albedo_error`` with the coordinate ``mu`` among their
  dimensions, of one shape, numeric;
* ``mu`` one-dimensional, at least two values, finite, in (0, 1] and strictly increasing *as
  stored* (a scrambled table is refused, not re-sorted);
* ``albedo`` and ``albedo_error`` finite and >= 0;
* the ``spec`` attribute JSON of a loadable model (a user function's spec needs its function
  registered in the session and is only checked for its form); ``interpolation_error`` finite
  and >= 0, ``interpolation_degree`` 3 or 5, ``rtol`` and ``atol`` finite and > 0 where present,
  ``interpolation_breaks`` (where present) inner nodes of ``mu``.

Byte flips in the data are caught by HDF5's Fletcher-32 checksums, which :func:`checksum_encoding`
turns on for every numeric variable (netCDF4's ``fletcher32``); netCDF then refuses to read a
damaged chunk.  Attributes carry no checksum, hence the checks above.
"""

from __future__ import annotations

import json
import math
import os
from typing import Any

import numpy as np

from ..core import SpecError

__all__ = ["TableError", "checksum_encoding", "content_digest", "DIGEST_ATTR", "validate_dataset", "spec_attribute"]

#: the attribute that holds :func:`content_digest` of a file written by pumpup
DIGEST_ATTR = "pumpup_digest"


class TableError(ValueError):
    """A file is not a valid pumpup table: damaged, edited or of another kind (the message names
    the file and what is wrong).
    """


def checksum_encoding(ds) -> dict:
    """netCDF4 encoding that stores a Fletcher-32 checksum with every numeric variable of ``ds``
    (data variables and coordinates of at least one dimension).
    """
    enc = {}
    for name, var in {**ds.coords, **ds.data_vars}.items():
        if var.ndim >= 1 and var.dtype.kind in "fiub":
            enc[name] = {"fletcher32": True}
    return enc


def _canonical(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return [_canonical(v) for v in value.tolist()] if value.ndim else _canonical(value.item())
    if isinstance(value, np.generic):
        return _canonical(value.item())
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return [_canonical(v) for v in value]
    return value if isinstance(value, (int, str, bool)) or value is None else repr(value)


def content_digest(ds) -> str:
    """SHA-256 of a Dataset's content as pumpup reads it back: the attributes (except the digest),
    and every variable's name, dimensions, attributes and values.  Stored as the attribute
    :data:`DIGEST_ATTR` by :func:`pumpup.write_table`, checked by :func:`pumpup.open_table`, so an
    edited attribute or value is detected as well as a flipped byte (HDF5's checksums cover the
    data only).
    """
    import hashlib

    h = hashlib.sha256()

    def put(obj):
        h.update(json.dumps(obj, sort_keys=True).encode())

    put({k: _canonical(v) for k, v in ds.attrs.items() if k != DIGEST_ATTR})
    for name in sorted(map(str, [*ds.coords, *ds.data_vars])):
        var = ds[name].variable
        v = np.asarray(var.values)
        put([name, list(var.dims), list(v.shape), {k: _canonical(a) for k, a in var.attrs.items()}])
        if v.dtype.kind == "f":
            h.update(np.ascontiguousarray(v, dtype=np.float64).tobytes())
        elif v.dtype.kind in "iu":
            h.update(np.ascontiguousarray(v, dtype=np.int64).tobytes())
        elif v.dtype.kind == "b":
            h.update(np.ascontiguousarray(v, dtype=np.uint8).tobytes())
        else:
            put([str(x) for x in v.ravel().tolist()])
    return h.hexdigest()


def _attr_number(path: str, ds, name: str, lo: float, lo_open: bool, what: str) -> None:
    if name not in ds.attrs:
        return
    v = ds.attrs[name]
    if isinstance(v, np.ndarray) and v.size == 1:
        v = v.item()
    ok = isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, bool) and math.isfinite(float(v))
    if ok:
        ok = float(v) > lo if lo_open else float(v) >= lo
    if not ok:
        raise TableError(f"{path!r}: attribute {name!r} must be {what}, got {v!r}")


def spec_attribute(path: str, ds, name: str = "spec") -> dict:
    """The model spec stored as JSON in attribute ``name``, checked to load (a TableError if not)."""
    from ..core import load

    text = ds.attrs.get(name)
    if not isinstance(text, str):
        raise TableError(f"{path!r}: attribute {name!r} (the model spec as JSON) is missing or not text")
    try:
        spec = json.loads(text)
    except json.JSONDecodeError as exc:
        raise TableError(f"{path!r}: attribute {name!r} is not valid JSON: {exc}") from None
    if not isinstance(spec, dict) or not isinstance(spec.get("type"), str):
        raise TableError(f"{path!r}: attribute {name!r} is not a model spec (a JSON object with a 'type'): "
                         f"{text[:80]!r}")
    if not _mentions_function(spec):
        try:
            load(spec)
        except (SpecError, ValueError, TypeError) as exc:
            raise TableError(f"{path!r}: attribute {name!r} does not load: {exc}") from None
    return spec


def _mentions_function(spec: Any) -> bool:
    """True if a spec holds a user function (loadable only where the function is registered)."""
    if isinstance(spec, dict):
        return spec.get("type") == "function" or any(_mentions_function(v) for v in spec.values())
    if isinstance(spec, list):
        return any(_mentions_function(v) for v in spec)
    return False


def _finite_nonnegative(path: str, ds, name: str) -> None:
    v = np.asarray(ds[name].values)
    if v.dtype.kind not in "fiu":
        raise TableError(f"{path!r}: variable {name!r} must be numeric, got dtype {v.dtype}")
    bad = ~np.isfinite(v) | (v < 0)
    if np.any(bad):
        i = tuple(int(k) for k in np.argwhere(bad)[0])
        raise TableError(f"{path!r}: {name}{list(i)} = {v[i].item()!r}; it must be finite and >= 0")


def _check_mu(path: str, ds, increasing: bool) -> None:
    mu = np.asarray(ds["mu"].values)
    if mu.ndim != 1 or mu.dtype.kind not in "fiu":
        raise TableError(f"{path!r}: coordinate 'mu' must be a 1-D numeric array, got shape {mu.shape}, dtype "
                         f"{mu.dtype}")
    bad = ~np.isfinite(mu) | (mu <= 0) | (mu > 1)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise TableError(f"{path!r}: mu[{i}] = {mu[i].item()!r}; mu = cos(theta_i) must be in (0, 1]")
    if increasing:
        if mu.size < 2:
            raise TableError(f"{path!r}: an albedo table needs at least two values of mu, it has {mu.size}")
        down = np.nonzero(np.diff(mu) <= 0)[0]
        if down.size:
            i = int(down[0])
            raise TableError(f"{path!r}: mu must be strictly increasing as stored; mu[{i}] = {mu[i].item()!r} >= "
                             f"mu[{i + 1}] = {mu[i + 1].item()!r} (a scrambled or edited table)")


def _check_albedo_vars(path: str, ds) -> None:
    for name in ("albedo", "albedo_error"):
        if name not in ds.data_vars:
            raise TableError(f"{path!r}: the variable {name!r} is missing (not a complete albedo table)")
    if "mu" not in ds.coords:
        raise TableError(f"{path!r}: the coordinate 'mu' is missing (not a complete albedo table)")
    a, e = ds["albedo"], ds["albedo_error"]
    if "mu" not in a.dims or a.dims != e.dims or a.shape != e.shape:
        raise TableError(f"{path!r}: albedo {a.dims}{a.shape} and albedo_error {e.dims}{e.shape} must have the "
                         "same dimensions, including 'mu'")
    _finite_nonnegative(path, ds, "albedo")
    _finite_nonnegative(path, ds, "albedo_error")


def validate_dataset(ds, path: str, require_digest: bool = True) -> None:
    """Check a Dataset read from ``path`` by its ``pumpup_kind``; raise :class:`TableError` if it
    is not what pumpup wrote.  Every file pumpup writes carries its checksum (:data:`DIGEST_ATTR`); one without it is
    refused unless ``require_digest`` is False (a file written by another tool).
    """
    from . import TABLE_KIND

    path = os.fspath(path)
    kind = ds.attrs.get("pumpup_kind")
    if not isinstance(kind, str) or not kind.startswith("pumpup"):
        raise TableError(f"{path!r} is a netCDF file but not a pumpup table (no 'pumpup_kind' attribute)")
    if require_digest and DIGEST_ATTR not in ds.attrs:
        raise TableError(f"{path!r} has no checksum (attribute {DIGEST_ATTR!r}): pumpup writes one with every "
                         "file, so this one was edited or written by another tool (open_table(..., "
                         "require_digest=False) reads it unchecked)")
    if DIGEST_ATTR in ds.attrs:
        stored = ds.attrs[DIGEST_ATTR]
        if not isinstance(stored, str) or stored != content_digest(ds):
            raise TableError(f"{path!r}: its content does not match the checksum pumpup wrote with it "
                             f"(attribute {DIGEST_ATTR!r}): the file was damaged or edited")
    if kind == TABLE_KIND:
        _check_albedo_vars(path, ds)
        _check_mu(path, ds, increasing=True)
        spec_attribute(path, ds)
        _attr_number(path, ds, "interpolation_error", 0.0, False, "a finite number >= 0")
        _attr_number(path, ds, "rtol", 0.0, True, "a finite number > 0")
        _attr_number(path, ds, "atol", 0.0, True, "a finite number > 0")
        if "interpolation_degree" in ds.attrs:
            d = ds.attrs["interpolation_degree"]
            if isinstance(d, bool) or not isinstance(d, (int, np.integer)) or int(d) not in (3, 5):
                raise TableError(f"{path!r}: attribute 'interpolation_degree' must be 3 or 5, got {d!r}")
        if "interpolation_breaks" in ds.attrs:  # (AlbedoTable's kinks: inner nodes of mu)
            b = np.atleast_1d(ds.attrs["interpolation_breaks"])
            mu = ds["mu"].values
            if (b.dtype.kind != "f" or b.ndim != 1 or not np.all(np.isfinite(b)) or not np.all(np.isin(b, mu))
                    or b.size and not (b.min() > mu.min() and b.max() < mu.max())):
                raise TableError(f"{path!r}: attribute 'interpolation_breaks' must list inner nodes of mu, got {b!r}")
        if ds.sizes["mu"] < 2:
            raise TableError(f"{path!r}: an albedo table needs at least two values of mu")
        return
    if kind == "pumpup pumped BRDF":
        lv = ds.attrs.get("levels")
        if isinstance(lv, np.ndarray) and lv.size == 1:
            lv = lv.item()
        if isinstance(lv, bool) or not isinstance(lv, (int, np.integer)) or not 1 <= int(lv) <= 64:
            raise TableError(f"{path!r}: attribute 'levels' must be an integer in [1, 64], got {lv!r}")
        spec_attribute(path, ds)
        return
    if kind == "pumpup albedo sweep":
        _check_albedo_vars(path, ds)
        _check_mu(path, ds, increasing=True)
        return
    if "mu" in ds.coords:  # any other pumpup file: its mu, where it has one, is a cosine
        _check_mu(path, ds, increasing=False)
