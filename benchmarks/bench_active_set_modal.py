"""The stream solver's compiled active set on the two-way modal plate: cost per contact
against error, beside the coupled single-ball solver.

    python benchmarks/bench_active_set_modal.py --out DIR [--quick]

Reproduces the modal-plate table of docs/streams.md ("The parts, measured"). A sandstone ball
(30 mm) strikes the 0.6 x 0.6 x 0.01 m simply supported steel plate at (0.07, -0.05) m at
2 m/s (c = 0, g = 9.81, modal damping 1 %); plate: the closed-form Kirchhoff modes
(tailbeam.plate.closed_forms.ssss_kirchhoff_basis) truncated to m = 0 (the rigid plate), 25
and 100 modes, without residual flexibility. Cost per contact (start to end, best of 3 x 20
contacts; ``--quick``: 2) at rtol 1e-8, 1e-10, 1e-12, and the worst relative error of
t_end, v_out and peak force against ``simulate_coupled`` on the same m modes,
Richardson-extrapolated from 1600 and 3200 steps per contact (the same model: the error is
the integrator's; on the rigid plate the active set itself at rtol 1e-13). Baseline, in the
same run: ``simulate_coupled`` itself at its default 200 steps per contact (the whole 0.6 ms
run, one contact) and its error against the same truth.

Writes DIR/bench_active_set_modal.csv and DIR/table.md. Run single-threaded
(OMP_NUM_THREADS=1). The first calls compile the kernels (not timed).
"""

import argparse
import csv
import math
import time
from pathlib import Path

import numpy as np

from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.materials import SANDSTONE
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.stream.active.integrator.set import ActiveSet

RADIUS, SPEED, G, ZETA, XY = 0.03, 2.0, 9.81, 0.01, (0.07, -0.05)
PLATE = Plate()
BALL = Ball("s", SANDSTONE, RADIUS, (XY[0], XY[1], RADIUS + 1e-4), (0.0, 0.0, -SPEED))
LAW = ball_plate_law(SANDSTONE, RADIUS, PLATE.material, damping=0.0)


def basis_of(m):
    """The first m closed-form modes (m = 0: None, the rigid plate)."""
    return None if m == 0 else ssss_kirchhoff_basis(PLATE, 20000.0).truncated(count=m)


def active_set(basis, rtol):
    kw = {}
    if basis is not None:
        kw = dict(omega=basis.omega, zeta=np.full(basis.n_modes, ZETA),
                  phi=basis.deflection(np.array([XY])))  # fmt: skip
    return ActiveSet([BALL.position], [BALL.velocity], [BALL.mass], [RADIUS], [(0, -1)], [LAW],
                     (0.0, 0.0, -G), (0.3, 0.3), rtol=rtol, **kw)  # fmt: skip


def active_contact(basis, rtol, repeat):
    """Seconds per contact (START -> END), values, steps per contact."""
    best, values, steps = math.inf, None, 0
    for _ in range(repeat):
        sets = []
        for _ in range(20):
            s = active_set(basis, rtol)
            sets.append((s, s.advance(0.0, 1e-3)))
            s.io.reset_stats()  # count the contact's work only
        t0 = time.perf_counter()
        ends = [s.advance(start.t, 1e-3) for s, start in sets]
        best = min(best, (time.perf_counter() - t0) / len(sets))
        s = sets[0][0]
        values = np.array([ends[0].t, s.v[0, 2], s.contacts.peak[0], s.contacts.pen[0]])
        steps = s.stats["steps"]
    return best, values, steps


def coupled(basis, steps, residual):
    """(values, seconds) of simulate_coupled's first contact."""
    t0 = time.perf_counter()
    res = simulate_coupled(
        [BALL], basis, [LAW], 6e-4, gravity=G, damping_ratio=ZETA,
        residual_flexibility=residual, steps_per_contact=steps,
    )  # fmt: skip
    sec = time.perf_counter() - t0
    imp = res.impacts[0]
    return np.array([imp.t_end, imp.v_out, imp.peak_force, imp.max_penetration]), sec


def truth_of(basis):
    """simulate_coupled without residual flexibility, Richardson from 1600 / 3200 steps."""
    a, _ = coupled(basis, 1600, False)
    b, _ = coupled(basis, 3200, False)
    return b + (b - a) / 3.0


def rigid_truth():
    """The rigid plate: the active set itself at rtol 1e-13 (tests/test_active_set.py checks
    it against tailbeam.solvers.rigid to 2e-11)."""
    return active_contact(None, 1e-13, 1)[1]


def _err(values, truth):
    return float(np.max(np.abs(values[:3] / truth[:3] - 1.0)))


def per_contact(quick):
    rows = []
    for m in (0, 25, 100):
        basis = basis_of(m)
        truth = rigid_truth() if m == 0 else truth_of(basis)
        active_contact(basis, 1e-10, 1)  # compile / warm
        for rtol in (1e-8, 1e-10, 1e-12):
            sec, values, steps = active_contact(basis, rtol, 2 if quick else 3)
            rows.append({"solver": "active set", "modes": m, "setting": f"rtol {rtol:.0e}",
                         "us_per_contact": sec * 1e6, "max_rel_error": _err(values, truth),
                         "steps": steps})  # fmt: skip
            print(rows[-1], flush=True)
        if m:
            coupled(basis, 200, False)  # warm
            values, sec = coupled(basis, 200, False)
            rows.append({"solver": "simulate_coupled", "modes": m, "setting": "200 steps",
                         "us_per_contact": sec * 1e6, "max_rel_error": _err(values, truth),
                         "steps": 200})  # fmt: skip
            print(rows[-1], flush=True)
    return rows


def _write(path, rows):
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def main(out_dir, quick=False):
    rows = per_contact(quick)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    _write(out / "bench_active_set_modal.csv", rows)
    lines = ["| solver | modes | setting | us / contact | max rel. error (t_end, v_out, peak) | "
             "steps |", "|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        lines.append(f"| {r['solver']} | {r['modes']} | {r['setting']} | "
                     f"{r['us_per_contact']:.1f} | {r['max_rel_error']:.1e} | "
                     f"{r['steps']} |")  # fmt: skip
    (out / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    args = parser.parse_args()
    main(args.out, args.quick)
