"""The paper's variation-and-selection algorithm.

Each generation every econet is tested on the same ``trials`` random trial starts (one batch of
population x trials environments, environment e = econet * trials + trial), the econets are
ranked by fitness, the best ``parents`` are kept and each is copied population/parents times
with mutation (genome.mutate; which reading of the paper, config evolution.mutation_mode).
Every random draw comes from a stream named by (seed, run, generation, purpose), so a run is a
pure function of its seed and can resume from any finished generation.
The loop that runs generations into a result folder is ``runs.evolve_into``; an ``Evaluator``
(the contract declared here) is what it tests populations with (``InProcessEvaluator`` here, or
the node graph's), and an optimizer (optimizers.py: this GA, or CMA-ES or an evolution strategy
in its place) what breeds them.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, Sequence, runtime_checkable

import numpy as np

from . import genome
from .config import Config
from .controllers import Controller
from .plugins import make_controller
from .trials import BehaviourRecord, Record, TrialMeasures, Trace, run_trials
from .world import TrialSetup, World, sample_setups

# Purposes of the random streams of one generation; SEARCH is the one stream of a whole run that
# CMA-ES and the evolution strategy sample from (optimizers.py; taken at generation 0).
_SETUPS, _MUTATION, _NOISE, _INITIAL, SEARCH = range(5)


def rng_for(seed: int, run: int, generation: int, purpose: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(run, generation,
                                                                         purpose)))


def noise_seed(seed: int, run: int, generation: int) -> int:
    """The seed of a generation's movement noise (used by the random-movement controller)."""
    return int(rng_for(seed, run, generation, _NOISE).integers(2 ** 63))


def genome_weights(config: Config, genomes: np.ndarray) -> np.ndarray:
    """The real-valued weights genomes code for (the one decode every caller uses)."""
    e = config.evolution
    return genome.decode(genomes, e.bits_per_weight, e.weight_range, e.genome_code)


def generation_setups(config: Config, seed: int, run: int, generation: int) -> TrialSetup:
    """A generation's trial starts, one per environment (environment e = econet * trials +
    trial): the same ``trials`` starts for every econet, or fresh ones per econet."""
    e = config.evolution
    rng = rng_for(seed, run, generation, _SETUPS)
    if e.shared_trials:
        shared = sample_setups(rng, e.trials, config.model)
        return shared.take(np.tile(np.arange(e.trials), e.population))
    return sample_setups(rng, e.population * e.trials, config.model)


def score_generation(config: Config, generation: int, genomes: np.ndarray,
                     measures: TrialMeasures) -> GenerationResult:
    """A tested generation from its per-environment measures (environment e = econet *
    trials + trial), however the trials were run: in process or through the ROS graph."""
    e = config.evolution
    shape = (e.population, e.trials)
    per_econet = TrialMeasures(*(np.asarray(v).reshape(shape) for v in vars(measures).values()))
    parents = select_parents(per_econet.fitness.sum(axis=1), e.parents)
    return GenerationResult(generation, genomes, per_econet, parents, None)


@dataclass
class GenerationResult:
    """One tested generation: per-trial measures shaped (population, trials)."""

    generation: int
    genomes: np.ndarray           # (population, n_weights) codes that were tested
    measures: TrialMeasures       # each field (population, trials)
    parents: np.ndarray           # indices of the selected econets, best first
    trace: Trace | BehaviourRecord | None   # per-cycle record, when asked for

    @property
    def fitness(self) -> np.ndarray:
        """Per-econet fitness: cycles in contact summed over its trials."""
        return self.measures.fitness.sum(axis=1)


@runtime_checkable
class Evaluator(Protocol):
    """What ``runs.evolve_into`` tests whole populations with: in process
    (``InProcessEvaluator``), through the node graph (nodes/graph_evaluator.GraphEvaluator), or
    any other engine. Every implementation must give the results of the in-process one bit for
    bit (same trial starts, weights and noise), so that a run's folder does not depend on
    where it was tested; an engine that cannot do something (e.g. record) raises an
    EconetError saying so in one line rather than returning less."""

    @property
    def n_weights(self) -> int:
        """Weights per econet (the genome's length) of the controller being evolved."""

    def trial_setups(self, seed: int, run: int, generation: int) -> TrialSetup:
        """The generation's trial starts, one per environment (environment e = econet *
        trials + trial): ``generation_setups``, so a caller can run one econet's trials again."""

    def test_generation(self, genomes: np.ndarray, seed: int, run: int, generation: int,
                        record: Record = False) -> GenerationResult:
        """Test one generation's (population, n_weights) genomes exactly as the evolutionary
        run does (``trial_setups``, ``genome_weights``, ``noise_seed``), scored by
        ``score_generation``. ``record`` is what the result's ``trace`` holds: False nothing
        (None), True the full per-cycle ``Trace``, "behaviour" the ``BehaviourRecord`` the
        study's behaviour rows are computed from."""


GenerationRequest = tuple[np.ndarray, int, int, int]    # genomes, seed, run, generation


@runtime_checkable
class BatchEvaluator(Evaluator, Protocol):
    """An Evaluator that also tests the generations of several runs at once (cuda.CudaEvaluator:
    one launch), which ``runs.evolve_together`` advances side by side."""

    def test_generations(self, requests: Sequence[GenerationRequest],
                         record: Record = False) -> list[GenerationResult]:
        """What ``test_generation(genomes, seed, run, generation, record)`` gives for each
        request, in order."""


class InProcessEvaluator(Evaluator):
    """The Evaluator of this process: owns one world and one controller sized population x
    trials and runs whole trials in trials.run_trials's compiled loop."""

    def __init__(self, config: Config, controller: Controller | None = None):
        e = config.evolution
        self.config = config
        self.n_envs = e.population * e.trials
        self.world = World(self.n_envs, config.model)
        self.controller = controller or make_controller(e.condition, self.n_envs, config)

    @property
    def n_weights(self) -> int:
        return self.controller.n_params

    def trial_setups(self, seed: int, run: int, generation: int) -> TrialSetup:
        return generation_setups(self.config, seed, run, generation)

    def test_generation(self, genomes: np.ndarray, seed: int, run: int, generation: int,
                        record: Record = False) -> GenerationResult:
        weights = genome_weights(self.config, genomes)
        self.controller.load(weights, noise_seed(seed, run, generation))  # one per econet
        measures, trace = run_trials(self.world, self.controller,
                                     self.trial_setups(seed, run, generation),
                                     self.config.evolution.cycles, record)
        result = score_generation(self.config, generation, genomes, measures)
        result.trace = trace
        return result


def initial_genomes(config: Config, n_weights: int, seed: int, run: int) -> np.ndarray:
    e = config.evolution
    return genome.random_genomes(rng_for(seed, run, 0, _INITIAL), e.population, n_weights,
                                 e.bits_per_weight)


def select_parents(fitness: np.ndarray, n_parents: int) -> np.ndarray:
    """Indices of the n_parents fittest econets, best first; ties go to the lower index."""
    return np.argsort(-fitness, kind="stable")[:n_parents]


def next_generation(config: Config, result: GenerationResult, seed: int, run: int) -> np.ndarray:
    """Offspring: each parent copied population/parents times, every copy mutated."""
    e = config.evolution
    copies = np.repeat(result.genomes[result.parents], config.offspring_per_parent, axis=0)
    rng = rng_for(seed, run, result.generation, _MUTATION)
    return genome.mutate(rng, copies, e.bits_per_weight, e.mutation_rate, e.mutation_mode,
                         e.mutation_step, e.genome_code)
