"""The Gymnasium environments: Gymnasium's own checker, the same fitness as the in-process
engine, next-step autoreset, seeding, reset options, rendering and one-line errors."""
import subprocess
import sys
import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import econet_ros.gym  # noqa: F401  (registers econet_ros/Reach-v0)
from econet_ros.config import Config
from econet_ros.controllers import FourLayerNetwork
from econet_ros.errors import ActionError, SetupError
from econet_ros.evolution import InProcessEvaluator, genome_weights, initial_genomes
from econet_ros.gym import ReachEnv, ReachVectorEnv
from econet_ros.world import sample_setups

SMALL = Config().replace(**{"evolution.population": 4, "evolution.parents": 2,
                            "evolution.trials": 5})


def test_gymnasium_checker_passes_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for render_mode in (None, "rgb_array"):   # made with a spec: render modes checked
            check_env(gymnasium.make("econet_ros/Reach-v0", render_mode=render_mode).unwrapped)


def test_registered_id_makes_both_environments():
    env = gymnasium.make("econet_ros/Reach-v0", cycles=7)
    assert env.unwrapped.task.cycles == 7
    envs = gymnasium.make_vec("econet_ros/Reach-v0", num_envs=3,
                              vectorization_mode="vector_entry_point")
    assert isinstance(envs, ReachVectorEnv) and envs.observation_space.shape == (3, 13)


