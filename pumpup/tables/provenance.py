"""Provenance of generated data: which commit made a file, and writes that keep a checkout clean.

The tables and figures committed in ``tables/`` and ``figures/`` are what the current code
produces (issue 13, item 15).  Every generated netCDF file carries the commit of the code that
made it (attribute ``pumpup_commit``; ``-dirty`` appended when the code differed from that
commit, ``unknown`` outside a git checkout), and :func:`write_generated` leaves a file alone
when the new data equal what it holds already (only the provenance attributes may differ), so
that ``pumpup reproduce`` run on the same code changes no byte of the checkout.
"""

from __future__ import annotations

import functools
import os
import subprocess

__all__ = ["PROVENANCE_ATTRS", "source_commit", "same_data", "write_generated"]

#: attributes that record where and when a file was made, not what it holds
PROVENANCE_ATTRS = ("pumpup_commit", "pumpup_version", "pumpup_digest")

_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # the checkout, above pumpup/


def _git(*args: str) -> str | None:
    try:
        r = subprocess.run(["git", "-C", _ROOT, *args], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.SubprocessError):
        return None
    return r.stdout.strip() if r.returncode == 0 else None


@functools.lru_cache(maxsize=1)
def source_commit() -> str:
    """The commit of the code in this checkout (``<hash>``, ``<hash>-dirty`` if ``pumpup/`` or
    ``scripts/`` differ from it), or ``unknown`` when pumpup is not run from a git checkout.
    """
    if not os.path.isdir(os.path.join(_ROOT, ".git")) and not os.path.isfile(os.path.join(_ROOT, ".git")):
        return "unknown"
    head = _git("rev-parse", "HEAD")
    if not head:
        return "unknown"
    dirty = _git("status", "--porcelain", "--untracked-files=no", "--", "pumpup", "scripts")
    return head + ("-dirty" if dirty else "")


#: how close two error estimates (variables named ``*_error``) must be, relative to themselves, to be the same data:
#: an estimate is a difference of nearly equal sums, whose last digits carry the rounding of the machine's math
#: library (on an AMD EPYC, 49 of the 160 albedo errors of tables/sampling_efficiency.nc differed from those made on
#: an Intel Xeon, by at most 7.6e-9 of themselves)
ERROR_RTOL = 1e-7


def same_data(a, b) -> bool:
    """True if two Datasets hold the same variables, coordinates, values and attributes, apart from
    :data:`PROVENANCE_ATTRS`: the values bit for bit, except error estimates (variables named ``*_error``), which
    agree to :data:`ERROR_RTOL` of themselves.
    """
    import numpy as np
    import xarray as xr

    def strip(ds):
        ds = ds.copy()
        ds.attrs = {k: v for k, v in ds.attrs.items() if k not in PROVENANCE_ATTRS}
        return ds

    b = strip(b)
    for v in a.data_vars:  # (an estimate within ERROR_RTOL of a's takes a's values; all else is compared as it is)
        if str(v).endswith("_error") and v in b.data_vars and a[v].shape == b[v].shape and a[v].dtype == b[v].dtype:
            x, y = np.asarray(a[v].values, dtype=np.float64), np.asarray(b[v].values, dtype=np.float64)
            near = (x == y) | (np.isnan(x) & np.isnan(y)) | (np.abs(x - y) <= ERROR_RTOL * np.maximum(abs(x), abs(y)))
            if np.all(near):
                b[v] = b[v].copy(data=a[v].values)
    try:
        xr.testing.assert_identical(strip(a), b)
    except AssertionError:
        return False
    return True


def write_generated(ds, path) -> bool:
    """Write generated data with its provenance (:func:`pumpup.write_table`), unless ``path``
    already holds the same data (:func:`same_data`) made from committed code: then the file is
    left as it is.

    Returns True if the file was written.
    """
    from . import open_table, write_table

    ds = ds.copy()
    ds.attrs["pumpup_commit"] = source_commit()
    if os.path.exists(path):
        try:
            old = open_table(path)
        except (ValueError, OSError):
            old = None
        # kept only if it holds the same data and already says where it came from (a file of an
        # older pumpup, without pumpup_commit or its checksums, is rewritten once)
        if (old is not None and same_data(old, ds) and isinstance(old.attrs.get("pumpup_commit"), str)
                and not old.attrs["pumpup_commit"].endswith("-dirty") and old.attrs["pumpup_commit"] != "unknown"):
            return False
    write_table(ds, path)
    return True
