"""A plain reading of the paper's variation and selection, the reference model's own (the
independent check's end-to-end runs, econet_ros/science/reference_check.py): genomes of
fixed-point codes, their weights, per-bit mutation and truncation selection, written from the
Appendix and the genome docs (econet_ros/genome.py's docstring, docs/assumptions.md), without
the engine's genome or evolution code. Like the motor table's draw in model.py, two conventions
come from the engine so that the same seed gives the same run: each draw's random stream, named
by (seed, run, generation, purpose) as a NumPy SeedSequence's spawn key, and the shape and order
of each draw.
"""
from __future__ import annotations

import numpy as np

from econet_ros.config import Config

SETUPS, MUTATION, NOISE, INITIAL = range(4)     # the purposes of a generation's streams


def stream(seed: int, run: int, generation: int, purpose: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(run, generation,
                                                                         purpose)))


def weights(config: Config, codes: np.ndarray) -> np.ndarray:
    """The weights codes stand for. binary: code k is grid point k of 2**bits points spanning
    [-R, R] with both ends; gray: the reflected Gray code of the point; sign-magnitude: the
    highest bit the sign (1 negative), the others a magnitude m, the weight m R / (2**(bits-1)
    - 1)."""
    e = config.evolution
    bits, top = e.bits_per_weight, float(e.weight_range)
    codes = np.asarray(codes, dtype=np.int64)
    if e.genome_code == "sign-magnitude":
        largest = 2 ** (bits - 1) - 1
        magnitude = (codes % (largest + 1)) * top / largest
        return np.where(codes > largest, -magnitude, magnitude)
    points = codes.copy()
    if e.genome_code == "gray":                 # undo g = p xor (p >> 1), bit by bit from the top
        for shift in range(1, bits):
            points ^= codes >> shift
    return -top + 2 * top * points / (2 ** bits - 1)


def first_generation(config: Config, n_weights: int, seed: int, run: int) -> np.ndarray:
    """Generation 0: every bit of every genome random."""
    e = config.evolution
    return stream(seed, run, 0, INITIAL).integers(0, 2 ** e.bits_per_weight,
                                                  size=(e.population, n_weights))


def ranked(fitness) -> list[int]:
    """Econets from the fittest down; a tie goes to the earlier one."""
    return sorted(range(len(fitness)), key=lambda k: (-fitness[k], k))


def offspring(config: Config, genomes: np.ndarray, fitness: np.ndarray, seed: int, run: int,
              generation: int) -> np.ndarray:
    """The next generation: the ``parents`` fittest econets (``ranked``), best first, each
    copied population/parents times, every bit of every copy flipped with probability
    mutation_rate (Appendix: '2% of the bits were randomly selected and switched'). Only this
    reading, the default, is written here: the end-to-end runs use the defaults."""
    e = config.evolution
    copies = np.repeat(genomes[ranked(fitness)[:e.parents]], e.population // e.parents, axis=0)
    flips = stream(seed, run, generation, MUTATION).random(
        (*copies.shape, e.bits_per_weight)) < e.mutation_rate
    masks = (flips * (1 << np.arange(e.bits_per_weight))).sum(axis=2)
    return copies ^ masks
