"""The impact face of a structure, where the particles land: finding the named flat face
(``plane``), reading the modes and the z-displacement at points of it (``readings``), and its
static compliance under any contact disc from one matrix (``compliance``)."""
