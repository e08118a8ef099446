"""The transformed quadratic face basis of Γ_C: the discrete contact condition (b) on P2 faces
as a local sparse change of variables, (a) its α = 0 (docs/method.md, *Three dimensions: the
contact condition on P2 faces*, *Three dimensions: contact on faces*).

On the constraint rows of Γ_C (one per contact node and part),

    φ̃_v = φ_v + α Σ_{edges e ∋ v} φ_e,    φ̃_e = (1 − 2α) φ_e,    φ̃ = T φ,

``T_vv = 1``, ``T_ve = α`` for each edge ``e = (a, b)`` of Γ_C at ``v``, ``T_ee = 1 − 2α``: every
column sums to 1. With ``u_h = Σ ũ_z φ̃_z`` the coefficients are ``ũ = T^{-T} u``, explicitly
``ũ_v = u_v``, ``ũ_e = (u_e − α (u_a + u_b)) / (1 − 2α)``, and back ``u = Tᵀ ũ``. The change of
variables ``y = P ỹ`` (``P`` the identity but for ``Tᵀ`` on the constraint DOFs) turns the
constraints ``ỹ_n ≤ ψ̃ = T^{-T} ψ`` into simple bounds, so PDAS runs unchanged; the multiplier
of (b) is the force on the transformed functions, ``Λ̃ = T Λ``.

An edge enters ``T`` only when its midpoint and both ends carry a constraint row of the same
part (:class:`FaceEdges`); at a held end or a held midpoint the edge keeps ``φ̃ = φ``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

__all__ = ["DEFAULT_ALPHA", "FaceEdges", "change_of_variables", "face_edges"]

#: α of the transformed basis by default: variant (b) (Popp–Wohlmuth–Gee–Wall 2012 for
#: 6-node triangles); 0 is variant (a), the nodal constraints at all P2 nodes
DEFAULT_ALPHA = 1 / 5

#: the midpoint and the two ends of the sides (a, b), (b, c), (c, a) of a 6-node face
_SIDES = np.array([[3, 0, 1], [4, 1, 2], [5, 2, 0]])


@dataclass(frozen=True)
class FaceEdges:
    """The edges of Γ_C that the transformed basis couples, on the constraint rows.

    Attributes
    ----------
    n_rows : int
        The constraint rows ``k``.
    alpha : float
        α in ``[0, 1/2)``.
    mid, start, end : (n_e,) int arrays
        Rows of each edge's midpoint and its two ends (distinct triples).
    """

    n_rows: int
    alpha: float
    mid: np.ndarray
    start: np.ndarray
    end: np.ndarray

    @property
    def transform(self) -> sp.csr_matrix:
        """``T (k, k)``: rows the new functions φ̃, columns the P2 ones."""
        k, a, e = self.n_rows, self.alpha, self.mid
        diagonal = np.ones(k)
        diagonal[e] = 1.0 - 2.0 * a
        rows = np.concatenate([np.arange(k), self.start, self.end])
        cols = np.concatenate([np.arange(k), e, e])
        values = np.concatenate([diagonal, np.full(2 * e.size, a)])
        return sp.csr_matrix((values, (rows, cols)), shape=(k, k))

    def coefficients(self, values: np.ndarray) -> np.ndarray:
        """``T^{-T} values (k,)``: nodal values as coefficients of the φ̃ (``ũ``, ``ψ̃``)."""
        out = np.array(values, dtype=np.float64)
        a = self.alpha
        out[self.mid] = (out[self.mid] - a * (out[self.start] + out[self.end])) / (1.0 - 2 * a)
        return out

    def nodal(self, coefficients: np.ndarray) -> np.ndarray:
        """``Tᵀ ũ (k,)``: coefficients of the φ̃ back to nodal values."""
        out = np.array(coefficients, dtype=np.float64)
        a = self.alpha
        out[self.mid] = (1.0 - 2 * a) * out[self.mid] + a * (out[self.start] + out[self.end])
        return out

    def transformed(self, force: np.ndarray) -> np.ndarray:
        """``T Λ (k,)``: nodal forces (or basis integrals) on the P2 functions as those on the
        φ̃ (``Λ̃``, ``w̃ = ∫ φ̃``)."""
        out = np.array(force, dtype=np.float64)
        f = np.asarray(force, dtype=np.float64)[self.mid]
        out[self.mid] = (1.0 - 2 * self.alpha) * f
        np.add.at(out, self.start, self.alpha * f)
        np.add.at(out, self.end, self.alpha * f)
        return out

    def untransformed(self, force: np.ndarray) -> np.ndarray:
        """``T^{-1} Λ̃ (k,)``: forces on the φ̃ back to those on the P2 functions,
        ``Λ_e = Λ̃_e / (1 − 2α)``, ``Λ_v = Λ̃_v − α Σ_{e ∋ v} Λ_e``."""
        out = np.array(force, dtype=np.float64)
        f = out[self.mid] / (1.0 - 2 * self.alpha)
        out[self.mid] = f
        np.add.at(out, self.start, -self.alpha * f)
        np.add.at(out, self.end, -self.alpha * f)
        return out


def face_edges(faces: np.ndarray, face_part: np.ndarray, row_of, n_rows: int, alpha: float):
    """The :class:`FaceEdges` of contact faces.

    Parameters
    ----------
    faces : (n_f, 6) int array
        The P2 nodes of the contact faces (vertices, then the midpoints of their sides).
    face_part : (n_f,) int array
        Each face's contact part.
    row_of : callable
        ``row_of(nodes, parts)`` the constraint row of each node for its part, ``-1`` where the
        node carries none (held along the part's direction).
    n_rows : int
    alpha : float
        In ``[0, 1/2)``.

    Returns
    -------
    FaceEdges
    """
    if not 0.0 <= alpha < 0.5:
        raise ValueError(f"the transformed face basis needs 0 <= alpha < 1/2, got {alpha!r}")
    triples = faces[:, _SIDES].reshape(-1, 3)  # (3 n_f, 3): midpoint, start, end
    rows = row_of(triples, np.repeat(face_part, 3)[:, None])
    rows = rows[(rows >= 0).all(axis=1)]
    rows[:, 1:] = np.sort(rows[:, 1:], axis=1)  # a side shared by two faces runs both ways
    rows = np.unique(rows, axis=0) if rows.size else np.zeros((0, 3), np.int64)
    return FaceEdges(n_rows, float(alpha), rows[:, 0], rows[:, 1], rows[:, 2])


def change_of_variables(n_dofs: int, dofs: np.ndarray, edges: FaceEdges) -> sp.csr_matrix:
    """``P (n_dofs, n_dofs)`` with ``y = P ỹ``: the identity but for ``Tᵀ`` on ``dofs (k,)``,
    the constraint DOF of each row."""
    dofs = np.asarray(dofs, dtype=np.int64)
    T = edges.transform.tocoo()
    other = np.setdiff1d(np.arange(n_dofs), dofs)
    rows = np.concatenate([dofs[T.col], other])
    cols = np.concatenate([dofs[T.row], other])
    values = np.concatenate([T.data, np.ones(other.size)])
    return sp.csr_matrix((values, (rows, cols)), shape=(n_dofs, n_dofs))
