"""The paper's open choices as settings, each reading checked on cases worked
by hand: Gray and sign-magnitude codes, the body text's weight steps, a bounded body axis, the
forward shoulder, whole-degree moves and a move past a joint limit cancelled; and the defaults
leaving stored results as they were."""
import json

import numpy as np
import pytest

from econet_ros import genome
from econet_ros.cli import main
from econet_ros.config import Config, ModelConfig
from econet_ros.errors import ConfigError, SetupError
from econet_ros.run_folders import RunData
from econet_ros.world import TrialSetup, World, sample_setups

# -- the genome code ----------------------------------------------------------------------------
def test_gray_code_round_trips_and_neighbours_differ_in_one_bit():
    points = np.arange(256, dtype=np.uint8)
    codes = genome.to_gray(points)
    assert sorted(codes) == list(range(256))                 # a permutation of the codes
    np.testing.assert_array_equal(genome.from_gray(codes), points)
    for k in range(255):
        assert genome.flipped_bits(codes[k:k + 1], codes[k + 1:k + 2]) == 1
    # hand-worked: grid point 5 = 0b101 has Gray code 0b111; 6 = 0b110 -> 0b101
    assert (codes[5], codes[6]) == (0b111, 0b101)
    weights = np.array([-10.0, -0.04, 3.3, 10.0])
    for code in ("binary", "gray"):
        coded = genome.encode(weights, 8, 10.0, code)
        np.testing.assert_allclose(genome.decode(coded, 8, 10.0, code), weights, atol=10 / 255)
    assert genome.decode(np.array([0b111], np.uint8), 8, 10.0, "gray")[0] == \
        genome.decode(np.array([5], np.uint8), 8, 10.0, "binary")[0]


# -- the body text's mutation: 2% of the weights, each by a small step --------------------------
@pytest.mark.parametrize("code", ["binary", "gray", "sign-magnitude"])
def test_weight_mutation_moves_two_percent_of_weights_by_small_steps(code):
    rng = np.random.default_rng(4)
    points = rng.integers(10, 246, size=(2000, 160)).astype(np.uint8)   # away from the ends
    codes = genome.codes_of(points, 8, code)
    mutated = genome.mutate(rng, codes, 8, 0.02, mode="weights", step=4, code=code)
    moves = genome.grid_points(mutated, 8, code).astype(int) - points.astype(int)
    changed = moves != 0
    # 320,000 weights at 2%: 6,400 expected, s.d. 79
    assert abs(changed.mean() - 0.02) < 0.001, changed.mean()
    sizes = np.abs(moves[changed])
    assert sizes.min() == 1 and sizes.max() == 4
    assert abs(sizes.mean() - 2.5) < 0.05                     # uniform over 1..4
    assert abs(np.sign(moves[changed]).mean()) < 0.05          # up as often as down


def test_weight_mutation_stops_at_the_ends_of_the_grid():
    rng = np.random.default_rng(1)
    ends = np.tile(np.array([0, 255], np.uint8), (5000, 1))
    mutated = genome.mutate(rng, ends, 8, 1.0, mode="weights", step=3)
    assert mutated.min() == 0 and mutated.max() == 255
    assert set(np.unique(mutated[:, 0])) <= {0, 1, 2, 3}
    assert set(np.unique(mutated[:, 1])) <= {252, 253, 254, 255}


def test_per_bit_flips_change_many_weights_where_the_body_text_changes_few():
    """Why the reading matters: per-bit 2% flips touch about 1 - 0.98^8 = 15% of the weights,
    a fifth of them by a most-significant bit (a jump of about 10 weight units)."""
    rng = np.random.default_rng(0)
    codes = genome.random_genomes(rng, 2000, 160, 8)
    per_bit = genome.mutate(rng, codes, 8, 0.02)
    assert abs((per_bit != codes).mean() - (1 - 0.98 ** 8)) < 0.005
    weights = genome.mutate(rng, codes, 8, 0.02, mode="weights", step=4)
    assert abs((weights != codes).mean() - 0.02) < 0.002


