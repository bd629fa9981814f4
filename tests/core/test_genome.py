"""8-bit genomes: the round trip, the range of random genomes, and the two bit-flip mutations."""
import numpy as np
import pytest

from econet_ros import genome


def test_genome_round_trip_and_range():
    codes = np.arange(256, dtype=np.uint8)
    weights = genome.decode(codes, 8, 10.0)
    assert weights[0] == -10.0 and weights[-1] == 10.0
    np.testing.assert_array_equal(genome.encode(weights, 8, 10.0), codes)
    assert np.all(np.diff(weights) > 0)


def test_random_genomes_cover_the_weight_range():
    weights = genome.decode(genome.random_genomes(np.random.default_rng(0), 100, 160, 8), 8, 10)
    assert weights.min() == -10 and weights.max() == 10
    assert abs(weights.mean()) < 0.2


def test_per_bit_mutation_flips_two_percent_of_bits():
    rng = np.random.default_rng(1)
    codes = genome.random_genomes(rng, 500, 160, 8)
    mutated = genome.mutate(rng, codes, 8, 0.02)
    rate = genome.flipped_bits(codes, mutated) / codes.size / 8
    assert rate == pytest.approx(0.02, abs=0.001)


def test_exact_mutation_flips_exactly_two_percent_of_each_genome():
    rng = np.random.default_rng(2)
    codes = genome.random_genomes(rng, 50, 160, 8)
    mutated = genome.mutate(rng, codes, 8, 0.02, mode="exact")
    for before, after in zip(codes, mutated):
        assert genome.flipped_bits(before, after) == round(0.02 * 160 * 8)
