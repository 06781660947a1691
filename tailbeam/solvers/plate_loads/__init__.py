"""The modal plate's exact response to prescribed loads: sparse load histories (``loads``),
the compiled march through them (``kernel``), the response at points and sensors
(``response``), the exact modal propagator for piecewise-linear forces (``propagator``) and
the dense forced response used as a check (``forced``)."""
