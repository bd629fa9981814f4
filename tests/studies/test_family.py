"""The experiments' page (family.py): folders recognised by what they hold, the registered
sentences chosen by the adjusted verdicts, E2's onset read from a run's series, E4's claims
tallied against an earlier table, and a whole page from tiny folders."""
from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from econet_ros.cli import main
from econet_ros.science.sweeps.report import build_sweep_report
from econet_ros.science.sweeps.spec import load_spec
from econet_ros.science.verdicts import ABSENT, INCONCLUSIVE, REPLICATES, REVERSED
from econet_ros.studies import experiments, family, screen
from sweep_helpers import evolved_sweep

MODULARITY = '''
name = "tiny-e3"
generations = 20
seeds = [3, 4]
behaviour = false

[settings]
"evolution.population" = 4
"evolution.parents" = 2
"evolution.trials" = 2
"evolution.cycles" = 30

[rule]
name = "e3-modularity"
modular = "modular"
scrambled = "scrambled"
three = "three"

[cells.modular]
set = {"network.visual_hidden" = 2, "network.proprio_hidden" = 2, "network.intermodal_hidden" = 4}
conditions = ["normal"]

[cells.scrambled]
set = {"network.visual_hidden" = 2, "network.proprio_hidden" = 2, "network.intermodal_hidden" = 4, "network.first_layer_wiring" = "scrambled"}
seeded = ["network.wiring_seed"]
conditions = ["normal"]

[cells.three]
set = {"network.three_layer_hidden" = 4}
conditions = ["three-layer"]
'''


@pytest.fixture(scope="module")
def e3_folder(tmp_path_factory) -> Path:
    """A tiny sweep under E3's rule, evolved in process."""
    return evolved_sweep(MODULARITY, tmp_path_factory.mktemp("family"))


def write_claims(path: Path, verdicts: dict[str, tuple[str, str]]) -> Path:
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, ["key", "verdict", "verdict_holm"])
        writer.writeheader()
        for key, (raw, adjusted) in verdicts.items():
            writer.writerow({"key": key, "verdict": raw, "verdict_holm": adjusted})
    return path


def test_the_registered_sentences_follow_the_adjusted_verdicts():
    assert family.e1_sentence(REPLICATES, ABSENT).startswith("The width of the last hidden layer")
    assert family.e1_sentence(ABSENT, REPLICATES).startswith("The number of weights")
    assert family.e1_sentence(INCONCLUSIVE, REPLICATES) == (
        "Width: inconclusive; weights: replicates.")
    undecided = family.e1_sentence(REPLICATES, INCONCLUSIVE, {"E1-N": (-9.5, -4.4),
                                                               "E1-W": (-0.21, 2.46)})
    assert undecided == ("Width: replicates; weights: inconclusive; so the registered sentence "
                         "that the width, not the number of weights, decides holding is not "
                         "reached (it needs the weights absent); holding falls as the last "
                         "hidden layer widens, the fit's other terms held equal; the weights "
                         "coefficient's interval [-0.21, 2.46] allows no effect and a rise "
                         "beyond 0.5 and rules out a fall of 0.5 or more.")
    assert family.e2_sentences({"E2-S": REPLICATES, "E2-T": REPLICATES})[0].startswith("Discovery")
    assert family.e2_sentences({"E2-S": REPLICATES, "E2-T": REVERSED})[0].startswith("Maintenance")
    assert family.e2_sentences({"E2-T": INCONCLUSIVE, "E2-O": REPLICATES})[1].endswith(
        "(E2-O replicates).")
    assert "does not replicate" in family.e3_sentences({"E3-M": ABSENT})[0]
    assert "inconclusive" in family.e3_sentences({"E3-M": INCONCLUSIVE})[0]
    both = family.e3_sentences({"E3-M": REVERSED, "E3-H": ABSENT, "E3-T": REVERSED})
    assert len(both) == 3 and "equally often" in both[1] and "three-layer" in both[2]
    assert family.e3_sentences({}) == [family.e1_sentence(None, ABSENT)] == [family.NOT_RUN]
    assert family.e2_sentences({"E2-S": REPLICATES})[0].startswith("Without the transplant")


def test_the_onset_is_the_first_window_whose_top_20_hold(monkeypatch):
    separations = np.r_[np.full(40, 30.0), np.full(20, 5.0), np.full(40, 30.0)]
    successes = np.full(100, 10.0)
    monkeypatch.setattr(family, "run_series", lambda folder: {
        "top_separations": separations, "top_successes": successes})
    assert family.onset_generation(Path("x")) == 40
    separations[:] = 30.0
    assert family.onset_generation(Path("x")) is None


