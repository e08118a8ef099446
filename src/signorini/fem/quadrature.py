"""Quadrature rules on the reference triangle, the reference tetrahedron and the unit interval.

The one owner of Gauss-Legendre points on [0, 1]: :func:`gauss_legendre` by number of
points, :func:`line_rule` by polynomial degree.

The reference triangle is ``T = {(x, y) : x >= 0, y >= 0, x + y <= 1}`` with
vertices (0, 0), (1, 0), (0, 1) and area 1/2; the reference interval is [0, 1].

Rules of low degree are the classical symmetric ones (centroid rule, the
three-point interior rule of degree 2, Radon's seven-point rule of degree 5).
All others are collapsed (Duffy) tensor rules: the square [0, 1]^2 is mapped
onto ``T`` by ``(s, t) -> (s, t (1 - s))``, whose Jacobian ``1 - s`` is absorbed
into a Gauss-Jacobi rule in ``s``, with a Gauss-Legendre rule in ``t``.  With
``n`` points per direction the collapsed rule integrates every polynomial of
total degree ``<= 2 n - 1`` exactly; all its weights are positive and all its
points lie strictly inside ``T``.

The reference tetrahedron is ``{x, y, z >= 0, x + y + z <= 1}`` (volume 1/6,
:data:`~signorini.mesh.reference.TETRAHEDRON`): the centroid rule (degree 1), the symmetric
four-point rule (degree 2, the stiffness of affine P2 cells), the symmetric 14-point rule of
degree 5 for degrees 4 and 5, with positive weights (two four-point orbits ``(a, a, a, 1 − 3a)``
and one six-point orbit ``(b, b, 1/2 − b, 1/2 − b)``; Walkington [4], Felippa [5]: the
curved cells' stiffness, loads, errors and η1, at about half the 27 points of the collapsed
rule of the same degree), and for degree 3 and above 5 the collapsed (conical product)
rules ``(s, t, r) -> (s, t (1 - s), r (1 - s)(1 - t))`` with Gauss-Jacobi rules of weights
``(1 - s)²`` and ``(1 - t)`` and Gauss-Legendre in ``r``: ``n³`` points, exact to degree
``2 n - 1``, positive weights, points strictly inside (Stroud [3]).

The returned arrays are cached and read-only; copy them before modifying.

References
----------
.. [1] J. Radon, "Zur mechanischen Kubatur", Monatsh. Math. 52 (1948) 286-300.
.. [2] G. Strang, G. Fix, *An Analysis of the Finite Element Method*,
   Prentice-Hall (1973), Table 4.1.
.. [3] A. H. Stroud, *Approximate Calculation of Multiple Integrals*,
   Prentice-Hall (1971) (conical product rules).
.. [4] N. Walkington, "Quadrature on simplices of arbitrary dimension", Technical report,
   Carnegie Mellon University (2000).
.. [5] C. A. Felippa, *Advanced Finite Element Methods*, University of Colorado, §17.4
   (the 14-point tetrahedron rule).
"""

from __future__ import annotations

import operator
from functools import cache, lru_cache

import numpy as np
from scipy.special import roots_jacobi

__all__ = ["exact_degree", "gauss_legendre", "line_rule", "tetrahedron_rule", "triangle_rule"]


def _check_integer(degree: int, what: str = "quadrature degree", minimum: int = 0) -> int:
    """Return ``degree`` as a Python int ``>= minimum``, or raise ``ValueError`` naming ``what``."""
    message = f"{what} must be an integer >= {minimum}, got {degree!r}"
    if isinstance(degree, bool | np.bool_):
        raise ValueError(message)
    try:
        deg = operator.index(degree)
    except TypeError:
        raise ValueError(message) from None
    if deg < minimum:
        raise ValueError(message)
    return deg


