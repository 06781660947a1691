"""The active set: the balls in contact and their neighbours, integrated by a compiled DOP853
with every kink of the law located as an event (``kernel``, ``step``, ``events``, ``fresh``,
``pairs``), its Python wrapper (``set``, ``modal_block``) and the driver's view of it by ball
and pair key (``members``, ``tails``)."""
