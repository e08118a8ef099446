"""KKT residuals (signorini.algebra.kkt) on closed-form points."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import scipy.sparse as sp
from linalg_problems import p2_elasticity

from signorini.algebra import kkt_residuals
from signorini.algebra.kkt import KKTResiduals, ill_conditioned_message


def test_kkt_residuals_closed_form():
    K = sp.identity(3, format="csr")
    F = np.array([1.0, 2.0, 0.0])
    c, g = np.array([0, 1]), np.array([0.5, 5.0])
    x = np.array([0.6, 2.0, 0.0])  # violates x_0 <= 0.5 by 0.1, multiplier 0.4
    kkt = kkt_residuals(K, F, x, c, g)
    assert kkt.disp_scale == 2.0  # max |x|; g = 5 is away from the contact (x_1 < g_1)
    assert kkt.force_scale == 2.0  # max(|F|, |K||x|)
    assert kkt.contact_force == 0.4 and kkt.contact_force_scale == 0.4
    assert np.isclose(kkt.primal, 0.1 / 2.0)
    assert kkt.dual == 0.0
    assert np.isclose(kkt.complementarity, min(0.4 / 0.4, 0.1 / 2.0))
    assert kkt.stationarity == 0.0
    x2 = np.array([0.5, 2.0, 0.3])  # free row residual -0.3; x_0 at the bound
    kkt2 = kkt_residuals(K, F, x2, c, g, dirichlet=[2], dirichlet_values=0.1)
    assert np.isclose(kkt2.dirichlet, 0.2 / 2.0)
    assert kkt2.stationarity == 0.0  # row 2 is a Dirichlet row, not a free one
    kkt3 = kkt_residuals(K, np.array([0.0, 2.0, 0.0]), np.array([0.5, 2.0, 0.0]), c, g)
    # multiplier -0.5 at the active bound and no positive contact force: the force scale
    assert kkt3.contact_force == 0.0 and kkt3.contact_force_scale == 2.0
    assert np.isclose(kkt3.dual, 0.5 / 2.0)
    assert np.isclose(kkt3.max, 0.25)
    g4 = np.array([-3.0, 5.0])  # the obstacle penetrates: x_0 = 0.6 >= g_0, |g_0| counts
    assert kkt_residuals(K, F, x, c, g4).disp_scale == 3.0
    assert kkt.columns() == {
        "kkt_primal": kkt.primal,
        "kkt_dual": 0.0,
        "kkt_complementarity": kkt.complementarity,
        "kkt_stationarity": 0.0,
        "kkt_dirichlet": 0.0,
    }


def test_a_far_gap_does_not_hide_a_penetration():
    # Hertz-like: a clamped P2 block whose bottom nodes carry the gap 49.9 far from the contact
    # and 0 at one node that touches; the displacement is of size 0.1. A penetration of 1e-6
    # (1e-5 of the displacement) read 2e-8 against the old scale max|g| = 49.9.
    K, xy = p2_elasticity(4, 4, lam=1.0, mu=1.0)
    top = np.flatnonzero(xy[:, 1] > 1 - 1e-12)
    bottom = np.flatnonzero(xy[:, 1] < 1e-12)
    c = 2 * bottom + 1  # the y DOFs of the bottom nodes
    g = np.full(bottom.size, 49.9)
    touching = np.argmin(np.abs(xy[bottom, 0] - 0.5))
    g[touching] = 0.0
    rng = np.random.default_rng(3)
    x = 0.1 * rng.uniform(-1, 1, K.shape[0])
    x[c] = np.minimum(x[c], 0.09)
    x[c[touching]] = 1e-6  # penetrates by 1e-6
    d = np.r_[2 * top, 2 * top + 1]
    F = K @ x
    F[c[touching]] += 0.05  # a contact force at the touching node
    kkt = kkt_residuals(K, F, x, c, g, d, x[d])
    assert kkt.disp_scale == np.abs(x).max() <= 0.1
    assert np.isclose(kkt.primal, 1e-6 / np.abs(x).max())
    assert kkt.primal > 1e-5  # the old scale max(|x|, |g|) = 49.9 read it as 2e-8
    assert np.isclose(kkt.contact_force, 0.05)
    assert np.isclose(kkt.complementarity, min(1.0, 1e-6 / np.abs(x).max()))
    assert kkt.stationarity < 1e-15 and kkt.dual < 1e-13


def test_stationarity_on_a_free_row_and_zero_scales():
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    kkt = kkt_residuals(K, np.array([0.0, 1.0]), np.array([0.0, 0.0]), [0], 0.0)
    # x = 0: force scale max|F| = 1, displacement scale 1 (all vanish), row 1 residual 1
    assert (kkt.force_scale, kkt.disp_scale) == (1.0, 1.0)
    assert kkt.stationarity == 1.0 and kkt.max == 1.0
    with pytest.raises(ValueError, match=r"x must have shape \(2,\)"):
        kkt_residuals(K, np.zeros(2), np.zeros(3), [0], 0.0)


def test_scales_follow_the_forces_not_the_stiffness():
    """Two DOFs tied by a spring of 1e10 (a stiff material: |K||x| = 2e10 where K x = 1): an
    out-of-balance force of 0.5 is a third of the forces, and a tensile force at the contact
    is a fraction of the contact force. The former scale max(|F|, |K||x|) read both as 2e-11."""
    k = 1e10
    K = sp.csr_matrix(np.array([[k + 1.0, -k], [-k, k + 1.0]]))
    x = np.array([1.0, 1.0])  # K x = (1, 1)
    F = np.array([1.0, 1.5])
    kkt = kkt_residuals(K, F, x, [0], 2.0)
    assert kkt.force_scale == 1.5 and kkt.round_off_scale == 2 * k + 1
    assert kkt.stationarity == pytest.approx(0.5 / 1.5)
    # x_0 held at its bound 1 with Λ_0 = F_0 − (K x)_0 = −0.25 and a second contact DOF
    # carrying 0.75: the tensile force is a third of the contact force
    kkt2 = kkt_residuals(K, np.array([0.75, 1.75]), x, [0, 1], [1.0, 1.0])
    assert kkt2.contact_force == 0.75 and kkt2.contact_force_scale == 0.75
    assert kkt2.dual == pytest.approx(0.25 / 0.75)
    # forces at round-off of |K||x| (a rigid motion, no load): the round-off scale
    rigid = kkt_residuals(K - sp.identity(2, format="csr"), np.zeros(2), x, [0], 2.0)
    assert rigid.force_scale == rigid.round_off_scale == 2 * k
    assert rigid.stationarity == 0.0


def test_the_warning_of_a_tensile_contact_force_says_its_size_and_the_forces_round_off():
    """Example 6.2's 4 × 4 mesh with ν = 0.499999999 ends with a tensile force of 0.00876 at an
    active node: the warning said only "kkt_dual 6.5e-05". Its residuals, as measured there."""
    kkt = KKTResiduals(
        primal=0.0,
        dual=6.455e-05,
        complementarity=9.7e-09,
        stationarity=2.9e-07,
        dirichlet=0.0,
        force_scale=45.31,
        disp_scale=0.2,
        contact_force=135.7406,
        contact_force_scale=135.7406,
        round_off_scale=7.5697e10,
    )
    message = ill_conditioned_message(kkt, 1e-6, 1e3 * np.finfo(np.float64).eps)
    for text in (
        "only to 6.5e-05 relative (kkt_dual 6.5e-05)",
        "an active contact constraint carries a tensile force of 0.00876, 6.5e-05 of the total "
        "contact force 135.741, within the round-off band of the forces, 0.0168 (2.2e-13 max "
        "|K||x|)",
        "the contact forces are exact to about that size",
        "close to incompressible, in any region, a contrast of stiffness between regions",
    ):
        assert text in message, message
    # no tensile force: no word of one
    assert "tensile" not in ill_conditioned_message(
        dataclasses.replace(kkt, dual=0.0, stationarity=2e-6), 1e-6, 2.2e-13
    )
