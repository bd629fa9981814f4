"""E8's contrasts and E8/E9's choice of claims (docs/preregistrations.md, "E6-E9 and the E5-E9
family") on constructed series whose answers are known, and on a hand-made claims table."""
from pathlib import Path

import numpy as np
import pytest

from econet_ros.errors import ResultsError
from econet_ros.science.evidence import Evidence
from econet_ros.science.series import Windows
from econet_ros.science.study import ConditionData
from econet_ros.science.verdicts import ABSENT, REPLICATES, REVERSED
from econet_ros.studies import slowdown_claims as S

G, RUNS = 200, 30


def condition(name: str, **columns) -> ConditionData:
    table = {k: np.asarray(v, float) for k, v in columns.items()}
    return ConditionData(name, Path(name), G, table, {}, [G] * RUNS,
                         [Path(f"run-{i:02d}") for i in range(1, RUNS + 1)], [])


def speeds(drop: float, seed: int) -> np.ndarray:
    """(runs, G) hand speeds of 5 units/cycle, DROP lower over generations 1-19, with noise."""
    series = np.full((RUNS, G), 5.0)
    series[:, 1:20] -= drop
    return series + np.random.default_rng(seed).normal(0, 0.3, (RUNS, G))


def judged(fixated_drop, unfixated_drop, random_drop):
    ev = Evidence({"normal": condition("normal", top_hand_speed_fix=speeds(fixated_drop, 1),
                                       top_hand_speed_nofix=speeds(unfixated_drop, 2)),
                   "random": condition("random", top_hand_speed_fix=speeds(random_drop, 3))},
                  [], Windows(G))
    return {k: c.judged for k, c in S.contrasts(ev).items()}


def test_a_slowdown_only_in_sight_and_not_in_random_movement_replicates_both_contrasts():
    assert judged(3.0, 0.0, 0.0) == {"E8-F": REPLICATES, "E8-N": REPLICATES}


def test_a_slowdown_alike_without_sight_makes_e8_f_absent():
    assert judged(3.0, 3.0, 0.0)["E8-F"] == ABSENT


def test_a_slowdown_only_without_sight_reverses_e8_f():
    assert judged(0.0, 3.0, 0.0)["E8-F"] == REVERSED


def test_random_movement_slowing_as_much_makes_e8_n_absent():
    assert judged(3.0, 0.0, 3.0)["E8-N"] == ABSENT


def claims_table(tmp_path, keys, skip=()):
    lines = ["number,key,ours,verdict,p_raw"]
    lines += [f"{n},{k},measured {k},replicates,0.00{n}" for n, k in enumerate(keys, 1)
              if k not in skip]
    (tmp_path / "claims.csv").write_text("\n".join(lines) + "\n")
    return tmp_path


def test_the_named_claims_come_with_their_raw_verdicts_and_p_values(tmp_path):
    keys = [*S.E8_CLAIMS.values(), *S.E9_CLAIMS.values(), "fitness"]
    rows = S.claim_rows(claims_table(tmp_path, keys))
    found = S.claim_judgements(rows, S.E9_CLAIMS)
    assert [j.key for j in found] == list(S.E9_CLAIMS)
    latency = found[0]
    assert latency.verdict == REPLICATES and latency.p == pytest.approx(0.005)
    assert "claim 5 (latency)" in latency.measured


def test_a_claims_table_without_a_named_claim_is_refused_in_one_line(tmp_path):
    keys = [*S.E8_CLAIMS.values(), *S.E9_CLAIMS.values()]
    rows = S.claim_rows(claims_table(tmp_path, keys, skip=("away-25",)))
    with pytest.raises(ResultsError, match="lacks away-25"):
        S.claim_judgements(rows, S.E9_CLAIMS)
    with pytest.raises(ResultsError, match="no readable claims table"):
        S.claim_rows(tmp_path / "nowhere")


def test_e8_and_e9_with_the_contrasts_make_thirteen_of_the_family():
    from econet_ros.studies.experiments import FAMILY_E5_E9
    keys = [*S.E8_CLAIMS, "E8-F", "E8-N", *S.E9_CLAIMS]
    assert len(keys) == 13 and set(keys) <= set(FAMILY_E5_E9)


def test_a_p_value_that_underflows_is_shown_as_a_bound():
    assert S.finite(0.0) == "< 1e-300" and S.finite(0.0123) == "0.0123"
    assert S.finite(float("nan")) == "n/a"
