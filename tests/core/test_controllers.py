"""The networks: batching weights per econet must not change a bit, the weight counts and refusals,
which weights read which sense, and the vectorised logistic is the scalar formula."""
import math

import numba
import numpy as np
import pytest

from econet_ros import genome
from econet_ros.config import Config
from econet_ros.controllers import logistic
from econet_ros.elementary import EXP_NEAR_LIMIT
from econet_ros.plugins import make_controller

CONFIG = Config()


def test_weights_per_econet_equal_weights_repeated_per_environment():
    n_econets, trials = 5, 3
    n = n_econets * trials
    obs_inputs = np.random.default_rng(1).random((n, 13))
    shared = make_controller("normal", n, CONFIG)
    weights = genome.decode(genome.random_genomes(np.random.default_rng(2), n_econets,
                                                  shared.n_params, 8), 8, 10.0)
    shared.load(weights)
    repeated = make_controller("normal", n, CONFIG)
    repeated.load(np.repeat(weights, trials, axis=0))
    np.testing.assert_array_equal(shared.forward(obs_inputs), repeated.forward(obs_inputs))
    alone = make_controller("normal", 1, CONFIG)
    alone.load(weights[2:3])
    np.testing.assert_array_equal(alone.forward(obs_inputs[7:8]),
                                  shared.forward(obs_inputs)[7:8])


def test_network_weight_count_and_refusals():
    net = make_controller("normal", 4, CONFIG)
    n = CONFIG.network
    assert net.n_params == (8 * n.visual_hidden + 4 * n.proprio_hidden
                            + (1 + n.visual_hidden + n.proprio_hidden) * n.intermodal_hidden
                            + n.intermodal_hidden * 5)
    assert make_controller("three-layer", 4, CONFIG).n_params == 13 * 8 + 8 * 5
    with pytest.raises(ValueError, match="dividing 4"):
        net.load(np.zeros((3, net.n_params)))
    with pytest.raises(ValueError, match="unknown controller"):
        make_controller("five-layer", 4, CONFIG)


@numba.njit
def _logistic_scalar(total):
    """The formula as the networks computed it before (math.exp, one value at a time)."""
    return np.array([1.0 / (1.0 + math.exp(-t)) for t in total])


@numba.njit
def _logistic(total):
    out = np.empty_like(total)
    logistic(total, out)
    return out


SENSES = {"vision": slice(0, 8), "proprio": slice(8, 12), "touch": slice(12, 13)}


@pytest.mark.parametrize("condition", ["normal", "three-layer"])
@pytest.mark.parametrize("sense", SENSES)
def test_weights_reading_a_sense_are_all_that_carry_it(condition, sense):
    """With the weights the network says read a sense set to zero, that sense's inputs change
    nothing; every other weight is left, and the senses' weights are apart."""
    net = make_controller(condition, 2, CONFIG)
    mask = net.weights_reading(sense)
    others = [net.weights_reading(other) for other in SENSES if other != sense]
    assert mask.shape == (net.n_params,) and mask.any()
    assert not any((mask & other).any() for other in others)
    inputs = np.repeat(np.random.default_rng(4).random((1, 13)), 2, axis=0)
    inputs[1, SENSES[sense]] = 1.0 - inputs[0, SENSES[sense]]     # only this sense differs
    weights = np.random.default_rng(5).uniform(-10, 10, (1, net.n_params))
    net.load(np.repeat(weights, 2, axis=0))
    assert not np.allclose(*net.forward(inputs))
    weights[:, mask] = 0.0
    net.load(np.repeat(weights, 2, axis=0))
    np.testing.assert_array_equal(*net.forward(inputs))


def test_weights_reading_refuses_an_unknown_sense():
    with pytest.raises(ValueError, match="unknown sense 'smell'"):
        make_controller("normal", 1, CONFIG).weights_reading("smell")


def test_logistic_matches_the_scalar_formula_everywhere():
    rng = np.random.default_rng(1)
    total = np.concatenate([rng.uniform(-100, 100, 10_000),
                            [0.0, -0.0, 511.9, -511.9, 512.0, -512.0, 600.0, -600.0, 800.0,
                             -800.0, 1e5, -1e5, np.inf, -np.inf]])
    want = _logistic_scalar(total)
    np.testing.assert_array_max_ulp(_logistic(total), want, maxulp=1)
    far = np.abs(total) >= EXP_NEAR_LIMIT                   # these go through math.exp itself
    np.testing.assert_array_equal(_logistic(total)[far], want[far])
    assert np.isnan(_logistic(np.array([np.nan]))[0])


def test_network_refuses_inputs_of_the_wrong_shape():
    net = make_controller("normal", 4, CONFIG)
    net.load(np.zeros((2, net.n_params)))
    assert net.forward(np.zeros((4, 13))).shape == (4, 5)
    for bad in (np.zeros((3, 13)), np.zeros((4, 12)), np.zeros(13)):
        with pytest.raises(ValueError, match="network inputs"):
            net.forward(bad)
