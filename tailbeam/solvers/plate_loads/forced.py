"""The modal plate's exact response to prescribed, piecewise-linear point loads.

Loads press down on the top surface (like a ball's contact force, N, >= 0 pushes -z); between
the node times the load is linear in time and every mode is propagated exactly
(``tailbeam.solvers.plate_loads.propagator.replay``). Used by the one-way coupling, the checks
against direct time integration and by users who measure a force and want the plate's answer.
"""

import numpy as np

from tailbeam.errors import InputError
from tailbeam.solvers.plate_loads.propagator import replay


def forced_response(
    basis, load_points, t_nodes, forces, times, points, *, damping_ratio=0.01, rayleigh=None
) -> dict:
    """Deflection "w" (m), velocity "v" (m/s), acceleration "a" (m/s^2) at ``points`` (p, 2)
    and sorted ``times`` (s), each (p, len(times)); loads (K, n_loads) N at the sorted node
    times t_nodes (K,) s on load_points (n_loads, 2) m; the plate is at rest at t_nodes[0]."""
    from tailbeam.plate.basis import modal_damping

    t_nodes = np.ascontiguousarray(t_nodes, dtype=float)
    forces = np.ascontiguousarray(np.reshape(forces, (len(t_nodes), -1)), dtype=float)
    times = np.ascontiguousarray(times, dtype=float)
    if np.any(np.diff(t_nodes) < 0) or np.any(np.diff(times) < 0):
        raise InputError("times", "node times and output times must be sorted")
    phi_loads = basis.deflection(load_points)
    if phi_loads.shape[0] != forces.shape[1]:
        raise InputError("forces", "need one force column per load point")
    omega = np.ascontiguousarray(basis.omega, dtype=float)
    zeta = np.ascontiguousarray(modal_damping(omega, damping_ratio, rayleigh))
    phi = np.ascontiguousarray(basis.deflection(points), dtype=float)
    w, v, a = (np.empty((phi.shape[0], len(times))) for _ in range(3))
    seg = np.zeros(len(t_nodes), dtype=np.int64)
    phis = np.ascontiguousarray(phi_loads[None])
    replay(omega, zeta, t_nodes, forces, seg, phis, times, w, v, a, phi, False)
    return {"w": w, "v": v, "a": a}
