"""One-way coupling: the balls see a rigid plate; the plate receives the rigid-plate forces.

This is what one gets by post-processing a rigid-plate simulation (the paper's model) through
the plate's modes. It is cheaper, but it ignores that the plate yields and vibrates under the
ball: restitution, peak force and contact duration are those of the rigid plate, and the
energy the ball loses into plate vibration (Zener's mechanism) is never taken from the ball.
The comparison with the two-way model is in tests/test_coupled_oneway.py and the example.

The rigid solution is sampled on a fine grid inside each contact (``points_per_contact``
nodes), where the force is then taken as linear in time; the plate is driven exactly by that
piecewise-linear force (the same node representation as the two-way result).
"""

import numpy as np

from tailbeam.physics.bodies import STANDARD_GRAVITY
from tailbeam.physics.contact_patch import load_radius
from tailbeam.physics.contacts import PLATE, contact_table
from tailbeam.plate.basis import modal_damping
from tailbeam.results.result import Result
from tailbeam.solvers.coupled.replay import ModalReplay, NodeStates
from tailbeam.solvers.rigid import simulate_rigid


def simulate_one_way(
    balls,
    basis,
    laws,
    duration,
    *,
    sensors=(),
    damping_ratio=0.01,
    rayleigh=None,
    rest_speed=None,
    gravity=STANDARD_GRAVITY,
    points_per_contact: int = 400,
    labels=(),
    info=None,
) -> Result:
    """Rigid-plate impacts (tailbeam.solvers.rigid) whose force histories drive the modal plate;
    ``laws``: the balls' ``ContactTable`` or one ball-plate ImpactLaw per ball."""
    kwargs = {} if rest_speed is None else {"rest_speed": rest_speed}
    if gravity != STANDARD_GRAVITY:
        kwargs["gravity"] = gravity
    contacts = contact_table(balls, laws)
    rigid = simulate_rigid(balls, basis.plate, contacts, duration, labels=labels, **kwargs)
    # node times: fine inside every contact, the contact limits, rest times, and the ends
    pieces = [np.array([0.0, duration])]
    for imp in rigid.impacts:
        t_end = min(imp.t_end, duration)
        pieces.append(np.linspace(imp.t_start, t_end, points_per_contact + 1))
    for t_rest in rigid.states.rest_time.values():
        if np.isfinite(t_rest):
            pieces.append(np.array([t_rest]))
    tn = np.unique(np.concatenate(pieces))
    tn = tn[(tn >= 0.0) & (tn <= duration)]
    states = rigid.sample(tn)
    names = [b.name for b in balls]
    z = np.column_stack([states[n]["z"] for n in names])
    vz = np.column_stack([states[n]["vz"] for n in names])
    force = np.column_stack([states[n]["force"] for n in names])
    delta = np.array([b.radius for b in balls])[None, :] - z
    # the same load model as the two-way solver: a point (Kirchhoff) or the Hertz disc (Mindlin)
    radii = [
        load_radius(basis.theory, b, contacts.law(i, PLATE), gravity) for i, b in enumerate(balls)
    ]
    phi = np.array([basis.load_deflection([balls[i].position[:2]], radii[i])[0]
                    for i in range(len(balls))])  # fmt: skip
    nodes = (tn, z, vz, force, delta)
    zeta = modal_damping(np.asarray(basis.omega), damping_ratio, rayleigh)
    phis = np.ascontiguousarray(phi[None, :, :])
    seg_phase = np.zeros(len(tn), dtype=np.int64)
    return Result(
        duration=rigid.duration, particles=rigid.particles, impacts=rigid.impacts,
        events=rigid.events, leaves=rigid.leaves, status=rigid.status, message=rigid.message,
        stats=rigid.stats, info={"coupling": "one-way", "rigid": rigid.info, **(info or {})},
        sensors=tuple(sensors),
        states=NodeStates(tuple(balls), gravity, nodes, dict(rigid.states.rest_time)),
        plate=ModalReplay(basis, zeta, nodes, seg_phase, phis),
    )  # fmt: skip
