"""E6-S, the screen with a real holding criterion (docs/preregistrations.md, "E6-S"): a trial
tests holding when its first contact leaves at least 20 cycles, holds when in contact on 90% of
the cycles from then on; a genome holds by the majority of its tests; E6-S sets the holding
shares of tested genomes of the large and small nets against each other. E2's published screen,
stored before E6, still reads and judges as it did."""
import csv
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.errors import ResultsError
from econet_ros.science.stats import share
from econet_ros.science.sweeps.spec import load_spec
from econet_ros.science.verdicts import ABSENT, REPLICATES
from econet_ros.studies import screen
from econet_ros.trials import TrialMeasures
from sweep_helpers import screened_into, tiny_screen

ROOT = Path(__file__).resolve().parents[2]
PUBLISHED = ROOT / "docs" / "results" / "sweeps" / "e2-screen"


def trials(*rows) -> TrialMeasures:
    """Hand-made trials, one (fitness, success, latency) a row."""
    fitness, success, latency = (np.array(column) for column in zip(*rows))
    return TrialMeasures(fitness, success, latency, np.zeros(len(rows)))


def test_a_trial_tests_holding_with_20_cycles_left_and_holds_on_90_percent_of_them():
    tests, held = screen.holding_tests(trials(
        (21, True, 80),     # latency = cycles - 20: a test; 21 cycles from contact, 18.9 needed
        (20, True, 81),     # latency = cycles - 19: no test, however long it stays
        (27, True, 71),     # 30 cycles from contact: 27 = 0.9 x 30 holds
        (26, True, 71),     # one less does not
        (90, True, 1),      # 90 of 100 holds
        (89, True, 1),
        (0, False, 100),    # no contact: no test
    ), cycles=100)
    assert tests.tolist() == [True, False, True, True, True, True, False]
    assert held.tolist() == [True, False, True, False, True, False, False]


def test_a_genome_holds_by_the_majority_of_its_tests_ties_brush_none_is_left_out():
    assert screen.lasting_kind(3, 2) == screen.lasting_kind(1, 1) == "holds"
    assert screen.lasting_kind(2, 1) == screen.lasting_kind(4, 2) == "brushes"     # ties
    assert screen.lasting_kind(1, 0) == "brushes"
    assert screen.lasting_kind(0, 0) == screen.UNTESTED


def test_e6_s_is_the_large_nets_holding_share_minus_the_small_nets():
    large, small = np.r_[np.ones(40), np.zeros(160)], np.r_[np.ones(120), np.zeros(80)]
    found = screen.e6_s(large, small, "large - small")["E6-S"]
    assert found.interval.mean == pytest.approx(-0.4) and found.judged == REPLICATES
    even = np.r_[np.ones(3000), np.zeros(3000)]
    assert screen.e6_s(even, even, "large - small")["E6-S"].judged == ABSENT


@pytest.fixture(scope="module")
def stored(tmp_path_factory) -> Path:
    return screened_into(tiny_screen("e6-screen"), tmp_path_factory.mktemp("e6-screen"))


def rows(path: Path) -> list[dict]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_the_stored_screen_counts_every_genomes_tests_to_the_table(stored):
    genomes, table = rows(stored / screen.GENOMES), rows(stored / screen.TABLE)
    assert sum(int(g["tests"]) for g in genomes) > 0          # a tiny screen still tests some
    for row in table:
        mine = [g for g in genomes if (g["cell"], g["seed"]) == (row["cell"], row["seed"])]
        assert all(g["lasting_kind"] == screen.lasting_kind(int(g["tests"]), int(g["tests_held"]))
                   for g in mine)
        assert sum(g["lasting_kind"] != screen.UNTESTED for g in mine) == int(row["tested"])
        assert sum(g["lasting_kind"] == "holds" for g in mine) == int(row["tested_hold"])


