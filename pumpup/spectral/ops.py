"""Energy compensation and saved pumped BRDFs, wavelength by wavelength (pumpup.spectral).

:func:`pumpup.compensate` of a spectral BRDF compensates every wavelength's model on its own
(:class:`SpectralCompensated`; the Kulla-Conty lobe and the 1/E scaling of
:mod:`pumpup.compensate`, or pumping for ``"g1"``/``"g2"``).  For a metal the Fresnel-1 lobe
(000 eq. 28 with F = 1, the stretched Phong lobe) is the same at every wavelength, so one E
table serves them all and only F_avg differs.

:func:`pumpup.save_pumped` of a spectral pumped BRDF writes one netCDF file
(:func:`save_spectral_pumped`): a root with the ``wavelength`` dimension, the spec and the
per-wavelength parameters, and one group ``wavelength{j}/level{i}`` per wavelength and level
holding that level's albedo table (each wavelength's adaptive grid is its own, so the tables
are not forced onto one grid); :func:`pumpup.load_pumped` reads it back without recomputing
(:func:`load_spectral_pumped`), every group validated by :func:`pumpup.open_table`.
"""

from __future__ import annotations

import json
import os
from typing import Any

import numpy as np

from ..core import SpecError
from . import Spectral, SpectralPumped

__all__ = ["SpectralCompensated", "compensate_spectral", "save_spectral_pumped", "load_spectral_pumped",
           "SPECTRAL_PUMPED_KIND"]

#: the ``pumpup_kind`` of a saved spectral pumped BRDF
SPECTRAL_PUMPED_KIND = "pumpup spectral pumped BRDF"


def compensate_spectral(base: Spectral, method: str = "kulla_conty", *, f0=None, f_avg=None, white=None,
                        force: bool = False) -> Spectral:
    """:func:`pumpup.compensate` of a spectral BRDF: pumping for ``"g1"``/``"g2"``
    (:class:`~pumpup.spectral.SpectralPumped`), else :class:`SpectralCompensated`.
    """
    if method in ("g1", "g2"):
        if f0 is not None or f_avg is not None or white is not None:
            raise SpecError(f"compensate: method {method!r} (pumping) takes no f0, f_avg or white")
        return SpectralPumped(base, g=method, force=force)
    return SpectralCompensated(base, method, f0=f0, f_avg=f_avg, white=white, force=force)


class SpectralCompensated(Spectral):
    """A spectral BRDF energy-compensated wavelength by wavelength (:func:`pumpup.compensate`).

    Parameters
    ----------
    base : Spectral
        A spectral metal or plastic (or a pumped or compensated one).
    method : {"kulla_conty", "scale"}
        As :func:`pumpup.compensate`, applied to each wavelength's model.
    f0, f_avg : float, in [0, 1], optional
        Shared by all wavelengths when given; by default "kulla_conty" takes each wavelength's
        own F_avg from its Fresnel factor (:func:`pumpup.operators.compensate.fresnel_average`) and
        "scale" takes F0 = 1.
    white : BRDF or spec, optional
        The Fresnel-1 BRDF whose albedo is E (default: each model without its Fresnel factor).
    force : bool
        Accept a non-reciprocal base.
    """

    def __init__(self, base: Spectral, method: str = "kulla_conty", *, f0=None, f_avg=None, white=None,
                 force: bool = False):
        from ..operators.compensate import compensate

        if method not in ("kulla_conty", "scale"):
            raise SpecError(f"compensate: method must be 'kulla_conty' or 'scale' here (pumping: 'g1', 'g2' through "
                            f"pumpup.compensate), got {method!r}")
        self.base = base
        self.method = method
        self.material = base.material
        self.wavelengths = base.wavelengths
        self.eta, self.k = getattr(base, "eta", None), getattr(base, "k", None)
        if method == "kulla_conty" and f0 is not None:
            if f_avg is not None:
                raise SpecError("compensate: give 'f0' or 'f_avg' for method 'kulla_conty', not both")
            f_avg, f0 = (20.0 * float(f0) + 1.0) / 21.0, None  # F_avg of Schlick's Fresnel, as pumpup.compensate
        self.f0, self.f_avg, self.force = f0, f_avg, bool(force)
        self.white = white
        models = []
        for w, m in zip(self.wavelengths, base.models):
            try:
                models.append(compensate(m, method=method, f0=f0, f_avg=f_avg, white=white, force=force))
            except SpecError as exc:
                raise SpecError(f"compensate at {w:g} nm: {exc}") from None
        self.models = models

    @classmethod
    def from_spec(cls, spec: dict, load) -> SpectralCompensated:
        """Build from ``{"type": "kulla_conty" | "scaled", "base": <spectral spec>, ...}``."""
        kind = spec["type"]
        allowed = {"base", "white", "force", "f_avg" if kind == "kulla_conty" else "f0"}
        kw = {k: v for k, v in spec.items() if k != "type"}
        bad = sorted(set(kw) - allowed)
        if bad or "base" not in kw:
            raise SpecError(f"spectral.load: a {kind} spec needs 'base' and allows {', '.join(sorted(allowed))}; "
                            f"got {sorted(kw)}")
        method = "kulla_conty" if kind == "kulla_conty" else "scale"
        return cls(load(kw["base"]), method, f0=kw.get("f0"), f_avg=kw.get("f_avg"), white=kw.get("white"),
                   force=kw.get("force", False))

    @property
    def spec(self) -> dict:
        """The model as a plain-JSON dict: a ``kulla_conty`` spec (with ``f_avg`` where given) or a ``scaled`` one
        (``f0``, 1 by default), with ``white`` and ``force`` where they are set.
        """
        if self.method == "kulla_conty":
            out: dict[str, Any] = {"type": "kulla_conty", "base": self.base.spec}
            if self.f_avg is not None:
                out["f_avg"] = float(self.f_avg)
        else:
            out = {"type": "scaled", "base": self.base.spec, "f0": 1.0 if self.f0 is None else float(self.f0)}
        if self.white is not None:
            out["white"] = self.white.spec if hasattr(self.white, "spec") else self.white
        if self.force:
            out["force"] = True
        return out

    def __repr__(self) -> str:
        return f"SpectralCompensated({self.base!r}, method={self.method!r})"


