"""The claims' statistics on constructed data whose answers are known: paired intervals, the
verdicts they give, first passage, the premise of lesion-start, and the two nulls."""
from pathlib import Path

import numpy as np
import pytest

from econet_ros.science import claims as C
from econet_ros.science.evidence import Evidence, first_passage
from econet_ros.science.measures import ReachSummary
from econet_ros.science.series import Windows
from econet_ros.science.study import ConditionData

G, RUNS = 40, 10


def condition(name: str, **columns) -> ConditionData:
    """A condition whose every column is given as (runs, G) or as one (G,) series for all."""
    table = {k: np.broadcast_to(np.asarray(v, float), (RUNS, G)).copy()
             for k, v in columns.items()}
    return ConditionData(name, Path(name), G, table, {}, [G] * RUNS,
                         [Path(f"run-{i:02d}") for i in range(1, RUNS + 1)], [])


def evidence(**conditions) -> Evidence:
    return Evidence(conditions, [], Windows(G))


def noisy(base, scale, seed):
    return base + np.random.default_rng(seed).normal(0, scale, (RUNS, G))


@pytest.mark.parametrize("shift, expected", [(5.0, "replicates"), (-5.0, "does not")])
def test_fitness_claim_follows_the_paired_interval(shift, expected):
    three = noisy(100.0, 3.0, 1)
    ev = evidence(normal=condition("normal", top_fitness=three + shift),
                  **{"three-layer": condition("three-layer", top_fitness=three)})
    judged = C.fitness_ahead(ev)
    assert judged.verdict == expected
    assert judged.comparison.diff.mean == pytest.approx(shift)
    assert judged.comparison.above == (RUNS if shift > 0 else 0)


def test_a_difference_inside_the_noise_is_only_partly():
    rng = np.random.default_rng(3)
    three = noisy(100.0, 3.0, 4)
    late = np.zeros((RUNS, G))
    late[:, -4:] = rng.normal(0.5, 20.0, (RUNS, 1))        # late: tiny mean, huge spread
    ev = evidence(normal=condition("normal", top_fitness=three + late),
                  **{"three-layer": condition("three-layer", top_fitness=three)})
    judged = C.fitness_ahead(ev)
    assert judged.comparison.diff.lo < 0 < judged.comparison.diff.hi
    assert judged.verdict in ("partly", "does not")


def test_first_passage_is_the_first_generation_that_holds():
    assert first_passage(np.array([0, 0, 1, 0, 1], bool)) == 2
    assert np.isnan(first_passage(np.zeros(5, bool)))


def test_lock_speed_reads_first_passage_not_staying_locked():
    flexion = np.full(G, 50.0)
    flexion[6:] = 2.0                 # locked from generation 6 ...
    flexion[30:33] = 50.0             # ... with a wobble later, which the old rule punished
    normal = condition("normal", all_shoulder_flexion=flexion, all_shoulder_angle=175.0,
                       all_elbow_flexion=50.0, all_elbow_angle=90.0, all_elbow_moving=0.5)
    judged = C.lock_speed(evidence(normal=normal))
    # smoothed over G/20 = 2 generations, flexion is first dominated at generation 7
    assert judged.estimate.mean == 7 and judged.verdict == "replicates"


def test_lesion_start_needs_its_premise():
    def summary(spread, start_spread):
        return ReachSummary(1, 10, 0.5, 0.5, 10, 5, spread, spread, 20, start_spread, 10)
    scattered = [{"intact": summary(30, 30), "lesioned": summary(40, 30)} for _ in range(RUNS)]
    ev = Evidence({}, scattered, Windows(G))
    judged = C.lesion_scatters_start(ev)
    assert judged.verdict == "does not" and "premise fails" in judged.ours
    tight = [{"intact": summary(5 + i % 2, 30), "lesioned": summary(25 + i % 3, 30)}
             for i in range(RUNS)]
    assert C.lesion_scatters_start(Evidence({}, tight, Windows(G))).verdict == "replicates"


def test_a_rising_curve_replicates_and_its_time_shuffled_copies_do_not():
    rising = np.linspace(0.3, 0.7, G)
    normal = condition("normal", top_approach_fix=noisy(rising, 0.02, 5),
                       top_approach_nofix=0.5, top_away_fix=0.3)
    random = condition("random", top_approach_fix=noisy(np.full(G, 0.5), 0.02, 6),
                       top_approach_nofix=0.5, top_away_fix=0.5)
    ev = evidence(normal=normal, random=random)
    claim = next(c for c in C.CLAIMS if c.key == "approach-increases")
    assert C.judge(claim, ev).verdict == "replicates"
    nulls = C.null_checks(claim, ev)
    assert nulls.random != "replicates"
    assert nulls.shuffled <= 0.2


def test_each_claim_is_defined_once_in_the_order_written_with_its_own_nulls():
    """@claim registers each claim where its measure is defined; two claims stacked on one
    measure keep the order they are written in and each passes its own argument."""
    keys = [claim.key for claim in C.CLAIMS]
    assert all(isinstance(claim, C.Claim) for claim in C.CLAIMS)
    assert len(set(keys)) == len(keys)
    assert keys.index("coact-early-shoulder") + 1 == keys.index("coact-early-elbow")
    assert keys.index("hand-slowdown") + 1 == keys.index("eye-slowdown")
    by_key = dict(zip(keys, C.CLAIMS))
    assert by_key["coact-early-elbow"].measure.keywords == {"joint": "elbow"}
    assert by_key["eye-slowdown"].measure.keywords == {"kind": "eye"}
    assert all(set(claim.nulls) <= {C.RANDOM, C.SHUFFLED} for claim in C.CLAIMS)
    assert C.RANDOM not in by_key["random-fitness"].nulls     # it reads random movement itself
    assert C.SHUFFLED in by_key["approach-increases"].nulls   # a time course