# -- the body axis --------------------------------------------------------------------------------
@pytest.mark.parametrize("axis, expected", [("unbounded", 30 + 450.0), ("within-360", 30 + 360.0)])
def test_a_bounded_body_axis_stops_at_its_limit(axis, expected):
    world = World(1, ModelConfig(body_axis=axis))
    world.body[:] = world.body_start[:] = 30.0
    turn_left = np.array([[1.0, 0.0, 0.0, 0.0, 0.0]])       # 15 degrees a cycle
    for _ in range(30):
        world.step(turn_left)
    assert world.body[0] == expected
    for _ in range(60):                                       # and it turns back freely
        world.step(1.0 - turn_left)
    assert world.body[0] == (30 - 360.0 if axis == "within-360" else expected - 900.0)


# -- the shoulder convention ------------------------------------------------------------------------
def posture(convention, shoulder, elbow):
    world = World(1, ModelConfig(shoulder_convention=convention))
    world.body[:], world.shoulder[:], world.elbow[:] = 0.0, shoulder, elbow
    world.object_xy[:] = (-40.0, 0.0)                       # behind the eye
    world.refresh()
    return world


def test_forward_shoulder_points_the_extended_arm_along_the_gaze():
    straight = posture("forward", 180.0, 180.0).arm_points()[0]
    np.testing.assert_allclose(straight[3], (50.0, 0.0), atol=1e-12)      # the tip
    np.testing.assert_allclose(straight[1], (25.0, 0.0), atol=1e-12)      # the elbow
    flexed = posture("forward", 90.0, 180.0).arm_points()[0]               # 90 deg to the left
    np.testing.assert_allclose(flexed[3], (0.0, 50.0), atol=1e-12)
    centred = posture("centred", 180.0, 180.0).arm_points()[0]             # 90 deg to the right
    np.testing.assert_allclose(centred[3], (0.0, -50.0), atol=1e-12)


@pytest.mark.parametrize("shoulder, elbow", [(179.5, 180.0), (150.0, 85.0), (100.0, 3.0),
                                             (95.0, 0.0)])
def test_forward_posture_sees_what_the_centred_one_90_degrees_lower_sees(shoulder, elbow):
    forward = posture("forward", shoulder, elbow)
    centred = posture("centred", shoulder - 90.0, elbow)
    np.testing.assert_allclose(forward.observe().vision, centred.observe().vision, atol=1e-12)
    np.testing.assert_allclose(forward.arm_points(), centred.arm_points(), atol=1e-12)
    assert forward.observe().proprio[0, 0] == shoulder / 180.0       # the joint's own angle


# -- stored results ------------------------------------------------------------------------------------
def test_added_settings_are_stored_only_when_not_default():
    stored = Config().to_dict()
    for section, name in (("model", "body_axis"), ("model", "shoulder_convention"),
                          ("model", "angle_steps"), ("model", "joint_limit"),
                          ("evolution", "genome_code"), ("evolution", "mutation_step")):
        assert name not in stored[section]
    changed = Config().replace(**{"evolution.genome_code": "gray",
                                  "model.body_axis": "within-360"})
    data = json.loads(changed.to_json())
    assert data["evolution"]["genome_code"] == "gray" and data["model"]["body_axis"] == "within-360"
    assert Config.from_dict(data) == changed and Config.from_dict(stored) == Config()


# -- readings of the science settings -----------------------------------------------------
HOLD = 0.5        # a muscle pair at equal activation, or the eye unit at 0.5: no move


def world_at(shoulder, elbow, body=0.0, **model):
    world = World(1, ModelConfig(**model))
    world.body[:] = world.body_start[:] = body
    world.shoulder[:], world.elbow[:] = shoulder, elbow
    world.refresh()
    return world


