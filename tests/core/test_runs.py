"""Run folders and the generation loop: a resumed run writes the same files as an uninterrupted
one, a torn metrics line is redone, and replay reproduces the stored fitness (faults while
writing: tests/cli/test_bad_input_and_faults.py)."""
import numpy as np
import pytest

from econet_ros.config import Config
from econet_ros.evolution import InProcessEvaluator
from econet_ros.runs import RunData, replay, run_condition


def small_config(**changes):
    settings = {"evolution.population": 20, "evolution.parents": 4, "evolution.trials": 5,
                "evolution.cycles": 40, "evolution.generations": 4}
    settings.update(changes)
    return Config().replace(**settings)


def test_resumed_run_writes_the_same_files_as_an_uninterrupted_one(tmp_path):
    config = small_config(**{"evolution.generations": 6})
    run_condition(config, 1, 11, tmp_path / "whole", progress=False)

    class Interrupt(Exception):
        pass

    evaluator = InProcessEvaluator(config)
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
