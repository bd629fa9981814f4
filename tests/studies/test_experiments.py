"""The pre-registered rules of the experiments (docs/preregistrations.md, "Experiments E1-E4 and
an independent check") on hand-made tidy rows of their own sweep specs: data built for a
hypothesis replicate it, data built against it reverse it, data with no effect make it absent
(where it can be), and Holm runs over the registered family."""
from pathlib import Path

import numpy as np
import pytest

from econet_ros.config import Config
from econet_ros.errors import ConfigError
from econet_ros.plugins import make_controller
from econet_ros.studies import experiments, screen
from econet_ros.science.sweeps.plan import SweepSpec
from econet_ros.science.sweeps.rules import Swept, known_rules, rule_of
from econet_ros.science.sweeps.spec import load_spec
from econet_ros.science.verdicts import ABSENT, INCONCLUSIVE, NOT_JUDGED, REPLICATES, REVERSED

SPECS = Path(__file__).resolve().parents[2] / "examples" / "sweeps"
WIDTH = load_spec(SPECS / "e1-width.toml")
RANGE = load_spec(SPECS / "e1-range.toml")
ONSET = load_spec(SPECS / "e2-onset-long.toml")
MODULARITY = load_spec(SPECS / "e3-modularity.toml")
RESAMPLES = 200          # enough to place a bootstrap interval in a test


def rows_for(spec, holds_at, seed=0, fitness=None):
    """Tidy rows of every run of SPEC; a run holds with the probability holds_at(run config,
    condition, weights) (a holding run 0.2 separations per reach, a brushing one 20)."""
    rng = np.random.default_rng(seed)
    rows = []
    for run in spec.runs():
        weights = make_controller(run.condition, 1, run.config).n_params
        held = rng.random() < holds_at(run.config, run.condition, weights)
        rows.append({"cell": run.cell, "condition": run.condition, "seed": run.seed,
                     "generations_done": spec.generations, "weights": weights,
                     "top_separations_per_success_late": 0.2 if held else 20.0,
                     "top_fitness_late": (fitness or (lambda c, h: 600.0 if h else 200.0))(
                         run.cell, held) + rng.normal(0, 10)})
    return rows


def width_of(config, condition):
    return (config.network.three_layer_hidden if condition == "three-layer"
            else config.network.intermodal_hidden)


def logistic(x):
    return 1 / (1 + np.exp(-x))


def judged(criteria):
    return {key: c.judged for key, c in criteria.items()}


def test_every_e1_cell_has_the_registered_weights_and_width():
    table = {(r.cell, make_controller(r.condition, 1, r.config).n_params,
              width_of(r.config, r.condition)) for r in WIDTH.runs()}
    assert {("four-3-3-2", 60, 2), ("four-1-1-6", 60, 6), ("four-6-6-2", 108, 2),
            ("four-1-1-12", 108, 12), ("four-9-9-2", 156, 2), ("four-1-1-18", 156, 18),
            ("three-6", 108, 6)} <= table
    assert len(WIDTH.runs()) == 240 and WIDTH.seeds == tuple(range(9101, 9121))


def test_holding_set_by_width_alone_replicates_e1_n_and_makes_weights_absent():
    rows = rows_for(WIDTH, lambda c, cond, w: logistic(6 - 3 * np.log2(width_of(c, cond))))
    found = judged(experiments.e1_width(WIDTH, rows, RESAMPLES))
    assert found["E1-N"] == REPLICATES
    assert found["E1-W"] in (ABSENT, INCONCLUSIVE) and found["E1-W"] != REPLICATES


def test_the_fit_table_shows_each_coefficient_with_both_intervals():
    rows = rows_for(WIDTH, lambda c, cond, w: logistic(6 - 3 * np.log2(width_of(c, cond))))
    criteria = experiments.e1_width(WIDTH, rows, RESAMPLES)
    lines = experiments.fit_markdown(WIDTH, rows, criteria)
    assert len(lines) == 2 + 3 + 1
    width = next(line for line in lines if line.startswith("| log2 width coefficient"))
    assert criteria["E1-N"].interval.text(2) in width
    assert width.count("[") == 2         # the bootstrap interval and the Wald one


def test_holding_set_by_weights_alone_replicates_e1_w_not_e1_n():
    rows = rows_for(WIDTH, lambda c, cond, w: logistic(18 - 3 * np.log2(w)))
    found = judged(experiments.e1_width(WIDTH, rows, RESAMPLES))
    assert found["E1-W"] == REPLICATES and found["E1-N"] != REPLICATES


