"""Balls on a flexible (modal) plate, two-way coupled; see ``simulate_coupled``.

Public API:
    simulate_coupled(balls, basis, laws, duration, *, sensors=(), ...) -> CoupledResult
    simulate_scene_modal(scene) -> CoupledResult   (builds the modal basis from the scene)
    PlateLoads, plate_response(basis, zeta, loads, points, times)   (sparse prescribed loads,
        one-way: a stream's contacts and dead loads; tailbeam.solvers.plate_loads.response)
"""

from tailbeam.plate.basis import DEFAULT_DAMPING_RATIO, modal_damping
from tailbeam.solvers.coupled.auto import choose_band, simulate_scene_modal
from tailbeam.solvers.coupled.result import CoupledResult
from tailbeam.solvers.coupled.solver import simulate_coupled
from tailbeam.solvers.plate_loads.loads import PlateLoads
from tailbeam.solvers.plate_loads.response import plate_response

__all__ = [
    "CoupledResult",
    "DEFAULT_DAMPING_RATIO",
    "PlateLoads",
    "choose_band",
    "modal_damping",
    "plate_response",
    "simulate_coupled",
    "simulate_scene_modal",
]
