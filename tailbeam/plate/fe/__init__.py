"""The plate's finite-element model (scikit-fem): meshes and named edges (``mesh``,
``boundary``), Kirchhoff and Reissner-Mindlin assembly (``kirchhoff``, ``mindlin``, ``model``),
the eigen-solve (``sparse_solve``, ``modes``), its cost (``cost``) and the automatic theory and
mesh choice (``resolution``)."""
