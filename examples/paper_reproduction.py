"""Reproduce the paper's rigid-plate study (sections 4.1-4.3) and check its claims.

Two coal/gangue balls (R = 0.03 m, Table 1) fall on a rigid carbon-steel plate; the contact is
the Adams IMPACT law with Hertz stiffness. ``main()`` runs the three scenarios with the default
contact settings and returns the results and the checked claims; ``visualize()`` plots the
analogues of the paper's Figs. 2-10 (only when run as a script).

    python examples/paper_reproduction.py
"""

from tailbeam.paper import claims as claims_mod
from tailbeam.paper.scenarios import SCENARIOS, run_all
from tailbeam.scene import ContactSettings


def main(contact: ContactSettings | None = None):
    """Run scenarios 4.1-4.3; return (results by scenario key, list of Claim)."""
    results = run_all(contact)
    claims = claims_mod.evaluate(results)
    for c in claims:
        print(f"{'PASS' if c.passed else 'FAIL'}  {c.id:30s} {c.numbers(3)}")
    for key, result in results.items():
        for ball in result.particles:
            first = result.impacts_of(ball.name)[0]
            print(
                f"{key:9s} {ball.name:10s} impact {first.v_in:.4f} m/s -> restitution "
                f"{first.restitution:.3f}, peak force {first.peak_force:.0f} N, "
                f"{len(result.impacts_of(ball.name))} collisions"
            )
    return results, claims


def visualize(results, out_dir="out/paper_reproduction"):
    """Write the position, velocity and force figures of every scenario to ``out_dir``."""
    from pathlib import Path

    from tailbeam.paper.figures import scenario_figures

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for key, result in results.items():
        scenario = SCENARIOS[key]
        paths += scenario_figures(result, scenario, out, sample_rate=scenario.sample_rate)
    print("figures:", ", ".join(str(p) for p in paths))
    return paths


if __name__ == "__main__":
    results, _ = main()
    visualize(results)
