"""Solvers layer: time integration and the searches it needs (broad phase, references).

Depends on the physics layer only (``tailbeam.physics``, ``tailbeam.physics.contact_law``, ...).
"""
