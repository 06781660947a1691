"""A structure's modes below a frequency (or the first few) as a ``ModalBasis``.

The number of modes below fmax comes first, exactly, from Sylvester's inertia of
K - (2 pi fmax)^2 M (``tailbeam.plate.fe.sparse_solve``); then that many lowest eigenpairs
(plus a margin of two) by shift-invert Lanczos at a shift below every eigenvalue, the same
solver as the flat plate's. Rigid-body modes of a free structure are dropped. Shapes are
unit-modal-mass; the basis reads them as the z-displacement of the impact face
(``deflection_at``, the contract every solver uses) and along any direction at any surface
point (``shape_at``, for sensors anywhere).
"""

import time
from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import threadpool_limits

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.plate.basis import ModalBasis
from tailbeam.plate.cache import default_cache_dir
from tailbeam.plate.fe.sparse_solve import count_eigenvalues_below, lowest_modes
from tailbeam.plate.solid import cached
from tailbeam.plate.solid.factor import factorize
from tailbeam.plate.solid.model import StructureModel
from tailbeam.plate.solid.surface import cyclic_corners
from tailbeam.progress import task

THEORY = "solid"
MARGIN = 2  # modes solved beyond the counted band, so its top is not the Lanczos edge


@dataclass(frozen=True, eq=False)
class StructureModalBasis(ModalBasis):
    """A ModalBasis of a solid structure, with ``mode_vectors`` (n_dofs, n) on the reduced
    DOFs (Phi^T M Phi = I) and ``model``, the StructureModel they belong to."""

    mode_vectors: np.ndarray | None = None
    model: StructureModel | None = field(default=None, repr=False)

    def shape_at(self, points, directions=None, field_name: str = "sensors") -> np.ndarray:
        """(p, n) modal displacements (1/sqrt(kg)) at surface points (p, 3) m along
        ``directions`` (p, 3; default the outward surface normal); InputError naming
        ``field_name`` for a point off the surface."""
        op = self.model.surface_operator(points, directions, field_name)
        return np.asarray(op @ self.mode_vectors)[:, : self.n_modes]

    def nodal_displacements(self, nodes=None) -> np.ndarray:
        """(p, 3, n) each mode's displacement vector (1/sqrt(kg)) at the mesh's corner nodes
        ``nodes`` (indices of ``model.vmesh.mesh.p`` columns; default all of them)."""
        probe = self.model.probe()
        if nodes is None:
            nodes = np.arange(self.model.vmesh.mesh.p.shape[1])
        scalar_dofs = probe.scalar.nodal_dofs[0, nodes]  # the value at each corner node
        out = np.empty((len(nodes), 3, self.n_modes))
        for c, idx in enumerate(probe.indices):
            rows = self.model.transform[idx[scalar_dofs]]
            out[:, c, :] = np.asarray(rows @ self.mode_vectors)[:, : self.n_modes]
        return out

    def vtk_structure(self):
        """(points (p, 3) m, meshio cell blocks, shapes (p, 3, n) 1/sqrt(kg)): the outer
        surface (its boundary faces on the mesh's corner nodes) and each mode's displacement
        at those nodes, for the ParaView series (``tailbeam.io.paraview``)."""
        mesh = self.model.vmesh.mesh
        corners = mesh.facets[:, mesh.boundary_facets()]
        kind = "triangle" if corners.shape[0] == 3 else "quad"
        if kind == "quad":
            corners = cyclic_corners(mesh.p, corners).T
        nodes, local = np.unique(corners, return_inverse=True)
        cells = [(kind, local.reshape(corners.shape).T.astype(np.int64))]
        return mesh.p[:, nodes].T.copy(), cells, self.nodal_displacements(nodes)


@dataclass(frozen=True)
class StructureModesListing:
    """The frequencies (Hz) and ``info`` of a structure's cached basis, without its mode
    vectors: what a listing of the modes needs (``cached_listing``)."""

    frequencies_hz: np.ndarray
    info: dict
    boundary: str
    theory: str = THEORY

    @property
    def n_modes(self) -> int:
        return len(self.frequencies_hz)


def cached_listing(model: StructureModel, *, fmax_hz=None, count=None, cache_dir=None):
    """The StructureModesListing of the basis ``structure_modes`` would read from the cache
    (the same key), reading its frequencies only; None when it is not cached there."""
    key = cached.basis_key(model, fmax_hz, count)
    path = cached.basis_path(cache_dir or default_cache_dir(), key)
    found = cached.load_frequencies(path, key)
    if found is None:
        return None
    freqs, info = found
    info.update(cache="hit", cache_file=str(path))
    return StructureModesListing(np.asarray(freqs, dtype=float), info, _boundary(model))


def _shift(model: StructureModel, fmax_hz: float | None) -> float:
    """A shift below every eigenvalue (negative), small next to the band's."""
    if fmax_hz is not None:
        return -((2.0 * np.pi * 1e-3 * fmax_hz) ** 2)
    ratio = model.stiffness.diagonal() / np.maximum(model.mass.diagonal(), 1e-300)
    return -1e-9 * float(np.median(ratio))


