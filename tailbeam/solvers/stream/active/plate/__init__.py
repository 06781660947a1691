"""The plate side of an active set's pairs: the modal plate's pairs (``pairs``: mode shapes under
the balls from ``shapes``, the residual compliance, the contact tails from ``tails``), the
plate force histories kept for the sensors (``forces``, thinned by ``thinning``), and putting a
ball of the set at rest on the plate (``rest``)."""
