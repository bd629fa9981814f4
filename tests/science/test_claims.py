"""The claims' statistics on constructed data whose answers are known: paired intervals, the
verdicts they give, first passage, the premise of lesion-start, and the two nulls."""
from pathlib import Path

import numpy as np
import pytest

from econet_ros.config import Config
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


@pytest.fixture(autouse=True)
def paper_settings(monkeypatch):
    """Constructed conditions have no run folders: their settings are the defaults (20 trials
    x 100 cycles, so the fitness margin is 5% of 2000)."""
    monkeypatch.setattr(Evidence, "run_config", lambda self, condition: Config())


def noisy(base, scale, seed):
    return base + np.random.default_rng(seed).normal(0, scale, (RUNS, G))


@pytest.mark.parametrize("shift, expected", [(150.0, "replicates"), (-150.0, "reversed"),
                                             (-5.0, "absent")])
def test_fitness_claim_follows_the_paired_interval(shift, expected):
    """Fitness is judged on the median paired difference; a difference of 5 lies within the
    margin (5% of the 2000 an econet can score): no effect of interest."""
    three = noisy(100.0, 3.0, 1)
    ev = evidence(normal=condition("normal", top_fitness=three + shift),
                  **{"three-layer": condition("three-layer", top_fitness=three)})
    judged = C.judged_as("fitness", ev)
    assert judged.verdict == expected
    late, early, ahead = judged.criteria
    assert late.interval.mean == pytest.approx(shift)
    assert late.interval.method == "order statistics" and late.margin == 100
    assert late.comparison.above == (RUNS if shift > 0 else 0)
    assert judged.decisive is late          # the first criterion with the claim's verdict


def test_a_difference_inside_the_noise_is_inconclusive():
    rng = np.random.default_rng(3)
    three = noisy(100.0, 3.0, 4)
    late = np.full((RUNS, G), 5.0)                         # clearly ahead early ...
    late[:, -4:] = rng.normal(0.5, 200.0, (RUNS, 1))       # ... late: tiny mean, huge spread
    ev = evidence(normal=condition("normal", top_fitness=three + late),
                  **{"three-layer": condition("three-layer", top_fitness=three)})
    judged = C.judged_as("fitness", ev)
    assert judged.criteria[0].interval.lo < 0 < judged.criteria[0].interval.hi
    assert [c.verdict for c in judged.criteria] == ["inconclusive", "replicates", "replicates"]
    assert judged.verdict == "inconclusive" and judged.decisive is judged.criteria[0]


def test_ahead_early_in_too_few_runs_withholds_replication_without_contradicting():
    """Ahead early in 7 of 10 runs: the sign test cannot show the early median above 0 (it
    needs 9 of 10), and the count withholds 'replicates' too, contradicting nothing."""
    three = noisy(100.0, 1.0, 7)
    shift = np.full((RUNS, G), 300.0)
    shift[7:, :4] = -1.0                                       # ahead early in 7 of 10
    ev = evidence(normal=condition("normal", top_fitness=three + shift),
                  **{"three-layer": condition("three-layer", top_fitness=three)})
    judged = C.judged_as("fitness", ev)
    late, early, ahead = judged.criteria
    assert late.judged == "replicates" and early.judged == "inconclusive"
    assert ahead.interval.mean == 0.7 and ahead.judged == "inconclusive"
    assert judged.verdict == "inconclusive"


def test_chance_is_the_random_conditions_level_not_one_half():
    """Non-fixated approach at 0.52 is above 0.5 but below random movement's 0.53 in this
    geometry: not above chance, and less than the margin (0.05) below it: absent. Below
    random's 0.6 by more than the margin, it is reversed."""
    normal = condition("normal", top_approach_nofix=noisy(np.full(G, 0.52), 0.003, 8))
    random = condition("random", top_approach_nofix=noisy(np.full(G, 0.53), 0.003, 9))
    judged = C.judged_as("nofix-above-chance", evidence(normal=normal, random=random))
    assert judged.criteria[0].interval.hi < 0 and judged.verdict == "absent"
    lower = condition("random", top_approach_nofix=noisy(np.full(G, 0.60), 0.003, 9))
    assert C.judged_as("nofix-above-chance", evidence(normal=normal, random=lower)).verdict \
        == "reversed"
    higher = condition("random", top_approach_nofix=noisy(np.full(G, 0.50), 0.003, 9))
    assert C.judged_as("nofix-above-chance", evidence(normal=normal, random=higher)).verdict == \
        "replicates"


def joints(shoulder_flexion):
    """A normal condition whose runs' shoulders have these late flexion %."""
    flexion = np.repeat(np.asarray(shoulder_flexion, float)[:, None], G, axis=1)
    return condition("normal", all_shoulder_flexion=flexion, all_shoulder_angle=175.0,
                     all_elbow_flexion=50.0, all_elbow_angle=90.0, all_elbow_moving=0.5)


