"""Random valid scenes through ``tailbeam simulate``: how many finish, how many the checks
before the work refuse, how many fail later (none should), and each run's time against the
estimate it printed before the work.

    python benchmarks/fuzz_scenes.py --out DIR [--scenes N] [--size small|full] [--first SEED]

The scenes are ``tests/random_scenes.draw_scene(seed, size)`` for seeds FIRST .. FIRST+N-1
(the generator of the property test ``tests/test_property_scenes.py``). Each runs in this
process through the command's own entry point, after the run-cost estimate has been taken
the way ``tailbeam.simulate`` takes it. Writes ``DIR/fuzz.csv`` (one row per seed) and prints
the tally.
"""

import argparse
import contextlib
import csv
import io
import sys
import time
from pathlib import Path

import tomli_w

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

from random_scenes import draw_scene  # noqa: E402

from tailbeam.cli import main  # noqa: E402
from tailbeam.errors import InputError, WorkLimitError  # noqa: E402
from tailbeam.io.scene_file import loads_scene  # noqa: E402
from tailbeam.simulation import choose_solver  # noqa: E402
from tailbeam.solvers.base import Options  # noqa: E402
from tailbeam.solvers.run_cost import estimate_run  # noqa: E402


def estimate(text: str):
    """(estimated seconds, None) if the checks before the work accept the scene, else
    (nan, the refusal's line)."""
    try:
        scene = loads_scene(text)
        method = choose_solver(scene)
        method.check(scene, Options())
        return estimate_run(scene, method).time_s, None
    except (InputError, WorkLimitError) as err:
        return float("nan"), str(err)


def one(seed: int, size: str, folder: Path) -> dict:
    text = tomli_w.dumps(draw_scene(seed, size))
    (folder / f"{seed}.toml").write_text(text)
    predicted, refusal = estimate(text)
    err = io.StringIO()
    start = time.perf_counter()
    with contextlib.redirect_stderr(err):
        code = main(["simulate", str(folder / f"{seed}.toml"), "--out", str(folder / "run")])
    wall = time.perf_counter() - start
    if refusal is not None:
        outcome = "refused" if code == 2 else "refused-up-front-but-ran"
    else:
        outcome = "finished" if code == 0 else "failed-after-acceptance"
    last = err.getvalue().strip().splitlines()[-1:] or [""]
    return {
        "seed": seed,
        "outcome": outcome,
        "exit": code,
        "estimate_s": round(predicted, 3),
        "wall_s": round(wall, 3),
        "ratio": round(wall / predicted, 3) if predicted == predicted and predicted else "",
        "message": refusal or (last[0] if code else ""),
    }


def tally(rows: list) -> str:
    count = {
        k: sum(r["outcome"] == k for r in rows) for k in dict.fromkeys(r["outcome"] for r in rows)
    }
    ratios = [r["ratio"] for r in rows if r["ratio"] != ""]
    within = sum(1 / 3 <= x <= 3 for x in ratios)
    lines = [f"{len(rows)} scenes: " + ", ".join(f"{v} {k}" for k, v in count.items())]
    if ratios:
        lines.append(
            f"time / estimate: {min(ratios):.2f} .. {max(ratios):.2f}, within 3x: "
            f"{within} of {len(ratios)}"
        )
    return "\n".join(lines)


WARM_UP = """
duration = 0.01
[plate]
model = "{model}"
inclination = {incline}
{fmax}
[[balls]]
name = "b"
material = "coal"
radius = 0.02
position = [0.0, 0.0, 0.021]
velocity = [0.0, 0.0, -1.0]
"""


def warm_up(folder: Path) -> None:
    """Compile the kernels (rigid, coupled, stream) before the clock runs: the first run in a
    fresh cache compiles them (~30 s each), which no estimate of a run includes."""
    for model, incline in (("rigid", 0.0), ("modal", 0.0), ("rigid", 10.0), ("modal", 10.0)):
        fmax = "fmax = 1500.0" if model == "modal" else ""
        (folder / "warm.toml").write_text(WARM_UP.format(model=model, incline=incline, fmax=fmax))
        with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
            main(["simulate", str(folder / "warm.toml"), "--out", str(folder / "run")])


def run(out: Path, scenes: int, size: str, first: int) -> list:
    out.mkdir(parents=True, exist_ok=True)
    warm_up(out)
    rows = []
    for seed in range(first, first + scenes):
        rows.append(one(seed, size, out))
        r = rows[-1]
        print(f"seed {seed}: {r['outcome']} {r['wall_s']} s (estimate {r['estimate_s']} s)")
    with open(out / "fuzz.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("--scenes", type=int, default=40)
    parser.add_argument("--size", choices=("small", "full"), default="small")
    parser.add_argument("--first", type=int, default=1)
    args = parser.parse_args()
    rows = run(args.out, args.scenes, args.size, args.first)
    print(tally(rows))
    sys.exit(0 if not any("after" in r["outcome"] or "but" in r["outcome"] for r in rows) else 1)
