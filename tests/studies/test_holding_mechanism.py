"""E5's rule (studies/holding_mechanism.py) on tiny hand-made networks and hand-made rows: the
buffer read is the engine's own, a net silenced by touch by construction is classed as
silencing and one that is not is not, and the verdict follows the registered criteria."""
import csv
import math

import numpy as np
import pytest

from econet_ros import genome
from econet_ros.config import Config
from econet_ros.plugins import make_controller
from econet_ros.science import holding
from econet_ros.science.verdicts import ABSENT, REPLICATES, REVERSED
from econet_ros.studies import holding_mechanism as e5
from econet_ros.world import Observation

CONFIG = Config()
NETS = [("normal", CONFIG), ("three-layer", CONFIG),
        ("normal", CONFIG.replace(**{"network.first_layer_wiring": "scrambled"}))]


@pytest.mark.parametrize("condition, config", NETS)
def test_the_buffer_ends_in_the_engines_outputs(condition, config):
    n = 6
    net = make_controller(condition, n, config)
    net.load(genome.decode(genome.random_genomes(np.random.default_rng(3), 2, net.n_params, 8),
                           8, 10.0))
    inputs = np.random.default_rng(4).random((n, 13))
    buffer = e5.layer_activations(net, np.repeat(net.weights, net.block, axis=0), inputs)
    np.testing.assert_allclose(buffer[:, -5:], net.forward(inputs), rtol=0, atol=1e-12)
    assert e5.last_hidden(net).stop == net.buffer_size - 5


def touch_net(condition: str, touch_weight: float, n: int = 2):
    """A net whose every weight is 0 but those reading touch: with touch = 1 its last hidden
    layer sits at logistic(touch_weight), without it at exactly 0.5."""
    net = make_controller(condition, n, CONFIG)
    net.load(np.where(net.weights_reading("touch"), touch_weight, 0.0)[None])
    return net


def observation(touch) -> Observation:
    n = len(touch)
    return Observation(0, np.zeros((n, 8)), np.zeros((n, 4)), np.asarray(touch, float),
                       np.zeros(n, bool))


def recorded_row(net, touch) -> dict:
    recorder = e5.ContactRecorder(net)
    recorder.act(observation(touch))
    largest = recorder.on_contact()
    return {"median_largest_on_contact": float(np.median(largest)) if len(largest) else math.nan,
            "contact_cycles": len(largest)}


@pytest.mark.parametrize("condition", ["normal", "three-layer"])
def test_a_net_silenced_by_touch_by_construction_silences(condition):
    row = recorded_row(touch_net(condition, -30.0), [1.0, 0.0])
    assert row["contact_cycles"] == 1                 # only the touching environment counts
    assert row["median_largest_on_contact"] < 1e-12
    assert e5.silences(row) == 1.0


@pytest.mark.parametrize("condition", ["normal", "three-layer"])
def test_a_net_that_touch_does_not_silence_does_not(condition):
    resting = recorded_row(touch_net(condition, 0.0), [1.0, 1.0])
    assert resting["median_largest_on_contact"] == 0.5
    assert e5.silences(resting) == 0.0
    weak = recorded_row(touch_net(condition, -2.0), [1.0, 1.0])   # logistic(-2) = 0.12
    assert e5.silences(weak) == 0.0 and e5.silences(weak, threshold=0.2) == 1.0


def test_no_contact_cannot_be_told():
    row = recorded_row(touch_net("normal", -30.0), [0.0, 0.0])
    assert row["contact_cycles"] == 0 and math.isnan(e5.silences(row))


def rows(kind: str, silent: int, loud: int, untold: int = 0) -> list[dict]:
    medians = [0.001] * silent + [0.5] * loud + [math.nan] * untold
    return [{"class": kind, "median_largest_on_contact": m} for m in medians]


def test_holders_silencing_and_brushers_not_replicates():
    judged = rows(holding.HOLDS, 20, 0) + rows(holding.BRUSHES, 0, 20) + \
        rows(holding.NO_REACH, 0, 10)
    c = e5.criteria(judged)
    assert c["E5-S"].interval.n == 20 and c["E5-D"].interval.mean == 1.0
    assert e5.verdict(judged)[0] == REPLICATES


