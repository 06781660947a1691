"""The Python side of the compiled active-set integrator: ``set.ActiveSet`` (one call of the
kernel over a horizon, its events and restarts), what it integrates (``model``, the modal
plate's block in ``modal_block``), the state of each watched pair (``contact_states``), its
error control (``tolerances``) and what the kernel writes besides the state (``kernel_io``)."""
