"""`tailbeam simulate SCENE.toml [--out DIR]`: simulate a scene file and write its results.

Writes impacts.csv, impacts.json and timeseries.csv into DIR; for a modal plate also
sensors.csv, sensor_spectra.csv and one sensor_<name>.png (time and spectrum) per sensor.
Bad input is reported as one line on stderr with exit code 2, and nothing is written: the
scene is fully validated before the solver runs, and results go through atomic_output_dir.
"""

from tailbeam.figures import sensor_figure
from tailbeam.output import atomic_output_dir
from tailbeam.results_io import (
    result_summary,
    write_impacts_csv,
    write_json,
    write_sensor_spectra_csv,
    write_sensors_csv,
    write_timeseries_csv,
)
from tailbeam.scene_file import load_scene, scene_to_dict


def add_arguments(parser):
    parser.add_argument("scene", help="scene file (TOML); keys in README, 'Scene files'")
    parser.add_argument("--out", default="out/simulate", help="output directory")


def solve(scene):
    """Run the scene's solver: rigid plate -> simulate_rigid, modal plate -> the coupled model."""
    if scene.plate_model == "rigid":
        from tailbeam.rigid import simulate_rigid

        return simulate_rigid(scene.balls, scene.plate, scene.laws(), scene.duration)
    from tailbeam.coupled import simulate_scene_modal

    # The modal path chooses its band from the scene (contact durations, sensor bandwidths),
    # the theory from the band, and records both choices in result.info.
    return simulate_scene_modal(scene)


def write_results(out_dir, scene, result) -> list:
    """Write every output file of ``result`` into ``out_dir`` (an existing directory)."""
    files = [
        write_impacts_csv(out_dir / "impacts.csv", result.impacts),
        write_json(out_dir / "impacts.json", result_summary(result, scene_to_dict(scene))),
        write_timeseries_csv(out_dir / "timeseries.csv", result, scene.sample_rate),
    ]
    outputs = getattr(result, "sensor_outputs", None)
    if outputs:
        files.append(write_sensors_csv(out_dir / "sensors.csv", result.sensor_signals))
        files.append(write_sensor_spectra_csv(out_dir / "sensor_spectra.csv", outputs))
        files += [
            sensor_figure(out, out_dir / f"sensor_{name}.png") for name, out in outputs.items()
        ]
    return files


def run(args) -> int:
    scene = load_scene(args.scene)
    result = solve(scene)
    with atomic_output_dir(args.out) as tmp:
        files = write_results(tmp, scene, result)
    n = len(result.impacts)
    names = ", ".join(f.name for f in files)
    print(f"{args.scene}: {n} impacts; wrote {names} to {args.out}")
    return 0
