"""The paper's qualitative claims (sections 4.1-4.3, conclusions 1-3) as checkable functions.

Each claim function takes the result of its scenario (a ``tailbeam.Result`` of the rigid
solver, or anything with the same ``impacts_of``, ``states.rest_time`` and ``duration``) and
returns a ``Claim``: the paper's words (short paraphrase), the quantity compared, the numbers
behind it, the threshold and whether it passed.
Where the paper is ambiguous the docstring says how we read it. Collision numbers n are 1-based
and only collisions inside the simulated time count; "after collision n" compares the two balls at
the same n for every n both balls reach. Rebound height = the apex of the ball's lowest point
above the plate after collision n (Impact.next_apex_height); rebound speed = Impact.v_out.
"""

from tailbeam.paper.claims_base import Claim
from tailbeam.paper.claims_material import (
    claim_42_coal_collides_more,
    claim_42_coal_lower,
    claim_42_coal_peak_sooner,
    claim_42_sand_decays_gently,
    claim_42_sand_faster,
    claim_42_sand_force_much_larger,
    claim_43_coal_force_smaller,
    claim_43_coal_rests_first,
    claim_43_coal_varies_more,
    claim_43_crossover,
    claim_c3_coal_loses_more,
)
from tailbeam.paper.claims_velocity import (
    claim_41_a_collides_more,
    claim_41_apex_decreasing,
    claim_41_b_higher_faster_stronger,
    claim_41_force_decreasing,
    claim_41_max_apex_b,
    claim_41_same_restitution,
    claim_41_short_contact,
    claim_c1_maxima_increase,
)

__all__ = ["Claim", "CLAIMS", "CONCLUSION_MAP", "claim_ids", "evaluate", "evaluate_one"]


# claim id -> (scenario key it is evaluated on, function), in paper order
CLAIMS = {
    "4.1-apex-decreasing": ("velocity", claim_41_apex_decreasing),
    "4.1-max-apex-B": ("velocity", claim_41_max_apex_b),
    "4.1-A-collides-more": ("velocity", claim_41_a_collides_more),
    "4.1-short-contact": ("velocity", claim_41_short_contact),
    "4.1-same-restitution": ("velocity", claim_41_same_restitution),
    "4.1-force-decreasing": ("velocity", claim_41_force_decreasing),
    "4.1-B-higher-faster-stronger": ("velocity", claim_41_b_higher_faster_stronger),
    "C1-maxima-increase": ("velocity", claim_c1_maxima_increase),
    "4.2-coal-lower": ("material", claim_42_coal_lower),
    "4.2-coal-peak-sooner": ("material", claim_42_coal_peak_sooner),
    "4.2-coal-collides-more": ("material", claim_42_coal_collides_more),
    "4.2-sand-rebounds-faster": ("material", claim_42_sand_faster),
    "4.2-sand-decays-gently": ("material", claim_42_sand_decays_gently),
    "4.2-sand-force-much-larger": ("material", claim_42_sand_force_much_larger),
    "4.3-crossover": ("energy", claim_43_crossover),
    "4.3-coal-varies-more": ("energy", claim_43_coal_varies_more),
    "4.3-coal-rests-first": ("energy", claim_43_coal_rests_first),
    "4.3-coal-force-smaller": ("energy", claim_43_coal_force_smaller),
    "C3-coal-loses-more-energy": ("energy", claim_c3_coal_loses_more),
}

# Each sentence of conclusions (1)-(3) and the claim ids that check it.
CONCLUSION_MAP = {
    "(1) velocity has greater influence on rebound distance and impact force": [
        "4.1-B-higher-faster-stronger",
        "C1-maxima-increase",
    ],
    "(1) max rebound distance and max collision force increase with initial velocity": [
        "C1-maxima-increase",
        "4.1-max-apex-B",
    ],
    "(1) after the same number of collisions the faster ball rebounds higher and faster": [
        "4.1-B-higher-faster-stronger"
    ],
    "(2) the stronger material has the greater collision force": [
        "4.2-sand-force-much-larger",
        "4.3-coal-force-smaller",
    ],
    "(2) its rebound distance and rebound velocity are larger after collision": [
        "4.2-coal-lower",
        "4.2-sand-rebounds-faster",
    ],
    "(2) its rebound velocity changes gently": ["4.2-sand-decays-gently"],
    "(2) the weaker material collides more often, with a smaller interval": [
        "4.2-coal-collides-more"
    ],
    "(3) the weaker material consumes more energy per collision": ["C3-coal-loses-more-energy"],
    "(3) so its collision force is small": ["4.3-coal-force-smaller"],
    "(3) and its rebound distance and velocity vary greatly": [
        "4.3-coal-varies-more",
        "4.3-crossover",
    ],
}


def claim_ids() -> list[str]:
    """Every claim id, in paper order."""
    return list(CLAIMS)


def evaluate_one(claim_id: str, results: dict) -> Claim:
    """Check one claim; ``results`` maps scenario key -> result of that scenario."""
    key, fn = CLAIMS[claim_id]
    return fn(results[key])


def evaluate(results: dict) -> list[Claim]:
    """Check every claim whose scenario is in ``results``."""
    return [evaluate_one(cid, results) for cid, (key, _) in CLAIMS.items() if key in results]