def solve_band(model: StructureModel, fmax_hz=None, count=None, on_solve=None):
    """(frequencies Hz (k,), unit-modal-mass vectors (n, k)) of the elastic modes below
    ``fmax_hz`` and/or the first ``count``."""
    rigid = model.rigid_modes
    wanted = count
    if fmax_hz is not None:
        value = (2.0 * np.pi * fmax_hz) ** 2
        below = count_eigenvalues_below(model.stiffness, model.mass, value, factorize)
        wanted = below - rigid if count is None else min(count, below - rigid)
        if wanted < 1:
            raise InputError("fmax_hz", f"no elastic mode lies below {fmax_hz!r} Hz")
    nev = min(wanted + rigid + MARGIN, model.n_dofs)
    lam, phi = lowest_modes(model.stiffness, model.mass, nev, shift=_shift(model, fmax_hz),
                            on_solve=on_solve, factorize=factorize)  # fmt: skip
    lam, phi = lam[rigid:], phi[:, rigid:]
    freqs = np.sqrt(np.maximum(lam, 0.0)) / (2.0 * np.pi)
    if fmax_hz is not None and np.count_nonzero(freqs <= fmax_hz) < wanted:
        raise WorkLimitError(
            f"the eigen-solver found {np.count_nonzero(freqs <= fmax_hz)} of the {wanted} "
            f"modes below {fmax_hz} Hz"
        )
    return freqs[:wanted], _signed(phi[:, :wanted])


def _signed(phi: np.ndarray) -> np.ndarray:
    """Columns with a reproducible sign: the largest entry of each is positive."""
    big = np.argmax(np.abs(phi), axis=0)
    signs = np.sign(phi[big, np.arange(phi.shape[1])])
    return phi * np.where(signs == 0, 1.0, signs)


def structure_modes(model: StructureModel, *, fmax_hz=None, count=None, blas_threads=1,
                    cache_dir=None, use_cache: bool = True):  # fmt: skip
    """The elastic modes of ``model`` below ``fmax_hz`` (Hz) and/or the first ``count``, as a
    StructureModalBasis (theory 'solid'); the static compliance of the held structure backs
    the residual flexibility.

    The basis and the static compliances are cached on disk (``tailbeam.plate.solid.cached``;
    ``cache_dir`` default $TAILBEAM_CACHE_DIR or ~/.cache/tailbeam); ``use_cache=False``
    neither reads nor writes. ``info["cache"]`` says "hit", "miss" or "off".
    """
    if fmax_hz is None and count is None:
        raise InputError("fmax_hz", "give fmax_hz or count")
    if fmax_hz is not None:
        fmax_hz = require_positive("fmax_hz", fmax_hz)
    folder = (cache_dir or default_cache_dir()) if use_cache else None
    path = key = hit = None
    if use_cache:
        key = cached.basis_key(model, fmax_hz, count)
        path = cached.basis_path(folder, key)
        hit = cached.load_basis(path, key, model.n_dofs)
    if hit is not None:
        freqs, phi, info = hit
        info.update(cache="hit", cache_file=str(path))
    else:
        t0 = time.perf_counter()
        with threadpool_limits(limits=blas_threads), task("eigen-solve", unit="solves") as bar:
            freqs, phi = solve_band(model, fmax_hz, count, on_solve=bar.update)
        info = _describe(model, fmax_hz, count, time.perf_counter() - t0)
        info.update(cache="miss" if use_cache else "off", cache_file=str(path) if path else None)
        if use_cache:
            cached.store_basis(path, key, freqs, phi, info)
    return _wrap(model, freqs, phi, info, folder)


def _wrap(model: StructureModel, freqs, phi, info: dict, cache_dir) -> StructureModalBasis:
    """The StructureModalBasis of reduced mode vectors ``phi`` (n_dofs, k)."""

    def deflection_at(points):
        return np.asarray(model.face_operator(points) @ phi)

    held = model.rigid_modes == 0
    return StructureModalBasis(
        plate=model.plate,
        frequencies_hz=np.asarray(freqs, dtype=float),
        deflection_at=deflection_at,
        theory=THEORY,
        boundary=_boundary(model),
        static_compliance_at=cached.StaticCompliances(model, cache_dir) if held else None,
        static_deflection_at=model.static_deflection if held else None,
        info=info,
        mode_vectors=phi,
        model=model,
    )


def _boundary(model: StructureModel) -> str:
    """The supports in a few words, e.g. 'pinned hinge, spring jack'."""
    if not model.supports:
        return "free"
    return ", ".join(f"{s.kind} {s.group or 'region'}" for s in model.supports)


def _describe(model: StructureModel, fmax_hz, count, seconds) -> dict:
    return {
        "theory": THEORY,
        "element": model.element,
        "mesh": model.vmesh.source,
        "n_cells": int(model.vmesh.mesh.t.shape[1]),
        "n_dofs": model.n_dofs,
        "impact_face": model.face.name,
        "fmax_hz": fmax_hz,
        "count": count,
        "rigid_body_modes_excluded": model.rigid_modes,
        "eigensolve_s": seconds,
    }
