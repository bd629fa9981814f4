"""The scrambled four-layer net (network.first_layer_wiring = "scrambled"): the same units and
weight count as the modular net, each first-layer unit reading a random subset of the senses of
the size it reads when modular, drawn from network.wiring_seed; the modular net unchanged."""
import numpy as np

from econet_ros.config import Config
from econet_ros.controllers import FourLayerNetwork, scrambled_wiring
from econet_ros.plugins import make_controller

SCRAMBLED = {"network.first_layer_wiring": "scrambled"}


def net(n_envs=16, **settings):
    return FourLayerNetwork(n_envs, Config().replace(**settings))


def test_scrambled_keeps_the_modular_weight_count_and_each_unit_its_number_of_inputs():
    modular, scrambled = net(), net(**SCRAMBLED)
    assert scrambled.n_params == modular.n_params == 64
    assert make_controller("random", 1, Config().replace(**SCRAMBLED)).n_params == 64
    wired = scrambled_wiring(Config().replace(**SCRAMBLED))
    per_unit = np.bincount(wired[wired < 12 * 4] // 12, minlength=4)
    assert per_unit.tolist() == [8, 8, 4, 4]     # visual units 8 inputs, proprioceptive 4
    assert len(set(wired.tolist())) == len(wired)


def test_the_wiring_is_drawn_from_its_seed():
    one, again, other = (scrambled_wiring(Config().replace(**SCRAMBLED, **{
        "network.wiring_seed": s})) for s in (1, 1, 2))
    assert np.array_equal(one, again) and not np.array_equal(one, other)


def test_a_unit_reads_only_the_inputs_it_is_wired_to():
    """The network computes the sparse net its genome says: weights only where it is wired, and
    its outputs those of the sparse net computed by hand."""
    scrambled = net(**SCRAMBLED)
    wired = scrambled_wiring(scrambled.config)
    rng = np.random.default_rng(0)
    scrambled.load(rng.uniform(-10, 10, (1, 64)))
    full = scrambled.weights[0]
    assert np.count_nonzero(full) == 64 and len(full) == 12 * 4 + 5 * 4 + 4 * 5
    # the sparse net by hand: each first-layer unit a logistic of its wired inputs only
    inputs = rng.random((16, 13))
    first = 1 / (1 + np.exp(-(inputs[:, :12] @ full[:48].reshape(4, 12).T)))
    hidden = np.column_stack([inputs[:, 12], first])
    inter = 1 / (1 + np.exp(-(hidden @ full[48:68].reshape(4, 5).T)))
    out = 1 / (1 + np.exp(-(inter @ full[68:].reshape(5, 4).T)))
    assert np.allclose(scrambled.forward(inputs), out, atol=1e-12)
    assert set(np.flatnonzero(full)) == set(wired.tolist())


def test_a_lesion_of_vision_finds_the_scrambled_weights_that_read_it():
    scrambled = net(**SCRAMBLED)
    wired = scrambled_wiring(scrambled.config)
    vision = scrambled.weights_reading("vision")
    assert len(vision) == 64
    first_layer = wired < 48
    assert np.array_equal(vision[first_layer], (wired[first_layer] % 12) < 8)
    assert not vision[~first_layer].any()


def test_modular_is_the_default_and_unchanged():
    assert Config().network.first_layer_wiring == "modular"
    modular = net()
    assert modular.wired is None and modular.layers[:2, :2].tolist() == [[0, 8], [8, 12]]
    assert "first_layer_wiring" not in Config().to_json()      # an added setting at its default
