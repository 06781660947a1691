"""How far every solver's results in this tree are from another revision's.

    python tools/compare_revisions.py --base REV [--quick] [--keep DIR]

Runs one scene per solver in this working tree and in ``git archive REV``, each tree in its
own single-threaded process with its own numba cache, and compares every number they report:

- ``rigid``, ``rigid reference``: the rigid solver and its scipy reference (paper section 4.1:
  coal balls at 1 and 2 m/s, c = 800 N s/m, 1 s): contact records, events, states sampled at
  5120 Hz and at every peak;
- ``coupled``: the two-way coupled modal solver (sandstone at 2 m/s on the closed-form SSSS
  plate, 5 kHz band, c = 800 N s/m, residual flexibility on): records, events, force nodes;
- ``FE reference``: the same ball on the Argyris 8x8 plate, dt 2e-7 s, 0.4 ms: records,
  sensor acceleration;
- ``stream``, ``stream reference``: the fast stream solver and its slow reference on the
  ten-ball scene of the tests (15 deg plate, c = 2000 N s/m, d = 2e-5 m: ball-ball contacts,
  clamp and STEP kinks): records, leaves, events (and the reference's energy);
- ``stream, modal plate``: the fast stream solver with one ball on the modal plate.

``--quick`` leaves out the FE reference and the stream reference (the slow ones, minutes).
``--keep DIR`` keeps both trees' results there and reuses DIR/old.pkl if it exists (the base
is then not run again).

Prints per solver "bit-identical", or the largest difference of any number relative to the
largest magnitude of its column (and that column); then the numeric columns whose length
changed (an adaptive reference that took other steps), the non-numeric columns (names, event
kinds, how contacts ended) that differ, and the columns only this tree has (a record
extended: the base's columns are compared, and each must still exist). Records are compared
by their fields and derived values (``as_dict()``: ``restitution``, ...), events by (t, ball,
kind, partner), an enum as its value. Exit code 1 if a non-numeric column differs; what
numeric difference is acceptable is the reader's call (docs/development.md, "Checking a
refactor"). The compiled active set's own bitwise check is ``compare_active_set_revisions.py``.
"""

import argparse
import enum
import pickle
import sys
import tempfile
from pathlib import Path

import numpy as np
from revisions import ROOT, extract_revision, from_either, plain, run_in, write_plain


def _columns(obj, prefix, out):
    """Flatten plain values (``revisions.plain``: dicts, lists, tuples, arrays, scalars) into
    named columns (lists of scalars)."""
    if isinstance(obj, dict):
        for key, value in obj.items():
            _columns(value, f"{prefix}.{key}", out)
    elif isinstance(obj, list | tuple):
        for i, value in enumerate(obj):
            _columns(value, f"{prefix}[{i}]" if len(obj) < 8 else f"{prefix}[]", out)
    elif isinstance(obj, np.ndarray):
        out.setdefault(prefix, []).extend(np.ravel(obj).tolist())
    else:
        out.setdefault(prefix, []).append(obj)


def _events(events) -> list:
    """Events as dicts (t, ball, kind, partner): ``Event`` records, or the tuples a revision
    without them wrote ((t, ball, kind) of a single-ball solver, partner the plate;
    (t, kind, ball, partner) of a stream solver)."""
    fields = ("t", "ball", "kind", "partner")
    out = []
    for ev in events:
        if hasattr(ev, "_asdict"):
            out.append(plain(ev))
        elif len(ev) == 3:
            out.append(plain(dict(zip(fields, (*ev, "plate"), strict=True))))
        elif isinstance(ev[1], enum.Enum):  # a stream solver's order: the kind second
            t, kind, ball, partner = ev
            out.append(plain(dict(zip(fields, (t, ball, kind, partner), strict=True))))
        else:
            out.append(plain(dict(zip(fields, ev, strict=True))))
    return out


def _nodes(result):
    """The coupled solver's force nodes: on the result's plate part, or on the result itself
    in a revision without one."""
    return result.plate.nodes if getattr(result, "plate", None) is not None else result.nodes


