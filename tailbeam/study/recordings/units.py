"""Acceleration units a recording may be in, and their factors to m/s^2."""

from tailbeam.errors import InputError

STANDARD_GRAVITY = 9.80665  # m/s^2 per g (ISO 80000-3)

# spellings accepted (case kept for "g" and "G"; spaces dropped) -> factor to m/s^2
FACTORS = {
    "m/s^2": 1.0,
    "m/s2": 1.0,
    "m/s**2": 1.0,
    "m/s²": 1.0,
    "m s^-2": 1.0,
    "ms^-2": 1.0,
    "ms-2": 1.0,
    "g": STANDARD_GRAVITY,
    "G": STANDARD_GRAVITY,
    "gn": STANDARD_GRAVITY,
    "g_n": STANDARD_GRAVITY,
    "mm/s^2": 1e-3,
    "mm/s2": 1e-3,
    "mm/s²": 1e-3,
    "mg": 1e-3 * STANDARD_GRAVITY,
}
NAMES = ("m/s^2", "g", "mm/s^2", "mg")  # the canonical names, for messages


def canonical(unit: str | None) -> str | None:
    """The unit as a key of FACTORS (spaces dropped), or None if it is not one."""
    if unit is None:
        return None
    key = str(unit).strip().replace(" ", "")
    if key in FACTORS:
        return key
    low = key.lower()
    return low if low in FACTORS and low not in ("g", "mg") else None


def factor(unit: str, field: str) -> float:
    """Factor from ``unit`` to m/s^2, or InputError naming ``field``."""
    key = canonical(unit)
    if key is None:
        raise InputError(field, f"unknown unit {unit!r}; use one of {', '.join(NAMES)}")
    return FACTORS[key]


def same_unit(a: str, b: str) -> bool:
    """True when two spellings name the same unit."""
    ka, kb = canonical(a), canonical(b)
    return ka is not None and kb is not None and FACTORS[ka] == FACTORS[kb]
