"""Flow statistics of a caving stream with friction: tailbeam against LIGGGHTS.

The same stream (the reference scene's, shortened: coal and 30 % sandstone spheres, radii
10-40 mm, 200 lumps/s released 0.3-0.8 m above the upper part of a 30 degree 0.6 x 0.6 m
steel plate) runs in tailbeam's fast stream solver (rigid plate, the Adams friction law with
rolling resistance) and in LIGGGHTS (``benchmarks/liggghts/stream.in``: Hertz normal
contact, Mindlin tangential spring capped by Coulomb friction, CDT or EPSD2 rolling
resistance) with the same lumps: release times, places, radii, materials (E, nu, density),
mu and mu_r. What the two contact laws cannot share:

* normal damping: tailbeam's IMPACT law (c = 300 N s/m ramped over d = 0.1 mm) gives a
  restitution that depends on size and speed; LIGGGHTS' Hertz takes one restitution
  coefficient per material pair. Each pair's LIGGGHTS coefficient is the median restitution
  tailbeam's run of that seed gave the pair (plate impacts faster than 0.5 m/s; ball-ball
  contacts approaching faster than 0.2 m/s; 0.5 where a pair had none);
* the tangential law: a Mindlin spring with a Coulomb cap against tailbeam's regularised
  Coulomb law without tangential compliance (stiction velocity 1e-3 m/s); mu_s = mu_d;
* the edge: tailbeam's lump leaves when its centre crosses an edge; in LIGGGHTS the plate is
  a triangle mesh, and the lump rolls round the edge until it is clear of it.

Both runs' trajectories are sampled every 0.5 ms and reduced by the same code:

* on the beam: centre over the plate and lowest point within 2 mm of it;
* residence time: from the first sample on the beam to the first with the centre no longer
  over the plate, for lumps that left before the end (bounces above the plate included);
* landings per lump: entries onto the beam from above 2 mm (hops lower than 2 mm are not
  counted), over the lumps that touched it;
* at rest: on the beam at the end with the centre slower than 1 cm/s (per lump that touched
  the beam).

Each setting runs with several stream seeds; the table gives mean +- standard deviation over
seeds. Writes ``table.md`` (``--table NAME``), the runs in a CSV of the same name and each
LIGGGHTS run's directory into --out.

    python benchmarks/compare_liggghts.py --out DIR [--quick] [--seeds 1 2 3]

Needs the ``liggghts`` executable (Debian: apt-get install liggghts).
"""

import argparse
import csv
import math
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tailbeam.io.scene_file import loads_scene  # noqa: E402
from tailbeam.physics.materials import get_material  # noqa: E402
from tailbeam.simulation import simulate  # noqa: E402

HERE = Path(__file__).resolve().parent / "liggghts"
SAMPLE = 5e-4  # s: trajectory sampling of both codes
GAP = 2e-3  # m: "on the beam" when the lowest point is within this of the plate
REST_SPEED = 0.01  # m/s
HALF = 0.3  # m: half side of the plate
DT = 2e-6  # s: LIGGGHTS timestep (~10 % of the Rayleigh time of a 10 mm sandstone lump)
TYPES = {"coal": 1, "sandstone": 2, "carbon_steel": 3}
FIRST_LUMP_ID = 2  # LIGGGHTS atom 1 is stream.in's anchor grain
AREA = ((-0.3, 0.1), (-0.2, 0.2))  # m: the stream's release area
R_MAX = 0.04  # m: the largest lump radius
CANDIDATES = 20  # release places tried per lump in LIGGGHTS
RETRIES, RETRY_WAIT = 300, 1e-3  # s: when every candidate is taken, wait and try again
PARK_X, PARK_Y, PARK_Z = (0.9, 1.0, 1.1, 1.2, 1.3, 1.4), np.arange(-0.6, 0.61, 0.1), 1.2  # m

