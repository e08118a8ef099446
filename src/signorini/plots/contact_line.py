"""Positions along the contact boundary: the coordinate the pressure is drawn against, and
where the contact zone ends (the zoom of the mesh figure)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["contact_coordinate", "free_boundary_ends"]


def contact_coordinate(cp: np.ndarray) -> tuple[np.ndarray, str]:
    """Abscissa along the contact boundary and its axis label.

    Parameters
    ----------
    cp : (k, 2) float array
        Points on the contact boundary, in any order.

    Returns
    -------
    t : (k,) float array
        ``x`` or ``y`` for an axis-parallel boundary, else the arclength ``s`` along the
        points' principal direction (starting at 0, increasing with the direction's largest
        component).
    label : str
        ``"$x$"``, ``"$y$"`` or ``"$s$ (along $\\Gamma_C$)"``.
    """
    span = np.ptp(cp, axis=0)
    tol = 1e-12 * max(float(span.max()), 1.0)
    if span[1] <= tol:
        return cp[:, 0], r"$x$"
    if span[0] <= tol:
        return cp[:, 1], r"$y$"
    centred = cp - cp.mean(axis=0)
    direction = np.linalg.svd(centred, full_matrices=False)[2][0]
    if direction[np.argmax(np.abs(direction))] < 0:
        direction = -direction
    t = centred @ direction
    return t - t.min(), r"$s$ (along $\Gamma_C$)"


def free_boundary_ends(contact_points: ArrayLike, active: ArrayLike) -> np.ndarray:
    """Where the contact zone ends: midpoints between neighbouring contact nodes, one active
    and one not, in order along the boundary (:func:`contact_coordinate`).

    Parameters
    ----------
    contact_points : (k, 2) float array
        The contact nodes, in any order.
    active : (k,) bool array
        Which of them are in contact.

    Returns
    -------
    (m, 2) float array
        The ends (none when the whole boundary, or none of it, is in contact).
    """
    cp = np.asarray(contact_points, dtype=np.float64).reshape(-1, 2)
    on = np.asarray(active, dtype=bool).reshape(-1)
    if on.shape != (cp.shape[0],):
        raise ValueError(f"active must have shape ({cp.shape[0]},), got {on.shape}")
    if cp.shape[0] < 2:
        return np.zeros((0, 2))
    order = np.argsort(contact_coordinate(cp)[0], kind="stable")
    q, a = cp[order], on[order]
    change = np.flatnonzero(a[1:] != a[:-1])
    return 0.5 * (q[change] + q[change + 1])
