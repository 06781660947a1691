"""The active set: the balls in contact and their neighbours, integrated by a compiled DOP853 with
every kink of the law located as an event (``compiled``: the numba parts), its Python wrapper
(``set``) with its parts: what is integrated (``model``, with the modes of ``modal_block``),
the pairs' contact state (``contact_states``), the error control (``tolerances``) and the
kernel's buffers (``kernel_io``); and the driver's view of it by ball and pair key
(``members``) with its parts: the fresh rows carried across rebuilds (``carry``), the plate
force histories (``forces``), putting a member at rest (``rest``) and the modal plate's pairs
(``plate_pairs``: mode shapes (``shapes``), residual compliance and contact tails (``tails``))."""