def run_solvers(out_path, quick):
    """Run the scenes with the tailbeam on sys.path; pickle their flattened results."""
    import stream_scenes

    import tailbeam
    from tailbeam import CARBON_STEEL, COAL, SANDSTONE, Ball, Plate, ball_plate_law

    InclinedPlate = from_either("InclinedPlate", "tailbeam.physics.incline")
    Particle = from_either("Particle", "tailbeam.streams.generator")
    ssss_kirchhoff_basis = from_either(
        "ssss_kirchhoff_basis", "tailbeam.plate.closed_forms", "tailbeam.modal"
    )
    simulate_coupled = from_either(
        "simulate_coupled", "tailbeam.solvers.coupled", "tailbeam.coupled"
    )
    simulate_rigid = from_either("simulate_rigid", "tailbeam.solvers.rigid", "tailbeam.rigid")
    simulate_rigid_reference = from_either(
        "simulate_rigid_reference", "tailbeam.solvers.rigid.reference", "tailbeam.rigid.reference"
    )
    solve_stream = from_either(
        "solve_stream",
        "tailbeam.solvers.stream.driver.loop",
        "tailbeam.solvers.stream.stream",
        "tailbeam.solvers.stream",
    )
    StreamPlate = from_either(
        "StreamPlate",
        "tailbeam.solvers.stream.plate",
        "tailbeam.solvers.stream.stream_plate",
        "tailbeam.solvers.stream_plate",
    )
    simulate_stream_reference = from_either(
        "simulate_stream_reference",
        "tailbeam.solvers.stream.reference.solver",
        "tailbeam.solvers.stream.stream_reference",
        "tailbeam.solvers.stream_reference",
    )

    print(f"running {tailbeam.__file__}", flush=True)
    law = ball_plate_law(COAL, 0.03, CARBON_STEEL, damping=800.0, penetration=1e-4)
    balls = [Ball("A", COAL, 0.03, (-0.1, 0.0, 0.13), (0.0, 0.0, -1.0)),
             Ball("B", COAL, 0.03, (0.1, 0.0, 0.13), (0.0, 0.0, -2.0))]  # fmt: skip
    runs = {}
    rigid = simulate_rigid(balls, Plate(), [law, law], 1.0, rtol=1e-11)
    grid = rigid.time_grid(5120.0)
    runs["rigid"] = (rigid.impacts, _events(rigid.events), rigid.sample(grid))
    ref = simulate_rigid_reference(balls, Plate(), [law, law], 1.0)
    runs["rigid reference"] = (ref.impacts, _events(ref.events), ref.sample(grid))

    basis = ssss_kirchhoff_basis(Plate(), 5000.0)
    ball = Ball("s", SANDSTONE, 0.03, (0.07, -0.05, 0.03 + 1e-4), (0.0, 0.0, -2.0))
    slaw = ball_plate_law(SANDSTONE, 0.03, CARBON_STEEL, damping=800.0)
    coupled = simulate_coupled([ball], basis, [slaw], 2e-3, gravity=9.80665)
    runs["coupled"] = (coupled.impacts, _events(coupled.events), _nodes(coupled))
    if not quick:
        assemble_plate = from_either("assemble_plate", "tailbeam.plate")
        fe_reference = from_either(
            "fe_reference", "tailbeam.solvers.coupled.fe_reference", "tailbeam.coupled.fe_reference"
        )

        model = assemble_plate(Plate(), "SSSS", theory="kirchhoff", divisions=8)
        fe = fe_reference(model, ball, slaw, 4e-4, dt=2e-7, sensors=[(0.05, 0.10)])
        runs["FE reference"] = (fe.impacts, fe.t, fe.sensor_a)

    incline = InclinedPlate(inclination=15.0)
    ten = stream_scenes.ten_ball_scene(incline)
    parts = [Particle(b.name, "", "coal", b.material, b.radius, b.mass, 0.0,
                      tuple(b.position), tuple(b.velocity)) for b in ten]  # fmt: skip
    opts = dict(damping=2000.0, penetration=2e-5)
    fast = solve_stream(parts, incline, 0.1, rtol=1e-12, rest_speed=0.0, progress=False, **opts)
    runs["stream"] = (fast.contacts, fast.leaves, _events(fast.events))
    if not quick:
        sref = simulate_stream_reference(ten, incline, 0.1, **opts)
        runs["stream reference"] = (sref.contacts, sref.leaves, _events(sref.events), sref.energy)
    plate = StreamPlate(basis, np.full(basis.n_modes, 0.01))
    one = [Particle("s", "", "gangue", SANDSTONE, 0.03, ball.mass, 0.0, tuple(ball.position),
                    tuple(ball.velocity))]  # fmt: skip
    modal = solve_stream(one, InclinedPlate(), 2e-3, damping=800.0, rtol=1e-12, progress=False,
                         plate=plate)  # fmt: skip
    runs["stream, modal plate"] = (modal.contacts, _events(modal.events))
    flat = {}
    for name, result in runs.items():
        flat[name] = {}
        _columns(plain(result), "", flat[name])
    write_plain(flat, out_path)


