"""Solvers layer: time integration and the searches it needs (broad phase, references).

- ``rigid``: balls on a rigid plate, the Adams IMPACT law (paper section 3) and its reference;
- ``coupled``: balls on the two-way coupled modal plate, its FE reference, plate loads;
- ``stream``: the fast stream solver (closed-form flight, broad phase, active sets) and the
  slow stream reference;
- ``records``: ``EventKind``, ``Event`` and ``Impact`` (the one contact record), shared by every
  solver.

Depends on the physics layer (``tailbeam.physics``), the plate (``tailbeam.plate``, through
``tailbeam.plate.basis``) and the sensor chain (``tailbeam.signals``), never on ``tailbeam.paper``.
"""
