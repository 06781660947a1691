"""The single-ball solvers as ``tailbeam.simulate`` runs them: exact per-ball integration on
the rigid plate (``tailbeam.solvers.rigid``) or the modal plate (``tailbeam.solvers.coupled``),
for scenes without streams, without inclination and without two balls that can touch."""

from tailbeam.errors import InputError
from tailbeam.progress import task
from tailbeam.results.frames import BallFrames
from tailbeam.results.result import Result
from tailbeam.scene import Scene
from tailbeam.solvers.base import Options, Solver, why_stream
from tailbeam.solvers.coupled.solver import simulate_coupled
from tailbeam.solvers.modal_setup.setup import single_ball_setup
from tailbeam.solvers.rigid.solver import simulate_rigid


class SingleBall(Solver):
    """Each ball alone with the plate: closed-form flights, every contact integrated with
    its events (rigid plate), or the balls and the modes stepped together (modal plate)."""

    name = "single-ball"
    stream = False

    def refusal(self, scene) -> str | None:
        if scene.friction is not None:
            return (
                "contact.friction: 'single-ball' models frictionless contacts only; friction "
                "and rotation run on --solver stream (rigid or modal plate) or stream-reference "
                "(rigid plate)"
            )
        if not scene.needs_stream_solver:
            return None
        return (
            f"'single-ball' cannot run this scene ({why_stream(scene)}): streams, an inclined "
            "plate and ball-ball contact need 'stream' or 'stream-reference'"
        )

    def check(self, scene, options: Options) -> None:
        if scene.plate_model == "modal" and options.given():
            raise InputError(
                next(iter(options.given())), "is not a setting of the modal plate solver"
            )

    def run(self, scene, plate, options: Options, **coupled) -> Result:
        """``coupled``: settings of ``simulate_coupled`` (e.g. ``steps_per_contact``); the
        frames (``options.frames``) sampled from the balls' solutions."""
        result = self._solve(scene, plate, options, **coupled)
        if options.frames:
            result.frames = BallFrames.from_states(result, options.frames)
        return result

    def _solve(self, scene, plate, options: Options, **coupled) -> Result:
        if plate is None:
            return self._rigid(scene, options)
        settings = plate.settings
        return simulate_coupled(
            scene.balls, plate.basis, scene.contacts(), scene.duration, sensors=scene.sensors,
            damping_ratio=settings.damping_ratio, rayleigh=settings.rayleigh,
            residual_flexibility=settings.residual_flexibility, coupling=settings.coupling,
            gravity=scene.gravity, labels=scene.labels,
            info={**plate.info(), "solver_choice": self.name}, **coupled,
        )  # fmt: skip

    def _rigid(self, scene, options: Options) -> Result:
        with task(f"simulating {scene.duration:g} s, {len(scene.balls)} balls, rigid plate"):
            return simulate_rigid(
                scene.balls, scene.plate, scene.contacts(), scene.duration,
                gravity=scene.gravity, labels=scene.labels, info={"solver_choice": self.name},
                **options.given(),
            )  # fmt: skip


def simulate_scene_modal(scene, *, basis=None, use_cache: bool = True, **options) -> Result:
    """A single-ball scene on the modal plate, with its set-up (band, basis unless ``basis``
    is given, tail); ``options`` go to ``simulate_coupled`` (e.g. ``steps_per_contact``)."""
    if not isinstance(scene, Scene):
        raise InputError("scene", "must be a tailbeam.scene.Scene")
    setup = single_ball_setup(scene, basis=basis, use_cache=use_cache)
    return SingleBall().run(scene, setup, Options(), **options)
