"""The residual compliance of a basis' truncated modes at contact points, cached per basis.

The static compliance of the full plate model at a point minus the kept modes' part
(``ModalBasis.residual_compliance``): the spring in series with a contact that holds the
truncated modes quasi-statically. The static solve is slow, so values are kept per basis and
point for the life of the basis.
"""

import weakref

from tailbeam.plate.basis import ModalBasis

_COMPLIANCE_CACHE: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


class Compliance:
    """Residual compliance at contact points, cached per basis (the static solve is slow).

    radius: the load model's disc radius (tailbeam.physics.contact_patch.load_radius, already on its
    5 % logarithmic grid; 0 for a point load)."""

    def __init__(self, basis: ModalBasis, enabled: bool):
        self.basis = basis
        self.enabled = enabled
        self.cache = _COMPLIANCE_CACHE.setdefault(basis, {})

    def __call__(self, x, y, radius):
        if not self.enabled:
            return 0.0
        key = (round(x, 9), round(y, 9), radius)
        if key not in self.cache:
            self.cache[key] = float(self.basis.residual_compliance([[x, y]], radius)[0])
        return self.cache[key]
