"""A thin-walled box beam as a solid (tailbeam.plate.solid) against beam theory.

Truths: Timoshenko beam theory solved exactly (the 4x4 transfer matrix of its ODEs, a
matrix exponential by eigen-decomposition, roots by brentq: no discretisation), with
Cowper's shear coefficient of a thin-walled box; Euler-Bernoulli as the same equations with
no shear or rotary inertia; Bredt's thin-walled torsion constant with Saint-Venant's
free-warping torsion. Each solid frequency must lie within the difference between the
theories: |solid/Timoshenko - 1| <= |Timoshenko/EB - 1| for bending; for torsion, within the
order t/d of Bredt's thin-wall approximation (d the smaller midline side).
"""

import numpy as np
import pytest
from scipy.optimize import brentq
from solid_meshes import box_beam_mesh

from tailbeam.physics.materials import CARBON_STEEL
from tailbeam.plate.solid import Support, assemble_structure, structure_modes

LENGTH, WIDTH, HEIGHT, WALL = 2.0, 0.15, 0.1, 0.01
E, NU, RHO = CARBON_STEEL.youngs_modulus, CARBON_STEEL.poisson_ratio, CARBON_STEEL.density
G = E / (2.0 * (1.0 + NU))
AREA = WIDTH * HEIGHT - (WIDTH - 2 * WALL) * (HEIGHT - 2 * WALL)
I_VERTICAL = (WIDTH * HEIGHT**3 - (WIDTH - 2 * WALL) * (HEIGHT - 2 * WALL) ** 3) / 12.0
I_LATERAL = (HEIGHT * WIDTH**3 - (HEIGHT - 2 * WALL) * (WIDTH - 2 * WALL) ** 3) / 12.0
F_SCAN = 600.0  # Hz: the beam-theory roots are searched below this
SPRING = 2.0e6  # N/m: the rigid bar's hinge-spring frequency near the first bending one


def cowper(flange, web):
    """Cowper's (1966) shear coefficient of a thin-walled box, equal walls, bending in the
    plane of the webs (``web`` deep, ``flange`` wide)."""
    m, n = flange / web, flange / web
    top = 10.0 * (1.0 + NU) * (1.0 + 3.0 * m) ** 2
    bottom = (12 + 72 * m + 150 * m**2 + 90 * m**3) + NU * (11 + 66 * m + 135 * m**2 + 90 * m**3)
    return top / (bottom + 10.0 * n**2 * ((3.0 + NU) * m + 3.0 * m**2))


def beam_frequencies(inertia, kappa, ends, count, *, spring=0.0, timoshenko=True):
    """The first ``count`` natural frequencies (Hz) of a uniform beam, from the transfer
    matrix of y = [w, psi, M, V]: w' = psi + V/(kappa G A), psi' = M/(E I),
    M' = -V - rho I w^2 psi, V' = -rho A w^2 w. ends: 'clamped-free' or 'pinned-spring'
    (spring N/m on w at x = L)."""
    shear = 1.0 / (kappa * G * AREA) if timoshenko else 0.0
    rotary = RHO * inertia if timoshenko else 0.0
    start = [2, 3] if ends == "clamped-free" else [1, 3]  # unknowns at x = 0

    def det(f):
        w2 = (2.0 * np.pi * f) ** 2
        a = np.array([[0, 1, 0, shear], [0, 0, 1 / (E * inertia), 0],
                      [0, -rotary * w2, 0, -1], [-RHO * AREA * w2, 0, 0, 0]])  # fmt: skip
        y = _expm(a * LENGTH)[:, start]
        end = y[[2, 3]] if ends == "clamped-free" else np.vstack([y[2], y[3] + spring * y[0]])
        return np.linalg.det(end)

    grid = np.linspace(1.0, F_SCAN, 300)  # steps of 2 Hz: well below these beams' spacing
    values = [det(f) for f in grid]
    roots = [brentq(det, a, b) for a, b, va, vb in
             zip(grid, grid[1:], values, values[1:], strict=False) if va * vb < 0]  # fmt: skip
    return np.array(roots[:count])


