"""The solvers of ``tailbeam.simulate``, each following one protocol (``base``):

- ``single_ball``: each ball alone with the plate, exact: ``rigid`` (the rigid plate, the
  paper's model, and its scipy reference) and ``coupled`` (the two-way modal plate, one-way
  coupling, the full finite-element reference);
- ``stream``: many balls, ball-ball contact, inclined plates: the fast solver (``solver``,
  ``driver``, ``active``) and its slow all-pairs ``reference``;
- shared parts, owned by no solver: ``modal_setup`` (the band, basis, damping and tail of the
  modal plate, set up from the scene), ``numerics`` (DOP853, Chebyshev root finding,
  closed-form flight), ``plate_loads`` (the plate's exact response to recorded loads).
"""
