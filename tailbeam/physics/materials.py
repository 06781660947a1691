"""Elastic materials: Table 1 of the paper, user-defined ones, and the effective modulus."""

from dataclasses import dataclass

from tailbeam.errors import InputError, require_positive, require_real


@dataclass(frozen=True)
class Material:
    """An isotropic linear-elastic material.

    density in kg/m^3, youngs_modulus in Pa, poisson_ratio dimensionless in (-1, 0.5).
    """

    name: str
    density: float
    youngs_modulus: float
    poisson_ratio: float

    def __post_init__(self):
        field = f"materials.{self.name}"
        object.__setattr__(self, "density", require_positive(f"{field}.density", self.density))
        object.__setattr__(
            self, "youngs_modulus", require_positive(f"{field}.youngs_modulus", self.youngs_modulus)
        )
        nu = require_real(f"{field}.poisson_ratio", self.poisson_ratio)
        if not -1.0 < nu < 0.5:
            raise InputError(f"{field}.poisson_ratio", f"must lie in (-1, 0.5), got {nu!r}")
        object.__setattr__(self, "poisson_ratio", nu)

    @property
    def plane_modulus(self) -> float:
        """E / (1 - nu^2) in Pa: the material's share of the Hertz effective modulus."""
        return self.youngs_modulus / (1.0 - self.poisson_ratio**2)


# Table 1 of the paper.
COAL = Material("coal", density=1380.0, youngs_modulus=5.3e9, poisson_ratio=0.32)
SANDSTONE = Material("sandstone", density=2487.0, youngs_modulus=1.35e10, poisson_ratio=0.123)
CARBON_STEEL = Material("carbon_steel", density=7850.0, youngs_modulus=2.06e11, poisson_ratio=0.28)

BUILTIN_MATERIALS = {m.name: m for m in (COAL, SANDSTONE, CARBON_STEEL)}


def get_material(name: str, extra: dict | None = None, *, field: str = "material") -> Material:
    """Look up ``name`` among ``extra`` (user-defined, takes precedence) and the built-ins."""
    table = {**BUILTIN_MATERIALS, **(extra or {})}
    if not isinstance(name, str) or name not in table:
        known = ", ".join(sorted(table))
        raise InputError(field, f"unknown material {name!r}; known materials: {known}")
    return table[name]


def effective_modulus(a: Material, b: Material | None = None) -> float:
    """Hertz effective modulus E* in Pa, eq. 6: 1/E* = (1-nu1^2)/E1 + (1-nu2^2)/E2.

    ``b = None`` is a rigid counterpart (infinite modulus).
    """
    compliance = 1.0 / a.plane_modulus
    if b is not None:
        compliance += 1.0 / b.plane_modulus
    return 1.0 / compliance
