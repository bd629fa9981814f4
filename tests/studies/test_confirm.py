"""The pre-registered rule (docs/preregistrations.md, "The confirmatory study") on hand-made tidy
rows of its own sweep specs: data built to meet a hypothesis replicate it, data built against
it contradict it, and data that cannot tell are inconclusive; the reports ask the rule, which
chooses the defaults over the regime rule and checks its registration."""
import math
from pathlib import Path

import numpy as np
import pytest

from econet_ros.science.sweeps.outcomes import OUTCOMES, WINDOWS
from econet_ros.science.sweeps.rules import Swept, choose_defaults, named_rule, rule_of
from econet_ros.science.sweeps.spec import load_spec
from econet_ros.studies import confirm

SPECS = Path(__file__).resolve().parents[2] / "examples" / "sweeps"
CONFIRM = load_spec(SPECS / "confirm.toml")
MAP = load_spec(SPECS / "load-map.toml")
# the commit that wrote the confirmatory study's and the map's pre-registration into the docs
REGISTRATION = "8b795cf729e77c19bbb05e21bbfdc270fb52c859"
NETS = named_rule("confirmatory").networks(Swept(CONFIRM, []))      # the cells its [rule] names
EQUAL = named_rule("load-map").equal_loads(Swept(MAP, []))


def confirm_rows(gap=300.0, early_gap=50.0, holding_runs=18, noise=20.0, seed=0):
    """F ahead of T8 and T4 by ``gap`` late, ``early_gap`` early; F holds in ``holding_runs``
    of 20 seeds (0.2 separations per reach), the three-layer nets brush (20 per reach)."""
    rng = np.random.default_rng(seed)
    rows = []
    for run in CONFIRM.runs():
        four = run.condition == "normal"
        i = CONFIRM.seeds.index(run.seed)
        per_reach = (0.2 if i < holding_runs else 20.0) if four else 20.0
        successes = 15.0 if four else 10.0
        rows.append({"cell": run.cell, "condition": run.condition, "seed": run.seed,
                     "generations_done": CONFIRM.generations,
                     "top_fitness_late": 400 + (gap if four else 0) + rng.normal(0, noise),
                     "top_fitness_early": 50 + (early_gap if four else 0) + rng.normal(0, 5),
                     "top_successes_late": successes + rng.normal(0, 0.5),
                     "top_separations_late": per_reach * successes,
                     "top_separations_per_success_late": per_reach})
    return rows


def verdicts(rows):
    return {c.key: c.verdict for c in confirm.h1_criteria(CONFIRM, rows, NETS)}


def test_data_built_to_meet_h1_replicate_it_and_make_2_2_4_the_default():
    rows = confirm_rows()
    assert set(verdicts(rows).values()) == {confirm.REPLICATES}
    assert confirm.decide(CONFIRM, rows, NETS) == confirm.REPLICATES
    text = "\n".join(confirm.confirmatory(CONFIRM, rows, NETS))
    assert "**H1 replicates.**" in text and "2/2/4 become the defaults" in text
    assert "survives size matching" in text        # T4 built as weak as T8 here


@pytest.mark.parametrize("change, key, verdict", [
    ({"gap": -300.0}, "H1-F1", confirm.CONTRADICTED),
    ({"gap": 0.0, "noise": 200.0}, "H1-F1", confirm.INCONCLUSIVE),
    ({"early_gap": -50.0}, "H1-F2", confirm.CONTRADICTED),
    ({"holding_runs": 4}, "H1-hold", confirm.CONTRADICTED),      # 4 of 20: [0.06, 0.44]
    ({"holding_runs": 12}, "H1-hold", confirm.INCONCLUSIVE),     # 12 of 20: [0.36, 0.81]
])
def test_breaking_one_criterion_decides_h1_by_that_criterion(change, key, verdict):
    rows = confirm_rows(**change)
    found = verdicts(rows)
    assert found[key] == verdict
    assert confirm.decide(CONFIRM, rows, NETS) == verdict
    assert "defaults stay the a-priori ones" in "\n".join(confirm.confirmatory(CONFIRM, rows, NETS))


def map_rows(holding_at, seed=1):
    """Every map run holds with the probability holding_at(load, weights, three_layer)."""
    rng = np.random.default_rng(seed)
    rows = []
    for run in MAP.runs():
        e, n = run.config.evolution, run.config.network
        three = run.condition == "three-layer"
        weights = 18 * n.three_layer_hidden if three else (
            8 * n.visual_hidden + 4 * n.proprio_hidden
            + (n.visual_hidden + n.proprio_hidden + 1) * n.intermodal_hidden
            + 5 * n.intermodal_hidden)
        load = weights * e.bits_per_weight * e.mutation_rate
        held = rng.random() < holding_at(load, weights, three)
        rows.append({"cell": run.cell, "condition": run.condition, "seed": run.seed,
                     "generations_done": MAP.generations, "weights": weights,
                     "bit_flips_per_copy": load, "top_fitness_late": 500.0 if held else 150.0,
                     "top_separations_per_success_late": 0.2 if held else 20.0})
    return rows