def after(world, eye=HOLD, s_flex=HOLD, s_ext=HOLD, e_flex=HOLD, e_ext=HOLD):
    world.step(np.array([[eye, s_flex, s_ext, e_flex, e_ext]]))
    return world.body[0], world.shoulder[0], world.elbow[0]


# -- whole degrees -------------------------------------------------------------------------------
@pytest.mark.parametrize("steps, eye, turn", [
    # 30 * (eye - 0.5) degrees: 0.48, 0.51, 1.875, -1.875, 15
    ("continuous", 0.516, 30 * (0.516 - 0.5)),
    ("round", 0.516, 0.0), ("round", 0.517, 1.0), ("round", 0.5625, 2.0), ("round", 0.4375, -2.0),
    ("truncate", 0.517, 0.0), ("truncate", 0.5625, 1.0), ("truncate", 0.4375, -1.0),
    ("round", 1.0, 15.0), ("truncate", 0.0, -15.0),
])
def test_whole_degree_eye_moves(steps, eye, turn):
    body, _, _ = after(world_at(90, 90, body=10.0, angle_steps=steps), eye=eye)
    assert body == 10.0 + turn


def test_round_leaves_the_eye_exactly_still_within_half_a_degree_of_no_move():
    # max_rotation 16: the eye turns 32 * (eye - 0.5), so eye = 0.5 + 1/64 asks for exactly 0.5
    # degrees, which rounds away from zero; a hair less rounds to no move at all.
    half = 0.5 + 1 / 64
    assert after(world_at(90, 90, angle_steps="round", max_rotation_deg=16), eye=half)[0] == 1.0
    for eye in (np.nextafter(half, 0.0), 0.5 + 1e-9, 0.5 - 1e-9, 1 - np.nextafter(half, 0.0)):
        body, _, _ = after(world_at(90, 90, angle_steps="round", max_rotation_deg=16), eye=eye)
        assert body == 0.0, eye


@pytest.mark.parametrize("steps, change", [("continuous", 7.5), ("round", 8.0),
                                           ("truncate", 7.0)])
def test_whole_degree_joint_moves_round_half_away_from_zero(steps, change):
    # -15 * (flexor - extensor) = -15 * (0.25 - 0.75) = +7.5 degrees, and -7.5 for the elbow
    _, shoulder, elbow = after(world_at(90, 90, angle_steps=steps), s_flex=0.25, s_ext=0.75,
                               e_flex=0.75, e_ext=0.25)
    assert (shoulder, elbow) == (90 + change, 90 - change)


@pytest.mark.parametrize("steps", ["round", "truncate"])
def test_whole_degree_trials_start_and_stay_on_whole_degrees(steps):
    model = ModelConfig(angle_steps=steps)
    setup = sample_setups(np.random.default_rng(1), 5000, model)
    for angles, top in ((setup.body, 359), (setup.shoulder, 180), (setup.elbow, 180)):
        assert np.all(angles == np.round(angles))
        assert angles.min() == 0 and angles.max() == top      # the whole range, ends included
    world = World(5000, model)
    world.reset(setup)
    motor = np.random.default_rng(2).random((20, 5000, 5))
    for t in range(20):
        world.step(motor[t])
    for angles in (world.body, world.shoulder, world.elbow):
        assert np.all(angles == np.round(angles))


def vision_at(shoulder, elbow, **model):
    world = world_at(shoulder, elbow, **model)
    world.object_xy[:] = (-40.0, 0.0)                         # behind the eye
    world.refresh()
    return world.observe().vision[0]


