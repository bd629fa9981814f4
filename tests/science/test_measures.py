"""Analyses on synthetic traces whose answers are known by construction."""
from types import SimpleNamespace

import numpy as np
import pytest

import behaviour_oracle as oracle
from econet_ros.science import lesion
from econet_ros.science import measures as A
from econet_ros.config import Config
from econet_ros.controllers import Controller, FourLayerNetwork
from econet_ros.plugins import make_controller
from econet_ros.trials import run_trials
from econet_ros.world import TrialSetup, World, sample_setups


class Scripted(Controller):
    """Fixed motor outputs every cycle (eye, sf, se, ef, ee)."""

    def __init__(self, n_envs, config, outputs):
        super().__init__(n_envs, config)
        self.outputs = np.asarray(outputs, dtype=float)

    def act(self, obs):
        return np.tile(self.outputs, (self.n_envs, 1))


def scripted_trace(outputs, n=30, cycles=30, seed=0, config=None):
    config = config or Config()
    world = World(n, config.model)
    setup = sample_setups(np.random.default_rng(seed), n, config.model)
    _, trace = run_trials(world, Scripted(n, config, outputs), setup, cycles, record=True)
    return trace


def far_setup(n, body=0.0, shoulder=90.0, elbow=90.0):
    """Object far behind the agent: no contact within a few cycles."""
    return TrialSetup(np.tile([-44.0, 0.0], (n, 1)), np.full(n, body), np.full(n, shoulder),
                      np.full(n, elbow))


def test_always_flexing_shoulder_gives_100_percent_flexion():
    trace = scripted_trace([0.5, 1.0, 0.0, 0.3, 0.7])
    assert oracle.flexion_percent(trace, oracle.SHOULDER) == pytest.approx(100.0)
    assert oracle.flexion_percent(trace, oracle.ELBOW) == pytest.approx(0.0)


def test_always_extending_shoulder_locks_it_fully_extended():
    trace = scripted_trace([0.5, 0.0, 1.0, 0.5, 0.5], cycles=40)
    assert oracle.flexion_percent(trace, oracle.SHOULDER) == 0.0
    # after at most 12 cycles of 15 deg the shoulder sits at 180 for good
    assert np.all(trace.shoulder[13:] == pytest.approx(180.0))


def test_equal_muscles_have_zero_deviation_from_coactivation():
    trace = scripted_trace([0.5, 0.7, 0.7, 0.2, 0.2])
    co, re = oracle.activation_deviations(trace, oracle.SHOULDER)
    assert co == pytest.approx(0.0)
    assert re == pytest.approx(abs(0.7 + 0.7 - 1) / np.sqrt(2))
    co, re = oracle.activation_deviations(trace, oracle.ELBOW)
    assert co == 0.0 and re == pytest.approx(0.6 / np.sqrt(2))


def test_reciprocal_muscles_have_zero_deviation_from_reciprocal_line():
    trace = scripted_trace([0.5, 0.9, 0.1, 0.25, 0.75])
    assert oracle.activation_deviations(trace, oracle.SHOULDER)[1] == pytest.approx(0.0)
    assert oracle.activation_deviations(trace, oracle.ELBOW)[1] == pytest.approx(0.0)
    assert oracle.activation_deviations(trace, oracle.SHOULDER)[0] == \
        pytest.approx(0.8 / np.sqrt(2))


def test_deviation_is_the_geometric_distance_to_each_line():
    f, e = np.array([0.8]), np.array([0.45])
    # foot of the perpendicular onto f = e is ((f+e)/2, (f+e)/2)
    m = (f + e) / 2
    assert A.coactivation_deviation(f, e)[0] == pytest.approx(np.hypot(f - m, e - m)[0])
    # onto f + e = 1: ((f-e+1)/2, (e-f+1)/2)
    p, q = (f - e + 1) / 2, (e - f + 1) / 2
    assert A.reciprocal_deviation(f, e)[0] == pytest.approx(np.hypot(f - p, e - q)[0])


