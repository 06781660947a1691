"""Figures: what they draw equals the tables, the axes are valid, nothing is cut off.

The reference values come from the data (impacts.csv written by results_io, closed-form sine
shapes, a sinusoid's RMS and Parseval), never from the plotting code.
"""

import csv
import io
import warnings

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.text import Text

from benchmarks.claim_map import QUICK
from tailbeam.io.results_io import write_impacts_csv
from tailbeam.paper import figures
from tailbeam.paper.scenarios import SCENARIOS, run_scenario
from tailbeam.signals.figures import build_sensor_figure, sensor_stats, welch_psd
from tailbeam.signals.sensor import SensorChain, SensorOutput, amplitude_spectrum


def render(fig):
    """Draw ``fig`` with Agg; returns its renderer."""
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def inside(fig, artist, renderer) -> bool:
    box, page = artist.get_window_extent(renderer), fig.bbox
    return (
        box.x0 >= page.x0 - 0.5
        and box.x1 <= page.x1 + 0.5
        and box.y0 >= page.y0 - 0.5
        and (box.y1 <= page.y1 + 0.5)
    )


def texts(fig) -> str:
    render(fig)
    return "\n".join(t.get_text() for t in fig.findobj(Text))


@pytest.fixture(scope="module")
def material():
    return run_scenario("material")


@pytest.fixture(scope="module")
def table(material, tmp_path_factory):
    """impacts.csv of the material scenario as written by the CLI, read back: ball -> rows."""
    path = write_impacts_csv(tmp_path_factory.mktemp("tab") / "impacts.csv", material.impacts)
    rows = {}
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            rows.setdefault(row["ball"], []).append(row)
    return rows


def test_claim_map_axes_positive_and_label_not_cut():
    dampings, penetrations, gaps = QUICK
    rng = np.random.default_rng(1)
    count = rng.integers(5, 20, size=(len(gaps), len(dampings), len(penetrations)))
    count[0, 3, 2] = 19
    fig = figures.build_claim_map_figure(
        gaps, dampings, penetrations, count, 19, defaults=(300.0, 1e-4, 0.005)
    )
    renderer = render(fig)
    panels = [ax for ax in fig.axes if ax.get_visible() and ax.get_xscale() == "log"]
    assert len(panels) == len(gaps)
    for ax in panels:
        x0, x1 = ax.get_xlim()
        y0, y1 = ax.get_ylim()
        # cell edges at geometric midpoints: the first lies a half step (in log) before 1e-5
        assert x0 == pytest.approx(penetrations[0] ** 1.5 / penetrations[1] ** 0.5)
        assert x1 == pytest.approx(penetrations[-1] ** 1.5 / penetrations[-2] ** 0.5)
        assert 0 < x0 < min(penetrations) and x1 > max(penetrations)
        assert 0 < y0 < min(dampings) and y1 > max(dampings)
        coords = ax.collections[0].get_coordinates()
        assert coords.min() > 0
    colorbar = panels[-1].collections[0].colorbar  # drawn for the last panel
    assert inside(fig, colorbar.ax.yaxis.label, renderer)
    assert all(inside(fig, leg, renderer) for leg in fig.legends)
    assert colorbar.get_ticks()[-1] == 19
    drawn = fig.get_tightbbox(renderer)
    assert fig.bbox_inches.x0 <= drawn.x0 and drawn.x1 <= fig.bbox_inches.x1
    assert fig.bbox_inches.y0 <= drawn.y0 and drawn.y1 <= fig.bbox_inches.y1


def test_log_edges_geometric():
    edges = figures.log_edges([1e-5, 4e-5, 1.6e-4])
    np.testing.assert_allclose(edges, [5e-6, 2e-5, 8e-5, 3.2e-4])  # half a step (x4) out


def test_collision_figure_draws_impact_table(material, table):
    fig = figures.collision_figure(material, SCENARIOS["material"])
    columns = [("peak_force", 1.0), ("next_apex_height", 1e3), ("restitution", 1.0)]
    for ax, (column, scale) in zip(fig.axes, columns, strict=True):
        lines = {line.get_label(): line for line in ax.lines}
        assert set(lines) == set(table)
        for ball, rows in table.items():
            want = [(int(r["index"]), float(r[column]) * scale) for r in rows if r[column] != ""]
            want = [(n, y) for n, y in want if np.isfinite(y)]
            np.testing.assert_array_equal(lines[ball].get_xdata(), [n for n, _ in want])
            np.testing.assert_allclose(lines[ball].get_ydata(), [y for _, y in want], rtol=1e-12)


def test_force_zoom_shows_both_first_peaks(material, table):
    t = figures.plot_grid(material, 20000.0)
    fig = figures.force_figure(material, SCENARIOS["material"], t, material.sample(t), 7)
    whole, zoom = fig.axes
    x0, x1 = zoom.get_xlim()
    curves = [line for line in zoom.lines if line.get_linestyle() == "-"]
    # the ball with the larger peak is drawn first, so the smaller pulse lies on top
    assert max(curves[0].get_ydata()) > max(curves[-1].get_ydata())
    for ball, rows in table.items():
        first = rows[0]
        assert x0 <= 1e3 * float(first["t_start"]) and 1e3 * float(first["t_end"]) <= x1
        curve = next(line for line in curves if line.get_label() == ball)
        assert max(curve.get_ydata()) == pytest.approx(float(first["peak_force"]), rel=1e-9)
        # every peak of the table is marked on the whole record
        marks = [m for m in whole.lines if m.get_linestyle() == "None"]
        marked = {round(float(y), 6) for m in marks for y in m.get_ydata()}
        assert {round(float(r["peak_force"]), 6) for r in rows} <= marked


