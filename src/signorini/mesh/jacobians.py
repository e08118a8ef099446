"""Jacobians of the maps from a reference simplex: det J, J⁻¹, J⁻ᵀ of ``(..., d, d)`` batches.

The one place where these are computed, each kernel choosing its closed form by the
dimension ``d = J.shape[-1]`` (the only dimension dispatch besides the mapping,
:mod:`signorini.fem.mapping`):

- ``d = 2``: ``det J = J₀₀ J₁₁ − J₀₁ J₁₀`` and ``J⁻¹ = [[J₁₁, −J₀₁], [−J₁₀, J₀₀]] / det J``,
  written exactly as the package has always evaluated them (the same operations in the same
  order), so every 2D result is bit for bit what it was.
- ``d = 3``: the cofactor matrix ``C = det J · J⁻ᵀ``, whose rows are the cross products of
  the rows of ``J`` (``C₀ = J₁ × J₂``, ``C₁ = J₂ × J₀``, ``C₂ = J₀ × J₁``), and
  ``det J = J₀ · C₀`` (the triple product, the rule of Sarrus); ``J⁻ᵀ = C / det J``,
  ``J⁻¹ = Cᵀ / det J``.

The module lives in the ground layer, beside :mod:`signorini.mesh.geometry`, so that the
mesh's own checks (a cell's signed measure) and the finite-element mapping read one
determinant. These are kernels on trusted arrays: nothing here checks for singular ``J``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["affine_jacobian", "cofactor", "determinant", "inverse", "inverse_transpose"]


def affine_jacobian(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Jacobians of the affine maps ``x = v₀ + J ξ`` from the reference simplex.

    Parameters
    ----------
    vertices : (m, d + 1, d) float array
        Cell vertices (``points[cells]``), positively oriented.

    Returns
    -------
    J : (m, d, d) float array
        Columns ``J[:, :, k − 1] = v_k − v₀``, k = 1 … d.
    det : (m,) float array
        ``det J`` = d! times the cell's measure (positive for positively oriented cells).
    """
    v = np.asarray(vertices, dtype=np.float64)
    J = np.stack([v[:, k] - v[:, 0] for k in range(1, v.shape[-1] + 1)], axis=2)
    return J, determinant(J)


def determinant(J: np.ndarray) -> np.ndarray:
    """``det J`` of a batch ``J (..., d, d)``, d = 2 or 3; shape ``(...)``."""
    if J.shape[-1] == 2:
        return J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
    return np.einsum("...i,...i->...", J[..., 0, :], np.cross(J[..., 1, :], J[..., 2, :]))


def cofactor(J: np.ndarray) -> np.ndarray:
    """The cofactor matrices ``C = det J · J⁻ᵀ`` of a batch ``J (..., d, d)``, d = 2 or 3.

    In 2D ``C = [[J₁₁, −J₁₀], [−J₀₁, J₀₀]]``; in 3D row i of ``C`` is the cross product of
    rows i + 1 and i + 2 (mod 3) of ``J``.
    """
    J = np.asarray(J, dtype=np.float64)
    out = np.empty_like(J)
    if J.shape[-1] == 2:
        out[..., 0, 0] = J[..., 1, 1]
        out[..., 0, 1] = -J[..., 1, 0]
        out[..., 1, 0] = -J[..., 0, 1]
        out[..., 1, 1] = J[..., 0, 0]
        return out
    for i in range(3):  # a loop over the three rows
        out[..., i, :] = np.cross(J[..., (i + 1) % 3, :], J[..., (i + 2) % 3, :])
    return out


def inverse_transpose(
    J: np.ndarray, det: np.ndarray | None = None, *, reciprocal: bool = False
) -> np.ndarray:
    """``J⁻ᵀ = C / det J`` of a batch ``J (..., d, d)``; physical gradients are ``J⁻ᵀ ∇_ξ``.

    Parameters
    ----------
    J : (..., d, d) float array
    det : (...) float array, optional
        ``det J`` (computed by :func:`determinant` if omitted).
    reciprocal : bool
        Multiply the cofactors by ``1 / det J`` (one division per matrix: the affine cells'
        form) instead of dividing each of them by ``det J`` (the per-point form of curved
        cells). The two differ in the last bit; each caller keeps its own.

    Returns
    -------
    (..., d, d) float array
    """
    J = np.asarray(J, dtype=np.float64)
    if det is None:
        det = determinant(J)
    if reciprocal:
        inv_det = 1.0 / det
        if J.shape[-1] == 2:  # the 2D form: each cofactor times 1 / det, as written here
            out = np.empty_like(J)
            out[..., 0, 0] = J[..., 1, 1] * inv_det
            out[..., 0, 1] = -J[..., 1, 0] * inv_det
            out[..., 1, 0] = -J[..., 0, 1] * inv_det
            out[..., 1, 1] = J[..., 0, 0] * inv_det
            return out
        return cofactor(J) * inv_det[..., None, None]
    out = cofactor(J)
    out /= det[..., None, None]
    return out


def inverse(J: np.ndarray, det: np.ndarray | None = None) -> np.ndarray:
    """``J⁻¹ = Cᵀ / det J`` of a batch ``J (..., d, d)`` (each cofactor divided by ``det J``).

    Parameters
    ----------
    J : (..., d, d) float array
    det : (...) float array, optional
        ``det J`` (computed by :func:`determinant` if omitted).

    Returns
    -------
    (..., d, d) float array, laid out in memory as ``J`` is
    """
    J = np.asarray(J, dtype=np.float64)
    if det is None:
        det = determinant(J)
    out = np.empty_like(J)
    if J.shape[-1] == 2:
        out[..., 0, 0] = J[..., 1, 1]
        out[..., 0, 1] = -J[..., 0, 1]
        out[..., 1, 0] = -J[..., 1, 0]
        out[..., 1, 1] = J[..., 0, 0]
    else:
        out[...] = np.swapaxes(cofactor(J), -1, -2)
    out /= det[..., None, None]
    return out
