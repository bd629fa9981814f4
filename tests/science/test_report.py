"""The report's claim and holding sections on hand-made results whose answers are known: the
holding table, the tally (the paper's claims apart from the added ones, raw and after Holm,
with the flagged ones counted), the window table, claims.csv, and what the optimizer study
concludes from the four verdicts."""
import csv
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from econet_ros.science import report
from econet_ros.science.claims import CLAIMS, ClaimResult, Judged, Nulls
from econet_ros.science.measures import ReachSummary
from econet_ros.science.optimizer_study import Comparison
from econet_ros.science.series import Windows
from econet_ros.science.stats import Estimate, paired, share
from econet_ros.science.study import ConditionData
from econet_ros.science.verdicts import above

G, RUNS = 20, 10
CLAIM = {claim.key: claim for claim in CLAIMS}


def condition(name, **columns):
    table = {k: np.broadcast_to(np.asarray(v, float), (RUNS, G)).copy()
             for k, v in columns.items()}
    return ConditionData(name, Path(name), G, table, {}, [G] * RUNS,
                         [Path(f"run-{i:02d}") for i in range(1, RUNS + 1)], [])


def test_holding_counts_runs_that_hold_brush_or_never_reach():
    per_run = lambda values: np.array(values, float)[:, None]  # noqa: E731
    separations = per_run([2] * 7 + [250] * 2 + [0])     # per generation, 10 successes each:
    successes = per_run([10] * 9 + [0])                   # 0.2 (holds) x7, 25 x2, none x1
    normal = condition("normal", top_separations=separations, top_successes=successes,
                       top_fitness=per_run([900] * 7 + [100] * 3))
    lines = report._holding(SimpleNamespace(windows=Windows(G), groups={"base": {
        "normal": normal}}))
    summary = next(line for line in lines if line.startswith("| normal |"))
    assert "| 7 / 2 / 1 |" in summary
    assert share([1] * 7 + [0] * 3).text() in summary       # 0.70 [0.35, 0.93] (n=10)
    assert "0.20 [0.20, 25.00] (n=9)" in summary              # the median of 9 reaching runs
    assert "| 660 [384, 936] (n=10); 900 [100, 900] (n=10) |" in summary   # mean; median
    assert "| run-01 | 0.20 (holds) |" in lines and "| run-08 | 25.00 (brushes) |" in lines
    assert "| run-10 | n/a (does not reach) |" in lines


def result(key, verdict, shuffled=math.nan, random="reversed", p_holm=None):
    """A claim result whose one criterion gives the verdict asked for (Holm-adjusted p: the
    raw one unless given)."""
    low = {"replicates": 1.0, "reversed": -3.0, "inconclusive": -0.5, "absent": -0.5}[verdict]
    difference = paired(low + np.linspace(0, 1.0, RUNS), np.zeros(RUNS))
    margin = 1.0 if verdict == "absent" else math.nan
    judged = Judged(f"{key} measured", (above(f"{key} difference", difference, margin=margin),))
    assert judged.verdict == verdict
    return ClaimResult(CLAIM[key], judged, Nulls(random, shuffled),
                       judged.p if p_holm is None else p_holm)


def conditional(key, premise_verdict, own_verdict, p_holm=None):
    """A claim result conditional on a premise judged premise_verdict, its own criteria
    own_verdict."""
    own, premise = result(key, own_verdict), result("stereotyped-start", premise_verdict)
    judged = own.judged._replace(premise=premise.judged, premise_key="stereotyped-start")
    return ClaimResult(CLAIM[key], judged, Nulls("reversed", math.nan),
                       judged.p if p_holm is None else p_holm)


