"""tailbeam: coal and gangue particles striking the tail beam of a caving support.

What to simulate is positional, how to simulate is keyword-only. SI units throughout.

The names below load on first use (``tailbeam.simulate`` imports the solvers, numba and
scipy when it is first looked up), so ``import tailbeam`` and the command line's start stay
cheap; ``from tailbeam import simulate`` works as for any module.
"""

import importlib
from typing import TYPE_CHECKING

from tailbeam.cachedir import configure_numba_cache

configure_numba_cache()  # before any module defines a cached numba kernel

# the imports below come after the cache is configured
from tailbeam._version import __version__  # noqa: E402
from tailbeam.errors import InputError, WorkLimitError  # noqa: E402

# name -> the module that defines it, imported when the name is first looked up (PEP 562)
_LAZY = {
    "load_scene": "tailbeam.io.scene_file",
    "Ball": "tailbeam.physics.bodies",
    "Plate": "tailbeam.physics.bodies",
    "ImpactLaw": "tailbeam.physics.contact_law",
    "ball_ball_law": "tailbeam.physics.contact_law",
    "ball_plate_law": "tailbeam.physics.contact_law",
    "impact_force": "tailbeam.physics.contact_law",
    "step": "tailbeam.physics.contact_law",
    "PLATE": "tailbeam.physics.contacts",
    "ContactTable": "tailbeam.physics.contacts",
    "CARBON_STEEL": "tailbeam.physics.materials",
    "COAL": "tailbeam.physics.materials",
    "SANDSTONE": "tailbeam.physics.materials",
    "Material": "tailbeam.physics.materials",
    "get_material": "tailbeam.physics.materials",
    "Result": "tailbeam.results.result",
    "simulate": "tailbeam.simulation",
}

if TYPE_CHECKING:  # the same names, for type checkers and editors
    from tailbeam.io.scene_file import load_scene
    from tailbeam.physics.bodies import Ball, Plate
    from tailbeam.physics.contact_law import (
        ImpactLaw,
        ball_ball_law,
        ball_plate_law,
        impact_force,
        step,
    )
    from tailbeam.physics.contacts import PLATE, ContactTable
    from tailbeam.physics.materials import CARBON_STEEL, COAL, SANDSTONE, Material, get_material
    from tailbeam.results.result import Result
    from tailbeam.simulation import simulate

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


def __getattr__(name: str):
    """A facade name, imported from its module on first use (then kept in this module)."""
    try:
        module = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list:
    return sorted(set(globals()) | set(_LAZY))