def test_still_arm_and_eye_have_zero_speed_and_no_approach():
    trace = scripted_trace([0.5, 0.5, 0.5, 0.5, 0.5])
    assert oracle.mean_speed(trace, "hand", None) == pytest.approx(0.0)
    assert oracle.mean_speed(trace, "eye", None) == pytest.approx(0.0)
    assert A.approach_probability(trace, None) == 0.0
    assert oracle.away_probability(trace, None) == 0.0


def test_eye_speed_is_the_body_rotation_per_cycle():
    trace = scripted_trace([1.0, 0.5, 0.5, 0.5, 0.5])          # eye turns +15 deg per cycle
    assert oracle.mean_speed(trace, "eye", None) == pytest.approx(15.0)
    # arm locked relative to the body: the hand moves along a circle, chord per 15 deg step
    radius = np.linalg.norm(trace.hand[0], axis=-1)
    chord = 2 * radius * np.sin(np.radians(7.5))
    np.testing.assert_allclose(A.hand_speed(trace)[0], chord, rtol=1e-6)


def test_approach_probability_counts_only_shrinking_gaps():
    config = Config()
    n = 4
    world = World(n, config.model)
    _, trace = run_trials(world, Scripted(n, config, [0.5, 0.5, 0.5, 0.5, 0.5]), far_setup(n),
                          10, record=True)
    d = np.linspace(50, 41, 11)[:, None].repeat(n, axis=1)
    d[6:, :2] = d[5, 0] + 1 + np.arange(5)[:, None]        # envs 0, 1 move away from cycle 5
    trace = trace._replace(hand_object_distance=d, fixated=np.zeros_like(trace.fixated))
    trace.fixated[:, 2:] = True                            # envs 2, 3 always fixate
    assert A.approach_probability(trace, True) == pytest.approx(1.0)
    assert A.approach_probability(trace, False) == pytest.approx(5 / 10)
    assert oracle.away_probability(trace, False) == pytest.approx(5 / 10)
    assert A.approach_probability(trace, None) == pytest.approx(30 / 40)


def test_pre_contact_mask_stops_at_the_first_touch():
    trace = scripted_trace([0.5] * 5, n=3, cycles=6)
    trace = trace._replace(touch=np.zeros_like(trace.touch))
    trace.touch[3, 0] = True         # env 0 touches after cycle 2 (row 3), then lets go
    trace.touch[0, 1] = True         # env 1 starts in contact
    mask = A.pre_contact(trace)
    np.testing.assert_array_equal(mask[:, 0], [True, True, True, False, False, False])
    assert not mask[:, 1].any()
    assert mask[:, 2].all()


def test_behaviour_row_groups_top_econets():
    config = Config()
    trials, econets = 3, 4
    n = trials * econets
    world = World(n, config.model)

    class PerEnv(Controller):
        def act(self, obs):
            out = np.full((n, 5), 0.5)
            out[:2 * trials, 1], out[:2 * trials, 2] = 1.0, 0.0    # econets 0, 1 flex
            out[2 * trials:, 1], out[2 * trials:, 2] = 0.0, 1.0    # econets 2, 3 extend
            return out

    _, trace = run_trials(world, PerEnv(n, config), far_setup(n), 5, record=True)
    row = oracle.behaviour_row(trace, 7, np.array([0, 1]), trials)
    assert row["generation"] == 7
    assert row["top_shoulder_flexion"] == pytest.approx(100.0)
    assert row["all_shoulder_flexion"] == pytest.approx(50.0)
    assert row["top_elbow_coact"] == pytest.approx(0.0)
    assert set(row) == set(A.BEHAVIOUR_COLUMNS)


@pytest.mark.parametrize("settings", [
    {}, {"evolution.condition": "three-layer"}, {"evolution.condition": "random"},
    {"model.angle_steps": "round", "model.joint_limit": "cancel"},
    {"model.start_posture": "extended", "model.object_radius": 6.0}])