HIGH, LOW = (0.3, 0.8), (0.02, 0.1)  # m: release gaps, the reference scene's and a low drop
SETTINGS = {  # name: mu, mu_r, release gaps
    "frictionless": (0.0, 0.0, HIGH),
    "mu=0.5 mu_r=0.1": (0.5, 0.1, HIGH),
    "mu=0.7 mu_r=0.7": (0.7, 0.7, HIGH),
    "low drop, mu=0.5 mu_r=0.1": (0.5, 0.1, LOW),
    "low drop, mu=0.7 mu_r=0.7": (0.7, 0.7, LOW),
}

SCENE = """
duration = {duration}
[contact]
damping = 300.0
penetration = 1e-4
{friction}
[plate]
model = "rigid"
inclination = 30.0

[[streams]]
name = "cave"
rate = 200.0
start = 0.0
stop = {stop}
gangue_fraction = 0.3
radius = [0.01, 0.04]
area = [[{x0}, {x1}], [{y0}, {y1}]]
height = [{h0}, {h1}]
seed = {seed}
"""

FRICTION = """[contact.friction]
static = {mu}
dynamic = {mu}
stiction_velocity = 1e-3
transition_velocity = 2e-3
rolling = {mu_r}
"""


def scene(mu, mu_r, seed, stop, duration, height=HIGH):
    friction = FRICTION.format(mu=mu, mu_r=mu_r) if mu > 0 or mu_r > 0 else ""
    text = SCENE.format(
        duration=duration, stop=stop, seed=seed, friction=friction, h0=height[0], h1=height[1],
        x0=AREA[0][0], x1=AREA[0][1], y0=AREA[1][0], y1=AREA[1][1],
    )  # fmt: skip
    return loads_scene(text)


def sample_times(duration):
    n = int(round(duration / SAMPLE))
    return np.arange(n + 1) * SAMPLE


def run_tailbeam(sc):
    """(result, wall s) on the rigid plate with frames at the sample times."""
    start = time.perf_counter()
    result = simulate(sc, solver="stream", frames=sample_times(sc.duration), progress=False)
    return result, time.perf_counter() - start


def restitutions(result) -> dict:
    """(material, material) -> median restitution of tailbeam's contacts of that pair."""
    imp = result.impacts_table()
    parts = result.particles_table()
    material = dict(zip(parts["name"], parts["material"], strict=True))
    pairs: dict = {}
    for k in range(len(imp["ball"])):
        partner = imp["partner"][k]
        if partner == "plate":
            if abs(imp["v_in"][k]) < 0.5:
                continue
            key = tuple(sorted((imp["material"][k], "carbon_steel")))
        else:
            if abs(imp["approach_in"][k]) < 0.2:
                continue
            key = tuple(sorted((imp["material"][k], material[partner])))
        e = imp["restitution"][k]
        if np.isfinite(e):
            pairs.setdefault(key, []).append(float(e))
    return {k: float(np.median(v)) for k, v in pairs.items()}


def pair_matrix(values: dict, default: float) -> list:
    names = list(TYPES)
    return [values.get(tuple(sorted((a, b))), default) for a in names for b in names]


def write_materials(path, restitution, mu, mu_r, rolling_model):
    mats = [get_material(n) for n in TYPES]
    e = pair_matrix(restitution, 0.5)
    lines = [
        "# written by benchmarks/compare_liggghts.py: types 1 coal, 2 sandstone, 3 steel",
        "fix m1 all property/global youngsModulus peratomtype "
        + " ".join(f"{m.youngs_modulus:.6g}" for m in mats),
        "fix m2 all property/global poissonsRatio peratomtype "
        + " ".join(f"{m.poisson_ratio:.6g}" for m in mats),
        "fix m3 all property/global coefficientRestitution peratomtypepair 3 "
        + " ".join(f"{v:.6g}" for v in e),
        "fix m4 all property/global coefficientFriction peratomtypepair 3 "
        + " ".join([f"{mu:.6g}"] * 9),
        "fix m5 all property/global coefficientRollingFriction peratomtypepair 3 "
        + " ".join([f"{mu_r:.6g}"] * 9),
    ]
    if rolling_model == "epsd2":
        lines.append(
            "fix m6 all property/global coefficientRollingViscousDamping peratomtypepair 3 "
            + " ".join(["0.0"] * 9)
        )
    lines.append(f"timestep {DT:.6g}")
    Path(path).write_text("\n".join(lines) + "\n")