def test_pulse_matches_table(material, table):
    pulses = figures.first_pulses(material)
    for ball, rows in table.items():
        tau, delta, force = pulses[ball]
        first = rows[0]
        duration = float(first["t_end"]) - float(first["t_start"])
        assert tau[-1] == pytest.approx(duration, rel=1e-12)
        assert force.max() == pytest.approx(float(first["peak_force"]), rel=1e-9)
        assert delta.max() == pytest.approx(float(first["max_penetration"]), rel=1e-4)


def test_scenario_figures_keep_names_and_add_new(material, tmp_path):
    paths = figures.scenario_figures(material, SCENARIOS["material"], tmp_path)
    names = sorted(p.name for p in paths)
    assert names == [
        "collisions_material.png",
        "fig05_material_position.png",
        "fig06_material_velocity.png",
        "fig07_material_force.png",
        "pulse_material.png",
    ]
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in paths)


def sine_output(amplitude=3.0, f0=1000.0, fs=51200.0, duration=0.2):
    t = np.arange(int(round(duration * fs))) / fs
    a = amplitude * np.sin(2 * np.pi * f0 * t)
    freq, amp = amplitude_spectrum(a, fs)
    chain = SensorChain(fs, fs / 2.56, 3 * fs / 2.56, 0.03, 2)
    return SensorOutput("s1", t, a, freq, amp, chain)


def test_sensor_stats_of_a_sinusoid():
    out = sine_output()
    stats = sensor_stats(out)
    assert stats.rms == pytest.approx(3.0 / np.sqrt(2.0), rel=1e-9)  # whole periods
    assert stats.peak == pytest.approx(3.0, rel=2e-3)  # 51.2 samples per period
    assert stats.df_spectrum == pytest.approx(51200.0 / len(out.t))
    f, psd = welch_psd(out, stats.welch_segment)
    assert np.trapezoid(psd, f) == pytest.approx(4.5, rel=1e-2)  # Parseval: A^2 / 2
    assert abs(f[np.argmax(psd)] - 1000.0) <= 51200.0 / stats.welch_segment


def test_sensor_figure_states_position_resolution_peak_rms():
    out = sine_output()
    stats = sensor_stats(out)
    fig = build_sensor_figure(out, position=(0.2, -0.1))
    words = texts(fig)
    assert "(x, y) = (0.2, -0.1) m" in words
    assert f"{stats.rms:.3g}" in words and f"{stats.peak:.3g}" in words
    assert f"Δf = fs/N = {51200.0 / len(out.t):.3g} Hz" in words
    assert f"Δf = {51200.0 / stats.welch_segment:.3g} Hz" in words
    assert f"Δf = {51200.0 / stats.spectrogram_segment:.3g} Hz" in words
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    assert buf.getvalue()[:4] == b"\x89PNG"


@pytest.mark.parametrize("band_hz", [2000.0, 30000.0])
def test_sensor_figure_marks_the_modal_band_below_the_bandwidth(band_hz):
    """A band below the plotted 20 kHz is a dotted line at its top on both spectra, the
    spectrogram's line at the same height, and a title line; a band above: nothing."""
    fig = build_sensor_figure(sine_output(), band_hz=band_hz)
    _time, spectrum, welch, spectrogram = fig.axes[:4]
    dotted = [
        [line for line in ax.get_lines() if line.get_linestyle() == ":"]
        for ax in (spectrum, welch, spectrogram)
    ]
    below = band_hz < 20000.0
    assert [len(lines) for lines in dotted] == [int(below)] * 3
    if below:
        assert all(line.get_xdata()[0] == band_hz / 1e3 for line in dotted[0] + dotted[1])
        assert dotted[2][0].get_ydata()[0] == band_hz / 1e3
    assert (f"modes to {band_hz:g} Hz (dotted line)" in texts(fig)) == below


def test_scenario_figures_have_nothing_cut_off(material):
    t = figures.plot_grid(material, 20000.0)
    states = material.sample(t)
    scenario = SCENARIOS["material"]
    built = [
        figures.force_figure(material, scenario, t, states, 7),
        figures.time_figure(material, scenario, t, states, "z", "z (m)", 5),
        figures.collision_figure(material, scenario),
        figures.pulse_figure(material, scenario),
        build_sensor_figure(sine_output(), position=(0.2, -0.1)),
    ]
    for fig in built:
        renderer = render(fig)
        drawn = fig.get_tightbbox(renderer)  # inches, every artist as drawn
        page = fig.bbox_inches
        assert drawn.x0 >= page.x0 and drawn.x1 <= page.x1, fig.texts
        assert drawn.y0 >= page.y0 and drawn.y1 <= page.y1, fig.texts


def test_sensor_figure_of_a_zero_record_says_so_without_a_warning(tmp_path):
    """A sensor that read nothing (no impact in the run): its spectra cannot be drawn on a log
    axis; the figure draws them flat, says so, and raises no warning."""
    out = sine_output()
    zero_a = np.zeros_like(out.t)
    freq, amp = amplitude_spectrum(zero_a, out.chain.sample_rate)
    zero = SensorOutput("s1", out.t, zero_a, freq, amp, out.chain)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = build_sensor_figure(zero)
        fig.savefig(tmp_path / "zero.png")
    _time, spectrum, welch, spectrogram = fig.axes[:4]
    for ax in (spectrum, welch, spectrogram):
        assert "zero throughout" in [t.get_text() for t in ax.texts]
    assert spectrum.get_yscale() == welch.get_yscale() == "linear"
