"""tailbeam: coal and gangue particles striking the tail beam of a caving support.

What to simulate is positional, how to simulate is keyword-only. SI units throughout.
"""

from tailbeam.bodies import Ball, Plate
from tailbeam.contact_law import ImpactLaw, ball_ball_law, ball_plate_law, impact_force, step
from tailbeam.errors import InputError, WorkLimitError
from tailbeam.materials import CARBON_STEEL, COAL, SANDSTONE, Material, get_material

__all__ = [
    "Ball",
    "Plate",
    "ImpactLaw",
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
]

__version__ = "0.1.0"