def test_e4_claims_are_tallied_and_compared_with_an_earlier_table(tmp_path):
    study = tmp_path / "e4"
    study.mkdir()
    write_claims(study / "claims.csv", {"a": (REPLICATES, REPLICATES), "b": (ABSENT, INCONCLUSIVE),
                                        "c": (INCONCLUSIVE, INCONCLUSIVE)})
    earlier = write_claims(tmp_path / "old.csv", {"a": (INCONCLUSIVE, INCONCLUSIVE),
                                                  "b": (INCONCLUSIVE, INCONCLUSIVE),
                                                  "c": (REPLICATES, INCONCLUSIVE)})
    text = "\n".join(family.claims_markdown(study, earlier))
    assert "| replicates | 1 | 1 |" in text and "| absent | 1 | 0 |" in text
    failed = tmp_path / "e4-premise"
    failed.mkdir()
    write_claims(failed / "claims.csv", {"a": ("premise fails", "premise fails"),
                                         "b": ("reversed", "inconclusive")})
    tally = family.claims_markdown(failed, None)
    assert "| premise fails | 1 | 1 |" in tally and "| reversed | 1 | 0 |" in tally
    assert "raw: of the 2 claims inconclusive in the earlier table, 2 leave inconclusive " \
           "(1 replicates, 1 absent); 3 of all claims change verdict." in text
    assert "after Holm: of the 3 claims inconclusive in the earlier table, 1 leave " \
           "inconclusive (1 replicates)" in text
    assert "changed after Holm: a: inconclusive -> replicates" in text


def test_a_folder_that_holds_no_experiment_is_a_one_line_error(tmp_path, capsys):
    assert main(["sweep", "experiments", str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "holds no experiment" in err and err.count("\n") == 1


def stored_screen(tmp_path: Path) -> Path:
    """A screen folder as econet sweep screen stores one, its counts made up."""
    (tmp_path / "screen.toml").write_text(
        '[cells.small]\n[cells.large]\n[rule]\nname = "e2-screen"\nlarge = "large"\n'
        'small = "small"\n')
    folder = tmp_path / "screen"
    folder.mkdir()
    (folder / screen.SPEC).write_text(json.dumps(load_spec(tmp_path / "screen.toml").to_dict()))
    (folder / screen.TABLE).write_text("cell,condition,seed,genomes,reach,hold\n"
                                       "small,normal,1,20,3,2\nlarge,normal,1,20,3,1\n")
    return folder


def test_the_page_judges_the_family_from_the_folders_given(e3_folder, tmp_path, monkeypatch,
                                                           capsys):
    moved = tmp_path / "moved"
    moved.mkdir()
    (moved / "transplant.json").write_text(json.dumps({"source": "s", "into": [4, 4, 8], "runs": [
        {"seed": s, "source": "s", "source_holds": True, "behaves_alike": True,
         "transplanted": "holds", "control": "brushes"} for s in range(6)]}))
    check = tmp_path / "check"
    check.mkdir()
    (check / family.REFERENCE_CHECK).write_text("## The independent check\n\nPASS (made up)\n")
    out = tmp_path / "page"
    assert main(["sweep", "experiments", str(e3_folder), str(moved), str(check),
                 str(stored_screen(tmp_path)), "--out", str(out)]) == 0
    text = (out / "experiments.md").read_text()
    for key in ("E2-S", "E2-T", "E3-M", "E3-H", "E3-T"):
        assert f"| {key} |" in text
    assert "E1-N" not in text.split("## E1")[0]       # not run: left out of the family
    assert "| transplanted | 6 | 1.00 [0.54, 1.00] (n=6) |" in text
    assert "PASS (made up)" in text and "sweep **tiny-e3** (e3-modularity; 6 runs)" in text
    assert family.E2_AS_BUILT in text and family.E1_S_GAIN not in text    # E1-S not run
    assert f"experiments: {out / 'experiments.md'}" in capsys.readouterr().out


def test_a_published_sweep_is_judged_from_its_spec_and_outcomes_as_its_folder_was(
        e3_folder, tmp_path):
    """The page judged from the sweep's published outcomes.csv and its spec gives the same
    family table as from its run folders."""
    build_sweep_report(e3_folder)
    published = tmp_path / "published"
    (published / "tiny-e3").mkdir(parents=True)
    shutil.copyfile(e3_folder / "outcomes.csv", published / "tiny-e3" / "outcomes.csv")
    spec = tmp_path / "tiny-e3.toml"
    spec.write_text(MODULARITY)
    pages = [family.experiments_page(folders, tmp_path / name, published=published).read_text()
             for name, folders in (("raw", [e3_folder]), ("stored", [spec]))]
    tables = [page.split("## E1")[0].split("## The family")[1] for page in pages]
    assert tables[0] == tables[1] and "| E3-M |" in tables[1]
    with pytest.raises(family.ResultsError, match="no published outcomes"):
        family.gather([spec], tmp_path)