def test_a_tip_exactly_on_a_window_edge_is_seen_by_both_windows():
    # Shoulder 180, elbow 60: the upper arm points 90 deg right, the tip lies 25 units out at
    # -30 deg, exactly on the edge of windows 1 and 2 (whole-degree angles make this common),
    # and the hand runs from there to the right. Windows are closed, so window 2 sees the tip:
    # as a tip a hair inside window 2 is seen, and 1 - 25/50 = 0.5 more than one a hair outside.
    tie = vision_at(180, 60)
    inside = vision_at(180 - 1e-9, 60)                # tip at -30 + 1e-9 degrees
    outside = vision_at(180, 60 + 2e-9)               # tip at -30 - 1e-9 degrees
    np.testing.assert_allclose(tie, inside, atol=1e-6)
    assert tie[0] - outside[0] == pytest.approx(0.5 / 8, abs=1e-6)
    np.testing.assert_array_equal(tie[1:], 0.0)


def test_a_straight_hand_along_a_window_edge_is_seen_by_both_windows():
    # Shoulder 100, elbow 180: the straight arm points along -10 deg, the edge of windows 21 and
    # 22 (both in unit 2); each sees the hand's base 45 units out: 2 x (1 - 45/50) / 8.
    expected = np.zeros(8)
    expected[2] = 2 * (1 - 45 / 50) / 8
    np.testing.assert_allclose(vision_at(100, 180), expected, atol=1e-12)


def test_whole_degree_moves_refuse_trial_starts_between_degrees():
    model = ModelConfig(angle_steps="round")
    setup = TrialSetup(np.array([[30.0, 0.0]]), np.array([10.0]), np.array([90.5]),
                       np.array([90.0]))
    with pytest.raises(SetupError, match="shoulder angles must be whole degrees under "
                                         "model.angle_steps=round"):
        World(1, model).reset(setup)
    setup.shoulder[:] = 90.0
    World(1, model).reset(setup)                                 # whole degrees are fine


def test_whole_degree_moves_need_a_whole_joint_range():
    with pytest.raises(ConfigError, match="need a whole joint_max_deg, got 170.5"):
        Config().replace(**{"model.angle_steps": "truncate", "model.joint_max_deg": 170.5})
    Config().replace(**{"model.angle_steps": "truncate", "model.joint_max_deg": 170})


# -- a move past a joint limit -------------------------------------------------------------------
@pytest.mark.parametrize("limit, shoulder, elbow", [("clip", 180.0, 0.0), ("cancel", 175.0, 5.0)])
def test_a_move_past_a_joint_limit_is_clipped_or_cancelled(limit, shoulder, elbow):
    # extend the shoulder at 175 by 15 (past 180) and flex the elbow at 5 by 15 (past 0)
    state = after(world_at(175, 5, joint_limit=limit), s_flex=0, s_ext=1, e_flex=1, e_ext=0)
    assert state == (0.0, shoulder, elbow)


def test_cancel_judges_each_joint_alone_and_allows_reaching_a_limit():
    world = world_at(165, 10, joint_limit="cancel")
    # the shoulder reaches 180 exactly; the elbow's -15 would pass 0 and is not made
    assert after(world, eye=1.0, s_flex=0, s_ext=1, e_flex=1, e_ext=0) == (15.0, 180.0, 10.0)
    # from the limit, a move back into the range is made
    assert after(world, s_flex=1, s_ext=0, e_flex=0, e_ext=1)[1:] == (165.0, 25.0)


def test_readings_reach_the_command_line(tmp_path):
    out = tmp_path / "runs"
    assert main(["evolve", "--out", str(out), "--quiet", "--runs", "1", "--generations", "2",
                 "--population", "10", "--parents", "2", "--trials", "2", "--cycles", "10",
                 "--set", "model.joint_limit=cancel", "--angle-steps", "truncate",
                 "--genome-code", "sign-magnitude"]) == 0
    config = RunData(out / "run-01").config
    assert (config.model.joint_limit, config.model.angle_steps, config.evolution.genome_code) \
        == ("cancel", "truncate", "sign-magnitude")


# -- the sign-magnitude weight code --------------------------------------------------------------
SM = "sign-magnitude"


