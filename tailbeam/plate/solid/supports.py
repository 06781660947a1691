"""How a structure is held: clamped, pinned and spring supports on named faces or box regions.

- ``clamped``: every displacement component of the face's nodes is fixed.
- ``pinned``: a hinge. The face moves as a rigid body that can only turn about the hinge
  axis (through the face's centroid, along ``axis`` or by default the face's longest
  extent): every node's displacement is theta * (axis x r), one rotation theta for the whole
  face. This is a lug on a rigid pin, or a beam end on a knife edge with plane sections;
  a line of fixed nodes would give a mesh-dependent line singularity instead.
- ``spring``: a total stiffness k (N/m) spread uniformly over the face, (k / A) (u . d)
  per unit area, along the face's outward normal d or a given ``direction``; a rigid
  translation of the face along d stores k u^2 / 2.

The supports become a constraint map T (full DOFs = T reduced DOFs) and a spring stiffness
added to the structure's, see ``apply_supports``.
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, FacetBasis
from skfem.helpers import dot

from tailbeam.errors import InputError, require_positive, require_vector
from tailbeam.plate.solid.elasticity import INTEGRATION_ORDER, components, rigid_body_modes

KINDS = ("clamped", "pinned", "spring")


@dataclass(frozen=True)
class Support:
    """One support of a structure.

    kind : 'clamped', 'pinned' or 'spring'. group : a named face group of the mesh, or
    region : ((x0, x1), (y0, y1), (z0, z1)) m, the boundary faces inside that box.
    stiffness : N/m (spring only). direction : the spring's direction (default the face's
    outward normal). axis : the hinge's direction (pinned; default the face's longest extent).
    """

    kind: str
    group: str | None = None
    region: tuple | None = None
    stiffness: float | None = None
    direction: tuple | None = None
    axis: tuple | None = None


def check_support(support: Support, field: str) -> Support:
    """The support with its values checked (InputError naming ``field``.key)."""
    if support.kind not in KINDS:
        raise InputError(f"{field}.kind", f"must be one of {', '.join(KINDS)}, got "
                         f"{support.kind!r}")  # fmt: skip
    if (support.group is None) == (support.region is None):
        raise InputError(field, "give either group or region")
    if support.kind == "spring":
        require_positive(f"{field}.stiffness", support.stiffness)
    elif support.stiffness is not None:
        raise InputError(f"{field}.stiffness", f"applies to springs only, not {support.kind}")
    for key in ("direction", "axis"):
        value = getattr(support, key)
        if value is not None and np.linalg.norm(require_vector(f"{field}.{key}", value, 3)) == 0:
            raise InputError(f"{field}.{key}", "must not be the zero vector")
    if support.region is not None:
        box = np.asarray(support.region, dtype=float) if _is_box(support.region) else None
        if box is None or not np.all(box[:, 0] <= box[:, 1]):
            raise InputError(f"{field}.region", "must be [[x0, x1], [y0, y1], [z0, z1]] m")
    return support


def _is_box(region) -> bool:
    try:
        return np.asarray(region, dtype=float).shape == (3, 2)
    except (TypeError, ValueError):
        return False


def support_facets(support: Support, vmesh, field: str) -> np.ndarray:
    """Boundary facets the support acts on (InputError if none)."""
    if support.group is not None:
        facets = vmesh.face(support.group, f"{field}.group")
    else:
        mesh, box = vmesh.mesh, np.asarray(support.region, dtype=float)
        tol = 1e-9 * vmesh.size
        boundary = mesh.boundary_facets()
        nodes = mesh.p[:, mesh.facets[:, boundary]]  # (3, corners, facets)
        inside = (nodes >= box[:, :1, None] - tol) & (nodes <= box[:, 1:, None] + tol)
        facets = boundary[inside.all(axis=(0, 1))]
        if len(facets) == 0:
            raise InputError(f"{field}.region", "holds no boundary face of the mesh")
    if len(facets) == 0:
        raise InputError(f"{field}.group", f"face group {support.group!r} is empty")
    return facets


@dataclass(frozen=True, eq=False)
class Constraints:
    """Supports as linear algebra: full displacement u = T q; springs add ``spring`` (full
    DOFs, N/m) to the stiffness. ``fixed``: clamped DOFs; ``hinges``: per pinned support its
    dependent DOFs and the motion g of a unit rotation (u[dofs] = g theta)."""

    transform: sp.csr_matrix
    spring: sp.csr_matrix
    fixed: np.ndarray
    hinges: tuple


def apply_supports(basis, vmesh, supports, fields) -> Constraints:
    """Constraint map and spring stiffness of ``supports`` (checked; ``fields`` name them)."""
    n = basis.N
    fixed = np.zeros(n, dtype=bool)
    spring = sp.csr_matrix((n, n))
    pinned = []
    for support, field in zip(supports, fields, strict=True):
        facets = support_facets(support, vmesh, field)
        if support.kind == "clamped":
            fixed[basis.get_dofs(facets=facets).all()] = True
        elif support.kind == "spring":
            spring = spring + _spring_matrix(basis, vmesh.mesh, facets, support)
        else:
            pinned.append((support, facets))
    claimed = fixed.copy()
    hinges = []
    for support, facets in pinned:
        dofs = np.setdiff1d(basis.get_dofs(facets=facets).all(), np.flatnonzero(claimed))
        claimed[dofs] = True
        hinges.append((dofs, _hinge_motion(basis, dofs, support.axis)))
    transform = _transform(n, claimed, hinges)
    return Constraints(transform, spring.tocsr(), np.flatnonzero(fixed), tuple(hinges))


def _hinge_motion(basis, dofs, axis) -> np.ndarray:
    """Displacement of ``dofs`` under a unit rotation (rad) about the hinge axis."""
    locs = basis.doflocs[:, dofs]
    center = locs.mean(axis=1)
    r = locs - center[:, None]
    if axis is None:
        # the face's longest extent: principal direction of its nodes' spread
        axis = np.linalg.eigh(r @ r.T)[1][:, -1]
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    motion = np.cross(axis, r.T).T  # (3, d)
    return motion[components(basis)[dofs], np.arange(len(dofs))]


def _transform(n, claimed, hinges) -> sp.csr_matrix:
    """T (n, n_reduced): identity on unclaimed DOFs, one column per hinge."""
    free = np.flatnonzero(~claimed)
    rows, cols, vals = [free], [np.arange(len(free))], [np.ones(len(free))]
    for k, (dofs, motion) in enumerate(hinges):
        rows.append(dofs)
        cols.append(np.full(len(dofs), len(free) + k))
        vals.append(motion)
    shape = (n, len(free) + len(hinges))
    return sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=shape
    )


def _spring_matrix(basis, mesh, facets, support) -> sp.csr_matrix:
    """(k / A) int_face (u . d)(v . d) dS on the face (d: direction or outward normal)."""
    fb = FacetBasis(mesh, basis.elem, facets=facets, intorder=INTEGRATION_ORDER)
    area = float(np.sum(fb.dx))
    k_area = float(support.stiffness) / area
    fixed_d = None
    if support.direction is not None:
        fixed_d = np.asarray(support.direction, dtype=float)
        fixed_d = fixed_d / np.linalg.norm(fixed_d)

    @BilinearForm
    def form(u, v, w):
        d = w.n if fixed_d is None else fixed_d[:, None, None] * np.ones_like(w.n)
        return k_area * dot(u, d) * dot(v, d)

    return form.assemble(fb).tocsr()


def free_rigid_motions(basis, constraints: Constraints) -> int:
    """How many independent rigid-body motions the supports leave free (0: held).

    A rigid motion R c is admissible when it meets every constraint (zero at clamped DOFs, a
    rotation about the axis on a hinge's face) and stores no spring energy; the count is the
    null space of the sum of those two quadratic forms on the six rigid motions, each scaled
    by its largest eigenvalue."""
    rigid = rigid_body_modes(basis)
    parts = []
    rows = [rigid[constraints.fixed]]
    for dofs, motion in constraints.hinges:
        block = rigid[dofs]
        g = motion / np.linalg.norm(motion)
        rows.append(block - np.outer(g, g @ block))
    c = np.vstack(rows)
    parts.append(c.T @ c)
    parts.append(rigid.T @ (constraints.spring @ rigid))
    gram = np.zeros((6, 6))
    for part in parts:
        top = np.max(np.abs(np.linalg.eigvalsh(part))) if part.size else 0.0
        if top > 0:
            gram += part / top
    eig = np.linalg.eigvalsh(gram)
    return int(np.count_nonzero(eig <= 1e-9 * max(eig.max(), 1e-300)))
