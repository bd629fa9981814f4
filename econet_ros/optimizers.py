"""What breeds each generation from the fitness of the last: the paper's genetic algorithm, CMA-ES,
or an OpenAI-style evolution strategy (setting ``evolution.optimizer``; docs/optimizers.md).

All three run inside the same generation loop (runs.evolve_into), test the same population size
on the same trials, and write the same run folders. CMA-ES and the evolution strategy search
real weight vectors; each candidate is folded into the weight range by reflection and rounded to
the genome's grid (genome.encode), and it is those codes that are tested and stored, so every
stored fitness replays exactly, as for the GA. They store no state of their own: a resumed run
rebuilds it by replaying ask and tell with the stored fitness (no trial is run again), which
gives the same candidates bit for bit.
"""
from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np

from . import genome
from .config import Config
from .errors import ResultsError
from .evolution import SEARCH, GenerationResult, initial_genomes, next_generation, rng_for


class Optimizer(ABC):
    """Proposes one run's populations, as genome codes (population, n_weights)."""

    def __init__(self, config: Config, n_weights: int, seed: int, run: int):
        self.config, self.n_weights, self.seed, self.run = config, n_weights, seed, run

    @abstractmethod
    def first_generation(self) -> np.ndarray:
        """The population tested in generation 0."""

    @abstractmethod
    def breed(self, result: GenerationResult) -> np.ndarray:
        """The population to test next, from a tested generation."""

    def catch_up(self, fitness: np.ndarray, next_genomes: np.ndarray) -> None:
        """Take up a run after len(fitness) finished generations, given their stored fitness
        (generations, population) and the stored population to be tested next. The GA needs
        nothing: its offspring depend only on the generation before, read back from the
        folder."""


class GeneticAlgorithm(Optimizer):
    """The paper's algorithm: the best ``parents`` copied with bit-flip mutation."""

    def first_generation(self) -> np.ndarray:
        return initial_genomes(self.config, self.n_weights, self.seed, self.run)

    def breed(self, result: GenerationResult) -> np.ndarray:
        return next_generation(self.config, result, self.seed, self.run)


def fold_into_range(weights: np.ndarray, limit: float) -> np.ndarray:
    """Real weights reflected at -limit and +limit until they lie between them (a search
    beyond the range thus never meets a flat region, as clipping would make)."""
    return limit - np.abs(np.mod(weights + limit, 4 * limit) - 2 * limit)


class AskTellOptimizer(Optimizer):
    """An optimizer with a search distribution: ``ask`` for real candidates, ``tell`` their
    fitness (higher is better)."""

    @abstractmethod
    def ask(self) -> np.ndarray:
        """Candidates (population, n_weights), real weights."""

    @abstractmethod
    def tell(self, fitness: np.ndarray) -> None:
        """Learn from the fitness of the candidates of the last ``ask``."""

    def codes(self, candidates: np.ndarray) -> np.ndarray:
        """The genome codes a generation's candidates are tested as."""
        e = self.config.evolution
        return genome.encode(fold_into_range(candidates, e.weight_range), e.bits_per_weight,
                             e.weight_range, e.genome_code)

    def first_generation(self) -> np.ndarray:
        return self.codes(self.ask())

    def breed(self, result: GenerationResult) -> np.ndarray:
        self.tell(np.asarray(result.fitness, dtype=np.float64))
        return self.codes(self.ask())

    def catch_up(self, fitness: np.ndarray, next_genomes: np.ndarray) -> None:
        codes = self.first_generation()
        for row in np.asarray(fitness, dtype=np.float64):
            self.tell(row)
            codes = self.codes(self.ask())
        if not np.array_equal(codes, next_genomes):
            raise ResultsError(f"cannot resume a {self.config.evolution.optimizer} run after "
                               f"{len(fitness)} generations: replaying its stored fitness does "
                               "not give its stored population (another numpy or cma version?)"
                               "; start it again in a new folder")


