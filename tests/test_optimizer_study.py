"""econet study --optimizers on a tiny study: the normal condition under CMA-ES and the ES,
paired with the base study's GA runs, and the report's optimizer section."""
import json

import pytest

from econet_ros.cli import main
from econet_ros.config import Config
from econet_ros.science.study import SENSITIVITY, StudySpec, run_study

TINY = ["--runs", "2", "--generations", "4", "--population", "10", "--parents", "2",
        "--trials", "3", "--cycles", "25", "--quiet", "--jobs", "1"]


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """A study with one sensitivity variant (1 run); then the optimizers added and reported."""
    out = tmp_path_factory.mktemp("study")
    config = Config().replace(**{"evolution.generations": 4, "evolution.population": 10,
                                 "evolution.parents": 2, "evolution.trials": 3,
                                 "evolution.cycles": 25})
    run_study(StudySpec(config, 2, 1, {"hidden-2-2-4": SENSITIVITY["hidden-2-2-4"]}, 1), out,
              progress=False)
    assert main(["study", "--out", str(out), *TINY, "--optimizers"]) == 0
    return out


def test_optimizer_variants_run_the_normal_condition_as_often_as_the_base(study):
    out = study
    for variant in ("optimizer-cmaes", "optimizer-es"):
        folder = out / "sensitivity" / variant
        assert sorted(p.name for p in folder.iterdir()) == ["normal"]
        runs = sorted((folder / "normal").iterdir())
        assert [p.name for p in runs] == ["run-01", "run-02"]
        assert all((run / "behaviour.csv").exists() for run in runs)
    assert [p.name for p in (out / "sensitivity" / "hidden-2-2-4" / "normal").iterdir()] == \
        ["run-01"]
    stored = json.loads((out / "study.json").read_text())
    assert stored["variant_runs"] == 1 and set(stored["variants"]) == {
        "hidden-2-2-4", "optimizer-cmaes", "optimizer-es"}


def test_report_has_the_optimizer_section(study):
    out = study
    title = "## Are the constraints the task's or the algorithm's?"
    text = (out / "report.md").read_text()
    section = text[text.index(title):]
    for figure in ("optimizers_fitness", "optimizers_constraints"):
        assert (out / "figures" / f"{figure}.png").exists() and figure in section
    for constraint in ("shoulder locking", "muscle coactivation", "stereotyped approach",
                       "slowdown"):
        assert f"| {constraint} |" in section
    assert "| GA (paper) | CMA-ES | ES |" in section and "CMA-ES - GA, paired by run" in section
    sensitivity = text[text.index("## Sensitivity"):text.index(title)]
    assert "hidden-2-2-4" in sensitivity and "optimizer-cmaes" not in sensitivity
