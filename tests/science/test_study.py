"""The study command end to end on a tiny study: resume, report, and errors for bad folders."""
import csv
import json
import shutil

import pytest

from econet_ros.cli import main
from econet_ros.config import Config
from econet_ros.errors import ResultsError
from econet_ros.science.claims import CLAIMS, Claim, Judged, evaluate, judge
from econet_ros.science.evidence import Evidence
from econet_ros.science.lesion import lesion_study
from econet_ros.science.report import build_report
from econet_ros.science.series import Windows
from econet_ros.science.study import StudySpec, load_study, run_study
from econet_ros.science.verdicts import FOUR_VERDICTS as VERDICTS

TINY = ["--runs", "2", "--generations", "4", "--population", "10", "--parents", "2",
        "--trials", "3", "--cycles", "25", "--quiet", "--jobs", "1"]


def tiny_spec(variants=None):
    config = Config().replace(**{"evolution.generations": 4, "evolution.population": 10,
                                 "evolution.parents": 2, "evolution.trials": 3,
                                 "evolution.cycles": 25})
    return StudySpec(config, 2, 1, variants or {})


@pytest.fixture(scope="module")
def tiny_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    spec = tiny_spec({"hidden-4-4-8": {"network.visual_hidden": 4,
                                       "network.proprio_hidden": 4,
                                       "network.intermodal_hidden": 8}})
    run_study(spec, out, jobs=1, progress=False)
    return out


def rows(path):
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_study_writes_every_condition_with_behaviour_rows(tiny_study):
    for condition in ("normal", "three-layer", "random"):
        for run in ("run-01", "run-02"):
            folder = tiny_study / condition / run
            assert len(rows(folder / "metrics.csv")) == 4
            assert [int(r["generation"]) for r in rows(folder / "behaviour.csv")] == [0, 1, 2, 3]
    # a network-size variant re-runs only the four-layer condition
    variant = tiny_study / "sensitivity" / "hidden-4-4-8"
    assert (variant / "normal" / "run-02" / "behaviour.csv").exists()
    assert not (variant / "random").exists() and not (variant / "three-layer").exists()


def test_worker_processes_do_not_change_the_results(tiny_study, tmp_path):
    """--jobs defaults to every CPU, so a study on another machine must not differ by it."""
    out = tmp_path / "two-jobs"
    run_study(tiny_spec(), out, jobs=2, progress=False)
    for condition in ("normal", "three-layer", "random"):
        for run in ("run-01", "run-02"):
            for name in ("metrics.csv", "behaviour.csv", "genomes.npy", "fitness.npy"):
                made = (out / condition / run / name).read_bytes()
                assert made == (tiny_study / condition / run / name).read_bytes(), name


def test_report_builds_with_every_claim_and_figure(tiny_study, tmp_path):
    report, notes = build_report(tiny_study, tmp_path / "report.md")
    assert notes == []
    text = report.read_text()
    for fig in ("fig3_performance", "fig4_shoulder_flexion", "fig5_elbow_flexion",
                "fig7_coactivation", "fig8_approach", "fig9_speed", "lesion", "sensitivity"):
        assert (tmp_path / "figures" / f"{fig}.png").stat().st_size > 1000
        assert f"figures/{fig}.png" in text
    for claim in ("Four-layer econets learn faster", "8 of 10 runs", "9 of 10 runs",
                  "reciprocal activation pattern", "roughly 25%", "Severing the proprioceptive",
                  "first 50 generations", "slowdown of hand", "is 0.5"):
        assert claim in text
    table = [line for line in text.splitlines() if line.startswith("| ") and "| **" in line]
    assert len(table) == 2 * len(CLAIMS)     # every claim, for the base study and the variant
    assert all(any(f"**{v}**" in line for v in VERDICTS) for line in table)
    assert "| the paper's, raw |" in text and "| added, Holm |" in text
    assert "## Hold or brush, per run" in text and "## Do the verdicts depend on the windows?" \
        in text
    claims = rows(tmp_path / "claims.csv")
    assert [row["key"] for row in claims] == [claim.key for claim in CLAIMS]
    assert all(row["verdict"] in VERDICTS and row["verdict_holm"] in VERDICTS for row in claims)
    measured = [row for row in claims if row["verdict"] != "n/a"]
    assert measured and all(row["method"].split(",")[0] in ("t", "Clopper-Pearson", "count",
                                                            "order statistics") and
                            int(row["n"]) >= 1 and row["criteria"] for row in measured)
    assert "All runs of all conditions are complete" in text
    assert "the algorithm's?" not in text          # no optimizer variants, no such section