@pytest.mark.parametrize("locked, expected", [(10, "replicates"), (7, "inconclusive"),
                                              (6, "reversed")])
def test_a_share_of_runs_is_judged_on_its_exact_interval(locked, expected):
    """'All ten runs': most runs replicate (10 of 10: [0.69, 1] > 0.5); 7 of 10 ([0.35, 0.93])
    cannot tell; 6 of 10 ([0.26, 0.88]) lies wholly below the paper's 0.9: reversed."""
    runs = joints([2.0] * locked + [50.0] * (RUNS - locked))
    judged = C.judged_as("shoulder-locked", evidence(normal=runs))
    (criterion,) = judged.criteria
    assert criterion.interval.method == "Clopper-Pearson" and criterion.interval.mean == locked / 10
    assert judged.verdict == expected and "reversed below 0.9" in criterion.text()


def reaches(**changes):
    base = dict(success_rate=1.0, latency=10, approach_prob=0.5, path_efficiency=0.5,
                turning=10, final_approach_cycles=5, start_spread_body=5, start_spread_world=5,
                start_radius=20, trial_start_spread_body=30, n_reaches=10)
    return ReachSummary(**{**base, **changes})


def test_lesion_disorganised_needs_three_of_four_measures_worse():
    def lesion(turning_shift, success_shift):
        return [{"intact": reaches(approach_prob=0.5, path_efficiency=0.5, turning=10,
                                   success_rate=0.8),
                 "lesioned": reaches(approach_prob=0.4 - 0.01 * (i % 3),
                                     path_efficiency=0.3 - 0.01 * (i % 2),
                                     turning=10 + turning_shift + i % 2,
                                     success_rate=0.8 + success_shift + 0.01 * (i % 3))}
                for i in range(RUNS)]
    three = C.judged_as("lesion-disorganised", Evidence({}, lesion(+5, +0.1), Windows(G)))
    assert [c.judged for c in three.criteria] == ["replicates", "replicates", "replicates",
                                                  "reversed"]
    assert three.verdict == "replicates"
    two = C.judged_as("lesion-disorganised", Evidence({}, lesion(-20, +0.1), Windows(G)))
    assert two.verdict == "reversed"              # two reversed: three of four cannot
    small = C.judged_as("lesion-disorganised", Evidence({}, lesion(-5, +0.1), Windows(G)))
    assert [c.judged for c in small.criteria][2:] == ["absent", "reversed"]
    assert small.verdict == "absent"              # turning less by 5 deg: within 9, no effect


def test_first_passage_is_the_first_generation_that_holds():
    assert first_passage(np.array([0, 0, 1, 0, 1], bool)) == 2
    assert np.isnan(first_passage(np.zeros(5, bool)))


def test_lock_speed_reads_first_passage_not_staying_locked():
    flexion = np.full(G, 50.0)
    flexion[6:] = 2.0                 # locked from generation 6 ...
    flexion[30:33] = 50.0             # ... with a wobble later, which the old rule punished
    normal = condition("normal", all_shoulder_flexion=flexion, all_shoulder_angle=175.0,
                       all_elbow_flexion=50.0, all_elbow_angle=90.0, all_elbow_moving=0.5)
    judged = C.judged_as("lock-speed", evidence(normal=normal))
    # smoothed over G/20 = 2 generations, flexion is first dominated at generation 7
    assert judged.criteria[1].interval.mean == 7 and judged.verdict == "replicates"


def test_no_run_locking_contradicts_lock_speed_without_a_speed_to_judge():
    judged = C.judged_as("lock-speed", evidence(normal=joints([50.0] * RUNS)))
    (locks,) = judged.criteria                      # 0 of 10: [0, 0.31], below 0.5
    assert locks.interval.hi < 0.5 and judged.verdict == "reversed"
    assert judged.ours == "no run's shoulder ever locks"


def test_lesion_start_fails_with_its_premise_and_reports_its_own_criterion_beside_it():
    scattered = [{"intact": reaches(start_spread_body=30),
                  "lesioned": reaches(start_spread_body=40 + i % 2)} for i in range(RUNS)]
    judged = C.judged_as("lesion-start", Evidence({}, scattered, Windows(G)))
    assert judged.verdict == "premise fails" and judged.premise.verdict == "reversed"
    assert judged.own[0] == "replicates"       # the spread grows, but from no one place
    assert judged.premise_key == "stereotyped-start" and judged.decisive is \
        judged.premise.criteria[0] and judged.p == judged.premise.p
    tight = [{"intact": reaches(start_spread_body=5 + i % 2),
              "lesioned": reaches(start_spread_body=25 + i % 3)} for i in range(RUNS)]
    assert C.judged_as("lesion-start", Evidence({}, tight, Windows(G))).verdict == "replicates"
    still = [{"intact": reaches(start_spread_body=5 + i % 2),
              "lesioned": reaches(start_spread_body=2 + i % 3)} for i in range(RUNS)]
    assert C.judged_as("lesion-start", Evidence({}, still, Windows(G))).verdict == "reversed"


