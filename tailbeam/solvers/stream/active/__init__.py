"""The active set: the balls in contact and their neighbours, integrated by a compiled DOP853 with
every kink of the law located as an event.

Three layers, each a subpackage:

- ``compiled``: the numba parts (the stepping loop, one step, the event search, the pair
  physics).
- ``integrator``: their Python wrapper, ``set.ActiveSet``, with what it integrates
  (``model``, with the modes of ``modal_block``), the pairs' contact state
  (``contact_states``), the error control (``tolerances``) and the kernel's buffers
  (``kernel_io``).
- ``plate``: the plate side of the set's pairs: the modal plate's pairs (``pairs``: mode
  shapes from ``shapes``, residual compliance, contact tails from ``tails``), the plate
  force histories for the sensors (``forces``, thinned by ``thinning``) and putting a member
  at rest on the plate (``rest``).

The driver's view of the set, by ball number and pair key, is ``members``, with its parts:
the fresh rows carried across rebuilds (``carry``) and the friction of each pair key
(``friction_pairs``); ``islands`` splits the set into islands that
are integrated with their own steps (rigid plate, friction).
"""
