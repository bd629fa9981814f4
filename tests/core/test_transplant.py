"""A small network's weights transplanted into a larger one of the same layers (the
pre-registered E2 transplant): the large network computes exactly what the small one does, and
every weight the small one lacks is exactly zero."""
import numpy as np
import pytest

from econet_ros import genome
from econet_ros.config import Config
from econet_ros.controllers import FourLayerNetwork, ThreeLayerNetwork, transplant


def four(v, p, i, n_envs=64):
    return FourLayerNetwork(n_envs, Config().replace(**{
        "network.visual_hidden": v, "network.proprio_hidden": p, "network.intermodal_hidden": i}))


def test_a_transplanted_2_2_4_net_computes_exactly_what_it_did_in_4_4_8():
    small, large = four(2, 2, 4), four(4, 4, 8)
    rng = np.random.default_rng(0)
    weights = rng.uniform(-10, 10, (4, small.n_params))
    moved = transplant(small, large, weights)
    assert moved.shape == (4, large.n_params)
    assert np.count_nonzero(moved, axis=1).tolist() == [small.n_params] * 4
    inputs = rng.random((64, Config().model.visual_units + 5))
    small.load(weights)
    large.load(moved)
    assert np.array_equal(small.forward(inputs), large.forward(inputs))


def test_each_weight_keeps_the_sense_it_reads():
    small, large = four(2, 2, 4), four(4, 4, 8)
    moved = transplant(small, large, np.arange(1.0, small.n_params + 1))
    for sense in ("vision", "proprio", "touch"):
        kept = moved[large.weights_reading(sense)]
        assert sorted(kept[kept != 0]) == sorted(np.arange(1.0, small.n_params + 1)[
            small.weights_reading(sense)])


def test_a_transplant_needs_the_same_layers_each_as_wide():
    with pytest.raises(ValueError, match="at least as wide"):
        transplant(four(4, 4, 8), four(2, 2, 4), np.zeros(160))
    three = ThreeLayerNetwork(1, Config())
    with pytest.raises(ValueError, match="same layers"):
        transplant(three, four(4, 4, 8), np.zeros(three.n_params))


def test_under_sign_magnitude_a_transplanted_genome_decodes_to_the_same_weights_and_zeros():
    small, large = four(2, 2, 4), four(4, 4, 8)
    codes = genome.random_genomes(np.random.default_rng(1), 3, small.n_params, 8)
    weights = genome.decode(codes, 8, 10.0, "sign-magnitude")
    moved = transplant(small, large, weights)
    again = genome.decode(genome.encode(moved, 8, 10.0, "sign-magnitude"), 8, 10.0,
                          "sign-magnitude")
    assert np.array_equal(again, moved)
