"""Edge conditions of the rectangular plate: the four-letter boundary code and the degrees of
freedom each condition fixes in each plate theory.

Boundary code: four letters, one per edge, in the order
    left (x = -a/2), bottom (y = -b/2), right (x = +a/2), top (y = +b/2);
    C = clamped, S = simply supported, F = free.
E.g. "SSSS" all simply supported; "CFFF" a cantilever clamped along x = -a/2.

Kirchhoff (Argyris element; nodal DOFs u, u_x, u_y, u_xx, u_xy, u_yy, edge DOF u_n):
    along an edge, w = 0 also zeroes every tangential derivative of w, and a clamp (w_n = 0)
    also zeroes the tangential derivative of w_n. On the plate's axis-parallel edges:
    S on x = const: u, u_y, u_yy          (u_x, the normal slope, stays free)
    C on x = const: u, u_y, u_yy, u_x, u_xy and the edge-midpoint normal slope u_n
    (swap x and y for y = const edges). Fixing only u would leave u_y, u_yy free and let the
    edge deflect between nodes: visibly wrong frequencies.
Reissner-Mindlin (w, rotations beta = (beta_x, beta_y), the slopes the normals follow):
    S ("hard" support, as in the closed form): w = 0 and the tangential rotation = 0
    C: w = 0, beta_x = beta_y = 0; F: nothing fixed.
"""

from tailbeam.errors import InputError

EDGES = ("left", "bottom", "right", "top")
CONDITIONS = {"C": "clamped", "S": "simply supported", "F": "free"}
_NORMAL_AXIS = {"left": "x", "right": "x", "bottom": "y", "top": "y"}


def parse_boundary(code) -> str:
    """Normalise and validate a boundary code; InputError('boundary', ...) when invalid."""
    if not isinstance(code, str):
        raise InputError("boundary", f"must be a string of four letters C/S/F, got {code!r}")
    norm = code.strip().upper()
    if len(norm) != 4 or any(ch not in CONDITIONS for ch in norm):
        raise InputError(
            "boundary",
            f"must be four letters from C (clamped), S (simply supported), F (free) for the "
            f"edges left, bottom, right, top (e.g. 'SSSS', 'CFFF'); got {code!r}",
        )
    return norm


def rigid_body_mode_count(code: str) -> int:
    """Zero-frequency modes the edge conditions allow: 3 for a free plate (heave, two tilts),
    1 when a single edge is simply supported and the rest free (rotation about it), else 0."""
    if "C" in code:
        return 0
    supported = code.count("S")
    return {0: 3, 1: 1}.get(supported, 0)


def kirchhoff_fixed_names(edge: str, condition: str) -> list[str]:
    """Argyris DOF names fixed on ``edge`` for condition C/S/F (see module docstring)."""
    normal = _NORMAL_AXIS[edge]
    tangent = "y" if normal == "x" else "x"
    if condition == "F":
        return []
    names = ["u", f"u_{tangent}", f"u_{tangent}{tangent}"]
    if condition == "C":
        names += [f"u_{normal}", "u_xy", "u_n"]
    return names


def mindlin_fixed_fields(edge: str, condition: str) -> list[str]:
    """Fields fixed on ``edge``: a subset of 'w', 'beta_x', 'beta_y'."""
    if condition == "F":
        return []
    if condition == "C":
        return ["w", "beta_x", "beta_y"]
    tangential = "beta_y" if _NORMAL_AXIS[edge] == "x" else "beta_x"
    return ["w", tangential]


def describe(code: str) -> str:
    """'left clamped, bottom free, ...' for messages and reports."""
    return ", ".join(f"{edge} {CONDITIONS[ch]}" for edge, ch in zip(EDGES, code, strict=True))