def test_holders_not_silencing_is_reversed():
    judged = rows(holding.HOLDS, 0, 20) + rows(holding.BRUSHES, 20, 0)
    assert e5.verdict(judged)[0] == REVERSED


def test_equal_shares_are_absent_and_untold_champions_left_out():
    judged = rows(holding.HOLDS, 150, 50, untold=30) + rows(holding.BRUSHES, 150, 50)
    c = e5.criteria(judged)
    assert c["E5-S"].judged == REPLICATES and c["E5-S"].interval.n == 200
    assert c["E5-D"].judged == ABSENT
    assert e5.verdict(judged)[0] == ABSENT


def test_the_threshold_moves_the_class():
    judged = [{"class": holding.HOLDS, "median_largest_on_contact": 0.03}]
    assert e5.flags(judged, holding.HOLDS) == [1.0]
    assert e5.flags(judged, holding.HOLDS, threshold=0.02) == [0.0]


def tiny_run(folder, shared: bool):
    from econet_ros.runs import run_condition
    config = CONFIG.replace(**{"evolution.population": 8, "evolution.parents": 2,
                               "evolution.trials": 4, "evolution.cycles": 40,
                               "evolution.generations": 3, "evolution.shared_trials": shared})
    run_condition(config, 1, 5, folder, progress=False)
    return folder / "run-01"


@pytest.mark.parametrize("shared", [True, False])
def test_the_champion_replays_exactly_on_its_own_trials(tmp_path, shared):
    row = e5.champion_row(tiny_run(tmp_path / "normal", shared), "x/normal/run-01")
    assert row["replay_fitness"] == row["stored_fitness"]
    assert row["architecture"] == "normal" and row["run"] == "x/normal/run-01"
    assert set(row) == set(e5.COLUMNS)


def test_the_command_writes_a_table_and_a_partial_summary(tmp_path):
    tiny_run(tmp_path / "e4" / "normal", True)
    e5.main([str(tmp_path / "e4"), "--out", str(tmp_path / "e5")])
    with open(tmp_path / "e5" / e5.TABLE) as table:
        lines = list(csv.DictReader(table))
    assert [line["run"] for line in lines] == ["e4/normal/run-01"]
    assert lines[0]["silences"] in ("yes", "no", "n/a")
    summary = (tmp_path / "e5" / e5.SUMMARY).read_text()
    assert "**PARTIAL**: without e1-width" in summary and "| all | 0.05 |" in summary
    assert "| normal | 0.02 |" in summary and "| normal | 0.1 |" in summary
    assert "| e4 | 0.05 |" in summary


def test_stored_rows_join_the_table_under_their_name(tmp_path):
    tiny_run(tmp_path / "e1-width" / "normal", True)
    e5.main([str(tmp_path / "e1-width"), "--out", str(tmp_path / "first")])
    e5.main(["--stored", f"e4={tmp_path / 'first' / e5.TABLE}", str(tmp_path / "e1-width"),
             "--out", str(tmp_path / "again")])
    with open(tmp_path / "again" / e5.TABLE) as table:
        runs = [line["run"] for line in csv.DictReader(table)]
    assert runs == ["e1-width/normal/run-01", "e4/e1-width/normal/run-01"]
    summary = (tmp_path / "again" / e5.SUMMARY).read_text()
    assert "Rows kept from an earlier table: e4=" in summary


def test_every_registered_source_makes_the_summary_whole():
    judged = [{"run": f"{name}/run-01", "class": holding.HOLDS,
               "median_largest_on_contact": 0.001} for name in e5.REGISTERED_DATA]
    assert e5.coverage(judged).startswith("Data: every registered source")
    assert "PARTIAL" in e5.coverage(judged[1:])


@pytest.mark.parametrize("argv, said", [
    (["--stored", "e4"], "expected NAME=CSV"),
    (["--stored", "e4=nowhere.csv"], "nowhere.csv is not a readable E5 table"),
    ([], "give result folders, --stored NAME=CSV, or both"),
    (["empty-folder"], "no finished run with a network under"),
])
def test_bad_input_is_one_line_and_exit_status_2(tmp_path, capsys, monkeypatch, argv, said):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "empty-folder").mkdir()
    with pytest.raises(SystemExit) as stop:
        e5.main([*argv, "--out", str(tmp_path / "out")])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert said in err[-1] and "Traceback" not in "\n".join(err)
    assert not (tmp_path / "out").exists()
