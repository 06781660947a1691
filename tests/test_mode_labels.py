"""(m, n) labels of mode shapes (tailbeam.plate.mode_labels) against closed-form shapes and
the closed-form SSSS frequency order, and modes.png."""

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.text import Text

from tailbeam.physics.bodies import Plate
from tailbeam.plate import compute_modes
from tailbeam.plate.closed_forms import ssss_modes
from tailbeam.plate.export import build_modes_figure, write_png
from tailbeam.plate.mode_labels import label_modes, nodal_label, projection_label

A, B = 0.6, 0.4
X = np.linspace(-A / 2, A / 2, 121)
Y = np.linspace(-B / 2, B / 2, 101)
XX, YY = np.meshgrid(X, Y)


def sine(m, n):
    return np.sin(m * np.pi * (XX + A / 2) / A) * np.sin(n * np.pi * (YY + B / 2) / B)


@pytest.mark.parametrize("m, n", [(1, 1), (2, 1), (1, 3), (4, 2)])
def test_projection_finds_the_sine(m, n):
    label = projection_label(-2.5 * sine(m, n), X, Y, A, B)
    assert (label.m, label.n) == (m, n)
    assert label.share == pytest.approx(1.0, abs=1e-6) and label.second is None


def test_projection_names_a_mixture_with_its_shares():
    label = projection_label(0.6 * sine(1, 2) + 0.8 * sine(2, 1), X, Y, A, B)
    assert (label.m, label.n) == (2, 1) and label.share == pytest.approx(0.64, abs=1e-6)
    m2, n2, share2 = label.second
    assert (m2, n2) == (1, 2) and share2 == pytest.approx(0.36, abs=1e-6)
    assert label.text() == "(2, 1) 64% + (1, 2) 36%"


def test_nodal_count_of_a_free_edge_like_shape():
    # cos over a full period along x crosses zero twice (3 half-waves); one crossing along y
    z = np.cos(2 * np.pi * (XX + A / 2) / A) * (YY + 0.05)
    label = nodal_label(z)
    assert (label.m, label.n) == (3, 2) and label.text() == "nodal (3, 2)"


def test_fe_ssss_labels_follow_the_closed_form_order():
    plate = Plate(size_x=A, size_y=B)  # not square: no degenerate pairs
    basis = compute_modes(plate, "SSSS", theory="kirchhoff", count=8, divisions=10, use_cache=False)
    phi = basis.deflection(np.column_stack([XX.ravel(), YY.ravel()]))
    shapes = [phi[:, i].reshape(XX.shape) for i in range(basis.n_modes)]
    labels = label_modes("SSSS", shapes, X, Y, A, B)
    ref = ssss_modes(plate, "kirchhoff", count=basis.n_modes)
    assert [(lab.m, lab.n) for lab in labels] == list(zip(ref.m, ref.n, strict=True))
    assert min(lab.share for lab in labels) > 0.99
    # the nodal count agrees with the projection where both apply
    assert [(nodal_label(z).m, nodal_label(z).n) for z in shapes] == [
        (lab.m, lab.n) for lab in labels
    ]


def test_cantilever_first_bending_then_torsion(tmp_path):
    # CFFF: the first mode bends along x (no nodal line), the second twists about the x axis
    # (one nodal line along y = 0): Leissa's cantilever plate, modes 1 and 2
    basis = compute_modes(
        Plate(), "CFFF", theory="kirchhoff", count=2, divisions=8, use_cache=False
    )
    x = y = np.linspace(-0.3, 0.3, 61)
    xx, yy = np.meshgrid(x, y)
    phi = basis.deflection(np.column_stack([xx.ravel(), yy.ravel()]))
    labels = label_modes("CFFF", [phi[:, i].reshape(xx.shape) for i in range(2)], x, y, 0.6, 0.6)
    assert [(lab.m, lab.n) for lab in labels] == [(1, 1), (1, 2)]
    path = write_png(tmp_path / "modes.png", basis)
    assert path.read_bytes()[:4] == b"\x89PNG"
    fig = build_modes_figure(basis)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    drawn, page = fig.get_tightbbox(canvas.get_renderer()), fig.bbox_inches
    assert page.x0 <= drawn.x0 and drawn.x1 <= page.x1 and page.y0 <= drawn.y0
    assert drawn.y1 <= page.y1
    words = "\n".join(t.get_text() for t in fig.findobj(Text))
    assert "left clamped, bottom free, right free, top free" in words
    assert "nodal (1, 2)" in words
