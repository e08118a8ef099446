"""Hierarchical subdivision (:mod:`signorini.estimator.h_half_norm.subdivision`): pairs
that need cutting, convergence of every rule, and failure on crossing edges."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import dblquad

from signorini.estimator.h_half_norm import (
    hhalf_norm2_positive_part,
    parameters,
    positive_part_pieces,
)
from signorini.estimator.h_half_norm.subdivision import cross_edge_integral, zero_run_pair_integral

from .polylines import monotone_polyline, on_line, polyline


def test_touching_pieces_of_unequal_length_against_dblquad():
    """Arms of lengths 1 and 0.3 at 60°, v = 1 + t: the longer panel is cut at the length
    of the shorter, the rest is a separated pair."""
    al = np.deg2rad(60.0)
    arm = 0.3 * np.array([np.cos(al), np.sin(al)])
    x0, x1, w = polyline([arm, [0.0, 0.0], [1.0, 0.0]], lambda p: 1 + np.hypot(p[:, 0], p[:, 1]))
    pc = positive_part_pieces(x0, x1, w)
    got = cross_edge_integral(pc, np.array([0]), np.array([1]))[0]
    cos = np.cos(al)
    expected, _ = dblquad(
        lambda s, t: (t - s) ** 2 / (t * t + s * s - 2 * t * s * cos),
        0,
        1,
        0,
        0.3,
        epsabs=1e-14,
        epsrel=1e-13,
    )
    assert got == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("run", [0.1, 0.01, 1e-5])
def test_short_zero_run_needs_subdivision(run):
    """v = t on [0, 1] next to a zero run [−L, 0] with L ≪ 1: closed form
    L − L² ln(1 + 1/L)."""
    x0, x1, w = on_line([-run, 0, 1], lambda x: x)
    pc = positive_part_pieces(x0, x1, w)
    got = zero_run_pair_integral(pc, np.array([0]), np.array([0]))[0]
    assert got == pytest.approx(run - run**2 * np.log1p(1 / run), rel=1e-13)


def test_quadrature_is_converged(monkeypatch):
    """Tightening every rule and criterion does not move the result."""
    cases = [monotone_polyline(s) for s in (0, 1, 2)]
    cases.append(
        polyline(
            [[np.cos(0.2), np.sin(0.2)], [0, 0], [1, 0]],
            lambda p: 1 + np.hypot(p[:, 0], p[:, 1]),
            [[0.5], [0.5]],
        )
    )
    cases.append(on_line([-1, 0, 1e-6, 2e-6, 1], lambda x: x + 0.5e-6))
    base = [hhalf_norm2_positive_part(*c)[0] for c in cases]
    monkeypatch.setattr(parameters, "FAR_TIERS", ((64.0, 12), (16.0, 16), (4.0, 32)))
    monkeypatch.setattr(parameters, "TOUCH_RUN_RATIO", 8.0)
    monkeypatch.setattr(parameters, "TOUCH_RUN_ORDER", 32)
    monkeypatch.setattr(parameters, "DUFFY_ORDER", (6, 60))
    monkeypatch.setattr(parameters, "BLOCK", 7)  # many blocks: the split changes nothing
    tight = [hhalf_norm2_positive_part(*c)[0] for c in cases]
    np.testing.assert_allclose(base, tight, rtol=1e-13)


@pytest.mark.parametrize("cross_at", [0.5, 0.3])
def test_crossing_edges_are_reported(cross_at):
    # two crossing edges with v > 0 on both (the norm is infinite): crossing at the
    # midpoints, where bisection points coincide, and at a generic point
    x0 = np.array([[0.0, 0.0], [cross_at, -0.5]])
    x1 = np.array([[1.0, 0.0], [cross_at, 0.7]])
    w = np.array([[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]])
    with pytest.raises(ValueError, match="overlap or cross"):
        hhalf_norm2_positive_part(x0, x1, w)
    # a positive piece crossing a zero edge
    with pytest.raises(ValueError, match="overlap or cross"):
        hhalf_norm2_positive_part(x0, x1, np.array([[1.0, 1.0, 1.0], [-1.0, -1.0, -1.0]]))


def test_runaway_subdivision_is_stopped(monkeypatch):
    x0 = np.array([[0.0, 0.0], [0.5, -0.5]])
    x1 = np.array([[1.0, 0.0], [0.5, 0.7]])
    w = np.array([[1.0, 1.0, 1.0], [2.0, 2.0, 2.0]])
    monkeypatch.setattr(parameters, "MAX_ACTIVE", 10)
    with pytest.raises(ValueError, match="still unresolved"):
        hhalf_norm2_positive_part(x0, x1, w)
