"""Error norms against a known solution (:mod:`signorini.fem.norms`): exact for quadratics,
closed forms with ``u_h = 0``, and the interpolation rates of P2."""

import numpy as np
import pytest
from contact_problems import random_quadratic
from fem_problems import SquareMesh, gauss_square

from signorini.fem.material import Material
from signorini.fem.norms import energy_error2, h1_seminorm_error2, l2_error2

RNG = np.random.default_rng(13)
MAT = Material.from_lame(1.3, 0.8)


def smooth(x):
    X, Y = x[..., 0], x[..., 1]
    return np.stack([np.sin(2 * X) * np.exp(Y), X * Y**2 * np.cos(Y)], axis=-1)


def smooth_grad(x):
    X, Y = x[..., 0], x[..., 1]
    g = np.empty(x.shape[:-1] + (2, 2))
    g[..., 0, 0] = 2 * np.cos(2 * X) * np.exp(Y)
    g[..., 0, 1] = np.sin(2 * X) * np.exp(Y)
    g[..., 1, 0] = Y**2 * np.cos(Y)
    g[..., 1, 1] = X * (2 * Y * np.cos(Y) - Y**2 * np.sin(Y))
    return g


def test_errors_vanish_for_quadratic_and_match_closed_forms():
    mesh = SquareMesh(3, RNG, perturb=0.3)
    u = random_quadratic(RNG)
    u_cell = mesh.interpolate(u.value)[mesh.cell_dofs]
    V = mesh.vertices
    assert energy_error2(V, u_cell, u.gradient, MAT).sum() < 1e-24
    assert h1_seminorm_error2(V, u_cell, u.gradient).sum() < 1e-24
    assert l2_error2(V, u_cell, u.value).sum() < 1e-24
    # with u_h = 0 the errors are the norms of u: Gauss on the square is independent
    zero = np.zeros_like(u_cell)
    x, w = gauss_square(4)
    g = u.gradient(x)
    energy = np.sum(w * np.einsum("qij,qij->q", u.stress(x, MAT), g))
    e2 = energy_error2(V, zero, u.gradient, MAT)
    assert e2.shape == (len(V),) and np.all(e2 >= 0)
    assert e2.sum() == pytest.approx(energy, rel=1e-12)
    assert h1_seminorm_error2(V, zero, u.gradient).sum() == pytest.approx(
        np.sum(w * np.einsum("qij,qij->q", g, g)), rel=1e-12
    )
    ux = u.value(x)
    assert l2_error2(V, zero, u.value).sum() == pytest.approx(
        np.sum(w * np.einsum("qi,qi->q", ux, ux)), rel=1e-12
    )
    xs, ws = gauss_square(12)
    assert l2_error2(V, zero, smooth, degree=12).sum() == pytest.approx(
        np.sum(ws * np.einsum("qi,qi->q", smooth(xs), smooth(xs))), rel=1e-12
    )


def test_energy_error_weighs_lam_and_mu():
    # a pure dilation has div e = 2, eps(e) = I: a(e, e) = (4 lam + 4 mu) |Omega|
    mesh = SquareMesh(2)
    zero = np.zeros((len(mesh.cells), 12))
    e2 = energy_error2(
        mesh.vertices, zero, lambda x: np.broadcast_to(np.eye(2), x.shape + (2,)), MAT
    )
    assert e2.sum() == pytest.approx(4 * MAT.lam + 4 * MAT.mu, rel=1e-13)


def test_interpolation_error_rates():
    h1, l2, en = [], [], []
    for n in (4, 8, 16):
        mesh = SquareMesh(n)
        u_cell = mesh.interpolate(smooth)[mesh.cell_dofs]
        V = mesh.vertices
        h1.append(np.sqrt(h1_seminorm_error2(V, u_cell, smooth_grad).sum()))
        en.append(np.sqrt(energy_error2(V, u_cell, smooth_grad, MAT).sum()))
        l2.append(np.sqrt(l2_error2(V, u_cell, smooth).sum()))
    for name, errs, expected in (("H1", h1, 2.0), ("energy", en, 2.0), ("L2", l2, 3.0)):
        rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
        assert np.all(np.abs(rates - expected) < 0.15), (
            f"{name} rates {np.round(rates, 3)}, expected {expected}"
        )
