"""The E5-E9 page (studies/second_family.py): Holm over the registered family in its order,
E6's decision and README's mechanism sentence as registered, from adjusted verdicts; a page
from a stored E5 table."""
import csv

import pytest

from econet_ros.errors import ResultsError
from econet_ros.science import holding
from econet_ros.science.verdicts import ABSENT, INCONCLUSIVE, REPLICATES, REVERSED
from econet_ros.studies import holding_mechanism as e5
from econet_ros.studies import second_family as F
from econet_ros.studies.slowdown_claims import Judgement


def test_holm_runs_over_the_judged_hypotheses_in_the_registered_order():
    found = {"E7-W": Judgement("E7-W", "w", REPLICATES, 0.03),
             "E5": Judgement("E5", "five", REPLICATES, 0.001)}
    adjusted = F.adjust(found)
    assert [a.judgement.key for a in adjusted] == ["E5", "E7-W"]
    assert adjusted[0].adjusted_p == pytest.approx(0.002) and adjusted[0].adjusted == REPLICATES
    assert adjusted[1].adjusted_p == pytest.approx(0.03) and adjusted[1].adjusted == REPLICATES
    with pytest.raises(ValueError, match="not in the registered family"):
        F.adjust({"E1-N": Judgement("E1-N", "", REPLICATES, 0.01)})


@pytest.mark.parametrize("gap, screen, rescue, expected", [
    (REPLICATES, INCONCLUSIVE, REPLICATES, "**maintenance**, through the last layer's"),
    (REPLICATES, ABSENT, ABSENT, "**maintenance**, not through"),
    (REPLICATES, REPLICATES, INCONCLUSIVE, "**both** discovery and maintenance (E6-G"),
    (ABSENT, REPLICATES, ABSENT, "**discovery**"),
    (ABSENT, ABSENT, ABSENT, "**Neither, at these margins**"),
    (INCONCLUSIVE, REPLICATES, ABSENT, "No decision: E6-G is inconclusive"),
    (REVERSED, ABSENT, ABSENT, "No decision: E6-G is reversed"),
])
def test_e6s_decision_is_the_registered_one(gap, screen, rescue, expected):
    assert expected in F.decision({"E6-G": gap, "E6-S": screen, "E6-R": rescue})


def test_the_decision_waits_for_both_of_its_hypotheses():
    assert "waits" in F.decision({"E6-G": REPLICATES})


def test_the_mechanism_sentence_needs_all_five_verdicts():
    allowed = {"E5": REPLICATES, "E6-G": REPLICATES, "E6-R": REPLICATES, "E7-D": REPLICATES,
               "E7-W": ABSENT}
    assert F.mechanism_sentence(allowed).startswith("Holding is touch silencing")
    told = F.mechanism_sentence({**allowed, "E7-W": REPLICATES})
    assert "not (yet) allowed" in told and "E7-W replicates" in told
    assert "E6-R not yet judged" in F.mechanism_sentence({"E5": REPLICATES})


def e5_table(folder, sources):
    folder.mkdir()
    with open(folder / e5.TABLE, "w", newline="") as out:
        writer = csv.DictWriter(out, ["run", "class", "median_largest_on_contact"])
        writer.writeheader()
        for i, source in enumerate(sources):
            writer.writerow({"run": f"{source}/run-01", "class": holding.HOLDS,
                             "median_largest_on_contact": 0.001})
            writer.writerow({"run": f"{source}/run-02", "class": holding.BRUSHES,
                             "median_largest_on_contact": 0.9})
    return folder


def test_a_page_from_a_whole_e5_table_judges_e5_and_names_what_waits(tmp_path):
    folder = e5_table(tmp_path / "e5", e5.REGISTERED_DATA)
    page = F.second_family_page({"e5": folder}, tmp_path / "page").read_text()
    assert "| E5 |" in page and "E6-P, E6-G" in page and "Not judged yet" in page
    assert "E6's decision waits" in page


def test_a_partial_e5_table_is_named_not_judged(tmp_path):
    folder = e5_table(tmp_path / "e5", ["e4"])
    page = F.second_family_page({"e5": folder}, tmp_path / "page").read_text()
    assert "| E5 |" not in page and "E5 not judged here: its table is partial" in page


def test_an_unknown_experiment_or_a_missing_folder_is_refused_in_one_line(tmp_path):
    with pytest.raises(ResultsError, match="no experiment named 'e10'"):
        F.second_family_page({"e10": tmp_path}, tmp_path / "page")
    with pytest.raises(ResultsError, match="e7: no folder"):
        F.second_family_page({"e7": tmp_path / "none"}, tmp_path / "page")


def test_e6_s_comes_from_an_e6_screen_and_not_from_e2s(tmp_path):
    from sweep_helpers import screened_into, tiny_screen
    (tmp_path / "e6").mkdir()
    (tmp_path / "e2").mkdir()
    e6 = screened_into(tiny_screen("e6-screen"), tmp_path / "e6")
    page = F.second_family_page({"e6_screen": e6}, tmp_path / "page").read_text()
    assert "| E6-S |" in page and "- E6-S screen: **Code**" in page
    e2 = screened_into(tiny_screen("e2-screen"), tmp_path / "e2")
    with pytest.raises(ResultsError, match="another rule than E6's"):
        F.second_family_page({"e6_screen": e2}, tmp_path / "page")


def test_e6s_arms_and_assay_come_from_their_stored_folders(tmp_path):
    import json
    arms = tmp_path / "arms"
    arms.mkdir()
    runs = [{"seed": s, "source_holds": True, "padded": holding.BRUSHES if s % 2 else
             holding.HOLDS, "silenced": holding.HOLDS, "continued": holding.HOLDS}
            for s in range(60)]
    (arms / "transplant.json").write_text(json.dumps(
        {"source": "x", "into": [4, 4, 8], "arms": ["padded", "silenced", "continued"],
         "runs": runs}))
    assay = tmp_path / "assay"
    assay.mkdir()
    lines = ["seed,kind,mutants,holding,share"] + [
        f"{s},{kind},100,{held},{held / 100}" for s in range(30)
        for kind, held in (("champion", 90), ("padded", 40), ("silenced", 85))]
    lines.append("9101,natural e1-width/four-4-4-8,100,50,0.5")
    (assay / "robustness.csv").write_text("\n".join(lines) + "\n")
    page = F.second_family_page({"e6_transplant": arms, "e6_robustness": assay},
                                tmp_path / "page").read_text()
    for key in ("E6-P", "E6-G", "E6-R", "E6-M"):
        assert f"| {key} |" in page
    assert "silenced - champion" in page
    assert "natural 4/4/8 holders' mutants hold in a median share of 0.500 (n = 1" in page
    assert "(n = 30)" in page                # the natural row is not a champion of E6-M
    (arms / "transplant.json").write_text(json.dumps(
        {"source": "x", "into": [4, 4, 8], "arms": ["transplanted", "control"], "runs": []}))
    with pytest.raises(ResultsError, match="holds no E6 arm"):
        F.second_family_page({"e6_transplant": arms}, tmp_path / "page")
