"""Genomes: every connection weight held as a fixed-point binary code (paper, Appendix).

A genome is an array of unsigned integer codes, one per weight, each ``bits`` wide (8 in the
paper). Grid point k decodes to -R + 2R * k / (2**bits - 1): the 256 points span [-R, R] evenly
with both ends included (R = 10 in the paper). The code of grid point k is k itself ("binary",
the default: a flipped high bit moves a weight far, a flipped low bit a little, as in the
paper's example) or its reflected Gray code ("gray": neighbouring grid points differ in one bit).

"sign-magnitude" codes a weight as a sign bit (the highest; 1 = negative) and bits - 1 bits of
magnitude m: w = +-m * R / (2**(bits - 1) - 1). Zero is a code (twice: +0 and -0), so the
weights nearest zero are not, as in binary, on the 8-bit cliff between codes 127 and 128, and
w and -w differ in one bit. Its grid is the 255 distinct weights, point k = 127 + the signed
magnitude (zero is point 127 and codes back to +0).

Mutation, in the readings the paper allows (config evolution.mutation_mode):
    per-bit  every bit flips independently with probability ``rate`` (the Appendix: "2% of the
             bits were randomly selected and switched");
    exact    each genome gets exactly round(rate x its bit count) distinct bits flipped;
    weights  each weight is chosen with probability ``rate`` and moved up or down the grid by a
             uniform random 1..``step`` points, stopping at the grid's ends (the body text:
             "strengthening or weakening 2% of the connection weights, selected at random, by a
             small random amount"); under sign-magnitude, a step through zero counts zero once.
"""
from __future__ import annotations

import numpy as np

def code_dtype(bits: int) -> type:
    return np.uint8 if bits <= 8 else np.uint16


def random_genomes(rng: np.random.Generator, n: int, n_weights: int, bits: int) -> np.ndarray:
    """n genomes with codes uniform over all 2**bits values, i.e. random bits (weights uniform
    over the grid of [-R, R] under every code; under sign-magnitude zero, coded twice, is twice
    as likely as any other weight)."""
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


def largest_magnitude(bits: int) -> int:
    """The sign-magnitude code's largest magnitude, 2**(bits - 1) - 1 (127 for 8 bits)."""
    return 2 ** (bits - 1) - 1


def n_grid_points(bits: int, code: str = "binary") -> int:
    """How many distinct weights the codes give: all 2**bits, but one fewer under
    sign-magnitude, whose +0 and -0 are the same weight."""
    return 2 ** bits - 1 if code == "sign-magnitude" else 2 ** bits


def grid_points(codes: np.ndarray, bits: int, code: str = "binary") -> np.ndarray:
    """The weight-ordered grid point of each code (0 = -R, the last = +R)."""
    if code == "gray":
        return from_gray(codes)
    if code == "sign-magnitude":
        top = largest_magnitude(bits)
        magnitude = (codes & top).astype(np.int64)
        return (top + np.where(codes >> (bits - 1), -magnitude, magnitude)).astype(codes.dtype)
    return codes


def codes_of(points: np.ndarray, bits: int, code: str = "binary") -> np.ndarray:
    """The code of each grid point (inverse of grid_points; zero codes as +0)."""
    if code == "gray":
        return to_gray(points)
    if code == "sign-magnitude":
        top = largest_magnitude(bits)
        signed = points.astype(np.int64) - top
        return np.where(signed < 0, (top + 1) | -signed, signed).astype(points.dtype)
    return points


def decode(codes: np.ndarray, bits: int, weight_range: float, code: str = "binary") -> np.ndarray:
    """Real-valued weights for integer codes of any shape."""
    if code == "sign-magnitude":       # sign x magnitude, so that w and -w are exact opposites
        top = largest_magnitude(bits)
        magnitude = (codes & top).astype(np.float64) * weight_range / top
        return np.where(codes >> (bits - 1), -magnitude, magnitude)
    points = grid_points(codes, bits, code)
    return -weight_range + 2.0 * weight_range * points.astype(np.float64) / (2 ** bits - 1)


def encode(weights: np.ndarray, bits: int, weight_range: float,
           code: str = "binary") -> np.ndarray:
    """Nearest codes for real weights (clipped to [-R, R])."""
    scaled = (np.clip(weights, -weight_range, weight_range) + weight_range) / (2 * weight_range)
    points = np.rint(scaled * (n_grid_points(bits, code) - 1)).astype(code_dtype(bits))
    return codes_of(points, bits, code)


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
    points = grid_points(codes, bits, code).astype(np.int64)
    moved = np.clip(points + np.where(chosen, sign * size, 0), 0, n_grid_points(bits, code) - 1)
    # Weights not chosen keep their codes (a sign-magnitude -0 stays -0).
    return np.where(chosen, codes_of(moved.astype(codes.dtype), bits, code), codes)


def flipped_bits(a: np.ndarray, b: np.ndarray) -> int:
    """How many bits differ between two code arrays (for tests and diagnostics)."""
    return int(np.unpackbits(np.atleast_1d(a ^ b).view(np.uint8)).sum())
