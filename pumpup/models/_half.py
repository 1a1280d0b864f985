"""A compiled helper shared by the (N.H) models (Blinn, Ward, Schlick, Cook-Torrance)."""

from numba import njit


@njit(cache=True, inline="always")
def tan2_half(lx, ly, lz, vx, vy, vz):  # pragma: no cover - compiled
    """tan^2(delta), delta the angle between N and H = (L + V) / |L + V|.

    Computed from S = L + V without normalising, (S_x^2 + S_y^2) / S_z^2: exact near the
    highlight (no 1 - (N.H)^2 cancellation) and symmetric in L and V to the last bit.
    """
    sz = lz + vz
    qx = (lx + vx) / sz  # h_x / h_z
    qy = (ly + vy) / sz  # h_y / h_z
    return qx * qx + qy * qy
