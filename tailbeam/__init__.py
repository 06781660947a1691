"""tailbeam: coal and gangue particles striking the tail beam of a caving support.

What to simulate is positional, how to simulate is keyword-only. SI units throughout.
"""

from tailbeam.cachedir import configure_numba_cache

configure_numba_cache()  # before any module defines a cached numba kernel

# the imports below come after the cache is configured
from tailbeam._version import __version__  # noqa: E402
from tailbeam.errors import InputError, WorkLimitError  # noqa: E402
from tailbeam.io.scene_file import load_scene  # noqa: E402
from tailbeam.physics.bodies import Ball, Plate  # noqa: E402
from tailbeam.physics.contact_law import (  # noqa: E402
    ImpactLaw,
    ball_ball_law,
    ball_plate_law,
    impact_force,
    step,
)
from tailbeam.physics.contacts import PLATE, ContactTable  # noqa: E402
from tailbeam.physics.materials import CARBON_STEEL, COAL, SANDSTONE, Material, get_material  # noqa: E402
from tailbeam.results.result import Result  # noqa: E402
from tailbeam.simulation import simulate  # noqa: E402

__all__ = [
    "__version__",
    "Ball",
    "Plate",
    "ImpactLaw",
    "ContactTable",
    "PLATE",
    "ball_ball_law",
    "ball_plate_law",
    "impact_force",
    "step",
    "InputError",
    "WorkLimitError",
    "Material",
    "COAL",
    "SANDSTONE",
    "CARBON_STEEL",
    "get_material",
    "load_scene",
    "simulate",
    "Result",
]
