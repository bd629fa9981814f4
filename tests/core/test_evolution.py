"""Selection, offspring, determinism and learning of the evolutionary algorithm, and the
Evaluator contract its engines keep."""
import importlib
import inspect

import numpy as np
import pytest

from econet_ros import genome
from econet_ros.config import Config
from econet_ros.errors import GraphError
from econet_ros.evolution import (Evaluator, GenerationResult, InProcessEvaluator,
                                  next_generation, select_parents)
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


def graph_evaluator_class():
    """nodes/graph_evaluator.GraphEvaluator (imports rclpy; starts nothing)."""
    pytest.importorskip("rclpy")
    return importlib.import_module("econet_ros.nodes.graph_evaluator").GraphEvaluator


def parameters(method) -> list[tuple]:
    return [(p.name, p.kind, p.default) for p in inspect.signature(method).parameters.values()]


@pytest.mark.parametrize("engine", [lambda: InProcessEvaluator, graph_evaluator_class],
                         ids=["in-process", "graph"])
def test_every_engine_declares_the_evaluator_contract(engine):
    cls = engine()
    assert Evaluator in cls.__mro__                  # declared, not merely alike
    assert isinstance(inspect.getattr_static(cls, "n_weights"), property)
    for name in ("trial_setups", "test_generation"):
        assert parameters(getattr(cls, name)) == parameters(getattr(Evaluator, name)), name


def test_the_in_process_engine_keeps_the_contract_and_records_on_request():
    config = small_config(**{"evolution.population": 4, "evolution.parents": 2,
                             "evolution.trials": 2, "evolution.cycles": 10})
    evaluator = InProcessEvaluator(config)
    assert isinstance(evaluator, Evaluator)
    genomes = genome.random_genomes(np.random.default_rng(1), 4, evaluator.n_weights, 8)
    assert evaluator.test_generation(genomes, 1, 1, 0).trace is None
    assert evaluator.test_generation(genomes, 1, 1, 0, record=True).trace.motor.shape == \
        (10, 8, 5)
    assert type(evaluator.test_generation(genomes, 1, 1, 0, "behaviour").trace).__name__ == \
        "BehaviourRecord"


@pytest.mark.parametrize("record", [True, "behaviour"])
def test_the_graph_evaluator_refuses_to_record_in_one_line(record):
    """It hears only touch: asked for a trace it says so instead of returning none."""
    evaluator = object.__new__(graph_evaluator_class())      # no node: it refuses first
    with pytest.raises(GraphError, match="records no per-cycle trace") as refused:
        evaluator.test_generation(np.zeros((4, 3), dtype=np.uint8), 1, 1, 0, record)
    assert "\n" not in str(refused.value)
