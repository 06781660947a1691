"""One case of a sweep, as it runs on a Dask worker: scene TOML in, plain arrays out.

The functions here are what Dask ships to the workers; they take and return only plain data
(strings, dicts, numpy arrays), so results travel cheaply and nothing depends on the client.
A case that fails (bad scene, work limit, solver error, anything) returns its status and a
one-line error instead of raising, so one bad case never stops a sweep.
"""

import json
import math
import time
import traceback

import numpy as np

from tailbeam.progress import quiet


def basis_signature(scene) -> str:
    """A key shared by the cases that use the same modal basis (plate, boundary, theory, mesh,
    band; and a stream's tail basis): a sweep warms the cache once per key before its cases
    run; "" on the rigid plate (no basis)."""
    if scene.plate_model != "modal":
        return ""
    m = scene.modal
    p = scene.plate
    mat = p.material
    band = _band(scene)
    structure = [m.mesh, m.impact_face, repr(m.supports)] if m.mesh is not None else []
    return json.dumps(
        structure
        + [
            [p.size_x, p.size_y, p.thickness],
            [mat.density, mat.youngs_modulus, mat.poisson_ratio],
            m.boundary,
            m.theory,
            m.mesh_divisions,
            float(band["fmax_hz"]),
            band.get("tail_band_hz"),  # a stream's contact tails: their basis too
        ]
    )


def _band(scene) -> dict:
    """The band the scene's solver will use: a stream scene's (``stream_band``), else
    the scene's plate.fmax when set (then the contact pulses choose_band also estimates,
    ~5 ms per case, are not needed here), else choose_band's."""
    from tailbeam.solvers.modal_setup.band import choose_band, stream_band

    if scene.needs_stream_solver:
        return stream_band(scene)
    if scene.modal.fmax_hz is not None:
        return {"fmax_hz": scene.modal.fmax_hz}
    return choose_band(scene, scene.modal)


def warm_basis(scene_toml: str) -> str:
    """Compute (or load) the modal basis of the scene into the on-disk cache; returns the
    basis description. Runs once per basis_signature before the sweep's cases."""
    from tailbeam.io.scene_file import loads_scene
    from tailbeam.solvers.modal_setup.band import stream_band
    from tailbeam.solvers.modal_setup.setup import build_basis, tail_basis

    try:
        scene = loads_scene(scene_toml)
        if scene.plate_model != "modal":
            return "rigid plate: no basis"
        band = stream_band(scene) if scene.needs_stream_solver else None
        with quiet():  # a worker's notes and bars would interleave on the user's terminal
            basis = build_basis(scene, band)
            if band and band["tail_band_hz"]:  # a stream's contact tails: their basis too
                tail_basis(scene, band, basis)
    except Exception as err:  # noqa: BLE001 - the cases then fail with their own error
        return f"basis not cached: {_one_line(err)}"
    return f"{basis.theory} {basis.boundary}, {basis.n_modes} modes"


def _one_line(err: BaseException) -> str:
    text = str(err).strip().splitlines()
    return f"{type(err).__name__}: {text[0] if text else ''}".strip()


def _impact_rows(result) -> list:
    """impacts_table() (every impacts.csv column) as row dicts, plus ``class`` (= the
    striking ball's ``label``: the scene's, which the sweep sets from ``labels.coal`` for
    ``[[balls]]``; a stream decides what is gangue)."""
    table = result.impacts_table()
    names = list(table)
    rows = [dict(zip(names, values, strict=True)) for values in zip(*table.values(), strict=True)]
    for row in rows:
        row["class"] = row["label"]
    return [{k: v.item() if isinstance(v, np.generic) else v for k, v in r.items()} for r in rows]


def _band_columns(result) -> dict:
    """The modal band a case ran with (Hz) and the band check's upper estimate of its
    peak-force error (tailbeam.solvers.modal_setup.band: for a stream, at its hardest plate
    contact); none on the rigid plate (the dataset then records NaN)."""
    band = result.info.get("band") or {}
    if "fmax_hz" not in band:
        return {}
    error = band.get("truncation_force_error", math.nan)
    return {"band_hz": float(band["fmax_hz"]), "band_force_error": float(error)}


