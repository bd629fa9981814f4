"""The engine against a plain, independent reading of the model (econet_ros/reference):
for the same weights and trial starts, every trial's fitness, success, latency and separations,
and its whole course (states, outputs and contact cycle by cycle), under every setting that
changes the physics. The graph and the Gymnasium env run the engine's kernels; this is what
checks those kernels against the paper and docs/assumptions.md.

The two readings compute geometry differently (the reference in the workspace's frame with
libm's trigonometry), so their states agree to about 1e-13 degrees a cycle. A network's
feedback may amplify that smoothly ('drift': in a chaotic econet by about 1.45 a cycle; 2 of
5,640 trials, 15 times as many as below from other starts, ended more than 1e-6 degrees apart,
24 when the default four-layer net was 4/4/8, none with other measures). Courses may jump apart only where such a rounding sits on a boundary of the model
(the hand at the object's edge; a move at a whole-degree step or a joint limit; a point on a
window edge): each jump is found, explained by how near the reference stood to that boundary
(within what the drift can move it), counted, and must be rare. In those 5,640 trials there
was none.
"""
from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from econet_ros import genome
from econet_ros.config import Config
from econet_ros.evolution import (InProcessEvaluator, genome_weights, initial_genomes,
                                  next_generation)
from econet_ros.plugins import make_controller
from econet_ros.reference import model as ref
from econet_ros.reference.partings import (CONTACT_EDGE, STATE_TOLERANCE, boundary_kind,
                                           first_parting)
from econet_ros.science.reference_check import engine_senses
from econet_ros.trials import run_trials
from econet_ros.world import World, sample_setups

CYCLES = 100
SETTINGS = {
    "default": {},
    "forward shoulder": {"model.shoulder_convention": "forward"},
    "body within 360": {"model.body_axis": "within-360"},
    "extended start": {"model.start_posture": "extended"},
    "bigger object, nearer": {"model.object_radius": 4.0, "model.reach_min": 5.0,
                              "model.reach_max": 30.0},
    "wider field, shorter sight": {"model.field_of_view_deg": 96.0,
                                   "model.windows_per_unit": 12, "model.visual_range": 40.0},
    "four visual units": {"model.visual_units": 4, "model.windows_per_unit": 16},
    "faster moves": {"model.max_rotation_deg": 25.0},
    "joints to 150": {"model.joint_max_deg": 150.0},
    "other arm": {"model.segment_length": 20.0, "model.hand_length": 8.0,
                  "model.reach_max": 38.0},
    "whole degrees, rounded": {"model.angle_steps": "round"},
    "whole degrees, truncated": {"model.angle_steps": "truncate"},
    "limit cancels": {"model.joint_limit": "cancel"},
    "all new readings, forward": {"model.angle_steps": "round", "model.joint_limit": "cancel",
                                  "model.shoulder_convention": "forward",
                                  "model.body_axis": "within-360"},
}


@pytest.fixture(scope="module")
def champions() -> dict[str, np.ndarray]:
    """The best econet of a short evolution per network (random nets rarely touch)."""
    best = {}
    for condition in ("normal", "three-layer"):
        config = Config().replace(**{"evolution.condition": condition,
                                     "evolution.population": 50, "evolution.parents": 10,
                                     "evolution.trials": 10})
        evaluator = InProcessEvaluator(config)
        genomes = initial_genomes(config, evaluator.n_weights, 1, 1)
        for generation in range(15):
            result = evaluator.test_generation(genomes, 1, 1, generation)
            genomes = next_generation(config, result, 1, 1)
        best[condition] = genome_weights(config, result.genomes[result.parents[0]])
    return best


def controllers(config: Config, champions) -> list[tuple[str, np.ndarray | None, int]]:
    """(condition, weights or None for random movement, trials) to compare: the champions
    where their weights fit the network, random weights, and random movement."""
    rng = np.random.default_rng(11)
    chosen = [(c, w, 8) for c, w in champions.items()
              if len(w) == make_controller(c, 1, config).n_params]
    for condition in ("normal", "three-layer"):
        n_weights = make_controller(condition, 1, config).n_params
        codes = genome.random_genomes(rng, 1, n_weights, 8)[0]
        chosen.append((condition, genome.decode(codes, 8, 10.0), 4))
    return chosen + [("random", None, 4)]


