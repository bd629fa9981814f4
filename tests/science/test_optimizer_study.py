"""econet study --optimizers on a tiny study: the normal condition under CMA-ES and the ES,
paired with the base study's GA runs, and the report's optimizer section."""
import dataclasses
import json

import pytest
from test_study import TINY, tiny_spec

from econet_ros.cli import main
from econet_ros.science.study import SENSITIVITY, run_study


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    """A study with one sensitivity variant (1 run); then the optimizers added and reported."""
    out = tmp_path_factory.mktemp("study")
    spec = tiny_spec({"hidden-4-4-8": SENSITIVITY["hidden-4-4-8"]})
    run_study(dataclasses.replace(spec, variant_runs=1), out, progress=False)
    assert main(["study", "--out", str(out), *TINY, "--optimizers"]) == 0
    return out


def test_optimizer_variants_run_the_normal_condition_as_often_as_the_base(out):
    for variant in ("optimizer-cmaes", "optimizer-es"):
        folder = out / "sensitivity" / variant
        assert sorted(p.name for p in folder.iterdir()) == ["normal"]
        runs = sorted((folder / "normal").iterdir())
        assert [p.name for p in runs] == ["run-01", "run-02"]
        assert all((run / "behaviour.csv").exists() for run in runs)
    assert [p.name for p in (out / "sensitivity" / "hidden-4-4-8" / "normal").iterdir()] == \
        ["run-01"]
    stored = json.loads((out / "study.json").read_text())
    assert stored["variant_runs"] == 1 and set(stored["variants"]) == {
        "hidden-4-4-8", "optimizer-cmaes", "optimizer-es"}


def test_report_has_the_optimizer_section(out):
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
    assert "hidden-4-4-8" in sensitivity and "optimizer-cmaes" not in sensitivity
