"""E6's pre-registered criteria (docs/preregistrations.md, "E6: discovery or maintenance, done
right") on hand-made records and assay rows: data built for a hypothesis replicate it, data
built against it reverse it, and data with no effect make it absent."""
import numpy as np
import pytest

from econet_ros.science import holding
from econet_ros.science.verdicts import ABSENT, INCONCLUSIVE, REPLICATES, REVERSED
from econet_ros.studies import maintenance


def record(sources: int, holding_by_arm: dict[str, float]) -> dict:
    """A transplant record of E6's arms: in each arm the first share of the sources hold late;
    a brushing source (never transplanted) beside them."""
    runs = [{"seed": s, "source_holds": True, "behaves_alike": True,
             **{arm: holding.HOLDS if s < share * sources else holding.BRUSHES
                for arm, share in holding_by_arm.items()}} for s in range(sources)]
    return {"arms": list(holding_by_arm), "runs": runs + [{"seed": -1, "source_holds": False}]}


def rows(champion, padded, silenced) -> list[dict]:
    """Assay rows, one per source and kind, from per-source shares."""
    return [{"seed": s, "kind": kind, "mutants": 200, "holding": round(v * 200), "share": v}
            for s, shares in enumerate(zip(champion, padded, silenced))
            for kind, v in zip(("champion", "padded", "silenced"), shares)]


def test_a_large_net_that_loses_what_the_small_one_keeps_opens_the_maintenance_gap():
    criteria = maintenance.maintenance(record(60, {"padded": 0.5, "silenced": 0.5,
                                                   "continued": 1.0}))
    assert criteria["E6-G"].interval.mean == 0.5 and criteria["E6-G"].interval.n == 60
    assert criteria["E6-G"].judged == REPLICATES
    assert criteria["E6-R"].interval.mean == 0.0 and criteria["E6-R"].judged == ABSENT
    assert criteria["E6-P"].interval.mean == 0.5 and criteria["E6-P"].judged == INCONCLUSIVE


def test_padded_runs_that_keep_holding_replicate_e6_p_and_reverse_the_gap():
    criteria = maintenance.maintenance(record(40, {"padded": 1.0, "silenced": 0.3,
                                                   "continued": 0.3}))
    assert criteria["E6-P"].judged == REPLICATES
    assert criteria["E6-G"].judged == REVERSED and criteria["E6-R"].judged == REVERSED


def test_silencing_that_rescues_holding_replicates_e6_r():
    criteria = maintenance.maintenance(record(40, {"padded": 0.2, "silenced": 0.9,
                                                   "continued": 0.9}))
    assert criteria["E6-R"].judged == REPLICATES and criteria["E6-P"].judged == REVERSED


def test_fragile_padded_mutants_replicate_e6_m_and_silenced_ones_are_reported_beside():
    rng = np.random.default_rng(1)
    champion = rng.uniform(0.6, 0.9, 30)
    judged = maintenance.robustness(rows(champion, champion - 0.4, champion))["E6-M"]
    assert judged.interval.mean == pytest.approx(-0.4) and judged.interval.n == 30
    assert judged.judged == REPLICATES
    assert maintenance.against_champion(rows(champion, champion - 0.4, champion),
                                        "silenced").diff.mean == 0.0


def test_equal_robustness_is_absent_and_sturdier_padded_mutants_reverse_e6_m():
    champion = np.linspace(0.3, 0.6, 30)
    assert maintenance.robustness(rows(champion, champion, champion))["E6-M"].judged == ABSENT
    assert maintenance.robustness(rows(champion, champion + 0.3,
                                       champion))["E6-M"].judged == REVERSED
