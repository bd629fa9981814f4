"""Run folders and the generation loop: a resumed run writes the same files as an uninterrupted
one (its provenance adds a session), a torn metrics line is redone, the temporary file of a
killed write is removed, replay reproduces the stored fitness (with the recorded controller),
--overwrite clears under the folder lock, the controller record keeps runs of different
controllers apart (and only those), and a start that finished no generation blocks nothing
(faults while writing: tests/cli/test_bad_input_and_faults.py)."""
import json

import numpy as np
import pytest

from econet_ros.config import Config
from econet_ros.errors import ResultsError, UsageError, options_as_parameters
from econet_ros.evolution import InProcessEvaluator
from econet_ros.files import locked
from econet_ros.plugins import make_controller
from econet_ros.run_folders import (CONTROLLER_FILE, RunData, controller_record, read_sessions,
                                    writing_into)
from econet_ros.runs import replay, run_condition


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


def plugin_run(config, out, name="three-layer", runs=1):
    """Evolve ``runs`` runs of the plug-in ``name`` (condition normal) as econet evolve
    --controller does; returns the controller record."""
    e = config.evolution
    controller = make_controller(name, e.population * e.trials, config)
    record = controller_record(name, type(controller), controller.n_params, e.condition)
    run_condition(config, runs, 1, out, progress=False,
                  evaluator=InProcessEvaluator(config, controller), plugin=record)
    return record


def test_the_controller_record_keeps_runs_of_different_controllers_apart(tmp_path):
    config = small_config(**{"evolution.generations": 1})
    record = plugin_run(config, tmp_path / "plugin", runs=2)
    n_params = make_controller("three-layer", 1, config).n_params
    assert record == {"controller": "three-layer", "n_params": n_params,
                      "class": "econet_ros.controllers:ThreeLayerNetwork"}
    for run in ("run-01", "run-02"):
        assert json.loads((tmp_path / "plugin" / run / CONTROLLER_FILE).read_text()) == record
    # the same class under its module:Class name is the same controller
    plugin_run(config, tmp_path / "plugin", "econet_ros.controllers:ThreeLayerNetwork", 2)
    with pytest.raises(UsageError, match="evolved with three-layer; use --controller "
                                         "three-layer, or choose another output folder or "
                                         "pass --overwrite"):
        run_condition(config, 2, 1, tmp_path / "plugin", progress=False)
    run_condition(config, 1, 1, tmp_path / "network", progress=False)
    with options_as_parameters(), pytest.raises(
            UsageError, match="evolved with the condition's network; use controller:='', or "
                              "choose another output folder or pass overwrite:=true"):
        plugin_run(config, tmp_path / "network")
    assert not (tmp_path / "network" / "run-01" / CONTROLLER_FILE).exists()


class Refused(Exception):
    pass


def refused_at_generation(config, refused):
    """An in-process evaluator that raises Refused when it comes to generation ``refused``."""
    evaluator = InProcessEvaluator(config)
    original = evaluator.test_generation

    def test_generation(genomes, seed, run, generation, record=False):
        if generation == refused:
            raise Refused
        return original(genomes, seed, run, generation, record)
    evaluator.test_generation = test_generation
    return evaluator


def test_naming_the_conditions_own_network_is_no_difference(tmp_path):
    config = small_config(**{"evolution.generations": 2})
    normal = make_controller("normal", 1, config)
    assert controller_record("normal", type(normal), normal.n_params, "normal") is None
    run_condition(config, 1, 1, tmp_path / "whole", progress=False)
    with pytest.raises(Refused):
        run_condition(config, 1, 1, tmp_path / "cut", progress=False,
                      evaluator=refused_at_generation(config, 1))
    # what econet evolve --controller normal once recorded for the condition normal
    (tmp_path / "cut" / "run-01" / CONTROLLER_FILE).write_text(json.dumps(
        {"controller": "normal", "class": "econet_ros.controllers:FourLayerNetwork",
         "n_params": normal.n_params}))
    run_condition(config, 1, 1, tmp_path / "cut", progress=False)
    for name in ("metrics.csv", "genomes.npy", "fitness.npy"):
        assert (tmp_path / "whole" / "run-01" / name).read_bytes() == \
            (tmp_path / "cut" / "run-01" / name).read_bytes(), name


@pytest.mark.parametrize("then", ["other settings", "another controller"])
def test_a_start_that_finished_no_generation_does_not_block_the_next(tmp_path, then):
    config = small_config(**{"evolution.generations": 1})
    with pytest.raises(Refused):
        run_condition(config.replace(**{"evolution.cycles": 30}), 1, 1, tmp_path / "out",
                      progress=False, evaluator=refused_at_generation(config, 0))
    assert (tmp_path / "out" / "run-01" / "run.json").exists()
    if then == "other settings":
        run_condition(config, 1, 1, tmp_path / "out", progress=False)
    else:
        plugin_run(config, tmp_path / "out")
        plugin_run(config, tmp_path / "fresh")
    want = tmp_path / ("fresh" if then == "another controller" else "want")
    if then == "other settings":
        run_condition(config, 1, 1, want, progress=False)
    for name in ("run.json", "metrics.csv", "genomes.npy", "fitness.npy", CONTROLLER_FILE):
        got, expected = tmp_path / "out" / "run-01" / name, want / "run-01" / name
        assert got.exists() == expected.exists(), name
        assert not got.exists() or got.read_bytes() == expected.read_bytes(), name


def test_replay_runs_the_recorded_controller(tmp_path):
    config = small_config(**{"evolution.generations": 1})
    plugin_run(config, tmp_path)
    data = RunData(tmp_path / "run-01")
    assert np.array_equal(replay(data.path, 0, record=False).fitness, data.fitness()[0])
    (data.path / CONTROLLER_FILE).write_text(json.dumps(
        {"controller": "external", "class": None, "n_params": data.header["n_weights"]}))
    with pytest.raises(ResultsError, match="evolved with external, a controller node outside "
                                           "econet_ros"):
        replay(data.path, 0)
