"""The decision rule of docs/preregistrations.md applied to hand-made sweep rows: a setting built to
meet all eight criteria passes, and breaking any one criterion fails exactly that one, and
with it the setting's verdict and the rule's choice of defaults."""
import numpy as np
import pytest

from econet_ros.studies.regime import (defaults_markdown, judge_setting, paper_like,
                                       reproduces, settings, verdicts)
from econet_ros.science.sweeps.spec import load_spec

SPEC = """
name = "rule"
generations = 20
seeds = {first = 1, count = 10}
[cells.F]
set = {"network.intermodal_hidden" = 9}
conditions = ["normal"]
[cells.T]
conditions = ["three-layer"]
[cells.R]
conditions = ["random"]
[[compare]]
a = {cell = "F", condition = "normal"}
b = {cell = "T", condition = "three-layer"}
[[compare]]
a = {cell = "F", condition = "normal"}
b = {cell = "R", condition = "random"}
"""

# Late and early window values per side; every seed gets them plus a little seed noise.
PAPER_LIKE = {
    ("F", "normal"): dict(fitness_late=900, fitness_early=100, successes_late=15,
                          separations_late=5, separations_per_success_late=0.3, eye=3.0),
    ("T", "three-layer"): dict(fitness_late=600, fitness_early=50, successes_late=10,
                               separations_late=20, separations_per_success_late=2.0, eye=5.0),
    ("R", "random"): dict(fitness_late=15, fitness_early=15, successes_late=4,
                          separations_late=60, separations_per_success_late=2.7, eye=7.5),
}
# One change per criterion that should break exactly that criterion.
BREAKS = {
    "F1": (("F", "normal"), "fitness_late", 590),
    "F2": (("F", "normal"), "fitness_early", 40),
    "F3": (("F", "normal"), "successes_late", 9),
    "F4": (("F", "normal"), "separations_late", 25),
    "B1": (("F", "normal"), "separations_per_success_late", 1.5),
    "B2": (("R", "random"), "separations_late", 4),
    "B3": (("R", "random"), "fitness_late", 100),
    "B4": (("F", "normal"), "eye", 8.0),
}


def rows_for(sides):
    noise = np.random.default_rng(0).normal(0, 0.01, 10)
    return [{"cell": cell, "condition": condition, "seed": seed,
             "top_fitness_late": v["fitness_late"] * (1 + noise[k]),
             "top_fitness_early": v["fitness_early"] * (1 + noise[k]),
             "top_successes_late": v["successes_late"],
             "top_separations_late": v["separations_late"],
             "top_separations_per_success_late": v["separations_per_success_late"],
             "top_eye_speed_fix_late": v["eye"] + noise[k]}
            for (cell, condition), v in sides.items() for k, seed in enumerate(range(1, 11))]


@pytest.fixture(scope="module")
def spec(tmp_path_factory):
    path = tmp_path_factory.mktemp("rule") / "rule.toml"
    path.write_text(SPEC)
    return load_spec(path)


def test_a_paper_like_setting_meets_all_eight_and_becomes_the_default(spec):
    [setting] = settings(spec)
    criteria = judge_setting(spec, rows_for(PAPER_LIKE), setting)
    assert [c.key for c in criteria] == ["F1", "F2", "F3", "F4", "B1", "B2", "B3", "B4"]
    assert all(c.met for c in criteria), [c for c in criteria if not c.met]
    text = "".join(defaults_markdown(verdicts(spec, rows_for(PAPER_LIKE))))
    assert "both: F vs T" in text and "becomes the default" in text


@pytest.mark.parametrize("key", BREAKS)
def test_breaking_one_criterion_fails_only_it_and_keeps_the_defaults(spec, key):
    side, field, value = BREAKS[key]
    sides = {s: dict(v) for s, v in PAPER_LIKE.items()}
    sides[side][field] = value
    [setting] = settings(spec)
    criteria = judge_setting(spec, rows_for(sides), setting)
    assert [c.key for c in criteria if not c.met] == [key]
    assert reproduces(criteria) == key.startswith("B")
    assert paper_like(criteria) == key.startswith("F")
    text = "".join(defaults_markdown(verdicts(spec, rows_for(sides))))
    assert "both: none" in text and "the defaults stay" in text
