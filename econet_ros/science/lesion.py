"""The paper's proprioceptive lesion: evolved networks tested again with every connection from
the proprioceptive input units severed (paper: Stereotyped approach movements). ROS-free."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..config import Config
from ..controllers import FeedForwardNetwork
from ..evolution import genome_weights, rng_for, select_parents
from ..plugins import make_controller
from ..run_folders import RunData
from ..trials import Trace, run_trials
from ..world import TrialSetup, World, sample_setups
from .measures import summarize_reaches

LESION_TRIALS = 50     # fresh trials per selected econet in the lesion test
LESION_PURPOSE = 7     # random stream (evolution.rng_for) used for the lesion trials


def input_weight_mask(config: Config, condition: str, sense: str = "proprio") -> np.ndarray:
    """Bool mask over a condition's flat weight vector: True for every weight leaving one of the
    four proprioceptive input units (sense "proprio") or the visual ones ("vision"), as the
    network lays its weights out (controllers.FeedForwardNetwork.weights_reading)."""
    network = make_controller(condition, 1, config)
    if not isinstance(network, FeedForwardNetwork):
        raise ValueError(f"no input weights in condition '{condition}'")
    return network.weights_reading(sense)


def proprioceptive_weight_mask(config: Config, condition: str) -> np.ndarray:
    return input_weight_mask(config, condition, "proprio")


def sever(weights: np.ndarray, config: Config, condition: str, sense: str) -> np.ndarray:
    """Copy of (n, W) weights with one sense's outgoing weights set to zero."""
    out = np.array(weights, dtype=np.float64, copy=True)
    out[:, input_weight_mask(config, condition, sense)] = 0.0
    return out


def sever_proprioception(weights: np.ndarray, config: Config, condition: str) -> np.ndarray:
    """Copy of (n, W) weights with the proprioceptive inputs' outgoing weights set to zero."""
    return sever(weights, config, condition, "proprio")


def run_networks(config: Config, condition: str, weights: np.ndarray, setup: TrialSetup,
                 trials: int) -> Trace:
    """Run each of the (k, W) networks on the same ``trials`` trial starts (setup has
    ``trials`` entries); environment e = network * trials + trial."""
    k = weights.shape[0]
    n = k * trials
    world = World(n, config.model)
    controller = make_controller(condition, n, config)
    controller.load(np.repeat(weights, trials, axis=0), 0)
    _, trace = run_trials(world, controller, setup.take(np.tile(np.arange(trials), k)),
                          config.evolution.cycles, record=True)
    return trace


def lesion_study(run_dirs: list[Path]) -> list[dict]:
    """Final top-20 econets of each normal run, intact, with proprioception severed
    ("lesioned") and, as a control, with vision severed ("vision-lesioned"), on fresh trials
    (LESION_TRIALS per econet). Returns one dict per run."""
    out = []
    for path in run_dirs:
        run = RunData(path)
        g = run.generations_done - 1
        if g < 0:
            continue
        config: Config = run.config
        e = config.evolution
        parents = select_parents(run.fitness()[g], e.parents)
        weights = genome_weights(config, run.genomes(g)[parents])
        setup = sample_setups(rng_for(run.seed, run.run, e.generations, LESION_PURPOSE),
                              LESION_TRIALS, config.model)
        traces = {kind: run_networks(config, "normal", changed, setup, LESION_TRIALS)
                  for kind, changed in (
                      ("intact", weights),
                      ("lesioned", sever(weights, config, "normal", "proprio")),
                      ("vision-lesioned", sever(weights, config, "normal", "vision")))}
        out.append({"run": path.name, "generation": g, "traces": traces,
                    "radius": config.model.object_radius,
                    **{k: summarize_reaches(t) for k, t in traces.items()}})
    return out


