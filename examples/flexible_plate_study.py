"""The paper's three scenarios on a flexible tail beam: what changes when the plate can vibrate.

    python examples/flexible_plate_study.py [--quick] [--out DIR]

The paper (sections 4.1-4.3) drops two balls (R = 0.03 m, Table 1) on a rigid 0.6 x 0.6 x 0.01 m
steel plate. Here the same scenes (tailbeam.paper.scenarios: drop gap, c, d, durations) run on the
simply supported plate (SSSS: a panel bolted/pinned along its edges, the classic choice and the
one with an exact check) with FE modes up to 20 kHz (the sensor band; Mindlin, chosen by
tailbeam.plate from the band; ~40 s the first time, then cached), two-way coupled, 1 % modal
damping, and again one-way (rigid-plate forces fed to the plate). For each
ball: first-impact restitution, peak force, contact duration, bounces within the run, rest time.

Zener (1941): a ball on an infinite plate loses the energy the plate radiates, set by the
inelasticity lambda (tailbeam.solvers.coupled.zener). With c = 0 the study checks our restitution at
the plate centre against the Zener ODE, and then asks whether the ranking of energy loss between
coal and sandstone (rigid plate: set by the contact damping c) survives on the flexible plate.

Finally one accelerometer (0, 0.15) m, 51.2 kHz, records coal and sandstone dropped alone at the
same point at 1 m/s: time series and one-sided amplitude spectra side by side.
"""

import argparse
from pathlib import Path

import numpy as np

from tailbeam.paper.scenarios import SCENARIOS
from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.materials import CARBON_STEEL, COAL, SANDSTONE
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.scene import ContactSettings
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.coupled.zener import point_impedance, zener_impact
from tailbeam.solvers.rigid import simulate_rigid

FMAX_HZ = 20000.0
SENSOR = SensorSpec("S1", (0.0, 0.15))
R = 0.03


def _impact_numbers(result, name):
    impacts = result.impacts_of(name)
    first = impacts[0]
    return {
        "restitution": first.restitution,
        "peak_force_N": first.peak_force,
        "contact_duration_s": first.t_end - first.t_start,
        "bounces": len(impacts),
        "rest_time_s": result.states.rest_time[name],
        "energy_loss_first": 1.0 - first.restitution**2,
    }


def zener_check(plate: Plate, basis) -> dict:
    """c = 0 impacts at the plate centre, 1 m/s, vs the Zener ODE, for coal and sandstone."""
    out = {}
    for mat in (COAL, SANDSTONE):
        ball = Ball(mat.name, mat, R, (0.0, 0.0, R + 1e-5), (0.0, 0.0, -1.0))
        law = ball_plate_law(mat, R, plate.material, damping=0.0)
        res = simulate_coupled([ball], basis, [law], 1.5e-3, gravity=0.0, damping_ratio=0.0)
        ref = zener_impact(ball.mass, 1.0, law.stiffness, point_impedance(plate))
        imp = res.impacts[0]
        out[mat.name] = {
            "lambda": ref.lam,
            "restitution_zener": ref.restitution,
            "restitution_ours": imp.restitution,
            "duration_zener_s": ref.duration,
            "duration_ours_s": imp.t_end - imp.t_start,
        }
    return out


def first_impact_losses(basis, contact, scenario) -> dict:
    """Each ball of ``scenario`` dropped alone at its place and speed: first-impact energy loss
    (1 - e^2) on the rigid plate and on the flexible plate (no cross-talk between the balls)."""
    out = {}
    for ball in scenario.scene(contact).balls:
        law = contact.law_for(ball, CARBON_STEEL)
        rigid = simulate_rigid([ball], basis.plate, [law], 0.03)
        flex = simulate_coupled([ball], basis, [law], 0.03)
        out[ball.name] = {
            "rigid": 1.0 - rigid.impacts[0].restitution ** 2,
            "two_way": 1.0 - flex.impacts[0].restitution ** 2,
        }
    return out


def make_basis(plate: Plate, quick: bool):
    """Quick: exact Kirchhoff SSSS modes to 10 kHz. Full: the FE modes to 20 kHz with the theory
    chosen from the band (Mindlin there: Kirchhoff is 15 % stiff at 20 kHz), cached."""
    if quick:
        return ssss_kirchhoff_basis(plate, 10000.0)
    from tailbeam.plate import compute_modes

    return compute_modes(plate, "SSSS", theory="auto", fmax_hz=FMAX_HZ)


