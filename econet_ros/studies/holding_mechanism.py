"""E5, what holding is (docs/preregistrations.md, "E5: what holding is", registered 2026-12-07
before any champion's activations were read): the units have no biases, so an output rests at
exactly 0.5 (eye still, flexor equal to extensor) when every unit of the last hidden layer
feeding it is silent. A champion *silences its last layer on touch* when, over its
last-generation trials replayed exactly, the median over its contact cycles (observation touch
= 1) of the largest last-layer activation is below THRESHOLD. E5 predicts that most holding
champions silence, and more often than brushing ones. ROS-free."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..controllers import Controller, FeedForwardNetwork
from ..evolution import generation_setups, genome_weights
from ..plugins import make_controller
from ..run_folders import RunData
from ..science import holding
from ..science.stats import share, share_difference
from ..science.sweeps.outcomes import run_holding
from ..science.verdicts import MOST, Criterion, decide
from ..trials import run_trials
from ..world import World

THRESHOLD = 0.05                 # a tenth of a unit's rest (0.5): logistic(-2.94)
THRESHOLD_READINGS = (0.02, 0.1)  # read beside the registered verdict, never instead of it
SHARE_GAP_MARGIN = 0.2           # holders - brushers: a smaller gap in share does not matter
COLUMNS = ("run", "architecture", "class", "contact_cycles", "median_largest_on_contact",
           "replay_fitness", "stored_fitness")


# -- activations -------------------------------------------------------------------------------
def layer_activations(network: FeedForwardNetwork, weights: np.ndarray,
                      inputs: np.ndarray) -> np.ndarray:
    """The whole activation buffer (n, buffer_size) for inputs (n, n_inputs) and per-row weights
    (n, full weight vector): what forward_block computes, in NumPy, so that a hidden layer
    can be read (the engine keeps only the outputs)."""
    inputs = np.asarray(inputs, dtype=float)
    buffer = np.zeros((len(inputs), network.buffer_size))
    buffer[:, :inputs.shape[1]] = inputs
    w = 0
    for start, stop, out, end in network.layers:
        count = (stop - start) * (end - out)
        layer = weights[:, w:w + count].reshape(len(inputs), end - out, stop - start)
        total = np.einsum("nui,ni->nu", layer, buffer[:, start:stop])
        buffer[:, out:end] = 1.0 / (1.0 + np.exp(-total))
        w += count
    return buffer


def last_hidden(network: FeedForwardNetwork) -> slice:
    """The buffer rows of the last hidden layer: the layer the outputs read."""
    start, stop = network.layers[-1, :2]
    return slice(int(start), int(stop))


class ContactRecorder(Controller):
    """The network driving each cycle itself (its own outputs), keeping on every cycle whose
    observation has touch the largest activation of its last hidden layer, per environment."""

    def __init__(self, network: FeedForwardNetwork):
        super().__init__(network.n_envs, network.config)
        self.network = network
        self.largest: list[np.ndarray] = []    # per contact cycle: (largest, environment)

    def act(self, obs) -> np.ndarray:
        touching = np.flatnonzero(obs.touch > 0.5)
        if len(touching):
            weights = np.repeat(self.network.weights, self.network.block, axis=0)[touching]
            buffer = layer_activations(self.network, weights, obs.network_input()[touching])
            self.largest.append(np.column_stack([buffer[:, last_hidden(self.network)]
                                                 .max(axis=1), touching]))
        return self.network.act(obs)

    def on_contact(self) -> np.ndarray:
        """The largest last-layer activation of every contact cycle recorded."""
        return np.concatenate(self.largest)[:, 0] if self.largest else np.zeros(0)


# -- a champion --------------------------------------------------------------------------------
def champion_index(data: RunData, generation: int) -> int:
    """The champion's place in its generation (its trials' places when trials are not shared)."""
    genomes, champion = data.genomes(generation), data.best_genomes()[generation]
    return int(np.flatnonzero((genomes == champion).all(axis=1))[0])


def replay(data: RunData) -> tuple[ContactRecorder, int, int]:
    """The champion of the last generation on that generation's own trials, recorded: the
    recorder, the replay's fitness and the fitness stored for it (equal when exact)."""
    config, last = data.config, data.generations_done - 1
    trials, index = config.evolution.trials, champion_index(data, last)
    network = make_controller(config.evolution.condition, trials, config)
    network.load(genome_weights(config, data.best_genomes()[last][None]))
    recorder = ContactRecorder(network)
    setups = generation_setups(config, data.seed, data.run, last)
    measures, _ = run_trials(World(trials, config.model), recorder,
                             setups.take(np.arange(index * trials, (index + 1) * trials)),
                             config.evolution.cycles)
    return recorder, int(np.sum(measures.fitness)), int(data.fitness()[last][index])


def champion_row(folder: Path) -> dict:
    """One run's row of E5's table: its class (holding.py, late window), its champion's contact
    cycles and median largest last-layer activation on contact (NaN without contact)."""
    data = RunData(folder)
    recorder, fitness, stored = replay(data)
    largest = recorder.on_contact()
    return {"run": str(folder), "architecture": data.config.evolution.condition,
            "class": run_holding(Path(folder), data.config.evolution.generations),
            "contact_cycles": len(largest),
            "median_largest_on_contact": float(np.median(largest)) if len(largest) else math.nan,
            "replay_fitness": fitness, "stored_fitness": stored}


# -- the rule ----------------------------------------------------------------------------------
def silences(row: dict, threshold: float = THRESHOLD) -> float:
    """1.0 when the champion silences its last layer on touch, 0.0 when not, NaN without a
    contact cycle (it cannot be told, and is left out of the shares)."""
    median = row["median_largest_on_contact"]
    return math.nan if not np.isfinite(median) else float(median < threshold)


def flags(rows: list[dict], kind: str, threshold: float = THRESHOLD) -> list[float]:
    return [silences(r, threshold) for r in rows if r["class"] == kind]


def criteria(rows: list[dict], threshold: float = THRESHOLD) -> dict[str, Criterion]:
    """E5-S: most holding champions silence (Clopper-Pearson share above one half); E5-D: the
    share silencing, holders - brushers, above 0 (Newcombe; absent within the margin)."""
    holders, brushers = (flags(rows, kind, threshold) for kind in (holding.HOLDS,
                                                                   holding.BRUSHES))
    return {"E5-S": Criterion("share of holding champions silencing their last layer on touch",
                              share(holders), low=MOST),
            "E5-D": Criterion("share silencing, holders - brushers",
                              share_difference(holders, brushers), low=0.0,
                              margin=SHARE_GAP_MARGIN, null=True)}


def verdict(rows: list[dict], threshold: float = THRESHOLD) -> tuple[str, float]:
    """E5's four-way verdict and its p-value: replicates when both E5-S and E5-D do."""
    return decide(list(criteria(rows, threshold).values()))
