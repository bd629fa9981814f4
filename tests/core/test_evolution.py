"""Selection, offspring, determinism and learning of the evolutionary algorithm."""
import numpy as np

from econet_ros import genome
from econet_ros.config import Config
from econet_ros.evolution import GenerationResult, next_generation, select_parents
from econet_ros.runs import evolve_into
from econet_ros.trials import TrialMeasures


def small_config(**changes):
    settings = {"evolution.population": 20, "evolution.parents": 4, "evolution.trials": 5,
                "evolution.cycles": 40, "evolution.generations": 4}
    settings.update(changes)
    return Config().replace(**settings)


def test_selection_keeps_the_best_and_breaks_ties_by_position():
    fitness = np.array([5, 9, 1, 9, 7, 0])
    np.testing.assert_array_equal(select_parents(fitness, 3), [1, 3, 4])


def test_offspring_are_five_copies_of_each_of_the_best_twenty():
    config = Config().replace(**{"evolution.mutation_rate": 0.0})
    rng = np.random.default_rng(3)
    genomes = genome.random_genomes(rng, 100, 10, 8)
    fitness = rng.permutation(100)
    measures = TrialMeasures(fitness[:, None], fitness[:, None] > 0, fitness[:, None],
                             fitness[:, None])
    parents = select_parents(fitness, 20)
    result = GenerationResult(0, genomes, measures, parents, None)
    offspring = next_generation(config, result, seed=1, run=1)
    assert offspring.shape == genomes.shape
    for k, parent in enumerate(parents):
        np.testing.assert_array_equal(offspring[5 * k:5 * k + 5],
                                      np.repeat(genomes[parent][None], 5, axis=0))
    assert set(parents) == set(np.argsort(-fitness)[:20])


def collect(config, seed, run, folder):
    rows = []
    evolve_into(folder, config, seed, run, on_generation=lambda result, offspring: rows.append(
        (result.fitness.copy(), offspring.copy())))
    return rows


def test_a_run_is_determined_by_its_seed(tmp_path):
    config = small_config()
    first, again, other = (collect(config, seed, 1, tmp_path / name)
                           for seed, name in ((7, "a"), (7, "b"), (8, "c")))
    for (f1, g1), (f2, g2) in zip(first, again):
        np.testing.assert_array_equal(f1, f2)
        np.testing.assert_array_equal(g1, g2)
    assert any(not np.array_equal(a[1], b[1]) for a, b in zip(first, other))


def test_normal_condition_clearly_beats_random_movement(tmp_path):
    def late_top_fitness(condition):
        config = Config().replace(**{"evolution.condition": condition,
                                     "evolution.generations": 30})
        late = []
        evolve_into(tmp_path / condition, config, 1, 1, on_generation=lambda r, o: late.append(
            r.fitness[r.parents].mean()) if r.generation >= 20 else None)
        return np.mean(late)

    normal, random = late_top_fitness("normal"), late_top_fitness("random")
    assert normal > 3 * random, (normal, random)
