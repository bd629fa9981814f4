"""Elementary functions as plain arithmetic for the compiled kernels.

A libm call per value keeps a loop from vectorising and costs more than the arithmetic it
hides; written out, these functions vectorise over a block of environments (exp) or simply cost
less (cos/sin), and their results do not depend on the platform's libm.
"""
from __future__ import annotations

import math
import struct
from decimal import Decimal, localcontext

import numba
import numpy as np
from numba import types
from numba.extending import intrinsic

# math.exp is a libm call per value, so the loop over a block of environments does not vectorise
# and exp dominates the network's cost. ``exp_near`` is the same algorithm, constants and
# rounding steps as glibc's exp (from Arm's optimized-routines, in its FMA build, which glibc
# picks on CPUs with FMA): it returns math.exp's exact bits there, but as plain arithmetic that
# LLVM vectorises. It covers |x| < EXP_NEAR_LIMIT, where glibc takes this same path.

@intrinsic
def _fma(typingctx, a, b, c):
    """a * b + c with one rounding (llvm.fma; a vfmadd instruction on CPUs with FMA)."""
    def codegen(context, builder, signature, args):
        return builder.fma(*args)
    return types.float64(types.float64, types.float64, types.float64), codegen


@intrinsic
def _bits(typingctx, x):
    """The IEEE-754 bits of a float64, as an int64."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], context.get_value_type(types.int64))
    return types.int64(types.float64), codegen


@intrinsic
def _from_bits(typingctx, i):
    """The float64 with the given IEEE-754 bits."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], context.get_value_type(types.float64))
    return types.float64(types.int64), codegen


def _exp_table(n: int) -> np.ndarray:
    """glibc's table for 2^(k/n), k < n: the pair (bits of the tail t, bits of h minus
    k << (52 - log2 n)) with h = 2^(k/n) rounded and h * (1 + t) closer still."""
    def bits(x: float) -> int:
        return struct.unpack("<q", struct.pack("<d", x))[0]
    table = np.zeros(2 * n, dtype=np.int64)
    with localcontext() as context:
        context.prec = 60
        for k in range(n):
            exact = (Decimal(2).ln() * k / n).exp()
            head = float(exact)
            table[2 * k] = bits(float((exact - Decimal(head)) / Decimal(head)))
            table[2 * k + 1] = bits(head) - (k << 45)
    return table


_EXP_N = 128                              # table entries: exp(x) = 2^(k/N) * exp(r)
_EXP_TABLE = _exp_table(_EXP_N)
_INV_LN2_N = float.fromhex("0x1.71547652b82fep7")          # N / ln 2
_SHIFT = float.fromhex("0x1.8p52")                         # rounds to an integer when added
_NEG_LN2_HI_N = float.fromhex("-0x1.62e42fefa0000p-8")     # -ln 2 / N, in two parts
_NEG_LN2_LO_N = float.fromhex("-0x1.cf79abc9e3b3ap-47")
_C2 = float.fromhex("0x1.ffffffffffdbdp-2")                # exp(r) ~ 1 + r + C2 r^2 + ...
_C3 = float.fromhex("0x1.555555555543cp-3")
_C4 = float.fromhex("0x1.55555cf172b91p-5")
_C5 = float.fromhex("0x1.1111167a4d017p-7")
EXP_NEAR_LIMIT = 512.0                    # glibc handles larger |x| (and 0) separately


@numba.njit(cache=True, inline="always")
def exp_near(x):
    """exp(x) for |x| < EXP_NEAR_LIMIT: x = k ln2/N + r, exp(x) = 2^(k/N) * exp(r), with
    2^(k/N) from the table and exp(r) from a polynomial (error under 0.51 ulp)."""
    kd = _fma(x, _INV_LN2_N, _SHIFT)
    ki = _bits(kd)                        # k in the low bits
    kd -= _SHIFT
    r = _fma(kd, _NEG_LN2_LO_N, _fma(kd, _NEG_LN2_HI_N, x))
    index = 2 * (ki & (_EXP_N - 1))
    tail = _from_bits(_EXP_TABLE[index])      # 2^(k/N) ~ scale * (1 + tail)
    scale = _from_bits(_EXP_TABLE[index + 1] + (ki << 45))
    r2 = r * r
    tmp = _fma(r2 * r2, _fma(r, _C5, _C4), _fma(_fma(r, _C3, _C2), r2, r + tail))
    return _fma(scale, tmp, scale)


