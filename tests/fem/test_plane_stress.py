"""Plane stress as an option of Material: the effective λ* in the 2D law, σ_zz, and a bar
under uniaxial tension solved exactly (docs/method.md, *Plane stress*)."""

import numpy as np
import pytest

from signorini import ContactProblem, Dirichlet, Material, Neumann, rectangle
from signorini.contact.solution import solve
from signorini.fem.material import stress, stress_zz
from signorini.fem.space import P2Space

E, NU, S = 50.0, 0.3, 1.5  # Young's modulus, Poisson's ratio, the bar's axial stress

#: the exact displacement of a bar [0, 2] x [0, 1] under axial stress S: u = (a x, b y)
BAR = {
    "stress": (S / E, -NU * S / E),
    "strain": (S * (1 - NU**2) / E, -NU * (1 + NU) * S / E),
}


def test_plane_stress_lame_and_default():
    strain, plane_stress = Material.from_young(E, NU), Material.from_young(E, NU, plane="stress")
    assert strain.plane == "strain" and strain.lam_eff == strain.lam
    assert plane_stress.lam == strain.lam and plane_stress.mu == strain.mu
    # λ* = 2λμ/(λ + 2μ) = Eν/(1 − ν²)
    assert plane_stress.lam_eff == pytest.approx(E * NU / (1 - NU**2), rel=1e-14)
    assert plane_stress.young == pytest.approx(E, rel=1e-14)
    assert plane_stress.poisson == pytest.approx(NU, rel=1e-14)
    with pytest.raises(ValueError, match="plane must be"):
        Material.from_young(E, NU, plane="strian")


@pytest.mark.parametrize("plane", ["stress", "strain"])
def test_bar_in_uniaxial_tension_is_exact(plane):
    """u_x = σx/E, u_y = −νσy/E in plane stress; (1 − ν²)σx/E, −ν(1 + ν)σy/E in plane
    strain: P2 reproduces the linear field to round-off, and σ_zz is 0 or νσ."""
    a, b = BAR[plane]

    def exact(x):
        return np.stack([a * x[..., 0], b * x[..., 1]], axis=-1)

    mesh = rectangle(0, 2, 0, 1, nx=4, ny=2)
    free = Neumann((0.0, 0.0))
    material = Material.from_young(E, NU, plane=plane)
    conditions = {"left": Dirichlet(exact), "right": Neumann((S, 0.0)), "top": free, "bottom": free}
    result = solve(ContactProblem(mesh, material, conditions))
    error = np.abs(result.u - exact(P2Space(mesh).node_points)).max()
    assert error < 1e-13 * 2 * S / E  # round-off of the displacement scale
    grad = np.array([[a, 0.0], [0.0, b]])
    np.testing.assert_allclose(stress(material, grad), [[S, 0.0], [0.0, 0.0]], atol=1e-14)
    zz = stress_zz(material, grad)
    assert zz == pytest.approx(0.0 if plane == "stress" else NU * S, abs=1e-14)
    assert material.stress_zz(grad) == zz


def test_plane_stress_differs_from_plane_strain():
    """The two exact bars differ by the factor (1 − ν²) in u_x: the option is not a no-op."""
    assert BAR["strain"][0] / BAR["stress"][0] == pytest.approx(1 - NU**2)
