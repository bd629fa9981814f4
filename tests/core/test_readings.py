"""Readings of the paper tried as settings (issue 20): whole-degree moves and a move past a
joint limit cancelled; each checked on cases worked by hand."""
import numpy as np
import pytest

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
                 "--set", "model.joint_limit=cancel", "--angle-steps", "truncate"]) == 0
    config = RunData(out / "run-01").config
    assert (config.model.joint_limit, config.model.angle_steps) == ("cancel", "truncate")
