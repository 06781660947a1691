"""The modal plate every solver runs on, set up from the scene in one place: the band
(``band``), the basis and its damping, the tail of the modes above the band (``ritz_prepass``
for single balls, the contact tails for streams) and what was chosen (``setup``)."""