def _expm(a):
    """exp(a) of a diagonalisable 4x4 matrix (scipy's expm costs ~15 ms a call here)."""
    lam, vec = np.linalg.eig(a)
    return np.real(vec @ np.diag(np.exp(lam)) @ np.linalg.inv(vec))


def bredt_torsion_frequency():
    """First torsion frequency (Hz) of the cantilever: f = sqrt(G J / (rho I_p)) / (4 L),
    J = 4 A_m^2 t / s (Bredt), I_p the section's polar moment."""
    a_m = (WIDTH - WALL) * (HEIGHT - WALL)
    perimeter = 2.0 * ((WIDTH - WALL) + (HEIGHT - WALL))
    j = 4.0 * a_m**2 * WALL / perimeter
    return np.sqrt(G * j / (RHO * (I_VERTICAL + I_LATERAL))) / (4.0 * LENGTH)


@pytest.fixture(scope="module")
def beam_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("beam") / "box.msh"
    return box_beam_mesh(path, LENGTH, WIDTH, HEIGHT, WALL, cells_x=20)


def _classify(basis):
    """Per mode: 'vertical', 'lateral' or 'torsion', from its tip displacements read on the
    surface (z at both top corners, y at the top's centre line)."""
    tip = 0.5 * LENGTH
    pts = [[tip, -0.5 * WIDTH, 0.0], [tip, 0.5 * WIDTH, 0.0], [tip, 0.0, 0.0]]
    dirs = [[0, 0, 1], [0, 0, 1], [0, 1, 0]]
    z1, z2, y = basis.shape_at(pts, dirs)
    scores = np.vstack([np.abs(z1 + z2) / 2, np.abs(y), np.abs(z1 - z2) / 2])
    return np.array(["vertical", "lateral", "torsion"])[np.argmax(scores, axis=0)]


def test_cantilever_box_bending_and_torsion(beam_file):
    model = assemble_structure(beam_file, "top", [Support("clamped", group="root")])
    basis = structure_modes(model, count=6)
    kind = _classify(basis)
    f = basis.frequencies_hz
    checks = []
    for name, inertia, kappa, n in (("vertical", I_VERTICAL, cowper(WIDTH, HEIGHT), 2),
                                    ("lateral", I_LATERAL, cowper(HEIGHT, WIDTH), 1)):  # fmt: skip
        timo = beam_frequencies(inertia, kappa, "clamped-free", n)
        eb = beam_frequencies(inertia, kappa, "clamped-free", n, timoshenko=False)
        checks += [(name, s, t, e) for s, t, e in zip(f[kind == name][:n], timo, eb, strict=True)]
    for name, solid, timo, eb in checks:
        assert abs(solid / timo - 1) <= abs(timo / eb - 1), (name, solid, timo, eb)
    torsion = f[kind == "torsion"][0]
    bredt = bredt_torsion_frequency()
    thin_wall_order = WALL / (min(WIDTH, HEIGHT) - WALL)
    assert abs(torsion / bredt - 1) <= thin_wall_order, (torsion, bredt)


def test_hinge_and_jack_spring_against_beam_on_spring(beam_file):
    supports = [Support("pinned", group="root"),
                Support("spring", group="tip", stiffness=SPRING, direction=(0, 0, 1))]  # fmt: skip
    basis = structure_modes(assemble_structure(beam_file, "top", supports), count=4)
    vertical = basis.frequencies_hz[_classify(basis) == "vertical"][:2]
    kappa = cowper(WIDTH, HEIGHT)
    timo = beam_frequencies(I_VERTICAL, kappa, "pinned-spring", 2, spring=SPRING)
    eb = beam_frequencies(I_VERTICAL, kappa, "pinned-spring", 2, spring=SPRING, timoshenko=False)
    # the rigid bar on the spring (hinge inertia rho A L^3 / 3) bounds the first mode above
    rigid = np.sqrt(3.0 * SPRING / (RHO * AREA * LENGTH)) / (2.0 * np.pi)
    assert vertical[0] < rigid
    for solid, t, e in zip(vertical, timo, eb, strict=True):
        assert abs(solid / t - 1) <= abs(t / e - 1), (solid, t, e)