def test_wider_nets_holding_more_often_reverses_e1_n():
    rows = rows_for(WIDTH, lambda c, cond, w: logistic(-6 + 3 * np.log2(width_of(c, cond))))
    assert judged(experiments.e1_width(WIDTH, rows, RESAMPLES))["E1-N"] == REVERSED


def test_a_weak_three_layer_net_replicates_e1_a():
    rows = rows_for(WIDTH, lambda c, cond, w: 0.05 if cond == "three-layer" else 0.9)
    assert judged(experiments.e1_width(WIDTH, rows, RESAMPLES))["E1-A"] == REPLICATES


def test_the_seed_cluster_interval_is_reproducible_and_holds_the_point_fit():
    rows = rows_for(WIDTH, lambda c, cond, w: 0.5)
    runs = experiments.runs_of(WIDTH, rows)
    a, b = (experiments.clustered_fit(runs, ("weights", "width"), 100) for _ in range(2))
    assert a == b
    assert a["width"].method == experiments.BOOTSTRAP and a["width"].n == 240


def test_holding_that_falls_with_the_weight_range_replicates_e1_s():
    rows = rows_for(RANGE, lambda c, cond, w: logistic(7 - 2.5 * np.log2(
        c.evolution.weight_range)))
    assert judged(experiments.e1_range(RANGE, rows, RESAMPLES))["E1-S"] == REPLICATES
    flat = rows_for(RANGE, lambda c, cond, w: 0.5)
    assert judged(experiments.e1_range(RANGE, flat, RESAMPLES))["E1-S"] != REPLICATES


@pytest.mark.parametrize("large, verdict", [(0.05, REPLICATES), (0.30, ABSENT), (0.6, REVERSED)])
def test_the_screen_judges_the_large_net_against_the_small_one(large, verdict):
    rng = np.random.default_rng(3)
    small = (rng.random(2000) < 0.3).astype(float)
    big = (rng.random(2000) < large).astype(float)
    assert screen.e2_s(big, small, "large - small")["E2-S"].judged == verdict


@pytest.mark.parametrize("flags, verdict", [([1.0] * 15 + [0.0], REPLICATES),
                                            ([0.0] * 15 + [1.0], REVERSED),
                                            ([1.0, 0.0] * 5, INCONCLUSIVE),
                                            ([1.0] * 4, NOT_JUDGED)])
def test_the_transplant_keeps_or_loses_holding(flags, verdict):
    assert experiments.transplant_kept(flags)["E2-T"].judged == verdict


def test_the_onset_rule_reads_the_large_cell_its_spec_names():
    rows = rows_for(ONSET, lambda c, cond, w: 0.95 if w == 160 else 0.0)
    found = rule_of(ONSET).criteria(Swept(ONSET, rows))
    assert found["E2-O"].judged == REPLICATES and found["E2-O"].interval.n == 20


@pytest.mark.parametrize("scrambled_holds, e3_m", [(0.1, REPLICATES), (0.9, ABSENT)])
def test_e3_replicates_when_scrambling_hurts_and_is_absent_when_it_does_not(
        scrambled_holds, e3_m):
    spec = MODULARITY
    rows = rows_for(spec, lambda c, cond, w: 0.0, fitness=lambda cell, held: {
        "modular": 600.0, "scrambled": 600.0 if scrambled_holds > 0.5 else 200.0}.get(cell, 200.0))
    for r in rows:          # holding as built: modular 90%, scrambled as asked, three-layer none
        i = spec.seeds.index(r["seed"])
        share = {"modular": 0.9, "scrambled": scrambled_holds}.get(r["cell"], 0.0)
        r["top_separations_per_success_late"] = 0.2 if i < share * len(spec.seeds) else 20.0
    found = judged(rule_of(spec).criteria(Swept(spec, rows)))
    assert found["E3-M"] == e3_m
    assert found["E3-T"] == REPLICATES


def test_the_scrambled_cell_draws_its_wiring_from_each_run_seed_and_keeps_it_when_stored():
    scrambled = [r for r in MODULARITY.runs() if r.cell == "scrambled"]
    assert [r.config.network.wiring_seed for r in scrambled] == list(range(9301, 9361))
    assert all(r.config.network.first_layer_wiring == "scrambled" for r in scrambled)
    assert all(r.config.network.wiring_seed == 0 for r in MODULARITY.runs()
               if r.cell != "scrambled")
    again = SweepSpec.from_dict(MODULARITY.to_dict())
    assert [r.config for r in again.runs()] == [r.config for r in MODULARITY.runs()]
    assert "seeded" not in WIDTH.to_dict()["cells"][0]    # stored as before without it


