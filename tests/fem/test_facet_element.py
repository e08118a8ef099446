"""The facet elements (fem/facet_element.py) and the cell facts of Element (fem/element.py):
the basis shares are the integrals of the facet's basis, the pieces γ̃_p cover the facet
once, the pressure is the consistent one, and P1 fields read as P2 coefficients from the
reference cell's edges."""

from __future__ import annotations

import numpy as np
import pytest

from signorini.fem.element import ELEMENTS, P1, P2
from signorini.fem.facet_element import P1_INTERVAL, P2_INTERVAL
from signorini.fem.quadrature import gauss_legendre
from signorini.mesh.reference import INTERVAL, TRIANGLE


@pytest.mark.parametrize("element", list(ELEMENTS.values()), ids=str)
def test_cell_facts_and_facet_element(element):
    facet = element.facet
    assert element.reference is TRIANGLE and facet.reference is INTERVAL
    assert facet is {"P1": P1_INTERVAL, "P2": P2_INTERVAL}[element.name]
    assert element.reference_nodes.shape == (element.n_local, TRIANGLE.dim)
    assert np.allclose(element.basis(element.reference_nodes), np.eye(element.n_local))
    assert element.degree == {"P1": 1, "P2": 2}[element.name]
    # the facet's basis at its nodes [start, end(, midpoint)] is the identity
    nodes = np.array([0.0, 1.0, 0.5])[: facet.n_nodes]
    assert np.allclose(facet.basis(nodes), np.eye(facet.n_nodes))


@pytest.mark.parametrize("facet", [P1_INTERVAL, P2_INTERVAL], ids=str)
def test_shares_and_pieces(facet):
    t, w = gauss_legendre(4)
    assert np.allclose(w @ facet.basis(t), facet.basis_share, rtol=1e-14)
    # the hats and the basis are partitions of unity; the pieces γ̃_p cover [0, 1] once
    assert np.isclose(sum(facet.hat_share), 1.0) and np.isclose(sum(facet.basis_share), 1.0)
    assert np.isclose(sum(hi - lo for lo, hi, *_ in facet.hat_pieces), 1.0)
    parts = sorted((lo, hi) for lo, hi, _ in facet.node_parts)
    assert parts[0][0] == 0.0 and parts[-1][1] == 1.0
    assert all(a[1] == b[0] for a, b in zip(parts, parts[1:], strict=False))


@pytest.mark.parametrize("facet", [P1_INTERVAL, P2_INTERVAL], ids=str)
def test_pressure_is_the_consistent_division(facet):
    """For a pressure p of one degree less than the element's (P2: linear, P1: constant),
    Λ_z = ∫ p ψ_z and Λ_z / w_z = p(z) (the nodes of one facet)."""
    t, w = gauss_legendre(4)
    slope = 3.0 if facet.n_nodes == 3 else 0.0
    p = 2.0 + slope * t
    force = w @ (p[:, None] * facet.basis(t))
    weight = np.asarray(facet.basis_share)
    nodes = np.array([0.0, 1.0, 0.5])[: facet.n_nodes]
    assert np.allclose(facet.pressure(force, weight), 2.0 + slope * nodes, rtol=1e-14)
    assert np.array_equal(facet.pressure(force, weight), force / weight)


def test_facet_values_read_p1_facet_data_as_p2():
    values = np.array([[1.0, 3.0], [2.0, -2.0]])
    assert np.array_equal(P1.facet.facet_values(values), [[1.0, 3.0, 2.0], [2.0, -2.0, 0.0]])
    p2_values = np.arange(6.0).reshape(2, 3)
    assert np.array_equal(P2.facet.facet_values(p2_values), p2_values)


def test_p1_cell_coefficients_put_edge_means_at_the_midpoints():
    rng = np.random.default_rng(0)
    u = rng.random((4, 3 * 2))
    out = P1.cell_coefficients(u).reshape(4, 6, 2)
    v = u.reshape(4, 3, 2)
    for k, (a, b) in enumerate(TRIANGLE.edges):
        assert np.array_equal(out[:, 3 + k], 0.5 * (v[:, a] + v[:, b]))
    assert np.array_equal(out[:, :3], v)
    p2_cell = out.reshape(4, 12)
    assert P2.cell_coefficients(p2_cell) is p2_cell