def test_the_stored_screen_reads_back_and_shows_e6_s_with_e2_s_beside_it(stored):
    screened = screen.read_screen(stored)
    table = rows(stored / screen.TABLE)
    for cell in ("small", "large"):
        assert len(screened.lasting[cell]) == sum(int(r["tested"]) for r in table
                                                  if r["cell"] == cell)
        assert screened.genomes[cell] == 40
    text = "\n".join(screen.screen_markdown(screened))
    assert "E6-S: holding share of tested random genomes, large - small" in text
    assert "not judged: E2-S's criterion on the same genomes, holding share of random" in text
    assert "Beside it, small - large under E6's criterion:" in text
    assert list(screen.screen_criteria(screened)) == ["E6-S"]


def test_a_screen_of_e6s_rule_without_its_columns_is_refused(tmp_path):
    shutil.copytree(PUBLISHED, tmp_path / "old")
    spec = json.loads((tmp_path / "old" / screen.SPEC).read_text())
    spec["rule"]["name"] = "e6-screen"
    (tmp_path / "old" / screen.SPEC).write_text(json.dumps(spec))
    with pytest.raises(ResultsError, match="lacks the column"):
        screen.read_screen(tmp_path / "old")


def test_the_published_e2_screen_reads_and_judges_as_before():
    """Its screen.csv, counted as E2's screen was read before E6 (reach and hold per cell)."""
    table = rows(PUBLISHED / screen.TABLE)
    cells = list(dict.fromkeys(r["cell"] for r in table))
    flags = {c: np.r_[np.ones(sum(int(r["hold"]) for r in table if r["cell"] == c)),
                      np.zeros(sum(int(r["reach"]) - int(r["hold"]) for r in table
                                   if r["cell"] == c))] for c in cells}
    screened = screen.read_screen(PUBLISHED)
    assert screened.lasting == {}
    e2 = screen.e2_s(flags["4/4/8"], flags["2/2/4"], "4/4/8 - 2/2/4")["E2-S"]
    assert screen.screen_criteria(screened)["E2-S"].text(four=True) == e2.text(four=True)
    text = screen.screen_markdown(screened)
    assert [f"| {c} | {len(f)} | {share(f).text(3)} |" for c, f in flags.items()] == text[2:6]
    assert f"E2-S: {e2.text(four=True)}." in text


def test_the_verb_refuses_a_spec_of_another_rule_in_one_line(tmp_path, capsys):
    assert main(["sweep", "screen", str(ROOT / "examples" / "sweeps" / "e3-modularity.toml"),
                 "--out", str(tmp_path)]) == 2
    error = capsys.readouterr().err.strip()
    assert "is not a screen spec" in error and "e2-screen, e6-screen" in error
    assert len(error.splitlines()) == 1


def test_the_registered_e6_screen_names_its_networks_seeds_and_cells():
    spec = load_spec(ROOT / "examples" / "sweeps" / "e6-screen.toml")
    assert [c.name for c in spec.cells] == ["2/2/4", "4/4/8", "three-layer 4", "three-layer 8"]
    assert spec.seeds == tuple(range(9671, 9701))
    assert (spec.rule["name"], spec.rule["large"], spec.rule["small"]) == \
        ("e6-screen", "4/4/8", "2/2/4")
    assert spec.rule["registered"].startswith("1781986") and len(spec.rule["registered"]) == 40
    assert {r.config.evolution.population for r in spec.runs()} == {200}
    assert [c["label"] for c in spec.compare] == ["three-layer 8 - 4"]


def test_a_screen_records_the_code_that_made_it(tmp_path):
    from sweep_helpers import screened_into, tiny_screen

    from econet_ros.provenance import code
    from econet_ros.studies import screen
    folder = screened_into(tiny_screen("e6-screen"), tmp_path)
    assert screen.screen_code(folder) == (code()["commit"], code()["dirty"])
    assert screen.screen_code(tmp_path / "elsewhere") == ("", None)