class CMAES(AskTellOptimizer):
    """CMA-ES (Hansen's ``cma`` package, its default settings) with lambda = population, from
    the origin with step size ``cmaes_sigma``; its normal samples come from the run's SEARCH
    stream, so it touches no global random state."""

    def __init__(self, config: Config, n_weights: int, seed: int, run: int):
        super().__init__(config, n_weights, seed, run)
        import cma   # only runs that use it pay for the import

        rng = rng_for(seed, run, 0, SEARCH)
        e = config.evolution
        self.strategy = cma.CMAEvolutionStrategy(np.zeros(n_weights), e.cmaes_sigma, {
            "popsize": e.population, "seed": np.nan,
            "randn": lambda *shape: rng.standard_normal(shape),
            "verbose": -9, "verb_log": 0, "verb_disp": 0})
        self.candidates: list[np.ndarray] = []

    def ask(self) -> np.ndarray:
        self.candidates = self.strategy.ask()
        return np.array(self.candidates)

    def tell(self, fitness: np.ndarray) -> None:
        self.strategy.tell(self.candidates, list(-fitness))   # cma minimises


class EvolutionStrategy(AskTellOptimizer):
    """The evolution strategy of Salimans et al. (2017): population/2 antithetic pairs
    theta +- es_sigma * eps with eps ~ N(0, I); fitness shaped to centred ranks in [-0.5, 0.5];
    the gradient estimate sum_k rank_k eps_k / (population * es_sigma) moves theta by Adam
    (step size es_learning_rate, beta 0.9 / 0.999). theta starts at the origin."""

    BETA1, BETA2, EPSILON = 0.9, 0.999, 1e-8

    def __init__(self, config: Config, n_weights: int, seed: int, run: int):
        super().__init__(config, n_weights, seed, run)
        self.rng = rng_for(seed, run, 0, SEARCH)
        self.theta = np.zeros(n_weights)
        self.moment1 = np.zeros(n_weights)
        self.moment2 = np.zeros(n_weights)
        self.steps = 0
        self.noise = np.zeros((0, n_weights))

    def ask(self) -> np.ndarray:
        e = self.config.evolution
        self.noise = self.rng.standard_normal((e.population // 2, self.n_weights))
        return np.concatenate([self.theta + e.es_sigma * self.noise,
                               self.theta - e.es_sigma * self.noise])

    def tell(self, fitness: np.ndarray) -> None:
        e = self.config.evolution
        shaped = centred_ranks(fitness)
        pairs = len(self.noise)
        gradient = (shaped[:pairs] - shaped[pairs:]) @ self.noise / (len(fitness) * e.es_sigma)
        self.steps += 1
        self.moment1 = self.BETA1 * self.moment1 + (1 - self.BETA1) * gradient
        self.moment2 = self.BETA2 * self.moment2 + (1 - self.BETA2) * gradient ** 2
        corrected1 = self.moment1 / (1 - self.BETA1 ** self.steps)
        corrected2 = self.moment2 / (1 - self.BETA2 ** self.steps)
        self.theta = self.theta + e.es_learning_rate * corrected1 / (np.sqrt(corrected2)
                                                                      + self.EPSILON)


def centred_ranks(values: np.ndarray) -> np.ndarray:
    """Ranks scaled to [-0.5, 0.5], lowest value -0.5; tied values share their mean rank (so
    equal fitness carries no gradient)."""
    order = np.argsort(values, kind="stable")
    ranks = np.empty(len(values))
    ranks[order] = np.arange(len(values))
    _, tie_group = np.unique(values, return_inverse=True)
    ranks = (np.bincount(tie_group, ranks) / np.bincount(tie_group))[tie_group]
    return ranks / max(len(values) - 1, 1) - 0.5


OPTIMIZER_CLASSES = {"ga": GeneticAlgorithm, "cmaes": CMAES, "es": EvolutionStrategy}


def make_optimizer(config: Config, n_weights: int, seed: int, run: int) -> Optimizer:
    """The optimizer ``evolution.optimizer`` names, for one run."""
    return OPTIMIZER_CLASSES[config.evolution.optimizer](config, n_weights, seed, run)
