"""Genomes, selection, determinism, resume and learning of the evolutionary algorithm."""
import numpy as np
import pytest

from econet_ros import genome
from econet_ros.config import Config
from econet_ros.trials import TrialMeasures
from econet_ros.evolution import Evaluator, GenerationResult, next_generation, select_parents
from econet_ros.runs import RunData, evolve_into, replay, run_condition


def small_config(**changes):
    settings = {"evolution.population": 20, "evolution.parents": 4, "evolution.trials": 5,
                "evolution.cycles": 40, "evolution.generations": 4}
    settings.update(changes)
    return Config().replace(**settings)


def test_genome_round_trip_and_range():
    codes = np.arange(256, dtype=np.uint8)
    weights = genome.decode(codes, 8, 10.0)
    assert weights[0] == -10.0 and weights[-1] == 10.0
    np.testing.assert_array_equal(genome.encode(weights, 8, 10.0), codes)
    assert np.all(np.diff(weights) > 0)


def test_random_genomes_cover_the_weight_range():
    weights = genome.decode(genome.random_genomes(np.random.default_rng(0), 100, 160, 8), 8, 10)
    assert weights.min() == -10 and weights.max() == 10
    assert abs(weights.mean()) < 0.2


def test_per_bit_mutation_flips_two_percent_of_bits():
    rng = np.random.default_rng(1)
    codes = genome.random_genomes(rng, 500, 160, 8)
    mutated = genome.mutate(rng, codes, 8, 0.02)
    rate = genome.flipped_bits(codes, mutated) / codes.size / 8
    assert rate == pytest.approx(0.02, abs=0.001)


def test_exact_mutation_flips_exactly_two_percent_of_each_genome():
    rng = np.random.default_rng(2)
    codes = genome.random_genomes(rng, 50, 160, 8)
    mutated = genome.mutate(rng, codes, 8, 0.02, mode="exact")
    for before, after in zip(codes, mutated):
        assert genome.flipped_bits(before, after) == round(0.02 * 160 * 8)


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


def test_resumed_run_writes_the_same_files_as_an_uninterrupted_one(tmp_path):
    config = small_config(**{"evolution.generations": 6})
    run_condition(config, 1, 11, tmp_path / "whole", progress=False)

    class Interrupt(Exception):
        pass

    evaluator = Evaluator(config)
    original = evaluator.test_generation

    def stop_at_generation_3(genomes, seed, run, generation, record=False):
        if generation == 3:
            raise Interrupt
        return original(genomes, seed, run, generation, record)

    evaluator.test_generation = stop_at_generation_3
    with pytest.raises(Interrupt):
        run_condition(config, 1, 11, tmp_path / "split", progress=False, evaluator=evaluator)
    assert RunData(tmp_path / "split" / "run-01").generations_done == 3
    run_condition(config, 1, 11, tmp_path / "split", progress=False)

    whole, split = tmp_path / "whole" / "run-01", tmp_path / "split" / "run-01"
    assert (whole / "metrics.csv").read_bytes() == (split / "metrics.csv").read_bytes()
    for name in ("genomes.npy", "fitness.npy", "best_genomes.npy", "run.json"):
        assert (whole / name).read_bytes() == (split / name).read_bytes(), name


def test_a_torn_metrics_line_is_redone_on_resume(tmp_path):
    config = small_config(**{"evolution.generations": 3})
    run_condition(config, 1, 5, tmp_path / "a", progress=False)
    path = tmp_path / "a" / "run-01" / "metrics.csv"
    reference = path.read_bytes()
    path.write_bytes(reference[:-25])       # a crash half way through the last row
    run_condition(config, 1, 5, tmp_path / "a", progress=False)
    assert path.read_bytes() == reference   # every row, line endings included


def test_replay_reproduces_the_stored_fitness(tmp_path):
    config = small_config(**{"evolution.generations": 3})
    run_condition(config, 1, 2, tmp_path, progress=False)
    data = RunData(tmp_path / "run-01")
    result = replay(tmp_path / "run-01", 2)
    np.testing.assert_array_equal(result.fitness, data.fitness()[2])
    assert result.trace.shoulder.shape == (41, 20 * 5)
    assert result.trace.motor.shape == (40, 100, 5)


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