# cos/sin: Taylor coefficients (-1)^k / n!. On |x| <= pi/4 the first omitted terms (x^19/19!,
# x^18/18!) are below 1e-17 of the result.
_SIN_TAYLOR = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(1, 9))    # x^3 ... x^17
_COS_TAYLOR = tuple((-1) ** k / math.factorial(2 * k) for k in range(1, 9))        # x^2 ... x^16
_SIN3, _SIN5, _SIN7, _SIN9, _SIN11, _SIN13, _SIN15, _SIN17 = _SIN_TAYLOR
_COS2, _COS4, _COS6, _COS8, _COS10, _COS12, _COS14, _COS16 = _COS_TAYLOR
_RADIANS_PER_DEGREE = math.pi / 180.0


@numba.njit(cache=True, inline="always")
def cos_sin_deg(angle):
    """(cos, sin) of an angle in degrees, within an ulp or two of libm's. The angle is reduced to
    r in [-45, 45] plus quarter turns (so multiples of 90 degrees come out exact), then the
    polynomials in z = x^2 run as two independent chains of fused multiply-adds."""
    turns = math.floor(angle / 90.0 + 0.5)
    x = (angle - 90.0 * turns) * _RADIANS_PER_DEGREE
    z = x * x
    s = _fma(z, _SIN17, _SIN15)
    c = _fma(z, _COS16, _COS14)
    s = _fma(z, s, _SIN13)
    c = _fma(z, c, _COS12)
    s = _fma(z, s, _SIN11)
    c = _fma(z, c, _COS10)
    s = _fma(z, s, _SIN9)
    c = _fma(z, c, _COS8)
    s = _fma(z, s, _SIN7)
    c = _fma(z, c, _COS6)
    s = _fma(z, s, _SIN5)
    c = _fma(z, c, _COS4)
    s = _fma(z, s, _SIN3)
    c = _fma(z, c, _COS2)
    s = _fma(x * z, s, x)
    c = _fma(z, c, 1.0)
    quarter = int(turns) & 3
    if quarter == 0:
        return c, s
    if quarter == 1:
        return -s, c
    if quarter == 2:
        return -c, -s
    return s, -c


# atan: after folding into |u| <= tan(pi/8), the Taylor series to u^19 is within 5e-10.
_ATAN = tuple((-1) ** k / (2 * k + 1) for k in range(1, 10))              # u^3 ... u^19
_TAN_PI_8 = math.sqrt(2.0) - 1.0
ATAN2_ERROR = 5e-10


@numba.njit(cache=True, inline="always")
def atan2_approx(y, x):
    """atan2(y, x) in radians, within ATAN2_ERROR: enough to tell which one-degree window a
    direction falls in, for less than a libm call."""
    ax, ay = abs(x), abs(y)
    big, small = max(ax, ay), min(ax, ay)
    t = small / big if big > 0.0 else 0.0            # tangent of the angle to the nearer axis
    folded = t > _TAN_PI_8
    if folded:                                       # atan t = pi/4 + atan((t - 1) / (t + 1))
        t = (t - 1.0) / (t + 1.0)
    z = t * t
    p = _ATAN[8]
    for k in range(7, -1, -1):
        p = _fma(z, p, _ATAN[k])
    a = _fma(t * z, p, t)
    if folded:
        a += 0.25 * math.pi
    if ay > ax:
        a = 0.5 * math.pi - a
    if x < 0.0:
        a = math.pi - a
    return -a if y < 0.0 else a
