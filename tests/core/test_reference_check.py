"""The independent check (`econet check`, econet_ros/science/reference_check.py) on tiny sweeps:
it passes on real runs of every condition, fails on a forged champion and on an unfinished run,
judges partings as registered, its section goes into the experiments' page, and the reference
evolves the engine's champions."""
from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.config import Config
from econet_ros.files import cut_table
from econet_ros.reference.partings import CONTACT_EDGE
from econet_ros.science import reference_check as check
from econet_ros.studies import family
from sweep_helpers import evolved_sweep

TINY = '''
name = "tiny-check"
generations = 8
seeds = [5, 6]
behaviour = false

[settings]
"evolution.population" = 6
"evolution.parents" = 2
"evolution.trials" = 3
"evolution.cycles" = 60
"model.object_radius" = 4.0
"model.reach_min" = 5.0
"model.reach_max" = 30.0

[cells.four]
conditions = ["normal"]

[cells.three]
set = {"network.three_layer_hidden" = 3, "evolution.genome_code" = "sign-magnitude"}
conditions = ["three-layer"]

[cells.random]
conditions = ["random"]
'''


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    return evolved_sweep(TINY, tmp_path_factory.mktemp("check"))


def run_check(folder, tmp_path) -> tuple[int, dict]:
    code = main(["check", str(folder), "--json", str(tmp_path / "check.json"), "--quiet"])
    return code, json.loads((tmp_path / "check.json").read_text())


def test_the_champions_of_a_real_sweep_pass(sweep, tmp_path, capsys):
    assert main(["check", str(sweep), "--json", str(tmp_path / "check.json")]) == 0
    found = json.loads((tmp_path / "check.json").read_text())
    assert found["pass"], found["reasons"]
    said = capsys.readouterr().out.splitlines()
    assert said[:2] == ["checked four/normal/seed-005", "checked four/normal/seed-006"]
    assert len(said) == 7 and said[-1].endswith(": PASS")
    assert found["tally"]["champions"] == 6 and found["tally"]["trials"] == 18
    assert sum(sum(run["engine"]) for run in found["runs"]) > 0, "nothing touched: no test"


def forged(sweep, tmp_path):
    """A copy of the sweep whose first normal run's champion is replaced, in genomes.npy and
    best_genomes.npy alike, by a genome of its generation that scored otherwise."""
    copy = tmp_path / "forged"
    shutil.copytree(sweep, copy)
    run = copy / "four" / "normal" / "seed-005"
    fitness = np.load(run / "fitness.npy")[-1]
    champion, other = int(np.argmax(fitness)), int(np.argmin(fitness))
    assert fitness[champion] != fitness[other], "the tiny run cannot show a forgery"
    genomes, best = np.load(run / "genomes.npy"), np.load(run / "best_genomes.npy")
    genomes[-2, champion] = best[-1] = genomes[-2, other]
    np.save(run / "genomes.npy", genomes)
    np.save(run / "best_genomes.npy", best)
    return copy


def test_a_forged_champion_fails(sweep, tmp_path):
    code, found = run_check(forged(sweep, tmp_path), tmp_path)
    assert code == 1 and not found["pass"]
    assert any(r.startswith("four/normal/seed-005: the engine's re-run of generation 7 differs")
               for r in found["reasons"]), found["reasons"]


def test_an_unfinished_run_fails(sweep, tmp_path):
    copy = tmp_path / "cut"
    shutil.copytree(sweep, copy)
    cut_table(copy / "three" / "three-layer" / "seed-006" / "metrics.csv", 5)
    code, found = run_check(copy, tmp_path)
    assert code == 1
    assert found["reasons"] == ["three/three-layer/seed-006: unfinished: 5 of 8 generations"]


@pytest.mark.parametrize("arguments", [[], ["--end-to-end", "9501-x"], ["--processes", "0"]])
def test_a_folder_that_is_no_sweep_and_bad_options_are_one_line_errors(tmp_path, capsys,
                                                                         arguments):
    assert main(["check", str(tmp_path), *arguments]) == 2
    err = capsys.readouterr().err
    assert err.startswith("econet: error:") and err.count("\n") == 1, err


def made_up(partings, classes=("holds", "holds"), trials=100) -> check.RunCheck:
    return check.RunCheck("r", 0, [1] * trials, [1] * trials, *classes, partings)


def parting(boundary, reference=1, engine=1) -> dict:
    return {"trial": 0, "cycle": 3, "what": "state", "boundary": boundary,
            "reference": reference, "engine": engine}


def test_the_verdict_follows_the_registered_rule():
    """Explained partings pass up to 1% of trials; unexplained ones only with equal fitness;
    a class that differs fails."""
    explained = parting(CONTACT_EDGE, 2, 1)
    assert check.verdict([made_up([explained])])[0]
    assert not check.verdict([made_up([explained, explained])])[0]
    assert check.verdict([made_up([parting(None)])])[0]
    assert not check.verdict([made_up([parting(None, 2, 1)])])[0]
    assert not check.verdict([made_up([], ("holds", "brushes"))])[0]


def test_end_to_end_runs_pass_only_when_whole_and_alike():
    assert check.end_to_end_reasons({1: [True, True]}, 2) == []
    assert check.end_to_end_reasons({1: [True, False, False], 2: []}, 3) == [
        "end to end, seed 1: the champions differ in generations [1, 2]",
        "end to end, seed 2: 0 of 3 generations run"]


def test_the_section_goes_into_the_experiments_page(sweep, tmp_path):
    folder = tmp_path / "check"
    folder.mkdir()
    assert main(["check", str(sweep), "--markdown", str(folder / family.REFERENCE_CHECK),
                 "--quiet"]) == 0
    page = family.experiments_page([folder], tmp_path / "page").read_text()
    section = page.split("## The independent check\n")[1]
    assert page.count("\n## The independent check\n") == 1 and "\n## " not in section
    assert section.lstrip().startswith("**PASS**, as registered")
    assert "| 6 | 18 | 18 | 0 | 0 | 6 of 6 |" in section


def test_the_reference_evolves_the_engines_champions():
    config = Config().replace(**{"evolution.population": 6, "evolution.parents": 2,
                                 "evolution.trials": 3, "evolution.cycles": 40,
                                 "evolution.generations": 4})
    heard = []
    with check.workers(2) as starmap:
        agreed = check.end_to_end(config, 9501, starmap, lambda g, a: heard.append(g))
    assert agreed == [True] * 4 and heard == [0, 1, 2, 3]
