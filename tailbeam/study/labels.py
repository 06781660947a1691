"""The labels of a case: class of the balls (coal, gangue or mixed), gangue fraction and counts,
from the scene's ball labels or its streams' particles; and the labelling of a sweep's balls
by material (``[labels] coal``).
"""

import math


def case_labels(scene) -> dict:
    """Labels of a scene: class of the balls ("coal", "gangue" or "mixed"), gangue mass
    fraction, numbers of coal and gangue balls, from the scene's ball labels (the sweep sets
    them from ``labels.coal``: ``label_balls``; stream scenes: stream_labels)."""
    if scene.streams:
        return stream_labels(scene)
    is_coal = [label == "coal" for label in scene.labels]
    mass = sum(b.mass for b in scene.balls)
    gangue_mass = sum(b.mass for b, c in zip(scene.balls, is_coal, strict=True) if not c)
    n_coal = sum(is_coal)
    n_gangue = len(is_coal) - n_coal
    label = "mixed" if n_coal and n_gangue else ("coal" if n_coal else "gangue")
    return {
        "label": label,
        "gangue_fraction": gangue_mass / mass,
        "n_coal": n_coal,
        "n_gangue": n_gangue,
    }


def label_balls(data: dict, coal: tuple) -> None:
    """Give every ``[[balls]]`` table of the raw scene ``data`` that has no ``label`` the
    label of its material: coal if it is in ``coal``, else gangue (in place). The scene
    TOML then carries it where it differs from the default
    (tailbeam.streams.generator.default_label), and every output (impacts.csv's ``label``)
    agrees with the sweep's labels."""
    balls = data.get("balls")
    for ball in balls if isinstance(balls, list) else []:
        if isinstance(ball, dict) and "label" not in ball and isinstance(ball.get("material"), str):
            ball["label"] = "coal" if ball["material"] in coal else "gangue"


def stream_labels(scene) -> dict:
    """Labels of a scene with streams, from its particles (each labelled coal or gangue by
    its stream, [[balls]] by their label): ``label`` (coal, gangue or mixed), ``gangue_fraction``
    = the streams' declared gangue_fraction (the probability that a particle is gangue;
    several streams: weighted by their expected particle counts; [[balls]] not included),
    ``gangue_mass_fraction`` (realised, by mass, all particles released before the end),
    ``n_coal``, ``n_gangue``, ``n_particles`` (particles, [[balls]] included)."""
    parts = scene.particles
    gangue = [p for p in parts if p.label == "gangue"]
    expected = [max(n, 0.0) for n in scene.expected_particles()]
    declared = sum(n * s.gangue_fraction for n, s in zip(expected, scene.streams, strict=True))
    mass = sum(p.mass for p in parts)
    n_gangue = len(gangue)
    n_coal = len(parts) - n_gangue
    return {
        "label": "mixed" if n_coal and n_gangue else ("gangue" if n_gangue else "coal"),
        "gangue_fraction": declared / sum(expected) if sum(expected) > 0 else math.nan,
        "n_coal": n_coal,
        "n_gangue": n_gangue,
        "gangue_mass_fraction": sum(p.mass for p in gangue) / mass if mass > 0 else math.nan,
        "n_particles": len(parts),
    }
