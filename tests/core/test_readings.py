"""Readings of the paper tried as settings (issue 20): whole-degree moves, a move past a joint
limit cancelled, and a sign-magnitude weight code; each checked on cases worked by hand."""
import numpy as np
import pytest

from econet_ros import genome
from econet_ros.cli import main
from econet_ros.config import Config, ModelConfig
from econet_ros.errors import ConfigError, SetupError
from econet_ros.runs import RunData
from econet_ros.world import TrialSetup, World, sample_setups

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