# --- saving and loading a spectral pumped BRDF ----------------------------------------------------


def _group(j: int, i: int) -> str:
    return f"wavelength{j}/level{i}"


def save_spectral_pumped(f: Spectral, path) -> str:
    """Write a spectral pumped BRDF and the albedo tables of every wavelength's levels to one netCDF file.

    The root holds the ``wavelength`` coordinate [nm], the per-wavelength parameters of the
    innermost model (``eta``, ``k``, ``ad``, ``a_s``) and the spec; group ``wavelength{j}/level{i}``
    holds the table of level i (``level1``: the innermost base; ``level<levels + 1>``: the pumped model itself) of
    wavelength j.  Written
    atomically with checksums and digests (:func:`pumpup.tables.write_groups`).
    """
    import xarray as xr

    from .._version import __version__
    from ..operators.pumping import base_table
    from ..tables import write_groups

    if not isinstance(f, SpectralPumped):
        raise TypeError(f"save_pumped needs a pumped BRDF (pumpup.pump); got {f!r}, "
                        "a spectral model that is not pumped")
    chains = [m.chain() for m in f.models]
    levels = len(chains[0])
    data = {name: ("wavelength", v) for name, v in f.wavelength_variables().items()}
    root = xr.Dataset(data, coords={"wavelength": ("wavelength", np.asarray(f.wavelengths, dtype=np.float64),
                                                   {"units": "nm", "long_name": "vacuum wavelength"})},
                      attrs={"pumpup_kind": SPECTRAL_PUMPED_KIND, "spec": json.dumps(f.spec, sort_keys=True),
                             "levels": levels, "pumpup_version": __version__,
                             "layout": "group wavelength{j}/level{i}: albedo table of level i (1 = innermost base) "
                                       "at wavelength[j]"})
    material = f.innermost().material
    if material is not None:  # the provenance of the optical constants, as in tabulate's tables
        from . import optical

        for key, val in optical.metadata(material).items():
            root.attrs[f"optical_{key}"] = val
    groups = [(_group(j, i), level.table().dataset) for j, chain in enumerate(chains)
              for i, level in enumerate(chain, start=1)]
    groups += [(_group(j, len(chain) + 1), base_table(chain[-1]).dataset)  # each wavelength's pumped BRDF itself
               for j, chain in enumerate(chains)]
    return write_groups(path, root, groups)


def load_spectral_pumped(path, root=None, where: str | None = None) -> SpectralPumped:
    """Load a spectral pumped BRDF saved by :func:`save_spectral_pumped`, without recomputing its tables.

    Every group is validated (:func:`pumpup.open_table`: checksums, digest, values); the root's
    wavelengths and parameters must be those its spec builds, and each group must hold the
    table of the level its name says.  The tables serve only the returned object.

    Raises
    ------
    pumpup.tables.validate.TableError (a ValueError)
        If the file is damaged, edited, or not a saved spectral pumped BRDF.
    """
    from ..core import load
    from ..operators.pumping import attach_level_table, attach_top_table
    from ..tables import open_table, snapshot
    from ..tables.validate import TableError, spec_attribute

    if root is None:  # every group from one file, whatever a concurrent save puts at path meanwhile
        with snapshot(path) as copy:
            return load_spectral_pumped(copy, open_table(copy, _container=True, _name=os.fspath(path)),
                                        os.fspath(path))
    where = os.fspath(path) if where is None else where
    if root.attrs.get("pumpup_kind") != SPECTRAL_PUMPED_KIND:
        raise TableError(f"{where!r} is a pumpup file, not a saved spectral pumped BRDF")
    spec = spec_attribute(where, root)
    try:
        f = load(spec)
    except (SpecError, ValueError, TypeError) as exc:  # pragma: no cover - spec_attribute loaded it already
        raise TableError(f"{where!r}: its spec does not load: {exc}") from None
    if not isinstance(f, SpectralPumped):
        raise TableError(f"{where!r}: its spec is a {spec.get('type')!r}, not a spectral pumped BRDF")
    if "wavelength" not in root.coords or not np.array_equal(root["wavelength"].values, f.wavelengths):
        raise TableError(f"{where!r}: its wavelength coordinate is not the spec's wavelengths {f.wavelengths.tolist()}")
    for name, v in f.wavelength_variables().items():
        if name not in root or not np.array_equal(root[name].values, v):
            raise TableError(f"{where!r}: variable {name!r} is missing or differs from what its spec gives")
    try:
        levels = int(np.asarray(root.attrs["levels"]).item())
    except (KeyError, TypeError, ValueError):
        raise TableError(f"{where!r}: attribute 'levels' is missing or not an integer") from None
    for j, m in enumerate(f.models):
        chain = m.chain()
        if levels != len(chain):
            raise TableError(f"{where!r}: attribute 'levels' = {levels} but its spec has {len(chain)} levels")
        for i, level in enumerate(chain, start=1):
            attach_level_table(path, where, _group(j, i), level, f"level {i} at {f.wavelengths[j]:g} nm")
        attach_top_table(path, where, _group(j, len(chain) + 1), chain[-1])
    return f