def test_lock_position_counts_unlocked_runs_as_its_premise_failing_not_as_flexed():
    """4 of 10 runs lock, all extended: the shoulder does not lock in all runs (the premise
    is reversed), and the locked ones' position, all extended, is reported beside it."""
    judged = C.judged_as("lock-position", evidence(normal=joints([2.0] * 4 + [50.0] * 6)))
    assert judged.verdict == "premise fails" and judged.premise_key == "shoulder-locked"
    (extended,) = judged.criteria
    assert extended.interval.n == 4 and extended.interval.mean == 1.0
    assert judged.own[0] == "inconclusive"       # 4 of 4 cannot show most runs


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


def test_a_level_that_holds_throughout_is_flagged_by_its_shuffled_nulls():
    """Non-fixated approach above random's all through training 'replicates' early and on
    every shuffle: the rule cannot tell the paper's early excess from a constant level. Its
    random null differs from random by exactly 0: no effect, absent."""
    normal = condition("normal", top_approach_nofix=noisy(np.full(G, 0.56), 0.01, 10))
    random = condition("random", top_approach_nofix=noisy(np.full(G, 0.50), 0.01, 11))
    results = {r.claim.key: r for r in C.evaluate({"normal": normal, "random": random}, [],
                                                  Windows(G), nulls=True)}
    level = results["nofix-above-chance"]
    assert level.verdict == "replicates" and level.nulls.shuffled == 1.0 and level.flagged
    assert level.nulls.random == "absent" and not level.chance_flagged
    assert not results["random-chance"].flagged          # no shuffled null: never flagged


def test_a_verdict_can_depend_on_where_the_late_window_lies():
    """P(approach | fixated) 0.4 early, down to 0.25, up to 0.7 in the last two generations:
    the last 5% show the rise, the last 15% average it away (to no change: absent)."""
    curve = np.full(G, 0.4)
    curve[-6:-2], curve[-2:] = 0.25, 0.7
    ev = {"normal": condition("normal", top_approach_fix=noisy(curve, 0.01, 12))}
    claim = next(c for c in C.CLAIMS if c.key == "approach-increases")
    verdicts = {label: C.judge(claim, Evidence(ev, [], w)).verdict
                for label, w in Windows(G).moved().items()}
    assert C.judge(claim, Evidence(ev, [], Windows(G))).verdict == "replicates"
    assert verdicts["late gens 190-199"] == "replicates"
    assert verdicts["late gens 170-199"] == "absent"
    assert verdicts["early gens 0-9"] == verdicts["slowdown dip gens 1-9"] == "replicates"


def test_every_window_is_moved_one_at_a_time_the_slowdown_also_to_its_old_windows():
    w = Windows(200)
    assert (w.slowdown_start, w.slowdown_dip, w.recovery) == (slice(0, 1), slice(1, 20),
                                                              slice(20, 40))
    assert (w.start, w.early, w.dip, w.first_quarter, w.final) == (
        slice(0, 5), slice(0, 20), slice(10, 50), slice(0, 50), slice(180, 200))
    moved = w.moved()
    assert {name for name, _ in w.spans} == {label.rsplit(" gen", 1)[0] for label in moved}
    old = moved["slowdown dip gens 10-49"]
    assert (old.slowdown_dip, old.slowdown_start, old.dip) == (slice(10, 50), slice(0, 1),
                                                                slice(10, 50))
    assert moved["slowdown start gens 0-4"].slowdown_start == slice(0, 5)
    assert moved["recovery gens 180-199"].recovery == w.final
    assert (Windows(4).early, Windows(4).dip, Windows(4).final, Windows(4).slowdown_dip) == (
        slice(0, 1), slice(1, 2), slice(3, 4), slice(1, 2))


