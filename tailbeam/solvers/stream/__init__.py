"""The stream solver: many balls on an inclined plate, rigid or modal (docs/streams.md).

``stream`` is the fast solver's driver (``solve_stream``); ``engine`` picks it; the slow
independent reference is ``stream_reference`` (with ``reference_plate`` on the modal plate).
"""
