"""The bound-constrained QP's data, checked at the public entry (signorini.algebra.qp)."""

from __future__ import annotations

import numpy as np
import pytest
from linalg_problems import random_problem

from signorini.algebra.qp import check_qp


@pytest.fixture
def small():
    rng = np.random.default_rng(0)
    K, F, c, g, d, xd = random_problem(rng, 8, 3, 2)
    return {"K": K, "F": F, "constrained": c, "gap": g, "dirichlet": d, "dirichlet_values": xd}


@pytest.mark.parametrize(
    "change,message",
    [
        (lambda p: p.update(F=np.where(np.arange(8) == 2, np.nan, p["F"])), "F has non-finite"),
        (lambda p: p.update(gap=np.array([0.0, np.nan, 0.0])), "gap has non-finite"),
        (lambda p: p.update(gap=np.zeros(4)), r"gap must have shape \(3,\)"),
        (lambda p: p.update(gap="wide"), "gap must be a real array"),
        (lambda p: p.update(F=np.zeros(7)), r"F must have shape \(8,\)"),
        (lambda p: p.update(dirichlet=np.r_[p["dirichlet"][0], p["constrained"][1]]), "overlap"),
        (lambda p: p.update(constrained=np.array([0, 0, 1])), "constrained has repeated"),
        (lambda p: p.update(constrained=np.array([0, 1, 9])), "constrained has indices outside"),
        (lambda p: p.update(constrained=np.array([0.0, 1.0, 2.0])), "constrained must hold int"),
        (lambda p: p.update(constrained=np.ones((2, 2), int)), "constrained must be a 1D"),
        (lambda p: p.update(constrained=np.ones(3, bool)), r"boolean mask must have shape \(8,\)"),
        (lambda p: p.update(dirichlet_values=np.ones(3)), "dirichlet_values must have shape"),
        (lambda p: p.update(dirichlet_values=np.inf), "dirichlet_values has non-finite"),
        (lambda p: p.update(K=p["K"][:, :7]), "K must be square"),
        (lambda p: p.update(K=p["K"].toarray()), "K must be a scipy sparse"),
    ],
)
def test_bad_input_names_the_argument(small, change, message):
    change(small)
    with pytest.raises(ValueError, match=message):
        check_qp(**small)


def test_mask_index_and_value_forms_agree(small):
    n = small["K"].shape[0]
    d, xd = small["dirichlet"], small["dirichlet_values"]
    mask = np.zeros(n, dtype=bool)
    mask[d] = True
    order = np.argsort(d)
    full = np.zeros(n)
    full[d] = xd
    a = check_qp(**small)
    b = check_qp(small["K"], small["F"], small["constrained"], small["gap"], mask, xd[order])
    e = check_qp(small["K"], small["F"], small["constrained"], small["gap"], mask, full)
    assert np.array_equal(a.dirichlet[order], b.dirichlet)
    assert np.array_equal(a.dirichlet_values[order], b.dirichlet_values)
    assert np.array_equal(b.dirichlet_values, e.dirichlet_values)
    assert a.n == n and a.K is small["K"]  # canonical CSR is taken as it is


def test_defaults_and_scalar_gap(small):
    qp = check_qp(small["K"], small["F"], small["constrained"], 0.25)
    assert qp.dirichlet.size == 0 and qp.dirichlet_values.size == 0
    assert np.array_equal(qp.gap, [0.25, 0.25, 0.25])
    zero = check_qp(small["K"], small["F"], small["constrained"], 0.0, small["dirichlet"])
    assert np.array_equal(zero.dirichlet_values, [0.0, 0.0])
