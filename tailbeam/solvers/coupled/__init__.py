"""Balls on a flexible (modal) plate, two-way coupled: ``simulate_coupled``.

    from tailbeam.solvers.coupled import simulate_coupled

One-way coupling (rigid-plate forces driving the modes) is ``oneway``; the exact replay of a
run's balls and plate is ``replay``; the independent full finite-element reference is
``fe_reference``.
"""

from tailbeam.solvers.coupled.solver import simulate_coupled

__all__ = ["simulate_coupled"]
