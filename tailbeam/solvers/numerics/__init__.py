"""Numerical parts shared by the solvers and owned by none: the DOP853 tables and step
(``dop853``), the decorator of compiled helpers (``jit``), Chebyshev root finding on a step's
dense output (``chebyshev``, ``step_events``) and closed-form ballistic flight (``flight``)."""