def run_study(quick: bool = False):
    """(numbers, artefacts): numbers for main(), arrays for visualize()."""
    plate = Plate()
    basis = make_basis(plate, quick)
    contact = ContactSettings()
    numbers = {
        "basis": {
            "theory": basis.theory,
            "n_modes": basis.n_modes,
            "fmax_hz": float(basis.frequencies_hz[-1]),
        }
    }
    # Zener's ODE is the infinite *Kirchhoff* plate: check against the exact Kirchhoff modes
    numbers["zener"] = zener_check(plate, ssss_kirchhoff_basis(plate, FMAX_HZ))
    artefacts = {"forces": {}}
    numbers["scenarios"] = {}
    for key, scenario in SCENARIOS.items():
        scene = scenario.scene(contact, duration=0.3 if quick else None)
        laws = scene.laws()
        rigid = simulate_rigid(scene.balls, plate, laws, scene.duration)
        two = simulate_coupled(scene.balls, basis, laws, scene.duration)
        one = simulate_coupled(scene.balls, basis, laws, scene.duration, coupling="one-way")
        entry = {}
        for ball in scene.balls:
            entry[ball.name] = {
                "rigid": _impact_numbers(rigid, ball.name),
                "two_way": _impact_numbers(two, ball.name),
                "one_way": _impact_numbers(one, ball.name),
            }
        numbers["scenarios"][key] = entry
        # first-contact force histories for the figure
        t0 = min(i.t_start for i in two.impacts) - 5e-5
        t = np.linspace(t0, t0 + 6e-4, 1201)
        artefacts["forces"][key] = (t, rigid.sample(t), two.sample(t))
    # energy-loss ranking in the first impact, each ball alone (section 4.3 equal-energy speeds)
    losses = first_impact_losses(basis, contact, SCENARIOS["energy"])
    numbers["first_impact_loss"] = losses
    numbers["ranking"] = {
        model: max(losses, key=lambda name, m=model: losses[name][m])
        for model in ("rigid", "two_way")
    }
    # one sensor, each ball alone at the same point, 1 m/s
    numbers["sensor"] = {}
    artefacts["sensor"] = {}
    duration = 0.1 if quick else 0.25
    for mat in (COAL, SANDSTONE):
        ball = Ball(mat.name, mat, R, (0.15, 0.0, R + 0.01), (0.0, 0.0, -1.0))
        law = contact.law_for(ball, CARBON_STEEL)
        res = simulate_coupled([ball], basis, [law], duration, sensors=(SENSOR,))
        out = res.sensor_outputs[SENSOR.name]
        band = (out.freq > 20.0) & (out.freq < out.chain.bandwidth_hz)
        numbers["sensor"][mat.name] = {
            "peak_acceleration": float(np.max(np.abs(out.acceleration))),
            "rms_acceleration": float(np.sqrt(np.mean(out.acceleration**2))),
            "dominant_frequency_hz": float(out.freq[band][np.argmax(out.amplitude[band])]),
            "spectral_centroid_hz": float(
                np.sum(out.freq[band] * out.amplitude[band] ** 2) / np.sum(out.amplitude[band] ** 2)
            ),
        }
        artefacts["sensor"][mat.name] = out
    return numbers, artefacts


def main(quick: bool = False) -> dict:
    """The study's numbers (see the module docstring)."""
    return run_study(quick)[0]


def visualize(numbers, artefacts, out_dir: Path) -> list:
    """Figures: sensor time/spectrum (coal vs sandstone), first-contact forces rigid vs flexible."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir.mkdir(parents=True, exist_ok=True)
    files = []
    fig, axes = plt.subplots(2, 2, figsize=(11, 6.5), constrained_layout=True)
    for row, (name, out) in enumerate(artefacts["sensor"].items()):
        axes[row, 0].plot(out.t * 1e3, out.acceleration, lw=0.6)
        axes[row, 0].set(xlabel="t (ms)", ylabel="a (m/s$^2$)", title=f"{name}: sensor S1")
        axes[row, 1].semilogy(out.freq / 1e3, np.maximum(out.amplitude, 1e-6), lw=0.6)
        axes[row, 1].set(xlabel="f (kHz)", ylabel="|A| (m/s$^2$)", title=f"{name}: spectrum")
        axes[row, 1].set_xlim(0, out.chain.bandwidth_hz / 1e3)
    files.append(out_dir / "flexible_sensor.png")
    fig.savefig(files[-1], dpi=120)
    plt.close(fig)
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), constrained_layout=True)
    for ax, (key, (t, rig, two)) in zip(axes, artefacts["forces"].items(), strict=True):
        for name in rig:
            ax.plot(t * 1e3, rig[name]["force"], "--", lw=1, label=f"{name} rigid")
            ax.plot(t * 1e3, two[name]["force"], lw=1, label=f"{name} flexible")
        ax.set(xlabel="t (ms)", ylabel="F (N)", title=f"{SCENARIOS[key].section} first contact")
        ax.legend(fontsize=7)
    files.append(out_dir / "flexible_forces.png")
    fig.savefig(files[-1], dpi=120)
    plt.close(fig)
    return files


def _print(numbers):
    print(f"basis: {numbers['basis']}")
    for mat, z in numbers["zener"].items():
        print(f"Zener {mat}: lambda {z['lambda']:.3f}, e {z['restitution_ours']:.4f} "
              f"(ODE {z['restitution_zener']:.4f})")  # fmt: skip
    for key, entry in numbers["scenarios"].items():
        for name, models in entry.items():
            for model, v in models.items():
                print(f"{key:9s} {name:10s} {model:8s} e1 {v['restitution']:.3f}  "
                      f"F1 {v['peak_force_N']:7.1f} N  T1 {v['contact_duration_s'] * 1e6:6.1f} us  "
                      f"bounces {v['bounces']:3d}  rest {v['rest_time_s']:.3f} s")  # fmt: skip
    print(f"first-impact energy loss, balls alone (4.3): {numbers['first_impact_loss']}")
    print(f"larger first-impact energy loss (4.3): {numbers['ranking']}")
    for name, v in numbers["sensor"].items():
        print(f"sensor {name}: {v}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default="out/flexible_plate_study")
    args = parser.parse_args()
    nums, arts = run_study(args.quick)
    _print(nums)
    for f in visualize(nums, arts, Path(args.out)):
        print("wrote", f)