def test_module_prefixed_id_registers_without_an_import():
    code = ("import gymnasium\n"
            "env = gymnasium.make('econet_ros.gym:econet_ros/Reach-v0')\n"
            "print(env.observation_space.shape, env.action_space.shape)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            check=True)
    assert result.stdout.strip() == "(13,) (5,)"


def econet_fitness_in_process(config, seed=4):
    """Generation 0 of a run: genomes, its trial starts and each econet's fitness."""
    evaluator = InProcessEvaluator(config)
    genomes = initial_genomes(config, evaluator.n_weights, seed, 1)
    result = evaluator.test_generation(genomes, seed, 1, 0)
    return genome_weights(config, genomes), evaluator.trial_setups(seed, 1, 0), result.fitness


def start_options(setups, envs):
    return {"object_xy": setups.object_xy[envs], "body": setups.body[envs],
            "shoulder": setups.shoulder[envs], "elbow": setups.elbow[envs]}


def test_the_papers_network_scores_the_same_fitness_through_the_single_env():
    weights, setups, fitness = econet_fitness_in_process(SMALL)
    assert fitness.sum() > 0
    env, net = ReachEnv(SMALL), FourLayerNetwork(1, SMALL)
    trials = SMALL.evolution.trials
    for econet, expected in enumerate(fitness):
        net.load(weights[econet][None])
        total = 0.0
        for trial in range(trials):
            obs, _ = env.reset(options=start_options(setups, econet * trials + trial))
            truncated = False
            while not truncated:
                obs, reward, _, truncated, _ = env.step(net.forward(obs[None])[0])
                total += reward
        assert total == expected


def test_the_papers_network_scores_the_same_fitness_through_the_vector_env():
    weights, setups, fitness = econet_fitness_in_process(SMALL, seed=9)
    envs = ReachVectorEnv(len(setups), SMALL)
    net = FourLayerNetwork(len(setups), SMALL)
    net.load(weights)                          # one network per block of its trials
    obs, _ = envs.reset(options=start_options(setups, slice(None)))
    returns = np.zeros(len(setups))
    for _ in range(SMALL.evolution.cycles):
        obs, reward, _, truncated, _ = envs.step(net.forward(obs))
        returns += reward
    assert truncated.all()
    np.testing.assert_array_equal(returns.reshape(fitness.size, -1).sum(axis=1), fitness)


def test_vector_env_autoresets_on_the_step_after_truncation():
    envs = ReachVectorEnv(2, cycles=3)
    envs.reset(seed=5)
    moves = np.full((2, 5), 0.8)
    for step in range(3):
        _, _, terminated, truncated, _ = envs.step(moves)
        assert not terminated.any() and truncated.all() == (step == 2)
    # the next trials are the next draw from the vector env's generator
    rng = np.random.default_rng()
    rng.bit_generator.state = envs.np_random.bit_generator.state
    next_trials = sample_setups(rng, 2, envs.task.config.model)
    first_obs, _ = ReachVectorEnv(2).reset(options=start_options(next_trials, slice(None)))
    # the autoreset step ignores its actions (here invalid ones) and starts those trials
    obs, reward, terminated, truncated, _ = envs.step(np.full((2, 5), np.nan))
    np.testing.assert_array_equal(obs, first_obs)
    assert not reward.any() and not terminated.any() and not truncated.any()
    for step in range(3):
        assert envs.step(moves)[3].all() == (step == 2)


def test_partial_reset_staggers_trials_and_autoreset_restarts_only_the_ended_one():
    envs = ReachVectorEnv(2, cycles=3)
    envs.reset(seed=1)
    envs.step(np.full((2, 5), 0.5))
    before = envs.task.world.senses[1].copy()
    obs, _ = envs.reset(options={"reset_mask": np.array([True, False]), "elbow": 90.0})
    assert envs.task.world.elbow[0] == 90.0
    np.testing.assert_array_equal(obs[1], before)
    ends = [envs.step(np.full((2, 5), 0.5))[3].tolist() for _ in range(4)]
    assert ends == [[False, False], [False, True], [True, False], [False, False]]
    assert envs.elapsed.tolist() == [0, 1]


def test_reset_seed_is_reproducible_and_draws_as_the_world_does():
    env = ReachEnv()
    first, _ = env.reset(seed=42)
    model = env.task.config.model
    expected = sample_setups(np.random.default_rng(42), 1, model)
    np.testing.assert_array_equal(env.task.world.object_xy, expected.object_xy)
    np.testing.assert_array_equal(env.reset(seed=42)[0], first)
    assert not np.array_equal(env.reset(seed=43)[0], first)


def test_reset_options_place_the_object_and_the_arm():
    env = ReachEnv()
    env.reset(seed=3, options={"object_xy": (20.0, 5.0), "body": 10.0, "shoulder": 180.0,
                               "elbow": 0.0})
    world = env.task.world
    assert world.object_xy.tolist() == [[20.0, 5.0]]
    assert (world.body[0], world.shoulder[0], world.elbow[0]) == (10.0, 180.0, 0.0)
    obs, _ = env.reset(seed=3, options={"shoulder": 45.0})
    assert obs[8] == 0.25 and world.body[0] == sample_setups(
        np.random.default_rng(3), 1, env.task.config.model).body[0]


def test_rgb_array_render_is_an_image():
    env = ReachEnv(render_mode="rgb_array")
    env.reset(seed=0)
    env.step(env.action_space.sample())
    image = env.render()
    assert image.dtype == np.uint8 and image.shape == (320, 320, 3) and image.std() > 0
    assert ReachEnv().render() is None


def test_actions_outside_the_box_are_clipped_by_the_world():
    low, high = ReachEnv(), ReachEnv()
    for env, action in ((low, np.array([-3.0, 9.0, -1.0, 0.0, 7.0])),
                        (high, np.array([0.0, 1.0, 0.0, 0.0, 1.0]))):
        env.reset(seed=8)
        env.step(action)
    np.testing.assert_array_equal(low.task.world.senses, high.task.world.senses)


@pytest.mark.parametrize("action, message", [
    (np.full(5, np.nan), "NaN or infinite"),
    (np.array([0.5, 0.5, 0.5, 0.5, np.inf]), "NaN or infinite"),
    (np.zeros(4), "shape (5,)"),
    (np.zeros((1, 5)), "shape (5,)"),
    ("left", "numbers of shape (5,)"),
])
def test_bad_actions_are_one_line_errors_that_change_nothing(action, message):
    env = ReachEnv()
    env.reset(seed=2)
    state = env.task.world.senses.copy()
    with pytest.raises(ActionError, match=message.replace("(", r"\(").replace(")", r"\)")) \
            as error:
        env.step(action)
    assert "\n" not in str(error.value)
    np.testing.assert_array_equal(env.task.world.senses, state)


@pytest.mark.parametrize("options, message", [
    ({"object_xy": (60.0, 0.0)}, "out of reach"),
    ({"object_xy": (1.0, 0.0)}, "out of reach"),
    ({"shoulder": 200.0}, "between 0 and 180"),
    ({"body": 1e300}, "between -360 and 360"),
    ({"elbow": np.nan}, "NaN"),
    ({"object_xy": (1.0, 2.0, 3.0)}, "shape"),
    ({"colour": "red"}, "unknown reset option"),
])
def test_bad_reset_options_are_one_line_errors(options, message):
    with pytest.raises(SetupError, match=message) as error:
        ReachEnv().reset(seed=0, options=options)
    assert "\n" not in str(error.value)
    with pytest.raises(SetupError, match=message):
        ReachVectorEnv(3).reset(seed=0, options=options)


def test_stepping_outside_a_trial_needs_a_reset():
    env = ReachEnv(cycles=1)
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(np.zeros(5))
    env.reset(seed=0)
    assert env.step(np.zeros(5))[3]
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(np.zeros(5))
    with pytest.raises(gymnasium.error.ResetNeeded):
        ReachVectorEnv(2).step(np.zeros((2, 5)))
