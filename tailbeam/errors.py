"""Errors a user can act on: each names the offending field and the rule it broke."""

import math
from numbers import Real


class InputError(ValueError):
    """Bad input. ``field`` names what was wrong (e.g. ``balls[1].radius``), ``rule`` what it
    must satisfy. ``str(err)`` is one readable line, suitable for a CLI message."""

    def __init__(self, field: str, rule: str):
        self.field = field
        self.rule = rule
        super().__init__(f"{field}: {rule}")

    def renamed(self, names: dict) -> "InputError":
        """The same error under the caller's name of the field, e.g. {"fmax_hz": "--fmax"}."""
        return InputError(names.get(self.field, self.field), self.rule)


class WorkLimitError(RuntimeError):
    """A bounded computation hit its limit (steps, contacts, events). The message says which
    limit and how to raise it or change the scene."""


def require_real(field: str, value) -> float:
    """Return ``value`` as a finite float, or raise InputError naming ``field``."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise InputError(field, f"must be a number, got {type(value).__name__} {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise InputError(field, f"must be finite, got {value!r}")
    return value


def require_positive(field: str, value) -> float:
    value = require_real(field, value)
    if value <= 0.0:
        raise InputError(field, f"must be > 0, got {value!r}")
    return value


def require_nonnegative(field: str, value) -> float:
    value = require_real(field, value)
    if value < 0.0:
        raise InputError(field, f"must be >= 0, got {value!r}")
    return value


def require_vector(field: str, value, length: int) -> tuple[float, ...]:
    """A list/tuple/array of ``length`` finite numbers."""
    try:
        items = list(value)
    except TypeError:
        raise InputError(field, f"must be a list of {length} numbers, got {value!r}") from None
    if isinstance(value, (str, bytes)) or len(items) != length:
        raise InputError(field, f"must be a list of {length} numbers, got {value!r}")
    return tuple(require_real(f"{field}[{i}]", v) for i, v in enumerate(items))
