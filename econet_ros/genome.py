"""Genomes: every connection weight held as a fixed-point binary code (paper, Appendix).

A genome is an array of unsigned integer codes, one per weight, each ``bits`` wide (8 in the
paper). Code k decodes to -R + 2R * k / (2**bits - 1): the 256 codes span [-R, R] evenly with
both ends included (R = 10 in the paper). Codes are plain binary, not Gray-coded, so a flipped
high bit moves a weight far and a flipped low bit moves it a little, as in the paper's example.
"""
from __future__ import annotations

import numpy as np


def code_dtype(bits: int) -> type:
    return np.uint8 if bits <= 8 else np.uint16


def random_genomes(rng: np.random.Generator, n: int, n_weights: int, bits: int) -> np.ndarray:
    """n genomes with codes uniform over all 2**bits values (weights uniform in [-R, R])."""
    return rng.integers(0, 2 ** bits, size=(n, n_weights)).astype(code_dtype(bits))


def decode(codes: np.ndarray, bits: int, weight_range: float) -> np.ndarray:
    """Real-valued weights for integer codes of any shape."""
    return -weight_range + 2.0 * weight_range * codes.astype(np.float64) / (2 ** bits - 1)


def encode(weights: np.ndarray, bits: int, weight_range: float) -> np.ndarray:
    """Nearest codes for real weights (clipped to [-R, R])."""
    scaled = (np.clip(weights, -weight_range, weight_range) + weight_range) / (2 * weight_range)
    return np.rint(scaled * (2 ** bits - 1)).astype(code_dtype(bits))


def mutate(rng: np.random.Generator, codes: np.ndarray, bits: int, rate: float,
           mode: str = "per-bit") -> np.ndarray:
    """Copies of genomes (n, n_weights) with bits flipped.

    per-bit: every bit flips independently with probability ``rate``.
    exact:   each genome gets exactly round(rate * its bit count) distinct bits flipped.
    """
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


def flipped_bits(a: np.ndarray, b: np.ndarray) -> int:
    """How many bits differ between two code arrays (for tests and diagnostics)."""
    return int(np.unpackbits(np.atleast_1d(a ^ b).view(np.uint8)).sum())
