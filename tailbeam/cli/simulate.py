"""`tailbeam simulate SCENE.toml [--out DIR] [--overwrite] [--solver NAME]`: simulate a scene,
write results.

Without --out the results go to out/<the scene file's stem> (``default_out``): a folder an
earlier run of the same scene file wrote is replaced, a folder of another scene file (or of
another command) is refused unless --overwrite. An explicit --out replaces any earlier
tailbeam output, as it always has.

--solver chooses the solver (``tailbeam.simulation.CHOICES``; default auto), so one scene can
be run through two solvers and their impacts.csv compared.

Writes impacts.csv (every column of ``Result.impacts_table``), particles.csv, impacts.json
and manifest.json into DIR, for every scene (tailbeam.results.result); timeseries.csv (uniform grid)
when the solver keeps the balls' states (single balls, rigid or modal plate: not the stream
solver); on a modal plate with sensors also sensors.csv, sensor_spectra.csv and one
sensor_<name>.png (time and spectrum) per sensor. --export uff58 also writes the sensor records
as DIR/uff/<scene>.uff and DIR/uff/labels.csv (tailbeam.cli.export); --vtk (--vtk-rate HZ) a
ParaView time series of the particles and the plate in DIR/vtk/ (tailbeam.io.paraview).

Bad input is reported as one line on stderr with exit code 2, and nothing is written: the
scene and --out are fully validated before the solver runs, and the results replace DIR
whole (tailbeam.io.output), so DIR never mixes two runs.
"""

import json
from pathlib import Path

from tailbeam.cachedir import announce_first_compile
from tailbeam.cli import export
from tailbeam.errors import InputError
from tailbeam.io.output import MANIFEST, atomic_output_dir, check_output_dir, describe
from tailbeam.progress import task

# Heavy modules (scipy.signal, matplotlib) are imported where they are used, so that
# `tailbeam --help` and bad-input errors answer in a fraction of a second.


def add_arguments(parser):
    parser.add_argument("scene", help="scene file (TOML); keys in docs/scene-files.md")
    parser.add_argument(
        "--out",
        default=None,
        metavar="DIR",
        help="output folder (default: out/<SCENE's file name without .toml>)",
    )
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="without --out: replace out/<name> even when another scene file's run wrote it",
    )
    parser.add_argument(
        "--solver",
        default="auto",
        metavar="NAME",
        help="auto (the exact single-ball solvers where they can run, else the stream "
        "solver), single-ball, stream or stream-reference (the slow independent reference, "
        "rigid plate, <= 20 bodies): run one scene through two to compare them",
    )
    export.add_export_option(parser, "the sensor records (DIR/uff/)")
    parser.add_argument(
        "--vtk",
        action="store_true",
        help="also write a ParaView time series of the particles and the plate: "
        "DIR/vtk/particles.pvd and DIR/vtk/structure.pvd (docs/paraview.md)",
    )
    parser.add_argument(
        "--vtk-rate",
        type=float,
        default=None,
        metavar="HZ",
        help="frames per simulated second of the --vtk series; giving it implies --vtk "
        "(default: 200)",
    )


def write_results(out_dir, scene, result) -> list:
    """Write every output file of ``result`` into ``out_dir`` (an existing directory)."""
    from tailbeam.io.results_io import write_result_tables, write_timeseries_csv
    from tailbeam.io.scene_dump import scene_to_dict

    files = write_result_tables(out_dir, result, scene_to_dict(scene))
    if result.keeps_states:
        files.append(write_timeseries_csv(out_dir / "timeseries.csv", result, scene.sample_rate))
    if scene.sensors and result.plate_model == "modal":
        n = len(scene.sensors)
        steps = sum(len(s.channels()) for s in scene.sensors) + 1  # the replay, then a figure each
        with task(f"sensor replay and outputs, {n} sensors", total=steps, unit="steps") as bar:
            outputs = result.sensor_outputs  # the exact plate response through each chain
            bar.update(1)
            files += _write_sensors(out_dir, scene, result, outputs, bar)
    return files


def _write_sensors(out_dir, scene, result, outputs, bar) -> list:
    from tailbeam.io.results_io import write_sensor_spectra_csv, write_sensors_csv
    from tailbeam.signals.figures import sensor_figure

    meta = {c.name: _sensor_meta(c, outputs[c.name]) for s in scene.sensors for c in s.channels()}
    files = [
        describe(
            write_sensors_csv(out_dir / "sensors.csv", result.sensor_signals),
            units={"t": "s", **{n: "m/s^2" for n in outputs}},
            sensors=meta,
        ),
        describe(
            write_sensor_spectra_csv(out_dir / "sensor_spectra.csv", outputs),
            units={"freq": "Hz", "amp": "m/s^2 (one-sided peak amplitude)"},
            sensors=meta,
        ),
    ]
    band_hz = result.info.get("band", {}).get("fmax_hz")
    for name, out in outputs.items():
        position = tuple(meta[name]["position_m"])
        direction = meta[name].get("direction")
        files.append(sensor_figure(out, out_dir / f"sensor_{name}.png", position=position,
                                   direction=direction, band_hz=band_hz))  # fmt: skip
        bar.update(1)
    return files


