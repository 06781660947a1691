"""Balls bouncing on a rigid plate under the Adams IMPACT law (paper section 3).

    from tailbeam.solvers.rigid import simulate_rigid

The slow independent reference is ``tailbeam.solvers.rigid.reference.simulate_rigid_reference``;
the rest rules and defaults are documented in ``tailbeam.solvers.rigid.model``.
"""

from tailbeam.solvers.rigid.model import DEFAULT_MAX_CONTACTS, DEFAULT_MAX_STEPS, DEFAULT_REST_SPEED
from tailbeam.solvers.rigid.solver import simulate_rigid

__all__ = ["simulate_rigid", "DEFAULT_REST_SPEED", "DEFAULT_MAX_CONTACTS", "DEFAULT_MAX_STEPS"]
