"""Genomes: every connection weight held as a fixed-point binary code (paper, Appendix).

A genome is an array of unsigned integer codes, one per weight, each ``bits`` wide (8 in the
paper). Grid point k decodes to -R + 2R * k / (2**bits - 1): the 256 points span [-R, R] evenly
with both ends included (R = 10 in the paper). The code of grid point k is k itself ("binary",
the default: a flipped high bit moves a weight far, a flipped low bit a little, as in the
paper's example) or its reflected Gray code ("gray": neighbouring grid points differ in one bit).

Mutation, in the readings the paper allows (config evolution.mutation_mode):
    per-bit  every bit flips independently with probability ``rate`` (the Appendix: "2% of the
             bits were randomly selected and switched");
    exact    each genome gets exactly round(rate x its bit count) distinct bits flipped;
    weights  each weight is chosen with probability ``rate`` and moved up or down the grid by a
             uniform random 1..``step`` points, stopping at the grid's ends (the body text:
             "strengthening or weakening 2% of the connection weights, selected at random, by a
             small random amount").
"""
from __future__ import annotations

import numpy as np

def code_dtype(bits: int) -> type:
    return np.uint8 if bits <= 8 else np.uint16


def random_genomes(rng: np.random.Generator, n: int, n_weights: int, bits: int) -> np.ndarray:
    """n genomes with codes uniform over all 2**bits values (weights uniform in [-R, R], for
    either code)."""
    return rng.integers(0, 2 ** bits, size=(n, n_weights)).astype(code_dtype(bits))


def to_gray(points: np.ndarray) -> np.ndarray:
    """The reflected Gray code of grid points."""
    return points ^ (points >> 1)


def from_gray(codes: np.ndarray) -> np.ndarray:
    """Grid points of reflected Gray codes (inverse of to_gray)."""
    points = codes.copy()
    shift = codes >> 1
    while np.any(shift):
        points ^= shift
        shift >>= 1
    return points


def grid_points(codes: np.ndarray, code: str = "binary") -> np.ndarray:
    return from_gray(codes) if code == "gray" else codes


def codes_of(points: np.ndarray, code: str = "binary") -> np.ndarray:
    return to_gray(points) if code == "gray" else points


def decode(codes: np.ndarray, bits: int, weight_range: float, code: str = "binary") -> np.ndarray:
    """Real-valued weights for integer codes of any shape."""
    points = grid_points(codes, code)
    return -weight_range + 2.0 * weight_range * points.astype(np.float64) / (2 ** bits - 1)


def encode(weights: np.ndarray, bits: int, weight_range: float,
           code: str = "binary") -> np.ndarray:
    """Nearest codes for real weights (clipped to [-R, R])."""
    scaled = (np.clip(weights, -weight_range, weight_range) + weight_range) / (2 * weight_range)
    return codes_of(np.rint(scaled * (2 ** bits - 1)).astype(code_dtype(bits)), code)


def mutate(rng: np.random.Generator, codes: np.ndarray, bits: int, rate: float,
           mode: str = "per-bit", step: int = 1, code: str = "binary") -> np.ndarray:
    """Mutated copies of genomes (n, n_weights); see the module docstring for the modes."""
    if mode == "weights":
        return _step_weights(rng, codes, bits, rate, step, code)
    n, n_weights = codes.shape
    if mode == "per-bit":
        flips = rng.random((n, n_weights, bits)) < rate
    elif mode == "exact":
        total = n_weights * bits
        chosen = np.argsort(rng.random((n, total)), axis=1)[:, :int(round(rate * total))]
        flips = np.zeros((n, total), dtype=bool)
        np.put_along_axis(flips, chosen, True, axis=1)
        flips = flips.reshape(n, n_weights, bits)
    else:
        raise ValueError(f"unknown mutation mode '{mode}'")
    masks = (flips * (1 << np.arange(bits))).sum(axis=2)
    return (codes ^ masks).astype(codes.dtype)


def _step_weights(rng: np.random.Generator, codes: np.ndarray, bits: int, rate: float,
                  step: int, code: str) -> np.ndarray:
    chosen = rng.random(codes.shape) < rate
    size = rng.integers(1, step + 1, size=codes.shape)
    sign = np.where(rng.random(codes.shape) < 0.5, -1, 1)
    points = grid_points(codes, code).astype(np.int64)
    moved = np.clip(points + np.where(chosen, sign * size, 0), 0, 2 ** bits - 1)
    return codes_of(moved.astype(codes.dtype), code)


def flipped_bits(a: np.ndarray, b: np.ndarray) -> int:
    """How many bits differ between two code arrays (for tests and diagnostics)."""
    return int(np.unpackbits(np.atleast_1d(a ^ b).view(np.uint8)).sum())
