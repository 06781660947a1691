"""The one protocol every solver of ``tailbeam.simulate`` follows.

A solver is a part of the simulation, swapped by name (``solver=``, ``--solver``), in the
spirit of diffrax: every solver takes the same parts and returns the same ``Result``:

- the scene (``tailbeam.scene.Scene``): what to simulate;
- the modal plate (``tailbeam.solvers.modal_setup.setup.ModalSetup``, or None for the rigid
  plate), set up from the scene in one place for every solver, with the kind of set-up the
  solver asks for (``Solver.stream``);
- ``Options``: how to solve (tolerance, work bound; None keeps the solver's default).

``Solver.refusal`` says, before any work, why a solver cannot run a scene; ``Solver.check``
refuses what would fail or not fit later (limits, memory); ``Solver.run`` runs and builds the
Result once.
"""

import abc
from dataclasses import dataclass

from tailbeam.results.result import Result


@dataclass(frozen=True)
class Options:
    """How to solve a scene: the keyword-only settings of ``tailbeam.simulate``.

    Parameters
    ----------
    rtol : float, optional
        Relative tolerance of the solver's integrator (None: its default).
    max_steps : int, optional
        The solver's work bound in steps (None: its default); WorkLimitError beyond it.
    frames : tuple of float
        Times (s) at which the result keeps every body's state (``Result.frames``); empty:
        none. Not a setting of the integration (``given`` leaves it out).
    """

    rtol: float | None = None
    max_steps: int | None = None
    frames: tuple = ()

    def given(self) -> dict:
        """The settings the user gave, by name."""
        pairs = (("rtol", self.rtol), ("max_steps", self.max_steps))
        return {k: v for k, v in pairs if v is not None}


class Solver(abc.ABC):
    """A solver of ``tailbeam.simulate`` (see the module docstring).

    Attributes
    ----------
    name : str
        Its name, as users choose it.
    stream : bool
        True if it runs on the stream solvers' modal set-up (``stream_setup``: the sensors'
        band, contact tails), False for the single-ball set-up.
    frames : bool
        True if it can keep every body's state at frame times (``Options.frames``).
    """

    name: str = ""
    stream: bool = False
    frames: bool = True

    def refusal(self, scene) -> str | None:
        """Why this solver cannot run ``scene`` (one phrase naming what to change), or None."""
        return None

    def check(self, scene, options: Options) -> None:  # noqa: B027 (nothing to refuse by default)
        """Before any work: InputError or WorkLimitError, naming the setting to change, for
        what this solver would refuse later (limits, memory, settings it does not take)."""

    @abc.abstractmethod
    def run(self, scene, plate, options: Options) -> Result:
        """Simulate ``scene`` on ``plate`` (a ``ModalSetup``; None: the rigid plate) and
        return its Result, with ``info["solver_choice"]`` = ``name``."""


def why_stream(scene) -> str:
    """Why ``scene`` needs the stream solvers (one phrase), or "solver requested"."""
    if not scene.needs_stream_solver:
        return "solver requested"
    if scene.streams:
        return f"{len(scene.streams)} stream(s)"
    if scene.inclination != 0.0:
        return f"plate inclined {scene.inclination:g} degrees"
    return "balls that may touch each other"
