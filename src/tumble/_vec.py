"""Vector algebra: the one cross product, matrix product and 3×3 solve (compiled), and the one scaled norm.

Kernels pass vectors as three floats (``a1, a2, a3``) rather than arrays, so
that nothing is allocated in the inner loops; these functions are inlined
into their callers. :func:`norm` is the NumPy norm of the Python layer.
Frames are the callers' (the functions are frame-free).
"""

from __future__ import annotations

import numpy as np
from numba import njit


def norm(v) -> np.ndarray:
    """Euclidean norm ``|v|`` along the last axis of ``v`` (…, k), at any magnitude of the components.

    ``|v| = m |v / m|`` with ``m = max |vᵢ|``: the squares of ``v / m`` lie in
    [0, 1], so they neither overflow (``|[1e200, 0, 0]|`` is 1e200, where
    ``np.linalg.norm`` gives inf) nor underflow (``|[1e-200, 0, 0]|`` is
    1e-200, not 0). The result is inf only where ``|v|`` itself exceeds the
    float64 maximum (1.8e308); NaN where ``v`` holds NaN.
    """
    v = np.asarray(v, dtype=np.float64)
    largest = np.abs(v).max(axis=-1, initial=0.0)
    with np.errstate(over="ignore", invalid="ignore"):
        unit = v / np.where((largest > 0.0) & (largest < np.inf), largest, 1.0)[..., None]
        return largest * np.sqrt(np.einsum("...i,...i->...", unit, unit))


@njit(cache=True, inline="always")
def cross(a1, a2, a3, b1, b2, b3):
    """``a × b = (a₂b₃ − a₃b₂, a₃b₁ − a₁b₃, a₁b₂ − a₂b₁)`` of two 3-vectors given by components."""
    return a2 * b3 - a3 * b2, a3 * b1 - a1 * b3, a1 * b2 - a2 * b1


@njit(cache=True, inline="always")
def matvec(M, x1, x2, x3):
    """``M x`` for a (3, 3) array ``M`` and a 3-vector given by components."""
    return (
        M[0, 0] * x1 + M[0, 1] * x2 + M[0, 2] * x3,
        M[1, 0] * x1 + M[1, 1] * x2 + M[1, 2] * x3,
        M[2, 0] * x1 + M[2, 1] * x2 + M[2, 2] * x3,
    )


@njit(cache=True, inline="always")
def matvec_flat(d, o, x1, x2, x3):
    """``M x`` for the row-major 3×3 matrix ``M = d[o:o+9]`` stored in a flat parameter block."""
    return (d[o] * x1 + d[o + 1] * x2 + d[o + 2] * x3, d[o + 3] * x1 + d[o + 4] * x2 + d[o + 5] * x3,
            d[o + 6] * x1 + d[o + 7] * x2 + d[o + 8] * x3)


@njit(cache=True, inline="always")
def solve_symmetric(a00, a01, a02, a11, a12, a22, b0, b1, b2):
    """Solve ``A x = b`` for a symmetric 3×3 ``A`` (upper triangle given) by Cramer's rule.

    ``A`` must be non-singular (the callers pass positive-definite matrices).
    """
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    c11 = a00 * a22 - a02 * a02
    c12 = a01 * a02 - a00 * a12
    c22 = a00 * a11 - a01 * a01
    det = a00 * c00 + a01 * c01 + a02 * c02
    return ((c00 * b0 + c01 * b1 + c02 * b2) / det, (c01 * b0 + c11 * b1 + c12 * b2) / det,
            (c02 * b0 + c12 * b1 + c22 * b2) / det)


@njit(cache=True, inline="always")
def clip(x, limit):
    """``x`` clipped to ``[−limit, limit]`` (``limit ≥ 0``; ``inf`` for none)."""
    return min(max(x, -limit), limit)