def map_verdicts(rows):
    lines = confirm.load_map(MAP, rows, EQUAL)
    return {line.split(" | ")[0][2:]: line.rsplit(" | ", 1)[1][:-2] for line in lines
            if line.startswith("| H3")}


def test_holding_that_falls_with_load_alone_replicates_h3a_and_h3b():
    found = map_verdicts(map_rows(lambda load, w, three: 1 / (1 + (load / 12.0) ** 4)))
    assert found["H3a"] == confirm.REPLICATES
    assert found["H3b"] != confirm.CONTRADICTED and found["H3c"] != confirm.CONTRADICTED
    assert found["H3d-1"] != confirm.CONTRADICTED      # equal loads hold alike


def test_holding_set_by_size_not_load_contradicts_h3b():
    found = map_verdicts(map_rows(lambda load, w, three: 0.9 if w <= 72 else 0.05))
    assert found["H3b"] == confirm.CONTRADICTED
    assert found["H3d-1"] == confirm.CONTRADICTED      # 4/4/8 at 0.8% against 2/2/4 at 2%


def test_the_load_map_lists_every_cell_with_its_load():
    rows = map_rows(lambda load, w, three: 0.5)
    table = confirm.map_table(confirm.map_runs(MAP, rows))
    assert len(table) == 2 + len(MAP.cells)
    assert any(line.startswith("| four-4-4-8-L10.24 | 160 | 10.24 |") for line in table)


def test_holding_table_intervals_stay_inside_the_measures_range():
    """Most runs hold (0.2 separations per reach) and a few brush (20): the t interval of the
    mean reaches below 0, which no count of separations can; the table clips it at 0."""
    from econet_ros.science.holding import kind
    from econet_ros.science.sweeps.report import holding_markdown

    rows = confirm_rows(holding_runs=17)
    for row in rows:
        row["holding_late"] = kind(row["top_separations_per_success_late"])
    line = next(line for line in holding_markdown(CONFIRM, rows)
                if line.startswith(f"| {NETS.four[0]} | normal"))
    separations = line.split(" | ")[4]
    mean_part = separations.split(";")[0]                 # "3.2 [0.0, 6.5] (n=20)"
    low = float(mean_part.split("[")[1].split(",")[0])
    assert "17 / 3 / 0" in line and low == 0.0, line


# -- the rules as the reports ask them ---------------------------------------------------------
def confirmed_rows() -> list[dict]:
    """The confirmatory sweep's hand-made rows (test_confirm), with every other outcome NaN."""
    unmeasured = {f"{o.name}_{w}": math.nan for o in OUTCOMES for w in WINDOWS}
    return [{**unmeasured, "weights": 64, **row} for row in confirm_rows()]


def test_the_pre_registered_sweeps_name_their_registration_and_the_report_checks_it():
    for name in ("confirm", "load-map"):
        assert load_spec(SPECS / f"{name}.toml").rule["registered"] == REGISTRATION
    rows = [{**row, "commit": "", "dirty": ""} for row in confirmed_rows()]
    sweep = Swept(load_spec(SPECS / "confirm.toml"), rows)
    said = sweep.registration()
    assert said.startswith(f"Pre-registered at commit `{REGISTRATION[:12]}`")
    assert f"of 0 of its {len(rows)} run(s); {len(rows)} cannot be checked here" in said
    assert Swept(load_spec(SPECS / "arch-x-mutation.toml"), rows).registration() == ""


def test_the_rule_not_the_name_decides_the_report(tmp_path):
    spec = load_spec(SPECS / "confirm.toml")
    spec.name = "renamed"
    sweep = Swept(spec, confirmed_rows())
    text = "\n".join(rule_of(spec).markdown(sweep))
    assert "### H1:" in text and "setting by setting" in text    # its tables and regime's
    assert "2/2/4 become the defaults" in "\n".join(choose_defaults([sweep]))
    assert rule_of(spec).architecture(sweep, [sweep])[0].startswith("## The architecture")


def test_the_confirmatory_rule_chooses_the_defaults_over_the_regime_rule():
    confirmed = Swept(load_spec(SPECS / "confirm.toml"), confirmed_rows())
    regime = Swept(load_spec(SPECS / "arch-x-mutation.toml"), [])
    assert choose_defaults([regime, confirmed]) == choose_defaults([confirmed])