def test_the_slowdown_is_judged_from_generation_0_to_the_first_20_and_its_recovery_after():
    """Fixated hand speed 6 at generation 0, a trough of 3 over generations 1-9 of 200, 5 over
    10-19, back to 6 over 20-39, 2 after: the registered windows see a slowdown that recovers;
    the windows registered before (start 0-4, dip 10-49) put the fall inside the start and the
    recovery inside the dip, and call it a speed-up."""
    g = 200
    curve = np.full(g, 2.0)
    curve[0], curve[1:10], curve[10:20], curve[20:40] = 6.0, 3.0, 5.0, 6.0
    runs = curve + np.random.default_rng(5).normal(0, 0.05, (RUNS, g))
    data = ConditionData("normal", Path("normal"), g, {"top_hand_speed_fix": runs}, {},
                         [g] * RUNS, [Path(f"run-{i:02d}") for i in range(RUNS)], [])
    hand = next(c for c in C.CLAIMS if c.key == "hand-slowdown")
    assert C.judge(hand, Evidence({"normal": data}, [], Windows(g))).verdict == "replicates"
    before = Windows(g, spans=tuple({**dict(Windows(g).spans), "slowdown start": (0, 5),
                                     "slowdown dip": (10, 50)}.items()))
    assert C.judge(hand, Evidence({"normal": data}, [], before)).verdict == "reversed"


def test_each_claim_is_defined_once_in_the_order_written_with_its_own_nulls():
    """@claim registers each claim where its measure is defined; two claims stacked on one
    measure keep the order they are written in and each passes its own argument."""
    keys = [claim.key for claim in C.CLAIMS]
    assert all(isinstance(claim, C.Claim) for claim in C.CLAIMS)
    assert len(set(keys)) == len(keys)
    assert keys.index("coact-early-shoulder") + 1 == keys.index("coact-early-elbow")
    assert keys.index("hand-slowdown") + 1 == keys.index("eye-slowdown")
    by_key = dict(zip(keys, C.CLAIMS))
    assert by_key["coact-early-elbow"].measure.keywords["joint"] == "elbow"
    assert by_key["eye-slowdown"].measure.keywords["kind"] == "eye"
    assert by_key["eye-slowdown"].margin == C.EYE_MARGIN != by_key["hand-slowdown"].margin
    assert all(set(claim.nulls) <= {C.RANDOM, C.SHUFFLED} for claim in C.CLAIMS)
    assert C.RANDOM not in by_key["random-fitness"].nulls     # it reads random movement itself
    assert C.SHUFFLED in by_key["approach-increases"].nulls   # a time course


def test_a_verdict_on_a_threshold_of_ours_is_read_again_at_other_thresholds():
    """Every run's shoulder flexes on 12% of cycles: not locked at the registered 90/10
    (reversed), locked in all runs at 85/15 and 80/20; the registered verdict stays."""
    ev = evidence(normal=joints([12.0] * RUNS))
    claim = next(c for c in C.CLAIMS if c.key == "shoulder-locked")
    assert C.judge(claim, ev).verdict == "reversed"
    assert dict(C.readings(claim, ev)) == {"85/15": "replicates", "80/20": "replicates",
                                           "top 20": "n/a", "top 20, 80/20": "n/a"}
    position = next(c for c in C.CLAIMS if c.key == "lock-position")
    assert C.judge(position, ev).verdict == "premise fails"
    assert dict(C.readings(position, ev))["85/15"] == "replicates"   # the premise follows


def test_the_reach_start_bound_is_read_at_0_75_and_0_9():
    ratio_08 = [{"intact": reaches(start_spread_body=24 + i % 2), "lesioned": reaches()}
                for i in range(RUNS)]                      # 0.80-0.83 of the trial-start spread
    claim = next(c for c in C.CLAIMS if c.key == "stereotyped-start")
    ev = Evidence({}, ratio_08, Windows(G))
    assert C.judge(claim, ev).verdict == "reversed"
    assert dict(C.readings(claim, ev)) == {"< 0.75": "reversed", "< 0.9": "replicates"}


def test_the_lesion_is_read_again_without_survivor_bias():
    """The lesioned nets reach fewer trials, the ones they reach straight: over their
    successes path efficiency looks better (worse < 0), over every trial it is worse."""
    runs = [{"intact": reaches(path_efficiency=0.5, path_efficiency_every_trial=0.5,
                               approach_prob=0.5, success_rate=0.8),
             "lesioned": reaches(path_efficiency=0.8 + 0.01 * (i % 2),
                                 path_efficiency_every_trial=0.2 - 0.01 * (i % 3),
                                 approach_prob=0.4 - 0.01 * (i % 3),
                                 success_rate=0.3 + 0.01 * (i % 2))} for i in range(RUNS)]
    ev = Evidence({}, runs, Windows(G))
    claim = next(c for c in C.CLAIMS if c.key == "lesion-disorganised")
    registered = C.judge(claim, ev)
    assert registered.criteria[1].judged == "reversed"
    assert "survivor-biased" in registered.criteria[1].what
    every, both = (verdict for _, verdict in C.readings(claim, ev))
    assert every == "replicates"            # approach, efficiency and success worse: 3 of 4
    assert both == "n/a"                    # hand-made rows hold no trial-by-trial record