def test_a_cell_cannot_both_set_and_seed_a_setting(tmp_path):
    text = (SPECS / "e3-modularity.toml").read_text().replace(
        '"network.first_layer_wiring" = "scrambled"}',
        '"network.first_layer_wiring" = "scrambled", "network.wiring_seed" = 3}')
    (tmp_path / "both.toml").write_text(text)
    with pytest.raises(ConfigError, match="both sets and seeds network.wiring_seed"):
        load_spec(tmp_path / "both.toml")


def test_holm_runs_over_the_registered_family_and_can_only_withhold_a_verdict():
    rng = np.random.default_rng(4)
    criteria = {**screen.e2_s((rng.random(2000) < 0.25).astype(float),
                              (rng.random(2000) < 0.3).astype(float), "large - small"),
                **experiments.transplant_kept([1.0] * 15 + [0.0])}
    found = {j.key: j for j in experiments.family(criteria)}
    assert found["E2-T"].adjusted == found["E2-T"].verdict == REPLICATES
    assert found["E2-S"].adjusted_p >= found["E2-S"].p
    assert all(j.adjusted in (j.verdict, INCONCLUSIVE) for j in found.values())
    with pytest.raises(ValueError, match="not in the registered family"):
        experiments.family({"H1": criteria["E2-T"]})


def test_every_experiment_rule_is_registered_and_its_table_lists_its_hypotheses():
    assert {"e1-width", "e1-range", "e2-onset", "e2-population", "e3-modularity"} <= \
        set(known_rules())
    rows = rows_for(ONSET, lambda c, cond, w: 0.5)
    text = "\n".join(rule_of(ONSET).markdown(Swept(ONSET, rows)))
    assert "| E2-O |" in text and "Holm p" in text


# -- E7 (docs/preregistrations.md, "E6-E9 and the E5-E9 family") ------------------------------
DOSE = load_spec(SPECS / "e7-dose.toml")


def e7(rows):
    return experiments.e7_dose(DOSE, rows, DOSE.rule["dose"], DOSE.rule["control"], RESAMPLES)


def test_e7_cells_hold_the_registered_widths_and_weights():
    table = {(r.cell, make_controller(r.condition, 1, r.config).n_params,
              width_of(r.config, r.condition)) for r in DOSE.runs()}
    assert table == {("four-3-3-2", 60, 2), ("four-3-3-3", 72, 3), ("four-3-3-4", 84, 4),
                     ("four-3-3-6", 108, 6), ("four-3-3-8", 132, 8), ("four-3-3-12", 180, 12),
                     ("four-1-1-6", 60, 6), ("four-2-2-6", 84, 6), ("four-6-6-6", 180, 6),
                     ("four-9-9-6", 252, 6)}
    assert len(DOSE.runs()) == 200 and DOSE.seeds == tuple(range(9701, 9721))
    assert "four-3-3-6" in DOSE.rule["dose"] and "four-3-3-6" in DOSE.rule["control"]


def test_holding_set_by_width_alone_replicates_e7_d_and_leaves_weights_without_effect():
    rows = rows_for(DOSE, lambda c, cond, w: logistic(6 - 3 * np.log2(width_of(c, cond))))
    found = judged(e7(rows))
    assert found["E7-D"] == REPLICATES
    assert found["E7-W"] in (ABSENT, INCONCLUSIVE)


def test_holding_rising_with_the_weights_at_equal_width_reverses_e7_w():
    rows = rows_for(DOSE, lambda c, cond, w: logistic(4 * np.log2(w / 108)))
    assert judged(e7(rows))["E7-W"] == REVERSED


def test_e7_summary_shows_the_second_family_and_the_readings():
    rows = rows_for(DOSE, lambda c, cond, w: logistic(6 - 3 * np.log2(width_of(c, cond))))
    text = "\n".join(rule_of(DOSE).markdown(Swept(DOSE, rows)))
    assert "E6-E9 and the E5-E9 family" in text and "the 21 of E5-E9" in text
    assert "| E7-D |" in text and "| E7-W |" in text
    assert "joint fit over all 200 runs" in text


def test_a_rule_group_of_one_cell_is_refused_in_one_line():
    options = {**DOSE.rule, "dose": ["four-3-3-2"]}
    with pytest.raises(ConfigError, match="must name two or more cells"):
        rule_of(DOSE).check(options, {c.name for c in DOSE.cells})


def test_the_second_family_refuses_a_key_of_the_first():
    with pytest.raises(ValueError, match="not in the registered family"):
        experiments.family({"E1-N": None}, experiments.FAMILY_E5_E9)
