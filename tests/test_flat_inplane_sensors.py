"""Sensors on the flat plate read in any direction: a point of the top (bottom) face moves by
w along z and by -zeta grad w in the plane (zeta = +h/2 on top, -h/2 below; Kirchhoff's
kinematics). Truth: the simply supported plate's closed-form modes, differentiated by hand
(the reading takes central differences of the basis' deflection), and the derivative of its
Navier series for the static part."""

import numpy as np
import pytest

from tailbeam.errors import InputError
from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.bodies import Plate
from tailbeam.physics.materials import CARBON_STEEL
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.plate_loads.readings import Readings

A, B, H = 0.6, 0.4, 0.01
PLATE = Plate(CARBON_STEEL, A, B, H)
POINT = (0.1, 0.07)
SENSORS = [
    SensorSpec("top", POINT, axes="xyz"),  # (x, y) is the top face
    SensorSpec("bottom", (*POINT, -H), axes="xyz"),
    SensorSpec("tilted", (*POINT, -H), direction=(0.6, -0.48, 0.64)),
    SensorSpec("edge", (0.5 * A, 0.0), axes="x"),  # on the edge: one-sided differences
]


@pytest.fixture(scope="module")
def basis():
    return ssss_kirchhoff_basis(PLATE, 3000.0)


def _closed_form(m, n, xy):
    """(w, dw/dx, dw/dy) of the unit-modal-mass modes (m, n) at points xy (p, 2)."""
    amp = 2.0 / np.sqrt(PLATE.mass_per_area * A * B)
    ax, by = m * np.pi / A, n * np.pi / B
    x, y = xy[:, 0:1] + 0.5 * A, xy[:, 1:2] + 0.5 * B
    sx, cx, sy, cy = np.sin(ax * x), np.cos(ax * x), np.sin(by * y), np.cos(by * y)
    return amp * sx * sy, amp * ax * cx * sy, amp * by * sx * cy


def _expected(channel, field):
    """What a channel reads of a field given as (w, dw/dx, dw/dy) at its (x, y)."""
    w, wx, wy = field
    d = np.array(channel.direction if channel.direction is not None else (0.0, 0.0, 1.0))
    zeta = (channel.position[2] if len(channel.position) == 3 else 0.0) + 0.5 * H
    return d[2] * w - zeta * (d[0] * wx + d[1] * wy)


def _channels():
    return [c for s in SENSORS for c in s.channels()]


def test_modes_read_along_any_direction_on_either_face(basis):
    channels = _channels()
    shapes = Readings(basis, channels).shapes()
    m, n = basis.info["m"], basis.info["n"]
    for row, c in zip(shapes, channels, strict=True):
        field = _closed_form(m, n, np.array([c.position[:2]]))
        want = _expected(c, [f[0] for f in field])
        assert np.max(np.abs(row - want)) <= 1e-6 * np.max(np.abs(want)), c.name  # 2e-8 seen
    by = {c.name: row for row, c in zip(shapes, channels, strict=True)}
    # the faces move apart in-plane, not along z: bending's antisymmetry
    np.testing.assert_allclose(by["bottom_x"], -by["top_x"], rtol=1e-9)
    np.testing.assert_allclose(by["bottom_z"], by["top_z"], rtol=1e-12)
    assert np.max(np.abs(by["top_x"])) > 1e-3 * np.max(np.abs(by["top_z"]))


def _navier(load, point, terms=500):
    """(w, dw/dx, dw/dy) at ``point`` under 1 N at ``load``: the Navier series of the simply
    supported Kirchhoff plate, differentiated term by term."""
    k = np.arange(1, terms + 1)
    ax, by = k * np.pi / A, k * np.pi / B
    lx, ly = np.sin(ax * (load[0] + 0.5 * A)), np.sin(by * (load[1] + 0.5 * B))
    x, y = point[0] + 0.5 * A, point[1] + 0.5 * B
    inv = 1.0 / ((k[:, None] / A) ** 2 + (k[None, :] / B) ** 2) ** 2
    scale = 4.0 / (A * B * PLATE.bending_stiffness * np.pi**4)
    fx = (np.sin(ax * x) * lx, ax * np.cos(ax * x) * lx)
    fy = (np.sin(by * y) * ly, by * np.cos(by * y) * ly)
    return tuple(scale * (gx @ inv @ gy) for gx, gy in ((fx[0], fy[0]), (fx[1], fy[0]),
                                                       (fx[0], fy[1])))  # fmt: skip


def test_static_reading_is_the_derivative_of_the_navier_series(basis):
    channels = [c for c in _channels() if c.name in ("top_x", "top_z", "bottom_y", "tilted")]
    loads = np.array([[-0.12, 0.05], [0.2, -0.1]])
    static = Readings(basis, channels).static(loads)  # (loads, channels)
    for j, c in enumerate(channels):
        want = np.array([_expected(c, _navier(q, c.position[:2])) for q in loads])
        scale = np.max(np.abs(want))
        assert np.max(np.abs(static[:, j] - want)) <= 1e-6 * scale, c.name  # 3e-8 measured


def test_a_scene_on_the_flat_plate_takes_in_plane_directions():
    text = (
        'duration = 0.001\n[plate]\nmodel = "modal"\n[[balls]]\nname = "b"\n'
        'material = "sandstone"\nradius = 0.02\nposition = [0.0, 0.0, 0.05]\n'
        'velocity = [0.0, 0.0, -1.0]\n[[sensors]]\nname = "back"\n'
        'position = [0.1, 0.1, -0.01]\naxes = "xyz"\n'
    )
    scene = loads_scene(text)
    assert [c.name for c in scene.sensors[0].channels()] == ["back_x", "back_y", "back_z"]
    with pytest.raises(InputError, match=r"sensors\[1\]\.position"):
        loads_scene(text.replace("-0.01]", "-0.005]"))  # inside the plate, not on a face