def compare(a: dict, b: dict) -> tuple:
    """(bit-identical, differing non-numeric columns, numeric columns of another length,
    largest relative difference and its column, columns only the new revision has) of one
    solver's flattened results (a: base, b: new). A column the new revision lost counts as
    differing; one it added (a record extended) is listed, the common ones are compared."""
    text, lengths, added = sorted(a.keys() - b.keys()), [], sorted(b.keys() - a.keys())
    worst, where, identical = 0.0, "", True
    for key in sorted(a.keys() & b.keys()):
        x, y = a[key], b[key]
        numeric = all(isinstance(v, float | int) and not isinstance(v, bool) for v in x + y)
        if numeric and len(x) != len(y):
            lengths.append(f"{key}: {len(x)} vs {len(y)} values")
            continue
        if not numeric:
            if x != y:
                text.append(key)
            continue
        x, y = np.array(x, dtype=float), np.array(y, dtype=float)
        identical &= np.array_equal(x, y, equal_nan=True)
        scale = np.nanmax(np.abs(x)) if np.any(np.isfinite(x)) else 1.0
        diff = np.abs(x - y)[~(np.isnan(x) & np.isnan(y))]
        if diff.size and scale > 0.0 and float(np.max(diff)) / scale > worst:
            worst, where = float(np.max(diff)) / scale, key
    return identical and not text and not lengths, text, lengths, worst, where, added


def main(base, quick=False, keep=None):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        store = Path(keep).resolve() if keep else tmp
        store.mkdir(parents=True, exist_ok=True)
        if not (store / "old.pkl").exists():
            call = f"compare_revisions.run_solvers({str(store / 'old.pkl')!r}, {quick!r})"
            run_in(extract_revision(base, tmp), tmp / "cache-base", call)
        call = f"compare_revisions.run_solvers({str(store / 'new.pkl')!r}, {quick!r})"
        run_in(ROOT, tmp / "cache-new", call)
        a = pickle.loads((store / "old.pkl").read_bytes())
        b = pickle.loads((store / "new.pkl").read_bytes())
    ok = True
    for name in a:
        identical, text, lengths, worst, where, added = compare(a[name], b[name])
        ok &= not text
        n = sum(len(v) for v in a[name].values())
        what = (
            "bit-identical" if identical else f"largest relative difference {worst:.1e} ({where})"
        )
        notes = [f"DIFFERENT: {', '.join(text)}"] * bool(text) + lengths
        notes += [f"new columns: {', '.join(added)}"] * bool(added)
        print(f"{name}: {what} ({n} values)" + "".join(f"; {x}" for x in notes))
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", required=True, help="git revision to compare with")
    parser.add_argument("--quick", action="store_true", help="without the slow references")
    parser.add_argument("--keep", help="folder for the results (old.pkl there: base not rerun)")
    args = parser.parse_args()
    sys.exit(main(args.base, args.quick, args.keep))