def test_sign_magnitude_decodes_sign_times_magnitude():
    codes = np.array([0b00000000, 0b10000000, 0b00000001, 0b10000011, 0b01111111, 0b11111111],
                     np.uint8)
    weights = genome.decode(codes, 8, 10.0, SM)
    np.testing.assert_array_equal(weights, [0.0, 0.0, 10 / 127, -30 / 127, 10.0, -10.0])
    np.testing.assert_array_equal(genome.encode(weights, 8, 10.0, SM),
                                  [0, 0, 1, 0b10000011, 0b01111111, 0b11111111])   # -0 -> +0


def test_sign_magnitude_round_trips_and_flipping_the_sign_bit_negates():
    codes = np.arange(256, dtype=np.uint8)
    weights = genome.decode(codes, 8, 10.0, SM)
    assert len(np.unique(weights)) == 255 == genome.n_grid_points(8, SM)
    back = genome.encode(weights, 8, 10.0, SM)
    np.testing.assert_array_equal(back[codes != 128], codes[codes != 128])
    np.testing.assert_array_equal(genome.decode(codes ^ 0b10000000, 8, 10.0, SM), -weights)
    by_point = genome.codes_of(np.arange(255, dtype=np.uint8), 8, SM)
    assert np.all(np.diff(genome.decode(by_point, 8, 10.0, SM)) > 0)     # points in weight order
    np.testing.assert_array_equal(genome.grid_points(by_point, 8, SM), np.arange(255))


def test_sign_magnitude_puts_no_cliff_at_zero():
    # binary: the two weights nearest zero (codes 127 and 128) differ in all 8 bits
    near_zero = genome.encode(np.array([-0.03, 0.03]), 8, 10.0, "binary")
    assert tuple(near_zero) == (127, 128)
    assert genome.flipped_bits(near_zero[:1], near_zero[1:]) == 8
    # sign-magnitude: -1 step, 0, +1 step are one bit apart each
    minus, zero, plus = genome.encode(np.array([-10 / 127, 0.0, 10 / 127]), 8, 10.0, SM)
    assert (minus, zero, plus) == (0b10000001, 0, 1)
    assert genome.flipped_bits(np.array([minus]), np.array([plus])) == 1
    assert genome.flipped_bits(np.array([zero]), np.array([plus])) == 1
    assert genome.flipped_bits(np.array([0b10000000], np.uint8), np.array([minus])) == 1


def test_sign_magnitude_weight_steps_pass_zero_once():
    # from +1 step (code 1), moves of -2, -1, +1, +2 grid points give -1, 0, +2, +3 steps
    rng = np.random.default_rng(3)
    start = np.ones((4000, 1), np.uint8)
    mutated = genome.mutate(rng, start, 8, 1.0, mode="weights", step=2, code=SM)
    steps = np.rint(genome.decode(mutated, 8, 10.0, SM) * 127 / 10).astype(int)
    assert set(np.unique(steps)) == {-1, 0, 2, 3}
    assert set(np.unique(mutated[steps == 0])) == {0}                   # zero codes as +0
    ends = np.array([[0b01111111, 0b11111111, 0b10000000]], np.uint8)   # +10, -10, -0
    moved = genome.mutate(rng, np.repeat(ends, 2000, axis=0), 8, 1.0, mode="weights", step=3,
                          code=SM)
    assert genome.decode(moved, 8, 10.0, SM).max() == 10.0                 # stops at the ends
    assert genome.decode(moved, 8, 10.0, SM).min() == -10.0
    unchosen = genome.mutate(rng, ends, 8, 0.0, mode="weights", step=3, code=SM)
    np.testing.assert_array_equal(unchosen, ends)                           # -0 stays -0


def test_sign_magnitude_needs_a_sign_and_a_magnitude_bit():
    with pytest.raises(ConfigError, match="at least 2 bits_per_weight"):
        Config().replace(**{"evolution.genome_code": SM, "evolution.bits_per_weight": 1})
