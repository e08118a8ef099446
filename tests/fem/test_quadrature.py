"""Quadrature rules: exactness on monomials, and failure just past the stated degree."""

from math import factorial

import numpy as np
import pytest

from signorini.fem.quadrature import exact_degree, gauss_legendre, line_rule, triangle_rule


def monomial_triangle(a: int, b: int) -> float:
    """Closed form of int_T x^a y^b over the reference triangle."""
    return factorial(a) * factorial(b) / factorial(a + b + 2)


def worst_relative_error(xi, w, degree):
    """Largest relative error over all monomials x^a y^b of total degree ``degree``."""
    errs = []
    for a in range(degree + 1):
        b = degree - a
        approx = np.sum(w * xi[:, 0] ** a * xi[:, 1] ** b)
        exact = monomial_triangle(a, b)
        errs.append(abs(approx - exact) / exact)
    return max(errs)


@pytest.mark.parametrize("degree", range(0, 16))
def test_triangle_rule_exact_up_to_degree(degree):
    xi, w = triangle_rule(degree)
    assert xi.shape == (w.size, 2) and xi.dtype == np.float64
    assert np.all(w > 0)
    assert abs(w.sum() - 0.5) < 1e-15
    # strictly inside the reference triangle
    assert np.all(xi > 0) and np.all(xi.sum(axis=1) < 1)
    for d in range(exact_degree(degree) + 1):
        assert worst_relative_error(xi, w, d) < 1e-13, d


@pytest.mark.parametrize("degree", range(0, 16))
def test_triangle_rule_not_exact_past_its_degree(degree):
    xi, w = triangle_rule(degree)
    precise = exact_degree(degree)
    assert precise >= max(degree, 1)
    # the test above would catch a rule that is wrong: one degree more is not exact
    assert worst_relative_error(xi, w, precise + 1) > 1e-6


def test_exact_degree_is_the_requested_one_where_possible():
    # the small symmetric rules and every odd degree are exactly of the requested degree
    for d in (1, 2, 3, 5, 7, 9, 11, 13):
        assert exact_degree(d) == d
    for d in (4, 6, 8, 10, 12):
        assert exact_degree(d) == d + 1


def test_triangle_rule_point_counts():
    # the cheap rules used by the assembly
    assert triangle_rule(1)[0].shape == (1, 2)
    assert triangle_rule(2)[0].shape == (3, 2)
    assert triangle_rule(5)[0].shape == (7, 2)


@pytest.mark.parametrize("degree", range(0, 24))
def test_line_rule(degree):
    t, w = line_rule(degree)
    assert np.all(w > 0) and abs(w.sum() - 1.0) < 1e-15
    assert np.all((t > 0) & (t < 1)) and np.all(np.diff(t) > 0)
    top = 2 * (degree // 2) + 1
    assert top >= degree
    for k in range(top + 1):
        assert abs(np.sum(w * t**k) - 1.0 / (k + 1)) < 1e-14 * (k + 1), k
    # degree top + 1 = 2 n: the squared node polynomial vanishes at every point but
    # has the positive integral 1 / (2 n + 1) * (n!^2 / (2n)!)^2 (monic Legendre on [0, 1])
    n = t.size
    assert top + 1 == 2 * n
    node_poly2 = np.prod((t[:, None] - t[None, :]) ** 2, axis=1)
    assert np.allclose(node_poly2, 0.0)
    exact = (factorial(n) ** 2 / factorial(2 * n)) ** 2 / (2 * n + 1)
    tt, ww = line_rule(4 * n)  # a finer rule integrates it exactly
    fine = np.sum(ww * np.prod((tt[:, None] - t[None, :]) ** 2, axis=1))
    assert abs(fine - exact) < 1e-12 * exact
    assert np.sum(w * node_poly2) < 1e-6 * exact


def test_line_rule_integrates_a_shifted_polynomial():
    # int_0^1 (3 t - 1)^7 dt = (2^8 - (-1)^8) / (3 * 8)
    t, w = line_rule(7)
    assert abs(np.sum(w * (3 * t - 1) ** 7) - (2**8 - 1) / 24) < 1e-12


@pytest.mark.parametrize("n", [1, 2, 3, 7, 20, 400])
def test_gauss_legendre_exact_to_degree_2n_minus_1(n):
    t, w = gauss_legendre(n)
    assert t.shape == w.shape == (n,)
    assert np.all(w > 0) and abs(w.sum() - 1.0) < 1e-13
    assert np.all((t > 0) & (t < 1)) and np.all(np.diff(t) > 0)
    # Legendre polynomials shifted to [0, 1]: ∫ P_k = 0 for 1 <= k <= 2n - 1, and
    # ∫ P_{2n} = 0 is missed (P_{2n} = c q² + lower terms, q the node polynomial)
    for k in (1, n, 2 * n - 1):
        pk = np.polynomial.legendre.Legendre.basis(k)(2 * t - 1)
        assert abs(np.sum(w * pk)) < 1e-13, k
    p2n = np.polynomial.legendre.Legendre.basis(2 * n)(2 * t - 1)
    assert abs(np.sum(w * p2n)) > 1e-3


def test_line_rule_is_gauss_legendre_with_degree_over_two_plus_one_points():
    for degree in range(12):
        t, w = line_rule(degree)
        tg, wg = gauss_legendre(degree // 2 + 1)
        assert t is tg and w is wg  # one cached rule, the same arrays


@pytest.mark.parametrize("bad", [0, -2, 2.0, "3", None, False])
def test_bad_number_of_gauss_points_raises(bad):
    with pytest.raises(ValueError, match="number of Gauss points"):
        gauss_legendre(bad)


@pytest.mark.parametrize("bad", [-1, 1.5, "3", None, True])
def test_bad_degree_raises(bad):
    with pytest.raises(ValueError, match="degree"):
        triangle_rule(bad)
    with pytest.raises(ValueError, match="degree"):
        line_rule(bad)


def test_numpy_integer_degree_and_read_only():
    xi, w = triangle_rule(np.int64(4))
    with pytest.raises(ValueError):
        w[0] = 1.0
    assert xi.flags.writeable is False