def test_recorded_behaviour_row_equals_the_trace_one_to_the_last_bit(settings):
    """The study's behaviour row, from the compiled loop's BehaviourRecord, is the one the
    NumPy oracle computes from a full Trace of the same trials (repr: every bit, NaN too)."""
    from econet_ros.evolution import InProcessEvaluator, initial_genomes

    config = Config().replace(**{"evolution.population": 12, "evolution.parents": 3,
                                 "evolution.trials": 6, "evolution.cycles": 60, **settings})
    evaluator = InProcessEvaluator(config)
    genomes = initial_genomes(config, evaluator.n_weights, 5, 1)
    full = evaluator.test_generation(genomes, 5, 1, 0, record=True)
    lean = evaluator.test_generation(genomes, 5, 1, 0, record="behaviour")
    expected = oracle.behaviour_row(full.trace, 0, full.parents, 6)
    got = A.recorded_behaviour_row(lean.trace, lean.measures, 0, lean.parents, 6)
    assert {k: repr(v) for k, v in got.items()} == {k: repr(v) for k, v in expected.items()}


def test_a_behaviour_record_needs_a_compiled_controller():
    config = Config()
    world = World(4, config.model)
    with pytest.raises(ValueError, match="compiled"):
        run_trials(world, Scripted(4, config, [0.5] * 5), far_setup(4), 3, record="behaviour")


def test_severing_proprioception_removes_its_influence():
    config = Config()
    net = FourLayerNetwork(2, config)
    rng = np.random.default_rng(3)
    weights = rng.uniform(-10, 10, (1, net.n_params))
    cut = lesion.sever_proprioception(weights, config, "normal")
    assert np.count_nonzero(weights - cut) == 4 * config.network.proprio_hidden
    net.load(np.repeat(cut, 2, axis=0))
    inputs = np.zeros((2, 13))
    inputs[:, :8] = 0.3
    inputs[0, 8:12] = [0.0, 1.0, 0.2, 0.8]
    inputs[1, 8:12] = [1.0, 0.0, 0.9, 0.1]                  # different posture, same vision
    out = net.forward(inputs)
    np.testing.assert_allclose(out[0], out[1])
    net.load(np.repeat(weights, 2, axis=0))
    assert not np.allclose(*net.forward(inputs))            # intact: posture matters
    mask3 = lesion.proprioceptive_weight_mask(config, "three-layer")
    assert mask3.sum() == 4 * config.network.three_layer_hidden


def test_reach_start_is_the_start_of_the_final_approach():
    trace = scripted_trace([0.5] * 5, n=2, cycles=8)
    d = np.array([9, 8, 9, 10, 7, 5, 0, 0, 0], dtype=float)
    gap = np.stack([d, np.full(9, 20.0)], axis=1)
    trace = trace._replace(hand_object_distance=gap, touch=gap <= 0)
    starts, valid = A.reach_starts(trace)
    assert list(valid) == [True, False]
    assert starts[0] == 3                    # 10 -> 7 -> 5 -> 0: the approach starts at row 3


def test_identical_reach_starts_have_zero_spread():
    assert A.spread(np.tile([[3.0, 4.0]], (5, 1))) == 0.0
    assert A.spread(np.array([[0.0, 1.0], [0.0, -1.0]])) == pytest.approx(1.0)


def test_body_frame_undoes_the_body_rotation():
    trace = scripted_trace([1.0, 0.5, 0.5, 0.5, 0.5], n=2, cycles=5)
    # arm fixed relative to the body: the body-frame hand position never changes
    rows = np.arange(6)
    pts = np.stack([A.body_frame(trace, np.full(2, r), np.arange(2)) for r in rows])
    np.testing.assert_allclose(pts, np.broadcast_to(pts[0], pts.shape), atol=1e-9)


def test_summarize_reaches_follows_its_definitions_on_real_reaches():
    config = Config()
    n, cycles = 12, 60
    controller = make_controller("reacher", n, config)
    _, trace = run_trials(World(n, config.model), controller,
                          sample_setups(np.random.default_rng(1), n, config.model), cycles,
                          record=True)
    summary = A.summarize_reaches(trace)
    touched = trace.touch.any(axis=0)
    first = trace.touch.argmax(axis=0)
    assert touched.sum() >= n // 2                        # the reacher gives us reaches
    assert summary.success_rate == pytest.approx(touched.mean())
    assert summary.n_reaches == int((touched & (first > 0)).sum())
    starts, valid = A.reach_starts(trace)
    closing = trace.hand_object_distance[1:] < trace.hand_object_distance[:-1] - A.MOVE_EPS
    for env in np.flatnonzero(valid):
        s, c = starts[env], first[env]
        assert 0 <= s < c and closing[s:c, env].all()     # unbroken approach to first contact
        assert s == 0 or not closing[s - 1, env]          # ...and no longer
    assert summary.final_approach_cycles == pytest.approx(np.mean(first[valid] - starts[valid]))