def _frozen(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    for a in arrays:
        a.setflags(write=False)
    return arrays


def exact_degree(degree: int) -> int:
    """Highest total degree integrated exactly by ``triangle_rule(degree)``.

    This is ``degree`` itself for ``degree <= 3`` and for odd degrees, and
    ``degree + 1`` for the even degrees ``>= 4`` (both the seven-point rule
    used for degree 4 and the collapsed rules are of odd degree).

    Parameters
    ----------
    degree : int
        Requested degree, ``>= 0``.

    Returns
    -------
    int
        The precise polynomial degree of the rule.
    """
    deg = _check_integer(degree)
    if deg <= 1:
        return 1
    if deg in (2, 3):
        return deg
    return deg if deg % 2 else deg + 1


@lru_cache(maxsize=64)
def _triangle_rule(deg: int) -> tuple[np.ndarray, np.ndarray]:
    if deg <= 1:
        # centroid rule
        xi = np.array([[1.0 / 3.0, 1.0 / 3.0]])
        w = np.array([0.5])
    elif deg == 2:
        # three interior points, degree 2 (Strang-Fix)
        xi = np.array([[1.0 / 6.0, 1.0 / 6.0], [2.0 / 3.0, 1.0 / 6.0], [1.0 / 6.0, 2.0 / 3.0]])
        w = np.full(3, 1.0 / 6.0)
    elif deg in (4, 5):
        # Radon's seven-point rule, degree 5
        r15 = np.sqrt(15.0)
        a1 = (6.0 - r15) / 21.0
        a2 = (6.0 + r15) / 21.0
        w1 = (155.0 - r15) / 2400.0
        w2 = (155.0 + r15) / 2400.0
        xi = np.array(
            [
                [1.0 / 3.0, 1.0 / 3.0],
                [a1, a1],
                [1.0 - 2.0 * a1, a1],
                [a1, 1.0 - 2.0 * a1],
                [a2, a2],
                [1.0 - 2.0 * a2, a2],
                [a2, 1.0 - 2.0 * a2],
            ]
        )
        w = np.array([9.0 / 80.0, w1, w1, w1, w2, w2, w2])
    else:
        n = deg // 2 + 1  # 2 n - 1 >= deg
        # s in [0, 1] with weight (1 - s): Gauss-Jacobi(alpha=1, beta=0) on [-1, 1]
        xj, wj = roots_jacobi(n, 1.0, 0.0)
        s = 0.5 * (1.0 + xj)
        ws = 0.25 * wj
        t, wt = _gauss_legendre(n)
        S, T = np.meshgrid(s, t, indexing="ij")
        xi = np.column_stack([S.ravel(), (T * (1.0 - S)).ravel()])
        w = np.outer(ws, wt).ravel()
    return _frozen(np.ascontiguousarray(xi, dtype=np.float64), np.asarray(w, dtype=np.float64))


def triangle_rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Quadrature rule on the reference triangle (0, 0), (1, 0), (0, 1).

    Parameters
    ----------
    degree : int
        Every polynomial of total degree ``<= degree`` is integrated exactly
        (see :func:`exact_degree` for the precise degree, which may be one more).
        Any integer ``>= 0``.

    Returns
    -------
    xi : ndarray of float64, shape (q, 2)
        Points, strictly inside the triangle.
    w : ndarray of float64, shape (q,)
        Positive weights, summing to 1/2 (the area).

    Raises
    ------
    ValueError
        If ``degree`` is not a non-negative integer.
    """
    return _triangle_rule(_check_integer(degree))


@cache
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return _frozen(0.5 * (1.0 + x), 0.5 * w)


def gauss_legendre(n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``n_points``-point Gauss-Legendre rule on [0, 1].

    Parameters
    ----------
    n_points : int
        Number of points, ``>= 1``; polynomials of degree ``<= 2 n_points - 1`` are
        integrated exactly.

    Returns
    -------
    t : ndarray of float64, shape (n_points,)
        Points in (0, 1), increasing.
    w : ndarray of float64, shape (n_points,)
        Positive weights summing to 1.

    Raises
    ------
    ValueError
        If ``n_points`` is not an integer ``>= 1``.
    """
    return _gauss_legendre(_check_integer(n_points, "number of Gauss points", minimum=1))


def line_rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre rule on [0, 1] for a polynomial degree.

    Parameters
    ----------
    degree : int
        Polynomials of degree ``<= degree`` are integrated exactly (with
        ``degree // 2 + 1`` points, hence exactly up to degree
        ``2 (degree // 2) + 1``).

    Returns
    -------
    t : ndarray of float64, shape (q,)
        Points in (0, 1), increasing.
    w : ndarray of float64, shape (q,)
        Positive weights summing to 1.

    Raises
    ------
    ValueError
        If ``degree`` is not a non-negative integer.
    """
    return _gauss_legendre(_check_integer(degree) // 2 + 1)


#: the 14-point rule's orbits: (a, weight × 6) of ``(a, a, a, 1 − 3a)``, twice, then
#: ``(b, weight × 6)`` of ``(b, b, 1/2 − b, 1/2 − b)`` (barycentric coordinates)
_S31 = (
    (0.31088591926330060980, 0.11268792571801585080),
    (0.092735250310891226402, 0.073493043116361949544),
)
_S22 = (0.045503704125649649492, 0.042546020777081466438)


def _tetrahedron_14() -> tuple[np.ndarray, np.ndarray]:
    """The symmetric 14-point rule of degree 5 (barycentric orbits ``_S31``, ``_S22``)."""
    bary, w = [], []
    for a, weight in _S31:
        for k in range(4):  # the orbit's four points
            point = np.full(4, a)
            point[k] = 1.0 - 3.0 * a
            bary.append(point)
            w.append(weight)
    b, weight = _S22
    for i in range(4):  # the orbit's six points: the pairs i < j carrying b
        for j in range(i + 1, 4):
            point = np.full(4, 0.5 - b)
            point[[i, j]] = b
            bary.append(point)
            w.append(weight)
    return np.array(bary)[:, 1:], np.array(w) / 6.0


@lru_cache(maxsize=32)
def _tetrahedron_rule(deg: int) -> tuple[np.ndarray, np.ndarray]:
    if deg <= 1:
        xi = np.full((1, 3), 0.25)
        w = np.array([1.0 / 6.0])
    elif deg == 2:
        a = (5.0 - np.sqrt(5.0)) / 20.0
        b = 1.0 - 3.0 * a
        xi = np.full((4, 3), a)
        xi[1:, :][np.arange(3), np.arange(3)] = b
        w = np.full(4, 1.0 / 24.0)
    elif deg in (4, 5):
        xi, w = _tetrahedron_14()
    else:
        n = deg // 2 + 1  # 2 n - 1 >= deg
        xs, ws = roots_jacobi(n, 2.0, 0.0)  # weight (1 - s)² on [0, 1]
        xt, wt = roots_jacobi(n, 1.0, 0.0)  # weight (1 - t)
        r, wr = _gauss_legendre(n)
        s, t = 0.5 * (1.0 + xs), 0.5 * (1.0 + xt)
        S, T, R = np.meshgrid(s, t, r, indexing="ij")
        xi = np.column_stack(
            [S.ravel(), (T * (1.0 - S)).ravel(), (R * (1.0 - S) * (1.0 - T)).ravel()]
        )
        w = np.einsum("i,j,k->ijk", ws / 8.0, wt / 4.0, wr).ravel()
    return _frozen(np.ascontiguousarray(xi, dtype=np.float64), np.asarray(w, dtype=np.float64))


def tetrahedron_rule(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Quadrature rule on the reference tetrahedron (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1).

    Parameters
    ----------
    degree : int
        Every polynomial of total degree ``<= degree`` is integrated exactly: 1 point for
        degree 1, 4 for degree 2, 14 for degrees 4 and 5, ``n³`` with ``n = degree // 2 + 1``
        for the others (exact to ``2 n - 1``).

    Returns
    -------
    xi : ndarray of float64, shape (q, 3)
        Points, strictly inside the tetrahedron.
    w : ndarray of float64, shape (q,)
        Positive weights, summing to 1/6 (the volume).

    Raises
    ------
    ValueError
        If ``degree`` is not a non-negative integer.
    """
    return _tetrahedron_rule(_check_integer(degree))
