"""The contact patch test on stacked blocks, at the level of the linear algebra: dual mortar
against node-to-segment.

    python benchmarks/mortar_patch.py

Two blocks ``[0, 1] × [−1/2, 0]`` and ``[0, 1] × [0, 1/2]`` (E = 1, ν = 0.3, plane strain)
touch along ``y = 0`` with 5 and 7 P2 edges (non-matching); uniform pressure 1 on the top,
``u_y = 0`` on the bottom, ``u_x = 0`` on both left sides. The exact solution is a uniform
stress σ_yy = −1, so the contact pressure is 1 everywhere. With every contact node active
the contact constraints are equalities: the saddle point system ``[K Bᵀ; B 0] [u; λ] = [F; 0]``
is solved directly, and λ_j (the pressure coefficient: rows scaled by D_jj = ∫φ_j) is
compared with 1, for either block as slave.

- mortar: ``B_j = D_jj n_jᵀ (slave node j) − Σ_k M_jk n_jᵀ (master node k)``
  (:func:`signorini.contact.mortar.mortar_coupling`);
- node-to-segment: ``B_j = D_jj (n_jᵀ (slave node j) − Σ_b φ_b(η_j) n_jᵀ (master node b))``,
  η_j the slave node's projection onto its master edge (the slave node's nodal force is the
  consistent one, the master's the slave's nodal forces placed at the nodes' projections).

Prints the largest deviation of the nodal pressure from 1 per case and method.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from signorini.contact.mortar import mortar_coupling
from signorini.fem.loads import assemble_facet_load
from signorini.fem.mapping import StraightFacets
from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh.builders import rectangle
from signorini.mesh.mesh import Mesh


def stacked_blocks(n_upper: int, n_lower: int) -> P2Space:
    """The two blocks as one mesh, parts ``up.*`` and ``low.*``."""
    bodies = {
        "up": rectangle(0.0, 1.0, 0.0, 0.5, n_upper, 2),
        "low": rectangle(0.0, 1.0, -0.5, 0.0, n_lower, 2),
    }
    pts, cells, bnd, part, names, off = [], [], [], [], [], 0
    for key, m in bodies.items():
        pts.append(m.points)
        cells.append(m.cells + off)
        bnd.append(m.boundary + off)
        part.append(m.boundary_part + len(names))
        names += [f"{key}.{p}" for p in m.part_names]
        off += m.n_points
    mesh = Mesh(
        np.vstack(pts), np.vstack(cells), np.vstack(bnd), np.concatenate(part), names,
        validate=False,  # the blocks share the points of the interface
    )  # fmt: skip
    return P2Space(mesh)


def _rows(space: P2Space, slave: str, master: str, method: str):
    """The constraint rows ``B (s, n_dofs)`` and the slave nodes' coordinates."""
    c = mortar_coupling(space, slave, master)
    s = c.slave_nodes.size
    if method == "mortar":
        coupling = c.M
    else:  # node-to-segment: the slave node's projection (along n_j) onto the master edge
        x = space.node_points[c.slave_nodes]
        edges = space.facet_nodes(space.mesh.part_facets(master))
        a, b = space.node_points[edges[:, 0]], space.node_points[edges[:, 1]]
        lo, hi = np.minimum(a[:, 0], b[:, 0]), np.maximum(a[:, 0], b[:, 0])
        inside = (x[:, None, 0] >= lo - 1e-14) & (x[:, None, 0] <= hi + 1e-14)
        f = np.argmax(inside, axis=1)  # the (first) master edge under the node
        eta = (x[:, 0] - a[f, 0]) / (b[f, 0] - a[f, 0])
        phi = np.column_stack([(1 - eta) * (1 - 2 * eta), eta * (2 * eta - 1), 4 * eta * (1 - eta)])
        coupling = sp.csr_matrix(
            ((c.D[:, None] * phi).ravel(), (np.repeat(np.arange(s), 3), edges[f].ravel())),
            shape=(s, space.n_nodes),
        )
    slave_part = sp.csr_matrix((c.D, (np.arange(s), c.slave_nodes)), shape=(s, space.n_nodes))
    nodal = slave_part - coupling  # (s, n_nodes), then along n_j per component
    B = sp.hstack([nodal.multiply(c.normal[:, [0]]), nodal.multiply(c.normal[:, [1]])]).tocsr()
    # interleaved DOFs: column 2 k + i
    order = np.argsort(
        np.concatenate([2 * np.arange(space.n_nodes), 2 * np.arange(space.n_nodes) + 1])
    )
    return B[:, order], space.node_points[c.slave_nodes]


def pressure_deviation(n_upper: int, n_lower: int, slave: str, method: str) -> float:
    """``max_j |λ_j − 1|`` of the patch test (see the module's docstring)."""
    space = stacked_blocks(n_upper, n_lower)
    mesh = space.mesh
    n = space.n_dofs
    K = assemble_stiffness(space.mapping, space.cell_dofs, n, Material.from_young(1.0, 0.3))
    top = mesh.part_facets("up.top")
    nodes = space.facet_nodes(top)
    dofs = np.stack([2 * nodes, 2 * nodes + 1], axis=-1).reshape(-1, 6)
    F = assemble_facet_load(
        StraightFacets(space.node_points[nodes[:, :2]]),
        dofs,
        n,
        lambda x, nu: np.array([0.0, -1.0]),
    )
    held = np.concatenate(
        [2 * space.part_nodes(["up.left", "low.left"]), 2 * space.part_nodes(["low.bottom"]) + 1]
    )
    free = np.setdiff1d(np.arange(n), held)
    master = "low.top" if slave == "up.bottom" else "up.bottom"
    B, _ = _rows(space, slave, master, method)
    B = B[:, free]
    A = sp.bmat([[K[free][:, free], B.T], [B, None]]).tocsc()
    rhs = np.concatenate([F[free], np.zeros(B.shape[0])])
    lam = spla.spsolve(A, rhs)[free.size :]
    return float(np.abs(lam - 1.0).max())


def main() -> None:
    print(f"{'upper/lower edges':>18} {'slave':>10} {'mortar':>10} {'node-to-segment':>16}")
    for n_upper, n_lower in ((5, 7), (7, 5)):
        for slave in ("up.bottom", "low.top"):
            row = [pressure_deviation(n_upper, n_lower, slave, m) for m in ("mortar", "nts")]
            print(f"{f'{n_upper}/{n_lower}':>18} {slave:>10} {row[0]:10.2e} {row[1]:16.2e}")


if __name__ == "__main__":
    main()
