"""The compiled (numba) integrator of an active set: the stepping loop and its bookkeeping
(``kernel``), one DOP853 step and its dense output (``step``), the certified event search
(``events``), the rows just applied that a restart carries (``fresh``) and the pair physics:
the IMPACT law's regions, the right-hand side and the watched functions (``pairs``)."""
