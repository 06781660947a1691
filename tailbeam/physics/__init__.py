"""Physics layer: geometry and laws of the bodies, no time integration.

New modules of issue 7 (streams) live here; the refactor moves the existing physics modules
(materials, contact_law, hertz, bodies) under this folder.
"""
