"""Two mirrored half-discs pressed together against the one-body Hertz problem, at the level
of the linear algebra: the constraint direction decides whether they agree.

    python benchmarks/mortar_symmetry.py

The half-disc of :func:`~signorini.mesh.builders.half_disc` (R = 1, E = 1, ν = 0.3, plane
strain, its flat top moved by (0, −δ)) and its mirror image in y = 0 (top moved by (0, +δ)),
with mirrored meshes, touch at the origin; the arc of the upper one is the slave, the lower
one's the master (:func:`signorini.contact.mortar.mortar_coupling`; constraints at the arc's
nodes with |x| < 0.4 R, the rest never touch). The one-body problem is the upper half-disc on
the rigid plane y = 0 with the nodal constraints ``D_jj u_j·(0, −1) ≤ D_jj y_j`` at the same
nodes. Both are solved by the same primal-dual active set loop on ``min ½ uᵀKu − fᵀu``,
``B u ≤ g`` (the saddle point system of each active set solved directly). By symmetry the
two-body solution's upper half is the one-body solution exactly when the constraint
direction is the symmetry plane's normal (the averaged normal); a one-sided normal tilts
the constraint by the polar angle and shears the interface.

Prints, per direction, the largest difference of the upper body's displacement from the
one-body one (relative to the largest displacement), of the multipliers (relative to the
largest), whether the active sets agree, and how far the pair is from mirror-symmetric.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import cKDTree

from signorini.contact.mortar import mortar_coupling
from signorini.fem.material import Material
from signorini.fem.space import P2Space
from signorini.fem.stiffness import assemble_stiffness
from signorini.mesh.bodies import union as bodies_union
from signorini.mesh.builders import half_disc
from signorini.mesh.curves import Circle
from signorini.mesh.mesh import Mesh

DEPTH = 0.015  # δ / R: a / R ≈ 0.1


def mirrored(mesh: Mesh) -> Mesh:
    """The mirror image of ``mesh`` in y = 0 (cells reversed to stay counter-clockwise)."""
    curves = tuple(
        None if c is None else Circle(c.center * [1.0, -1.0], c.radius) for c in mesh.curves
    )
    return Mesh(
        mesh.points * [1.0, -1.0], mesh.cells[:, [1, 0, 2]], mesh.boundary, mesh.boundary_part,
        mesh.part_names, validate=False, curves=curves,
    )  # fmt: skip


def union(upper: Mesh, lower: Mesh) -> Mesh:
    """One mesh of two bodies, parts ``up.*`` and ``low.*`` (``mesh.bodies.union``)."""
    return bodies_union({"up": upper, "low": lower})


def solve_pdas(K, f, B, g, free, fixed_values):
    """``min ½ uᵀKu − fᵀu`` subject to ``B u ≤ g`` and ``u = fixed_values`` off ``free``:
    primal-dual active set (c = 1) on the saddle point systems. Returns u, λ, active."""
    u0 = fixed_values.copy()
    rhs_f = (f - K @ u0)[free]
    Kff = K[free][:, free]
    Bf = B[:, free]
    g0 = g - B @ u0
    active = g0 <= 0
    for _ in range(50):
        BA = Bf[active]
        A = sp.bmat([[Kff, BA.T], [BA, None]]).tocsc()
        sol = spla.spsolve(A, np.concatenate([rhs_f, g0[active]]))
        u = u0.copy()
        u[free] = sol[: free.size]
        lam = np.zeros(B.shape[0])
        lam[active] = sol[free.size :]
        new = lam + (B @ u - g) > 0
        if np.array_equal(new, active):
            return u, lam, active
        active = new
    raise RuntimeError("the active set did not settle in 50 iterations")


def _held(space: P2Space, part: str, value) -> tuple[np.ndarray, np.ndarray]:
    nodes = space.part_nodes([part])
    dofs = np.concatenate([2 * nodes, 2 * nodes + 1])
    values = np.concatenate([np.full(nodes.size, value[0]), np.full(nodes.size, value[1])])
    return dofs, values


def one_body(rings: int, h_bottom: float):
    """The upper half-disc on the plane y = 0: its space, u (n_nodes, 2), λ per constrained
    node and the constrained nodes."""
    space = P2Space(half_disc(1.0, rings, h_bottom=h_bottom))
    K = assemble_stiffness(space.mapping, space.cell_dofs, space.n_dofs, MATERIAL)
    dofs, values = _held(space, "top", (0.0, -DEPTH))
    nodes = _constrained(space, "arc", space.part_nodes(["top"]))
    weight = mortar_weights(space, nodes)
    B = sp.csr_matrix(
        (-weight, (np.arange(nodes.size), 2 * nodes + 1)), shape=(nodes.size, space.n_dofs)
    )
    g = weight * space.node_points[nodes, 1]
    fixed = np.zeros(space.n_dofs)
    fixed[dofs] = values
    free = np.setdiff1d(np.arange(space.n_dofs), dofs)
    u, lam, active = solve_pdas(K, np.zeros(space.n_dofs), B, g, free, fixed)
    return space, u.reshape(-1, 2), lam, active, nodes


def mortar_weights(space: P2Space, nodes: np.ndarray) -> np.ndarray:
    """``D_jj = ∫ φ_j ds`` over the arc at ``nodes``, from the two-body coupling's D (the
    same edges, the same rule)."""
    both = P2Space(union(space.mesh, mirrored(space.mesh)))
    c = mortar_coupling(both, "up.arc", "low.arc", constrained=[])
    dist, k = cKDTree(both.node_points[c.slave_nodes]).query(space.node_points[nodes])
    assert dist.max() < 1e-14
    return c.D[k]


def _constrained(space: P2Space, part: str, held: np.ndarray) -> np.ndarray:
    nodes = np.setdiff1d(space.part_nodes([part]), held)
    return nodes[np.abs(space.node_points[nodes, 0]) < 0.4]


def two_bodies(rings: int, h_bottom: float, direction: str):
    """The mirrored pair: its space, u, λ per constrained slave node, the active set, the
    constrained nodes and the number of cells of the upper body."""
    upper = half_disc(1.0, rings, h_bottom=h_bottom)
    space = P2Space(union(upper, mirrored(upper)))
    K = assemble_stiffness(space.mapping, space.cell_dofs, space.n_dofs, MATERIAL)
    d_up, v_up = _held(space, "up.top", (0.0, -DEPTH))
    d_low, v_low = _held(space, "low.top", (0.0, DEPTH))
    dofs, values = np.concatenate([d_up, d_low]), np.concatenate([v_up, v_low])
    nodes = _constrained(space, "up.arc", space.part_nodes(["up.top"]))
    c = mortar_coupling(space, "up.arc", "low.arc", constrained=nodes, direction=direction)
    rows = np.searchsorted(c.slave_nodes, nodes)
    s = rows.size
    slave = sp.csr_matrix((c.D[rows], (np.arange(s), nodes)), shape=(s, space.n_nodes))
    nodal = (slave - c.M[rows]).tocsr()
    n = c.normal[rows]
    B = sp.hstack([nodal.multiply(n[:, [0]]), nodal.multiply(n[:, [1]])]).tocsr()
    component = np.arange(space.n_nodes)
    B = B[:, np.argsort(np.concatenate([2 * component, 2 * component + 1]))]  # interleaved
    fixed = np.zeros(space.n_dofs)
    fixed[dofs] = values
    free = np.setdiff1d(np.arange(space.n_dofs), dofs)
    u, lam, active = solve_pdas(K, np.zeros(space.n_dofs), B, c.weighted_gap[rows], free, fixed)
    return space, u.reshape(-1, 2), lam, active, nodes, upper.n_cells


MATERIAL = Material.from_young(1.0, 0.3)


def compare(rings: int = 6, h_bottom: float = 0.02) -> dict[str, dict[str, float]]:
    """Per direction: ``u`` (max |u₂ − u₁| / max |u₁| on the upper body), ``lam`` (max
    |λ₂ − λ₁| / max λ₁), ``active`` (1.0 if the active sets agree) and ``mirror`` (max
    |u_lower(mirror x) − mirror(u_upper(x))| relative to max |u₁|)."""
    space1, u1, lam1, active1, nodes1 = one_body(rings, h_bottom)
    scale = np.abs(u1).max()
    out = {}
    for direction in ("averaged", "slave", "master"):
        space, u, lam, active, nodes, n_upper = two_bodies(rings, h_bottom, direction)
        upper = np.unique(space.cell_nodes[:n_upper])
        lower = np.unique(space.cell_nodes[n_upper:])
        x = space.node_points
        dist, k = cKDTree(space1.node_points).query(x[upper])
        assert dist.max() < 1e-14 and np.array_equal(x[nodes], space1.node_points[nodes1])
        dist, m = cKDTree(x[lower]).query(x[upper] * [1.0, -1.0])
        assert dist.max() < 1e-14
        out[direction] = {
            "u": float(np.abs(u[upper] - u1[k]).max() / scale),
            "lam": float(np.abs(lam - lam1).max() / lam1.max()),
            "active": float(np.array_equal(active, active1)),
            "mirror": float(np.abs(u[lower[m]] - u[upper] * [1.0, -1.0]).max() / scale),
        }
    return out


def main() -> None:
    print(f"{'direction':>10} {'u':>10} {'lambda':>10} {'active':>7} {'mirror':>10}")
    for direction, r in compare().items():
        same = "same" if r["active"] else "differ"
        print(f"{direction:>10} {r['u']:10.2e} {r['lam']:10.2e} {same:>7} {r['mirror']:10.2e}")


if __name__ == "__main__":
    main()