def _sensor_meta(channel, output) -> dict:
    """The manifest's entry of one sensor signal: position (m), direction (unit, plate frame;
    only for a sensor given a direction or axes), sample rate and bandwidth (Hz)."""
    meta = {"position_m": list(channel.position)}
    if channel.direction is not None:
        meta["direction"] = list(channel.direction)
    meta["sample_rate_hz"] = output.chain.sample_rate
    meta["bandwidth_hz"] = output.chain.bandwidth_hz
    return meta


def vtk_frames(args, scene, solver):
    """The frame times of --vtk (empty without it), refused before the work (InputError
    naming --vtk or --vtk-rate) for a solver that keeps no states or an absurd rate."""
    from tailbeam.io import paraview
    from tailbeam.progress import note

    if not (args.vtk or args.vtk_rate is not None):
        return ()
    if not solver.frames:
        raise InputError(
            "--vtk", f"the {solver.name!r} solver keeps no states at frame times; use "
            "--solver stream or auto"
        )  # fmt: skip
    rate = paraview.DEFAULT_RATE_HZ if args.vtk_rate is None else args.vtk_rate
    times = paraview.check_rate(rate, scene.duration, len(scene.particles), "--vtk-rate")
    note(f"--vtk: {len(times)} frames at {rate:g} Hz, world frame (z up), into DIR/vtk")
    return times


def write_vtk(out_dir, scene, result) -> list:
    """DIR/vtk/: the ParaView series of ``result.frames`` (tailbeam.io.paraview); its size
    said on stderr."""
    from tailbeam.io import paraview
    from tailbeam.progress import note

    pvds = paraview.write_series(Path(out_dir) / "vtk", scene, result)
    codes = paraview.material_codes(result.particles)
    size = sum(f.stat().st_size for f in (Path(out_dir) / "vtk").iterdir())
    meta = {"frame": "world: the plate frame turned by the inclination about y, z up",
            "inclination_deg": scene.inclination, "frames": len(result.frames.times),
            "bytes": size}  # fmt: skip
    describe(pvds[0], units={"radius": "m", "velocity": "m/s", "position": "m"},
             material_codes=codes, label_codes=paraview.LABEL_CODES, **meta)  # fmt: skip
    describe(pvds[1], units={"displacement": "m", "deflection": "m", "position": "m"}, **meta)
    note(f"--vtk: {len(result.frames.times)} frames, {size / 1e6:.3g} MB in DIR/vtk")
    return pvds


def default_out(scene_file, overwrite: bool = False) -> Path:
    """out/<stem of ``scene_file``>, refused (InputError naming --out) when it holds the
    outputs of another scene file or command, unless ``overwrite``."""
    out = Path("out") / Path(scene_file).stem
    writer = _written_by(out)
    mine = str(Path(scene_file).resolve())
    if writer is None or writer == mine or overwrite:
        return out
    raise InputError(
        "--out",
        f"the default folder {str(out)!r} holds the outputs of {writer}, not of {scene_file}; "
        "give --out DIR, or --overwrite to replace it",
    )


def _written_by(out: Path) -> str | None:
    """The scene file (absolute path) whose run wrote ``out``, a description of another
    command's run, or None when ``out`` holds no manifest (check_output_dir judges it)."""
    try:
        manifest = json.loads((out / MANIFEST).read_text())
    except (OSError, ValueError):
        return None
    meta = manifest.get("files", {}).get("impacts.json", {})
    if "scene_file" in meta:
        return meta["scene_file"]
    command = str(manifest.get("command", ""))
    if command.startswith("tailbeam simulate "):  # written before the scene file was recorded
        return str(Path(command.removeprefix("tailbeam simulate ")).resolve())
    return f"{command or 'another command'!r}"


def run(args) -> int:
    from tailbeam.io.scene_file import load_scene
    from tailbeam.simulation import choose_solver, simulate

    if args.out is None:
        args.out = str(default_out(args.scene, args.overwrite))
    check_output_dir(args.out)
    scene = load_scene(args.scene)
    solver = choose_solver(scene, args.solver, "--solver")
    if export.chosen(args):
        export.check_run_export(scene)
    frames = vtk_frames(args, scene, solver)
    if solver.name == "stream":
        announce_first_compile("stream")
    elif solver.name == "single-ball":
        announce_first_compile("rigid" if scene.plate_model == "rigid" else "coupled")
    result = simulate(scene, solver=solver.name, frames=frames)
    with atomic_output_dir(args.out, command=f"tailbeam simulate {args.scene}") as tmp:
        files = write_results(tmp, scene, result)
        if export.chosen(args):
            files += export.write_run_uff(tmp, args.scene, scene, result)
        if len(frames):
            files += write_vtk(tmp, scene, result)
        describe(tmp / "impacts.json", scene_file=str(Path(args.scene).resolve()))
    n = len(result.impacts)
    names = ", ".join(f.name for f in files)
    print(f"{args.scene}: {n} impacts; wrote {names} to {args.out}")
    return 0