def engine_trials(config: Config, condition: str, weights, setup, noise_seed: int):
    """Per-trial measures and the trace from the engine's compiled trials, and the random
    outputs it drew (the random-movement controller's whole table, drawn at once)."""
    n = len(setup)
    controller = make_controller(condition, n, config)
    controller.load(np.zeros((1, controller.n_params)) if weights is None else weights[None],
                    noise_seed)
    table = np.random.default_rng(noise_seed).random((CYCLES, n, 5))
    measures, trace = run_trials(World(n, config.model), controller, setup, CYCLES, record=True)
    return measures, trace, table if condition == "random" else None


def compare(config: Config, condition, weights, n_trials, seed) -> tuple[Counter, list, int]:
    """Run the same trials in the engine and the reference: how many trials' courses never
    part ('same'), drift apart smoothly ('drift') or part at each kind of boundary; every
    unexplained difference; and the reference's total fitness."""
    setup = sample_setups(np.random.default_rng(seed), n_trials, config.model)
    measures, trace, table = engine_trials(config, condition, weights, setup, seed)
    kinds, unexplained, fitness = Counter(), [], 0
    for i in range(n_trials):
        start = ref.State(setup.body[i], setup.shoulder[i], setup.elbow[i])
        trial = ref.run_trial(config, condition, start, setup.object_xy[i], CYCLES, weights,
                              None if table is None else table[:, i])
        ours = (trial.fitness, trial.success, trial.latency, trial.separations)
        engine = tuple(int(getattr(measures, f)[i]) for f in
                       ("fitness", "success", "latency", "separations"))
        fitness += trial.fitness
        parting = first_parting(trace, i, trial)
        if not parting.what:
            kinds["same" if parting.drift <= STATE_TOLERANCE else "drift"] += 1
            if ours != engine:
                unexplained.append((i, "same course, other measures", ours, engine))
            continue
        kind = boundary_kind(config, trace, i, trial, setup.object_xy[i], parting,
                             engine_senses)
        kinds[kind or "unexplained"] += 1
        if kind is None:
            unexplained.append((i, parting, ours, engine))
    return kinds, unexplained, fitness


@pytest.mark.parametrize("name", SETTINGS)
def test_engine_and_reference_run_the_same_trials(name, champions):
    config = Config().replace(**SETTINGS[name])
    kinds, unexplained, n_trials, fitness = Counter(), [], 0, 0
    for k, (condition, weights, trials) in enumerate(controllers(config, champions)):
        found, bad, touched = compare(config, condition, weights, trials, seed=100 + k)
        kinds.update(found)
        n_trials, fitness = n_trials + trials, fitness + touched
        unexplained += [(condition, *b) for b in bad]
    assert not unexplained, f"{name}: engine and reference differ: {unexplained}"
    at_boundaries = n_trials - kinds["same"] - kinds["drift"]
    assert at_boundaries <= 2 and kinds["drift"] <= n_trials // 4, f"{name}: {dict(kinds)}"
    assert fitness > 0, f"{name}: no trial touched the object"


def test_a_difference_away_from_every_boundary_is_not_explained(champions):
    """The explanation can fail: the engine's course with a contact flipped where the hand is
    far from the object's edge, or a joint a degree off where no move jumps, is unexplained;
    the same contact flip with the hand on the edge is explained."""
    config, weights = Config(), champions["normal"]
    setup = sample_setups(np.random.default_rng(100), 1, config.model)
    _, trace, _ = engine_trials(config, "normal", weights, setup, 100)
    start = ref.State(setup.body[0], setup.shoulder[0], setup.elbow[0])
    trial = ref.run_trial(config, "normal", start, setup.object_xy[0], CYCLES, weights)
    assert not first_parting(trace, 0, trial).what
    row = int(np.argmax(np.abs(trial.gaps[1:]) > 1.0)) + 1       # the hand well off the edge
    flipped = trace._replace(touch=trace.touch.copy())
    flipped.touch[row, 0] = not flipped.touch[row, 0]
    parting = first_parting(flipped, 0, trial)
    assert (parting.row, parting.what) == (row, "contact")
    assert boundary_kind(config, flipped, 0, trial, setup.object_xy[0], parting,
                         engine_senses) is None
    trial.gaps[row] = 1e-12                                       # as if on the edge
    assert boundary_kind(config, flipped, 0, trial, setup.object_xy[0], parting,
                         engine_senses) == CONTACT_EDGE
    moved = trace._replace(shoulder=trace.shoulder.copy())
    moved.shoulder[row:, 0] += 1.0
    parting = first_parting(moved, 0, trial)
    assert (parting.row, parting.what) == (row, "state")
    assert boundary_kind(config, moved, 0, trial, setup.object_xy[0], parting,
                         engine_senses) is None
