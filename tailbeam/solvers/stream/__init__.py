"""The stream solvers: many balls on an inclined plate, rigid or modal (docs/streams.md).

``solver`` runs them for ``tailbeam.simulate`` (``Stream``, ``StreamReference``); the fast
solver's event loop is ``driver`` and its compiled integrator of the balls in contact
``active``; the modal plate between active sets is ``plate``; the slow independent reference is
``reference``.
"""