def test_the_tally_counts_the_verdicts_raw_and_after_holm_premise_fails_apart():
    results = [result("fitness", "replicates", p_holm=0.2),              # Holm: inconclusive
               result("latency", "reversed"), result("successes", "absent"),
               result("lock-speed", "replicates", shuffled=1.0),            # flagged
               conditional("lesion-start", "reversed", "replicates"),
               conditional("lock-position", "reversed", "reversed", p_holm=0.3),
               result("others-mobile", "inconclusive", random="replicates"),  # added, flagged
               result("two-joint-search", "replicates", shuffled=0.5)]      # added, flagged
    lines = report._tally(results)
    # replicates | absent | reversed | premise fails | inconclusive | n/a | all | flagged
    assert "| the paper's, raw | 2 | 1 | 1 | 2 | 0 | 0 | 6 | 1 |" in lines
    assert "| the paper's, Holm | 1 | 1 | 1 | 1 | 2 | 0 | 6 | 1 |" in lines
    assert "| added, raw | 1 | 0 | 0 | 0 | 1 | 0 | 2 | 2 |" in lines
    assert lines[-1] == ("Flagged, every one: 4 lock-speed (replicates: cannot tell a time "
                         "course from a level); 7 others-mobile (inconclusive: replicates on "
                         "random movement: cannot tell learning from chance); 8 "
                         "two-joint-search (replicates: cannot tell a time course from a "
                         "level).\n")
    row = next(line for line in report._claims_table(results).split("\n")
               if line.startswith("| 5 |"))
    assert "**premise fails**" in row and "premise stereotyped-start: reversed" in row
    assert "own criteria: replicates<br>lesion-start difference" in row
    assert results[0].adjusted == "inconclusive" and results[1].adjusted == "reversed"
    table = report._claims_table(results, nulls=True)
    assert table.count("(flagged: cannot tell a time course from a level)") == 2
    assert table.count("(flagged: replicates on random movement") == 1
    assert "P(approach" not in table and "detectable" in table and "margin 1" in table


def test_the_window_table_has_a_row_per_moved_window_and_names_the_claims_that_move():
    base = [result("fitness", "replicates"), result("latency", "reversed")]
    moved = {label: list(base) for label in Windows(200).moved()}
    moved["slowdown dip gens 10-49"] = [base[0], result("latency", "inconclusive")]
    analysis = SimpleNamespace(windows=Windows(200), claims={"base": base},
                               moved_windows=moved)
    lines = report._windows(analysis)
    rows = [line for line in lines if line.startswith("| ") and "gens" in line.split("|")[1]]
    assert len(rows) == len(moved) == 18           # every window moved, start and dip included
    assert "| slowdown dip gens 10-49 | 2 latency: reversed -> inconclusive |" in rows
    assert "| slowdown start gens 0-4 | none |" in rows and "| start gens 0-7 | none |" in rows
    assert "1 of 2 claims depend on where a window lies: 2 latency" in lines[-1]
    unmoved = {label: list(base) for label in Windows(200).moved()}
    assert "0 of 2 claims depend" in report._windows(SimpleNamespace(
        windows=Windows(200), claims={"base": base}, moved_windows=unmoved))[-1]


def test_claims_csv_has_the_deciding_interval_its_method_power_and_flags(tmp_path):
    results = [result("fitness", "inconclusive"),
               result("lock-speed", "replicates", 0.9, random="replicates", p_holm=0.3),
               result("successes", "absent")]
    moved = {"early 5%": [results[0], result("lock-speed", "reversed"), results[2]]}
    path = tmp_path / "claims.csv"
    report.write_claims_csv(path, results, moved)
    rows = list(csv.DictReader(open(path, newline="")))
    assert list(rows[0]) == report.CLAIM_COLUMNS
    first, second, third = rows
    criterion = results[0].judged.criteria[0]
    assert (first["criterion"], first["method"], first["n"], first["region"]) == (
        "fitness difference", "t", "10", "> 0")
    assert float(first["ci_low"]) == pytest.approx(criterion.interval.lo)
    assert float(first["detectable"]) == pytest.approx(criterion.comparison.detectable)
    assert first["verdict"] == first["verdict_holm"] == "inconclusive"
    assert (first["flag_shuffled"], first["flag_random"], first["window_changes"]) == (
        "False", "False", "")
    assert (second["flag_shuffled"], second["flag_random"]) == ("True", "True")
    assert second["window_changes"] == "early 5%: reversed"
    assert (second["verdict"], second["verdict_holm"], float(second["p_holm"])) == (
        "replicates", "inconclusive", 0.3)
    assert float(second["p_raw"]) < 0.05 and second["null_random_verdict"] == "replicates"
    assert (third["verdict"], float(third["margin"])) == ("absent", 1.0)
    assert float(third["runs_for_80_power"]) >= 2