def candidates(p, i, height, n=CANDIDATES):
    """Release places of lump i (plate frame, m): the one tailbeam used, then ``n - 1`` drawn
    over the stream's release volume (area, gap ``height``) from the lump's number."""
    rng = np.random.default_rng(1000 + int(i))
    r = float(p["radius"][i])
    (x0, x1), (y0, y1) = AREA
    drawn = np.column_stack(
        [
            rng.uniform(x0, x1, n - 1),
            rng.uniform(y0, y1, n - 1),
            rng.uniform(height[0], height[1], n - 1) + r,
        ]
    )
    return np.vstack([[p["x0"][i], p["y0"][i], p["z0"][i]], drawn])


def write_releases(path, result, height):
    """One block per lump in release order: run to its release step, then create it at the
    first of its candidate places with no lump centre within its radius + R_MAX (tailbeam's
    rule: another free place of the release volume); when none is free, wait RETRY_WAIT and
    try again, up to RETRIES times; a lump that never finds a place is parked, held still,
    outside the beam. Returns the lumps' order."""
    p = result.particles_table()
    order = np.argsort(p["t_release"], kind="stable")
    wait = int(round(RETRY_WAIT / DT))
    lines = []
    for k, i in enumerate(order):
        atom_id = FIRST_LUMP_ID + k
        step = int(math.ceil(p["t_release"][i] / DT))
        rho = get_material(p["material"][i]).density
        kind, r = TYPES[p["material"][i]], float(p["radius"][i])

        def create(x, y, z, kind=kind, r=r, rho=rho, atom_id=atom_id):
            return (
                f'"create_atoms {kind} single {x:.9g} {y:.9g} {z:.9g} units box" '
                f'"set atom {atom_id} diameter {2.0 * r:.9g}" '
                f'"set atom {atom_id} density {rho:.9g}" "variable placed string 1"'
            )

        lines += [
            f"variable togo equal ({step}-step)*({step}>step)",
            "run ${togo}",
            "variable placed string 0",
            f"variable attempt loop {RETRIES}",
            f"label try_{atom_id}",
        ]
        for x, y, z in candidates(p, i, height):
            lines += [
                f"region probe sphere {x:.9g} {y:.9g} {z:.9g} {r + R_MAX + 2e-3:.9g} units box",
                f'if "${{placed}} == 0 && $(count(all,probe)) == 0" then {create(x, y, z)}',
                "region probe delete",
            ]
        park = (PARK_X[k % len(PARK_X)], PARK_Y[(k // len(PARK_X)) % len(PARK_Y)], PARK_Z)
        lines += [
            f'if "${{placed}} == 1" then "jump SELF placed_{atom_id}"',
            f"run {wait}",
            "next attempt",
            f"jump SELF try_{atom_id}",
            f"label placed_{atom_id}",
            "variable attempt delete",
            f'if "${{placed}} == 0" then {create(*park)} "group held id {atom_id}"',
        ]
    Path(path).write_text("\n".join(lines) + "\n")
    return order


def write_plate(path):
    h = HALF
    corners = [(-h, -h), (h, -h), (h, h), (-h, h)]
    tris = [(0, 1, 2), (0, 2, 3)]
    lines = ["solid plate"]
    for t in tris:
        lines += ["  facet normal 0 0 1", "    outer loop"]
        lines += [f"      vertex {corners[k][0]} {corners[k][1]} 0" for k in t]
        lines += ["    endloop", "  endfacet"]
    lines.append("endsolid plate")
    Path(path).write_text("\n".join(lines) + "\n")


def run_liggghts(workdir, result, mu, mu_r, rolling_model, duration, height):
    """Write the inputs, run LIGGGHTS; (position, velocity, radius arrays, wall s)."""
    workdir.mkdir(parents=True, exist_ok=True)
    shutil.copy(HERE / "stream.in", workdir / "stream.in")
    write_materials(workdir / "materials.in", restitutions(result), mu, mu_r, rolling_model)
    order = write_releases(workdir / "releases.in", result, height)
    write_plate(workdir / "plate.stl")
    every = int(round(SAMPLE / DT))
    cmd = [
        "liggghts", "-in", "stream.in", "-echo", "none", "-log", "log.liggghts",
        "-var", "rolling_model", rolling_model, "-var", "dump_every", str(every),
        "-var", "end_step", str(int(round(duration / DT))),
    ]  # fmt: skip
    start = time.perf_counter()
    with (workdir / "stdout.txt").open("w") as out:
        subprocess.run(cmd, cwd=workdir, check=True, stdout=out, stderr=subprocess.STDOUT)
    wall = time.perf_counter() - start
    return read_dump(workdir / "traj.dump", len(order), every, duration) + (wall,)


def read_dump(path, n, every, duration):
    """(position (F, n, 3), velocity (F, n, 3)) at the sample times from a custom dump
    ``id type radius x y z vx vy vz``; nan where a lump is absent."""
    times = sample_times(duration)
    pos = np.full((times.size, n, 3), np.nan)
    vel = np.full((times.size, n, 3), np.nan)
    with Path(path).open() as fh:
        lines = fh.read().split("\n")
    k = 0
    while k < len(lines):
        if lines[k].startswith("ITEM: TIMESTEP"):
            step = int(lines[k + 1])
            count = int(lines[k + 3])
            f = int(round(step / every))
            rows = lines[k + 9 : k + 9 + count]
            if rows and f < times.size:
                a = np.array([r.split() for r in rows], dtype=float)
                a = a[a[:, 0] >= FIRST_LUMP_ID]
                ids = a[:, 0].astype(int) - FIRST_LUMP_ID
                pos[f, ids] = a[:, 3:6]
                vel[f, ids] = a[:, 6:9]
            k += 9 + count
        else:
            k += 1
    return pos, vel


def flow_stats(pos, vel, radius, labels=None) -> dict:
    """The flow statistics of sampled trajectories (module docstring)."""
    gap = pos[:, :, 2] - radius[None, :]
    over = (np.abs(pos[:, :, 0]) <= HALF) & (np.abs(pos[:, :, 1]) <= HALF)
    on = over & (gap < GAP)
    touched = on.any(axis=0)
    last = on.shape[0] - 1
    residence, landings = [], []
    for i in np.flatnonzero(touched):
        k = np.flatnonzero(on[:, i])
        entries = int(on[0, i]) + int(np.sum(on[1:, i] & ~on[:-1, i]))
        landings.append(entries)
        gone = np.flatnonzero(~over[k[0] :, i])  # centre no longer over the plate
        if gone.size:
            residence.append(gone[0] * SAMPLE)
    parked = (pos[:, :, 0] > PARK_X[0] - 0.05) & (pos[:, :, 2] > PARK_Z - 0.05)
    moving = ~parked.any(axis=0)
    fastest = float(np.nanmax(np.linalg.norm(vel[:, moving], axis=2)))
    speed = np.linalg.norm(vel[last], axis=1)
    rest = on[last] & (speed < REST_SPEED)
    return {
        "lumps": int(radius.size),
        "touched": int(touched.sum()),
        "residence_s": float(np.mean(residence)) if residence else math.nan,
        "landings": float(np.mean(landings)) if landings else math.nan,
        "on_beam_end": int(on[last].sum()),
        "at_rest_end": int(rest.sum()),
        "fraction_at_rest": float(rest.sum() / max(1, touched.sum())),
        "max_speed": fastest,
        "parked": int((~moving).sum()),
    }


def tailbeam_arrays(result):
    fr = result.frames
    radius = np.asarray(result.particles_table()["radius"], float)
    return fr.position, fr.velocity, radius


def mean_sd(values) -> str:
    v = np.asarray([x for x in values if np.isfinite(x)], float)
    if not v.size:
        return "n/a"
    sd = float(v.std(ddof=1)) if v.size > 1 else 0.0
    return f"{v.mean():.3g} ± {sd:.2g}"


def write_table(path, rows, seeds, argv):
    keys = [
        ("residence_s", "residence (s)"),
        ("landings", "landings per lump"),
        ("fraction_at_rest", "at rest at the end / touched"),
        ("touched", "lumps that touched the beam"),
        ("on_beam_end", "on the beam at the end"),
        ("max_speed", "fastest lump (m/s)"),
        ("parked", "lumps that found no place"),
    ]
    lines = [
        "    python benchmarks/compare_liggghts.py " + " ".join(argv),
        "",
        f"mean ± standard deviation over stream seeds {', '.join(map(str, seeds))}",
        "",
        "| setting | code | " + " | ".join(k[1] for k in keys) + " | wall (s) |",
        "|---|---|" + "---|" * (len(keys) + 1),
    ]
    settings = list(dict.fromkeys(r["setting"] for r in rows))
    for s in settings:
        for code in dict.fromkeys(r["code"] for r in rows if r["setting"] == s):
            mine = [r for r in rows if r["setting"] == s and r["code"] == code]
            cells = [mean_sd([r[k] for r in mine]) for k, _ in keys]
            wall = mean_sd([r["wall_s"] for r in mine])
            lines.append(f"| {s} | {code} | " + " | ".join(cells) + f" | {wall} |")
    Path(path).write_text("\n".join(lines) + "\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument(
        "--quick",
        action="store_true",
        help="~65 lumps over 0.35 s, 1 s simulated (default: ~110 over 0.55 s, 1.5 s)",
    )
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--settings", nargs="+", default=list(SETTINGS), choices=list(SETTINGS))
    ap.add_argument("--table", default="table.md", help="name of the table written into --out")
    ap.add_argument("--rolling-models", nargs="+", default=["cdt"], choices=["cdt", "epsd2"])
    args = ap.parse_args(argv)
    if shutil.which("liggghts") is None:
        sys.exit(
            "compare_liggghts: the liggghts executable is not on PATH (apt-get install liggghts)"
        )
    args.out.mkdir(parents=True, exist_ok=True)
    stop, duration = (0.35, 1.0) if args.quick else (0.55, 1.5)
    rows = []
    for setting in args.settings:
        mu, mu_r, height = SETTINGS[setting]
        for seed in args.seeds:
            sc = scene(mu, mu_r, seed, stop, duration, height)
            result, wall = run_tailbeam(sc)
            pos, vel, radius = tailbeam_arrays(result)
            rows.append({"setting": setting, "code": "tailbeam", "seed": seed,
                         **flow_stats(pos, vel, radius), "wall_s": wall})  # fmt: skip
            print(f"{setting} seed {seed} tailbeam: {rows[-1]}", file=sys.stderr)
            order = np.argsort(result.particles_table()["t_release"], kind="stable")
            for model in args.rolling_models:
                tag = setting.replace(" ", "_").replace("=", "").replace(",", "")
                tag = f"{tag}_{model}_seed{seed}"
                lp, lv, wall = run_liggghts(
                    args.out / tag, result, mu, mu_r, model, duration, height
                )
                code = f"LIGGGHTS ({model})"
                rows.append({"setting": setting, "code": code, "seed": seed,
                             **flow_stats(lp, lv, radius[order]), "wall_s": wall})  # fmt: skip
                print(f"{setting} seed {seed} {code}: {rows[-1]}", file=sys.stderr)
    with (args.out / args.table.replace(".md", ".csv")).open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    write_table(args.out / args.table, rows, args.seeds, sys.argv[1:] if argv is None else argv)
    print((args.out / args.table).read_text())


if __name__ == "__main__":
    main()
