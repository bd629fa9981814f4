"""The optimizers behind ``econet evolve --optimizer``: complete run folders, byte-identical
resume, stored settings, and their building blocks."""
import json

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.config import Config, ConfigError
from econet_ros.errors import ResultsError
from econet_ros.evolution import InProcessEvaluator, genome_weights
from econet_ros.optimizers import centred_ranks, fold_into_range
from econet_ros.run_folders import RunData
from econet_ros.runs import replay, run_condition

TINY = ["--population", "10", "--parents", "2", "--trials", "3", "--cycles", "20"]


@pytest.mark.parametrize("optimizer", ["cmaes", "es"])
def test_evolve_with_an_optimizer_writes_complete_run_folders(tmp_path, optimizer):
    assert main(["evolve", "--optimizer", optimizer, "--out", str(tmp_path), "--quiet",
                 "--runs", "1", "--generations", "3", "--seed", "2", *TINY]) == 0
    data = RunData(tmp_path / "run-01")
    assert data.complete and data.config.evolution.optimizer == optimizer
    assert json.loads((tmp_path / "run-01" / "run.json").read_text())["config"]["evolution"][
        "optimizer"] == optimizer
    genomes = np.load(tmp_path / "run-01" / "genomes.npy")
    assert genomes.shape == (4, 10, data.header["n_weights"]) and genomes.dtype == np.uint8
    assert len({g.tobytes() for g in genomes}) == 4       # every generation is new
    np.testing.assert_array_equal(replay(tmp_path / "run-01", 2, record=False).fitness,
                                  data.fitness()[2])


def test_the_default_ga_stores_no_optimizer_settings(tmp_path):
    assert "optimizer" not in Config().to_dict()["evolution"]
    changed = Config().replace(**{"evolution.es_sigma": 2.0})
    assert changed.to_dict()["evolution"]["es_sigma"] == 2.0
    assert Config.from_dict(changed.to_dict()) == changed


def small(optimizer, generations=6):
    return Config().replace(**{"evolution.population": 10, "evolution.parents": 2,
                               "evolution.trials": 3, "evolution.cycles": 30,
                               "evolution.generations": generations,
                               "evolution.optimizer": optimizer})


class Interrupt(Exception):
    pass


def interrupted_at(config, generation):
    """An evaluator that fails when it reaches ``generation``."""
    evaluator = InProcessEvaluator(config)
    original = evaluator.test_generation

    def test_generation(genomes, seed, run, number, record=False):
        if number == generation:
            raise Interrupt
        return original(genomes, seed, run, number, record)

    evaluator.test_generation = test_generation
    return evaluator


@pytest.mark.parametrize("optimizer", ["cmaes", "es"])
def test_an_interrupted_run_resumes_byte_identically(tmp_path, optimizer):
    config = small(optimizer)
    run_condition(config, 1, 7, tmp_path / "whole", progress=False)
    with pytest.raises(Interrupt):
        run_condition(config, 1, 7, tmp_path / "split", progress=False,
                      evaluator=interrupted_at(config, 4))
    assert RunData(tmp_path / "split" / "run-01").generations_done == 4
    run_condition(config, 1, 7, tmp_path / "split", progress=False)
    for name in ("metrics.csv", "genomes.npy", "fitness.npy", "best_genomes.npy", "run.json"):
        assert (tmp_path / "whole" / "run-01" / name).read_bytes() == \
            (tmp_path / "split" / "run-01" / name).read_bytes(), name


def test_a_run_whose_stored_fitness_does_not_replay_is_not_resumed(tmp_path):
    config = small("cmaes")
    with pytest.raises(Interrupt):
        run_condition(config, 1, 3, tmp_path, progress=False,
                      evaluator=interrupted_at(config, 3))
    fitness = np.load(tmp_path / "run-01" / "fitness.npy", mmap_mode="r+")
    fitness[1] = np.arange(10) * 7 + 1      # not what generation 1 scored
    fitness.flush()
    with pytest.raises(ResultsError, match="replaying its stored fitness"):
        run_condition(config, 1, 3, tmp_path, progress=False)


def test_es_candidates_are_antithetic_pairs_on_the_genome_grid(tmp_path):
    config = small("es", generations=1)
    run_condition(config, 1, 5, tmp_path, progress=False)
    weights = genome_weights(config, RunData(tmp_path / "run-01").genomes(0))
    # theta starts at 0: each pair mirrors through the origin, up to rounding to the grid
    np.testing.assert_allclose(weights[:5], -weights[5:], atol=20 / 255 + 1e-12)


def test_es_needs_an_even_population():
    with pytest.raises(ConfigError, match="population must be even"):
        Config().replace(**{"evolution.optimizer": "es", "evolution.population": 99,
                            "evolution.parents": 3})


def test_centred_ranks_share_ties_and_span_minus_to_plus_half():
    np.testing.assert_allclose(centred_ranks(np.array([3.0, 0.0, 0.0, 7.0, 0.0])),
                               [0.25, -0.25, -0.25, 0.5, -0.25])


def test_folding_reflects_weights_into_the_range():
    np.testing.assert_allclose(fold_into_range(np.array([0.5, 12.0, -13.0, 31.0, 10.0]), 10.0),
                               [0.5, 8.0, -7.0, -9.0, 10.0])