def test_joint_mobility_tells_a_turning_eye_from_a_frozen_shoulder():
    """Eye at full speed (15 deg a cycle), shoulder muscles equal (frozen by coactivation),
    elbow extending 7.5 deg a cycle until it stops at 180: worked by hand."""
    n, cycles = 4, 12
    config = Config()
    world = World(n, config.model)
    controller = Scripted(n, config, [1.0, 0.6, 0.6, 0.25, 0.75])
    _, trace = run_trials(world, controller, far_setup(n, elbow=120.0), cycles, record=True)
    pre = A.pre_contact(trace)
    assert pre.all()                                   # the object is out of reach behind
    assert oracle.moving_share(trace, "body", pre) == 1.0
    assert oracle.moving_share(trace, "shoulder", pre) == 0.0
    assert oracle.moving_share(trace, "elbow", pre) == pytest.approx(8 / 12)   # 120 -> 180 in 8
    assert oracle.excursion(trace, "body", pre) == pytest.approx(15.0 * cycles)
    assert oracle.excursion(trace, "shoulder", pre) == 0.0
    assert oracle.excursion(trace, "elbow", pre) == pytest.approx(60.0)
    # 0.6/0.6 at the shoulder is co-contraction; 0.25/0.75 at the elbow is neither
    assert oracle.both_share(trace, oracle.SHOULDER, True, pre) == 1.0
    assert oracle.both_share(trace, oracle.SHOULDER, False, pre) == 0.0
    assert oracle.both_share(trace, oracle.ELBOW, True, pre) == \
        oracle.both_share(trace, oracle.ELBOW, False, pre) == 0


def test_latency_of_successes_counts_only_trials_that_touch():
    trace = scripted_trace([0.5, 0.5, 0.5, 0.5, 0.5])      # a still arm: few contacts
    hit = trace.touch[1:].any(axis=0)
    first = trace.touch[1:].argmax(axis=0) + 1
    expected = first[hit].mean() if hit.any() else np.nan
    np.testing.assert_equal(oracle.latency_of_successes(trace), expected)


def test_path_efficiency_over_every_trial_counts_a_miss_over_the_whole_trial():
    """Trial 0 reaches at row 2 straight (gap 10 -> 0 over a path of 10): 1; trial 1 never
    reaches, closing 2 of its gap over a path of 8: 0.25; trial 2 never moves: NaN."""
    gap = np.array([[10.0, 10.0, 5.0], [5.0, 9.0, 5.0], [0.0, 8.0, 5.0], [0.0, 8.0, 5.0]])
    speed = np.array([[5.0, 4.0, 0.0], [5.0, 2.0, 0.0], [3.0, 2.0, 0.0]])
    got = A.path_efficiencies(SimpleNamespace(hand_object_distance=gap), np.array([2, -1, -1]),
                            speed)
    assert got[:2].tolist() == [1.0, 0.25] and np.isnan(got[2])


def test_shared_reaches_compare_the_lesion_on_the_trials_both_nets_reach():
    """The lesioned net reaches only its two easiest trials: over its successes it looks more
    efficient than the intact net (0.9 against 0.6), on the trials both reach it is worse."""
    nan = float("nan")

    def summary(latency, efficiency):
        return A.ReachSummary(1.0, nan, 0.5, float(np.nanmean(efficiency)), 1, 1, 1, 1, 1, 1, 1,
                            trial_latency=tuple(latency), trial_efficiency=tuple(efficiency))
    intact = summary([10, 12, 40, 50], [0.95, 0.95, 0.3, 0.2])
    lesioned = summary([20, 22, nan, nan], [0.9, 0.9, nan, nan])
    assert lesioned.path_efficiency > intact.path_efficiency           # survivor bias
    shared = A.shared_reaches(intact, lesioned)
    assert shared == {"latency": (11.0, 21.0), "path_efficiency": (0.95, 0.9)}
