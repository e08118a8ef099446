"""The plane-strain material and Hooke's law (:mod:`signorini.fem.material`)."""

import numpy as np
import pytest

from signorini.fem.material import Material, strain, stress


def test_material_from_young_plane_strain():
    m = Material.from_young(500.0, 0.3)
    assert m.mu == pytest.approx(500 / 2.6, rel=1e-15)
    assert m.lam == pytest.approx(500 * 0.3 / (1.3 * 0.4), rel=1e-15)
    assert m.young == pytest.approx(500.0, rel=1e-14)
    assert m.poisson == pytest.approx(0.3, rel=1e-14)
    assert Material.from_lame(1, 1) == Material(lam=1.0, mu=1.0)


@pytest.mark.parametrize(
    ("args", "match"),
    [
        ((0.0, 0.3), "E must be positive"),
        ((-1.0, 0.3), "E must be positive"),
        ((1.0, 0.5), "incompressible limit not supported"),
        ((1.0, 0.7), "incompressible limit not supported"),
        ((1.0, -1.0), "nu must be > -1"),
        ((np.inf, 0.3), "finite"),
        ((1.0, np.nan), "finite"),
    ],
)
def test_material_from_young_rejects(args, match):
    with pytest.raises(ValueError, match=match):
        Material.from_young(*args)


def test_material_takes_its_parameters_by_name():
    m = Material(lam=1000.0, mu=0.3)
    assert (m.lam, m.mu) == (1000.0, 0.3)
    # Material(1000, 0.3) could be read as (lam, mu) or as (E, nu): refused
    with pytest.raises(TypeError) as info:
        Material(1000, 0.3)
    assert str(info.value) == (
        "Material takes its parameters by name, got Material(1000, 0.3): write "
        "Material.from_young(E, nu) for Young's modulus and Poisson's ratio, or "
        "Material(lam=..., mu=...) / Material.from_lame(lam, mu) for the Lamé parameters"
    )
    with pytest.raises(TypeError, match=r"^Material takes its parameters by name"):
        Material(1000, mu=0.3)
    with pytest.raises(TypeError, match=r"^Material needs mu: write Material\(lam=..., mu=...\)"):
        Material(lam=1.0)


@pytest.mark.parametrize(
    ("lam", "mu", "match"),
    [
        (1.0, 0.0, "mu must be positive"),
        (1.0, -2.0, "mu must be positive"),
        (-1.0, 1.0, "lam \\+ mu must be positive"),
        (-3.0, 1.0, "lam \\+ mu must be positive"),
        (np.nan, 1.0, "finite"),
        (1.0, np.inf, "finite"),
        ("a", 1.0, "real number"),
    ],
)
def test_material_from_lame_rejects(lam, mu, match):
    with pytest.raises(ValueError, match=match):
        Material.from_lame(lam, mu)


def test_material_allows_negative_lam_with_positive_bulk():
    # auxetic: nu < 0 gives lam < 0 but lam + mu > 0
    m = Material.from_young(1.0, -0.5)
    assert m.lam < 0 < m.lam + m.mu
    assert m.poisson == pytest.approx(-0.5, rel=1e-14)


def test_stress_closed_form():
    g = np.array([[1.0, 2.0], [4.0, -3.0]])
    assert np.array_equal(strain(g), [[1.0, 3.0], [3.0, -3.0]])
    sig = stress(Material(lam=2.0, mu=0.5), g)
    # eps = [[1, 3], [3, -3]], tr = -2: sigma = 2 * (-2) I + 1.0 * eps
    assert np.allclose(sig, [[-3.0, 3.0], [3.0, -7.0]])
    batch = stress(Material(lam=2.0, mu=0.5), np.broadcast_to(g, (4, 5, 2, 2)))
    assert batch.shape == (4, 5, 2, 2) and np.allclose(batch, sig)
    with pytest.raises(ValueError, match="grad_u"):
        stress(Material(lam=2.0, mu=0.5), np.zeros((3, 2)))


def test_stress_is_linear_and_gives_the_energy_density():
    # sigma(g) : g = lam tr(eps)^2 + 2 mu eps : eps, and sigma is linear in g
    rng = np.random.default_rng(3)
    mat = Material.from_young(3.0, 0.25)
    g, h = rng.standard_normal((2, 50, 2, 2))
    sg = stress(mat, g)
    eps = strain(g)
    density = mat.lam * np.trace(eps, axis1=1, axis2=2) ** 2 + 2 * mat.mu * np.einsum(
        "mij,mij->m", eps, eps
    )
    assert np.allclose(np.einsum("mij,mij->m", sg, g), density, rtol=1e-13)
    assert np.allclose(stress(mat, 2 * g - h), 2 * sg - stress(mat, h), atol=1e-13)
    # a rotation (antisymmetric gradient) carries no stress
    assert np.abs(stress(mat, g - np.swapaxes(g, 1, 2))).max() < 1e-14
