"""Run folders and the generation loop: a resumed run writes the same files as an uninterrupted
one (its provenance adds a session), a torn metrics line is redone, the temporary file of a
killed write is removed, replay reproduces the stored fitness, --overwrite clears under the
folder lock, and the controller record keeps runs of different controllers apart (faults while
writing: tests/cli/test_bad_input_and_faults.py)."""
import json

import numpy as np
import pytest

from econet_ros.config import Config
from econet_ros.errors import UsageError
from econet_ros.evolution import InProcessEvaluator
from econet_ros.files import locked
from econet_ros.plugins import make_controller
from econet_ros.runs import (CONTROLLER_FILE, RunData, controller_record, read_sessions,
                             record_controller, replay, run_condition, writing_into)


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
    whole, split = tmp_path / "whole" / "run-01", tmp_path / "split" / "run-01"
    [cut] = read_sessions(split)
    assert cut["first_generation"] == 0 and cut["ended"] is None
    run_condition(config, 1, 11, tmp_path / "split", progress=False)

    assert (whole / "metrics.csv").read_bytes() == (split / "metrics.csv").read_bytes()
    for name in ("genomes.npy", "fitness.npy", "best_genomes.npy", "run.json"):
        assert (whole / name).read_bytes() == (split / name).read_bytes(), name
    [alone] = read_sessions(whole)
    first, resumed = read_sessions(split)
    assert first == cut and alone["first_generation"] == 0 and alone["ended"]
    assert resumed["first_generation"] == 3 and resumed["started"] <= resumed["ended"]
    assert resumed["commit"] == alone["commit"]


def test_a_torn_metrics_line_is_redone_on_resume(tmp_path):
    config = small_config(**{"evolution.generations": 3})
    run_condition(config, 1, 5, tmp_path / "a", progress=False)
    path = tmp_path / "a" / "run-01" / "metrics.csv"
    reference = path.read_bytes()
    path.write_bytes(reference[:-25])       # a crash half way through the last row
    run_condition(config, 1, 5, tmp_path / "a", progress=False)
    assert path.read_bytes() == reference   # every row, line endings included


def test_a_resumed_run_removes_the_temporary_files_of_killed_writes(tmp_path):
    """write_atomically's temporary file (.<name>.<pid>.tmp) stays behind when a kill cuts the
    write short; reopening the folder removes it and leaves other hidden files alone."""
    config = small_config(**{"evolution.generations": 3})
    run_condition(config, 1, 5, tmp_path / "whole", progress=False)
    run_condition(config, 1, 5, tmp_path / "split", progress=False)
    run_dir = tmp_path / "split" / "run-01"
    metrics = run_dir / "metrics.csv"
    metrics.write_bytes(metrics.read_bytes()[:-25])      # killed in the last generation
    torn = [run_dir / ".run.json.4242.tmp", run_dir / ".controller.json.17.tmp"]
    for path in torn:
        path.write_text('{"form')
    (run_dir / ".notes.tmp").write_text("the user's own")
    run_condition(config, 1, 5, tmp_path / "split", progress=False)
    assert not any(path.exists() for path in torn)
    assert (run_dir / ".notes.tmp").read_text() == "the user's own"
    whole = tmp_path / "whole" / "run-01"
    for name in ("metrics.csv", "genomes.npy", "fitness.npy", "run.json"):
        assert (run_dir / name).read_bytes() == (whole / name).read_bytes(), name


def test_replay_reproduces_the_stored_fitness(tmp_path):
    config = small_config(**{"evolution.generations": 3})
    run_condition(config, 1, 2, tmp_path, progress=False)
    data = RunData(tmp_path / "run-01")
    result = replay(tmp_path / "run-01", 2)
    np.testing.assert_array_equal(result.fitness, data.fitness()[2])
    assert result.trace.shoulder.shape == (41, 20 * 5)
    assert result.trace.motor.shape == (40, 100, 5)


def test_overwrite_clears_the_run_folders_only_under_the_folder_lock(tmp_path):
    run_condition(small_config(**{"evolution.generations": 1}), 2, 1, tmp_path, progress=False)
    (tmp_path / "notes.txt").write_text("kept")
    with locked(tmp_path):                          # another writer (e.g. a supervisor) holds it
        with pytest.raises(UsageError, match="being written by another econet process"):
            with writing_into(tmp_path, overwrite=True):
                pass
    assert (tmp_path / "run-01" / "run.json").exists()
    with writing_into(tmp_path, overwrite=True):
        assert not list(tmp_path.glob("run-*"))
    assert (tmp_path / "notes.txt").read_text() == "kept"
    with writing_into(tmp_path, overwrite=False):
        (tmp_path / "run-01").mkdir()
    assert (tmp_path / "run-01").exists()


def test_the_controller_record_keeps_runs_of_different_controllers_apart(tmp_path):
    config = small_config(**{"evolution.generations": 1})
    record = controller_record("reacher", make_controller("reacher", 1, config))
    assert record == {"controller": "reacher", "n_params": 0,
                      "class": "econet_ros.reacher:HandWrittenReacher"}
    record_controller(tmp_path / "plugin", 2, record)
    for run in ("run-01", "run-02"):
        assert json.loads((tmp_path / "plugin" / run / CONTROLLER_FILE).read_text()) == record
    run_condition(config, 1, 1, tmp_path / "plugin", progress=False)
    record_controller(tmp_path / "plugin", 2, record)            # the same controller again
    with pytest.raises(UsageError, match="evolved with reacher; use --controller reacher"):
        record_controller(tmp_path / "plugin", 1, None)
    run_condition(config, 1, 1, tmp_path / "network", progress=False)
    with pytest.raises(UsageError, match="evolved with the condition's network; use no "
                                         "--controller"):
        record_controller(tmp_path / "network", 1, record)
    assert not (tmp_path / "network" / "run-01" / CONTROLLER_FILE).exists()
