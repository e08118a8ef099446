"""The contact fields of a 3D level's VTU file, read back with meshio: at the nodes of Γ_C
they are the solution's own arrays (gap u·n − ψ recomputed here from u, n_z and ψ), the
complementarity of condition (a) holds in them, off Γ_C they are the stated fill values, and
the ``triangle6`` faces of the contact part are the faces the rows live on."""

from __future__ import annotations

from functools import cache

import meshio
import numpy as np
import pytest

from signorini.contact.solution import solve
from signorini.examples.hertz3d import hertz_3d
from signorini.output.vtu import write_fields, write_vtu
from signorini.output.vtu3d import CONTACT_FIELDS_3D

ALPHA = {"b": None, "a": 0.0}


@cache
def solved(variant: str):
    return solve(hertz_3d(h_contact=0.15, face_alpha=ALPHA[variant]))


@cache
def read_back(variant: str, folder):
    return meshio.read(write_vtu(folder / f"hertz_{variant}.vtu", solved(variant)))


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("vtu3d")


@pytest.mark.parametrize("variant", ["b", "a"])
def test_the_fields_at_the_rows_are_the_solutions(variant, folder):
    r, data = solved(variant), read_back(variant, folder)
    cs, pd = r.contact, data.point_data
    assert np.unique(cs.node).size == cs.n_rows  # one part: one row per node
    assert set(CONTACT_FIELDS_3D) <= set(pd)
    z = cs.node
    gap = np.einsum("kc,kc->k", r.u[z], cs.direction) - cs.psi
    np.testing.assert_array_equal(pd["gap"][z], gap)
    np.testing.assert_array_equal(pd["contact_force"][z], r.contact_force)
    np.testing.assert_array_equal(
        pd["recovered_pressure"][z], cs.recovered_pressure(r.contact_force)
    )
    np.testing.assert_array_equal(pd["active"][z], r.active.astype(np.int32))
    np.testing.assert_array_equal(pd["contact_normal"][z], np.tile([0.0, 0.0, -1.0], (z.size, 1)))
    if variant == "b":
        np.testing.assert_array_equal(pd["pressure"][z], r.pressure)
    else:  # the P2 vertex weights vanish: no nodal pressure Λ_z / w_z
        assert np.isnan(pd["pressure"][z]).all()
    assert 0 < r.active.sum() < cs.n_rows  # a contact zone inside Γ_C


def test_complementarity_in_the_fields_of_condition_a(folder):
    """Condition (a) bounds u·n − ψ at the nodes themselves: 0 where active, ≤ 0 elsewhere,
    the force ≥ 0 and the recovered pressure positive at the pole."""
    data = read_back("a", folder)
    pd, z = data.point_data, solved("a").contact.node
    on = pd["active"][z] == 1
    scale = np.abs(solved("a").contact.psi).max()
    assert np.abs(pd["gap"][z][on]).max() <= 1e-12 * scale
    assert pd["gap"][z][~on].max() <= 1e-12 * scale and pd["gap"][z][~on].min() < -1e-3 * scale
    assert pd["contact_force"][z].min() >= -1e-12 * pd["contact_force"][z].max()
    pole = z[np.argmin(np.linalg.norm(data.points[z], axis=1))]
    assert pd["recovered_pressure"][pole] == pd["recovered_pressure"][z].max() > 0


def test_off_the_contact_surface_the_fill_values(folder):
    data = read_back("b", folder)
    off = np.setdiff1d(np.arange(data.points.shape[0]), solved("b").contact.node)
    pd = data.point_data
    assert np.isnan(pd["gap"][off]).all()
    for name in ("contact_force", "pressure", "recovered_pressure", "active", "contact_normal"):
        assert not np.any(pd[name][off]), name


def test_the_contact_parts_faces_carry_the_rows(folder):
    """The ``triangle6`` cells whose ``part`` is the contact part are the contact set's faces
    (their nodes sit at the solution's node points); the rows are on them, all but the nodes
    whose normal component is held (the equator, on the top moved by u_z = −δ)."""
    r, data = solved("b"), read_back("b", folder)
    blocks = [block.type for block in data.cells]
    faces = data.cells[blocks.index("triangle6")].data
    part = data.cell_data["part"][blocks.index("triangle6")]
    sphere = r.mesh.part_names.index("sphere")
    on_part = np.unique(faces[part == sphere])
    np.testing.assert_array_equal(on_part, np.unique(r.contact.faces))
    held = np.setdiff1d(on_part, r.contact.node)
    assert held.size > 0 and np.allclose(r.space.node_points[held, 2], 1.0)
    np.testing.assert_allclose(data.points, r.space.node_points, rtol=0, atol=0)


def test_fields_md_of_a_3d_run_lists_the_contact_fields(tmp_path):
    text = write_fields(tmp_path / "fields.md", solved("b").mesh).read_text()
    assert "VTK_QUADRATIC_TETRA" in text and "z = 0" not in text
    for name in CONTACT_FIELDS_3D:
        assert f"| `{name}` |" in text
    assert "| 0 | `body` |" in text  # the regions follow
