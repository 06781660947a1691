"""Physics layer: the bodies, their materials and the laws of their contacts (no time
integration): materials, bodies, hertz, contact_law, contact_patch, impact (the IMPACT law's
one numba definition), incline, pair.
"""