def _counts(rows: list, stream: bool) -> dict:
    """Coal and gangue impacts on the plate (ball-ball rows are not plate impacts) and, for
    streams, the number of ball-ball contacts (each gives two rows)."""
    plate = [r for r in rows if r["partner"] == "plate"]
    classes = [r["class"] for r in plate]
    out = {"n_coal_impacts": classes.count("coal"), "n_gangue_impacts": classes.count("gangue")}
    if stream:
        out["n_ball_contacts"] = (len(rows) - len(plate)) // 2
    return out


def band_estimate(scene) -> dict:
    """{"band_hz", "band_force_error"} the case's run will record (``_band_columns``), from its
    band check alone, before any basis is computed (single ball: ``choose_band``, ~10 ms a
    ball; stream: ``check_stream_band`` over its particles); {} on the rigid plate."""
    from tailbeam.solvers.modal_setup.band import check_stream_band, choose_band, stream_band

    if scene.plate_model != "modal":
        return {}
    if scene.needs_stream_solver:
        band = stream_band(scene)
        check_stream_band(scene, band)
    else:
        band = choose_band(scene, scene.modal)
    error = band.get("truncation_force_error", math.nan)
    return {"band_hz": float(band["fmax_hz"]), "band_force_error": float(error)}


def validity(columns: dict, accuracy: float) -> dict:
    """{"valid": bool, "invalid_reason": text}: a case is invalid when its band check's
    estimate ``band_force_error`` (from ``columns``) exceeds ``accuracy`` (the sweep's
    band_accuracy); NaN (rigid plate, no estimate) is valid."""
    error = columns.get("band_force_error", math.nan)
    if not error > accuracy:
        return {"valid": True, "invalid_reason": ""}
    band = columns.get("band_hz", math.nan)
    return {
        "valid": False,
        "invalid_reason": (
            f"band_force_error {error:.3g} > band_accuracy {accuracy:g}: the modal band "
            f"0-{band / 1e3:g} kHz is too low for the case's shortest contact (raise plate.fmax)"
        ),
    }


def run_case(scene_toml: str, *_after) -> dict:
    """Simulate one case. Returns {"status": "ok" | "failed", "error", "wall_time",
    "cpu_time" (s, this process),
    "signals": {sensor: float32 array m/s^2}, "impacts": [row dicts], "n_coal_impacts",
    "n_gangue_impacts" (plate impacts), for a stream scene "n_ball_contacts", and on the
    modal plate "band_hz" and "band_force_error" (``_band_columns``)}.
    ``_after`` are ignored (Dask dependencies, e.g. the warmed basis; callers before the
    labels moved into the scene passed the coal materials here)."""
    from tailbeam.io.scene_file import loads_scene
    from tailbeam.simulation import simulate

    t0 = time.perf_counter()
    c0 = time.process_time()
    out = {"status": "failed", "error": "", "signals": {}, "impacts": []}
    stream = False
    try:
        with quiet():  # the sweep's own bar reports progress; per-case notes would flood it
            scene = loads_scene(scene_toml)
            stream = scene.needs_stream_solver
            result = simulate(scene)
            if result.status != 0:
                out["error"] = f"solver stopped: {result.message}".splitlines()[0]
            else:
                out["signals"] = {
                    name: np.asarray(a, dtype=np.float32)
                    for name, (_t, a) in result.sensor_signals.items()
                }
                out["impacts"] = _impact_rows(result)
                out.update(_band_columns(result))
                out["status"] = "ok"
    except Exception as err:  # noqa: BLE001 - any failure is recorded, never raised
        out["error"] = _one_line(err) or traceback.format_exc().splitlines()[-1]
    out.update(_counts(out["impacts"], stream))
    out["wall_time"] = time.perf_counter() - t0
    out["cpu_time"] = time.process_time() - c0
    return out
