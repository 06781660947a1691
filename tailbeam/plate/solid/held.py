"""The structure a scene runs on, built once per mesh content, face, supports and material.

A scene file names its structure by ``plate.mesh`` (a path), ``plate.impact_face`` and
``plate.supports``; the scene reader builds it up front (so a bad mesh, face, group or an
unheld structure is refused before any work) and the modal set-up takes the same model
again. Building it reads the mesh and checks the face and supports without assembling the
stiffness and mass (``model``: on first use), so a run that reads its basis and compliances
from the disk cache assembles nothing. The key is the mesh file's SHA-256 (its content, not
its name or time), the face, the supports and the material, so an edited mesh is rebuilt.
"""

import functools
import hashlib
from pathlib import Path

from tailbeam.errors import InputError
from tailbeam.physics.materials import Material
from tailbeam.plate.solid.cached import read_mesh
from tailbeam.plate.solid.model import StructureModel, assemble_structure

MESH_FIELD = "plate.mesh"
KEPT = 2  # structures held in memory (a scene and a sweep's neighbour)


def mesh_digest(path) -> str:
    """SHA-256 (hex) of the mesh file's bytes; InputError naming plate.mesh if unreadable."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()
    except OSError as err:
        raise InputError(MESH_FIELD, f"cannot read {str(path)!r}: {err.strerror}") from None


def held_structure(path, impact_face: str, supports: tuple, material: Material) -> StructureModel:
    """The held structure of ``path`` (one per content, face, supports, material)."""
    return _built(str(path), mesh_digest(path), impact_face, tuple(supports), material)


@functools.lru_cache(maxsize=KEPT)
def _built(path, digest, impact_face, supports, material) -> StructureModel:
    vmesh = read_mesh(path, digest)  # the file read once per content, then from the cache
    return assemble_structure(vmesh, impact_face, supports, material=material)


__all__ = ["held_structure", "mesh_digest"]