def test_a_claim_without_criteria_is_written_as_not_measured(tmp_path):
    unmeasured = ClaimResult(CLAIM["fitness"], Judged("not measurable: no three-layer runs"))
    report.write_claims_csv(tmp_path / "claims.csv", [unmeasured])
    (row,) = csv.DictReader(open(tmp_path / "claims.csv", newline=""))
    assert (row["verdict"], row["criterion"], row["n"], row["estimate"]) == ("n/a", "", "0",
                                                                             "nan")


@pytest.mark.parametrize("ga, others, expected", [
    ("replicates", ("replicates", "replicates"), "Under every optimizer (not the GA's; the "
                                                 "task's or the shared network's): shoulder "
                                                 "locking"),
    ("replicates", ("reversed", "absent"), "(the algorithm's): shoulder locking"),
    ("replicates", ("reversed", "inconclusive"), "Cannot be told from these runs: shoulder "
                                                 "locking (GA (paper) replicates, CMA-ES "
                                                 "reversed, ES inconclusive)"),
    ("absent", ("reversed", "absent"), "Absent under every optimizer: shoulder locking"),
])
def test_the_optimizer_study_reads_the_four_verdicts(ga, others, expected):
    verdicts = dict(zip(("ga", "cmaes", "es"), (ga, *others)))
    claims = {opt: [result("shoulder-locked", v)] + [result(key, "inconclusive") for key in
                                                     ("elbow-coactivated", "stereotyped-start",
                                                      "hand-slowdown")]
              for opt, v in verdicts.items()}
    comparison = Comparison(dict.fromkeys(verdicts), claims, Windows(G))
    assert any(expected in line for line in comparison._conclusion())


def test_an_estimate_without_runs_gives_no_verdict():
    assert above("x", Estimate(math.nan, math.nan, math.nan, 0)).verdict == "n/a"


def test_the_threshold_table_stands_beside_the_registered_verdict_and_says_if_it_flips():
    locked = result("shoulder-locked", "reversed")._replace(
        readings=(("85/15", "reversed"), ("80/20", "replicates")))
    steady = result("stereotyped-start", "reversed")._replace(readings=(("< 0.75", "reversed"),))
    analysis = SimpleNamespace(claims={"base": [result("fitness", "replicates"), locked,
                                                steady]})
    lines = report._thresholds(analysis)
    assert lines[0] == "## Thresholds the paper does not give\n"
    rows = [line for line in lines if line.startswith("| 2 |") or line.startswith("| 3 |")]
    assert rows[0].endswith("| reversed; reversed | 85/15: reversed; 80/20: replicates | yes |")
    assert rows[1].endswith("| < 0.75: reversed | no |")
    assert not any(line.startswith("| 1 |") for line in lines)
    assert "at other thresholds: 85/15: reversed; 80/20: replicates" in report._claims_table(
        [locked])



def test_the_lesion_rows_are_published_per_run_and_kind(tmp_path):
    summary = ReachSummary(0.5, 20.0, 0.6, 0.7, 9.0, 4.0, 3.0, 3.5, 20.0, 30.0, 10,
                           latency_every_trial=60.0, trial_latency=(20.0, math.nan))
    runs = [{"run": f"run-0{i}", "generation": 199, "intact": summary, "lesioned": summary,
             "vision-lesioned": summary} for i in (1, 2)]
    report.write_lesion_rows(tmp_path / "data" / "lesion.csv", runs)
    with open(tmp_path / "data" / "lesion.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["run"], r["kind"]) for r in rows][:3] == [
        ("run-01", "intact"), ("run-01", "lesioned"), ("run-01", "vision-lesioned")]
    assert len(rows) == 6 and rows[0]["latency_every_trial"] == "60.0"
    assert rows[0]["path_efficiency"] == "0.7" and "trial_latency" not in rows[0]
    assert rows[0]["reach_elbow_spread"] == ""                     # NaN: not measured