def test_claims_table_is_judged_claim_by_claim_in_order(tiny_study):
    keys = [claim.key for claim in CLAIMS]
    assert len(set(keys)) == len(keys) == 37
    assert sum(not claim.added for claim in CLAIMS) == 30       # the paper's table
    assert {claim.section for claim in CLAIMS} == {
        "Overall performance", "1 Joint locking", "2 Muscle coactivation",
        "3 Stereotyped approach", "4 Movement slowdown"}
    assert all(claim.paper.strip() and claim.rule.strip() for claim in CLAIMS)
    spec, groups = load_study(tiny_study)
    base = groups["base"]
    results = evaluate(base, lesion_study(base["normal"].run_dirs),
                       Windows(spec.config.evolution.generations))
    assert [result.claim for result in results] == CLAIMS
    assert all(result.verdict in VERDICTS and result.ours for result in results)
    assert any(result.verdict != "n/a" for result in results)


def test_a_claim_that_cannot_be_measured_says_why(tiny_study):
    _, groups = load_study(tiny_study)
    without = {c: d for c, d in groups["base"].items() if c != "three-layer"}
    results = {result.claim.key: result for result in evaluate(without, [], Windows(4))}
    fitness = results["fitness"]
    assert (fitness.ours, fitness.verdict) == ("not measurable: no three-layer runs", "n/a")
    assert results["lesion-start"].ours == "not measurable: no normal runs"
    assert results["shoulder-locked"].verdict != "n/a"
    broken = Claim("broken", "test", "words", "rule", lambda evidence: {}["column"])
    judged = judge(broken, Evidence(without, [], Windows(4)))
    assert judged == Judged("not measurable (KeyError: 'column')") and judged.verdict == "n/a"


def test_interrupted_behaviour_is_refilled_by_replay(tiny_study, tmp_path):
    copy = tmp_path / "copy"
    shutil.copytree(tiny_study, copy)
    path = copy / "normal" / "run-01" / "behaviour.csv"
    before = rows(path)
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:2]) + lines[2][:10])    # 1 row and a torn one
    run_study(tiny_spec(json.loads((copy / "study.json").read_text())["variants"]), copy,
              jobs=1, progress=False)
    assert rows(path) == before


def test_partial_study_is_analysed_with_the_gap_stated(tiny_study, tmp_path):
    copy = tmp_path / "partial"
    shutil.copytree(tiny_study, copy)
    metrics = copy / "three-layer" / "run-02" / "metrics.csv"
    metrics.write_text("".join(metrics.read_text().splitlines(keepends=True)[:3]))
    shutil.rmtree(copy / "random" / "run-02")
    report, notes = build_report(copy)
    assert any("three-layer" in n and "2 of 4 generations" in n for n in notes)
    assert any("random" in n and "run-02" in n and "missing" in n for n in notes)
    text = report.read_text()
    assert "This study is incomplete" in text and "2 of 4 generations" in text


def test_analyze_errors_name_what_is_missing(tmp_path, capsys):
    assert main(["analyze", str(tmp_path / "nowhere")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert main(["analyze", str(tmp_path)]) == 2
    assert "study.json is missing" in capsys.readouterr().err
    (tmp_path / "study.json").write_text(json.dumps({"format": "econet-study/0"}))
    assert main(["analyze", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "econet-study/0" in err and err.count("\n") == 1
    (tmp_path / "study.json").write_text(tiny_spec().to_json())
    with pytest.raises(ResultsError, match="no finished generation"):
        load_study(tmp_path)
    assert main(["analyze", str(tmp_path)]) == 2


def test_old_behaviour_columns_are_reported(tiny_study, tmp_path):
    copy = tmp_path / "old"
    shutil.copytree(tiny_study, copy)
    path = copy / "normal" / "run-01" / "behaviour.csv"
    path.write_text("generation,flexion\n0,50\n")
    with pytest.raises(ResultsError, match="behaviour.csv has columns from another version"):
        load_study(copy)


def test_study_command_runs_and_reports(tmp_path, capsys):
    out = tmp_path / "cli"
    assert main(["study", "--out", str(out), *TINY]) == 0
    printed = capsys.readouterr().out
    assert "report:" in printed and (out / "report.md").exists()
    # a second call resumes (nothing left to do) and refuses other settings
    assert main(["study", "--out", str(out), *TINY]) == 0
    capsys.readouterr()
    assert main(["study", "--out", str(out), *TINY[:-2], "--jobs", "1", "--seed", "5"]) == 2
    assert "different settings" in capsys.readouterr().err
    assert main(["study", "--sensitivity", "bogus", "--out", str(out), *TINY]) == 2
    assert "unknown sensitivity variant" in capsys.readouterr().err
    # sensitivity variants can be added to a finished study later, with fewer runs
    assert main(["study", "--out", str(out), *TINY, "--sensitivity", "hidden-8-8-16",
                 "--sensitivity-runs", "1"]) == 0
    variant = out / "sensitivity" / "hidden-8-8-16" / "normal"
    assert sorted(p.name for p in variant.iterdir()) == ["run-01"]
    text = (out / "report.md").read_text()
    assert "**hidden-8-8-16**" in text and "Verdict depends on the setting" in text
