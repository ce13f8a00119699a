"""Vectorisable sin and cos of one angle: range reduction plus fdlibm's minimax polynomials.

Why: the batch drivers form the contact normal n = (cos Γ, sin Γ) per row. This numba
has no SVML, so ``math.cos``/``math.sin`` are scalar libm calls, and one call in a loop
stops LLVM from vectorising the rest of it. ``SINCOS_SOURCE`` is the text of a
``_sincos(x) -> (sin x, cos x)`` made only of float arithmetic, ``abs`` and conditional
expressions (which LLVM turns into selects), so the whole loop stays SIMD. The same text
runs as plain Python (single-scene path, no numba) with bit-identical results: IEEE
double arithmetic in the same order, no fused multiply-add (numba has no ``math.fma``
and does not contract by default; never compile it with ``fastmath``). In numba code,
compile it with ``numba.njit(inline="always")`` in the same file as its loops: called as
a separate njit function it is not inlined and the calling ``prange`` loop is not
vectorised (measured: 0 packed instructions, against 75 inlined).

Method (the medium-size path of fdlibm's ``__ieee754_rem_pio2`` and the kernels
``__kernel_sin``/``__kernel_cos``, made branch-free):

1. Quadrant: fn = x·2/π rounded to the nearest integer by adding and subtracting
   1.5·2^52 (exact for |x·2/π| < 2^51; no ``int()``/``math.floor``, which raise on NaN
   in plain Python).
2. Cody–Waite reduction: π/2 = P1 + P2 + P3 + P3T, where P1, P2, P3 are successive
   33-bit pieces of π/2 and P3T the rest rounded to a double. For |fn| ≤ 2^20 the
   products fn·P1, fn·P2, fn·P3 are exact and x - fn·P1 is exact (Sterbenz), and the
   two further subtractions are done as error-free TwoSums, so the reduced argument
   y0 + y1 = x - fn·π/2 is known to far below one ulp of y0 even when it cancels
   (near multiples of π/2). fdlibm chooses between 1, 2 or 3 rounds with branches;
   here all three always run, which costs a few flops and keeps the loop branch-free.
3. On |y0| ≲ π/4: sin by fdlibm's degree-13 odd polynomial and cos by its degree-14
   even polynomial (FreeBSD's branch-free ``__kernel_cos`` form, exact 1 - z/2 split),
   both with the first-order correction for the tail y1, in Horner form.
4. Quadrant k = fn mod 4 selects and negates (sin, cos) → (s, c), (c, -s), (-s, -c),
   (-c, s) by conditional expressions.

NaN and ±inf give NaN (inf - inf in the reduction); ±0 give (±0, 1). ``SINCOS_LIMIT``
is where fn reaches 2^20 (|x| ≈ 1.65e6): beyond it the products above stop being
exact and the runtime uses numpy's cos/sin instead. Up to it the error is ≤ 1 ulp
against 50-digit mpmath (``proofs()`` here on a few thousand points;
tests/test_sincos.py on many more and every hard case of the reduction).

The polynomial coefficients and reduction constants are fdlibm's, under this notice:

    Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.

    Developed at SunPro, a Sun Microsystems, Inc. business.
    Permission to use, copy, modify, and distribute this
    software is freely granted, provided that this notice
    is preserved.

(``__kernel_cos`` as rewritten for FreeBSD by Bruce D. Evans, same notice). The
reduction constants are re-derived below from π with mpmath and checked against
fdlibm's bit patterns; the polynomials' approximation errors are re-measured.
"""

from __future__ import annotations

import math
import random
import struct

import mpmath

SINCOS_LIMIT_QUADRANTS = 2**20
"""Largest |fn| = |round(x·2/π)| for which the reduction is exact (53 - 33 bits)."""

SHIFT = 1.5 * 2.0**52
"""Adding and subtracting it rounds a double of magnitude < 2^51 to an integer."""

# fdlibm's constants as IEEE bit patterns (e_rem_pio2.c, k_sin.c, k_cos.c).
_FDLIBM_REDUCTION = {
    "INVPIO2": 0x3FE45F306DC9C883,  # 6.36619772367581382433e-01  2/π
    "P1": 0x3FF921FB54400000,  # 1.57079632673412561417e+00  first 33 bits of π/2
    "P2": 0x3DD0B4611A600000,  # 6.07710050630396597660e-11  second 33 bits
    "P3": 0x3BA3198A2E000000,  # 2.02226624871116645580e-21  third 33 bits
    "P3T": 0x397B839A252049C1,  # 8.47842766036889956997e-32  π/2 - (P1 + P2 + P3)
}
_FDLIBM_SIN = (  # S1..S6: sin x ≈ x + S1 x^3 + ... + S6 x^13 on [-π/4, π/4]
    0xBFC5555555555549,  # -1.66666666666666324348e-01
    0x3F8111111110F8A6,  #  8.33333333332248946124e-03
    0xBF2A01A019C161D5,  # -1.98412698298579493134e-04
    0x3EC71DE357B1FE7D,  #  2.75573137070700676789e-06
    0xBE5AE5E68A2B9CEB,  # -2.50507602534068634195e-08
    0x3DE5D93A5ACFD57C,  #  1.58969099521155010221e-10
)
_FDLIBM_COS = (  # C1..C6: cos x ≈ 1 - x^2/2 + C1 x^4 + ... + C6 x^14 on [-π/4, π/4]
    0x3FA555555555554C,  #  4.16666666666666019037e-02
    0xBF56C16C16C15177,  # -1.38888888888741095749e-03
    0x3EFA01A019CB1590,  #  2.48015872894767294178e-05
    0xBE927E4F809C52AD,  # -2.75573143513906633035e-07
    0x3E21EE9EBDB4B1C4,  #  2.08757232129817482790e-09
    0xBDA8FAE9BE8838D4,  # -1.13596475577881948265e-11
)


def _from_bits(bits: int) -> float:
    return struct.unpack("<d", struct.pack("<Q", bits))[0]


def _truncated(v, bits: int) -> float:
    """v > 0 truncated (towards 0) to its leading `bits` significant bits, exactly."""
    mant, exp = mpmath.frexp(v)  # v = mant·2^exp, 0.5 <= mant < 1
    return float(mpmath.ldexp(mpmath.floor(mpmath.ldexp(mant, bits)), exp - bits))


def reduction_constants() -> dict[str, float]:
    """2/π and π/2 = P1 + P2 + P3 + P3T (three 33-bit pieces and a rounded tail),
    derived from π at 300 bits."""
    with mpmath.workprec(300):
        half_pi = mpmath.pi / 2
        p1 = _truncated(half_pi, 33)
        p2 = _truncated(half_pi - p1, 33)
        p3 = _truncated(half_pi - p1 - p2, 33)
        return {
            "INVPIO2": float(2 / mpmath.pi),
            "P1": p1,
            "P2": p2,
            "P3": p3,
            "P3T": float(half_pi - p1 - p2 - p3),
        }


SIN_COEFFICIENTS = tuple(_from_bits(b) for b in _FDLIBM_SIN)
COS_COEFFICIENTS = tuple(_from_bits(b) for b in _FDLIBM_COS)
REDUCTION = reduction_constants()
SINCOS_LIMIT = float(SINCOS_LIMIT_QUADRANTS * 0.5 * mpmath.pi) * (1 - 2.0**-40)
"""|x| up to which ``_sincos`` is within 1 ulp: just below 2^20·π/2 ≈ 1.647e6 rad."""

_TEMPLATE = '''\
def _sincos(x):
    """(sin x, cos x) of x in radians, each within 1 ulp for |x| <= {limit!r}.

    Generated from derive/trig.py (method and proofs there): Cody-Waite reduction
    by pi/2 and fdlibm's minimax polynomials (Copyright (C) 1993 by Sun Microsystems,
    Inc. All rights reserved. Developed at SunPro, a Sun Microsystems, Inc. business.
    Permission to use, copy, modify, and distribute this software is freely granted,
    provided that this notice is preserved.). Float arithmetic and conditional
    expressions only, so numba loops calling it vectorise; NaN and +-inf give NaN.
    """
    # fn = x*2/pi rounded to the nearest integer by the 1.5*2^52 shift (no int()/floor).
    fn = (x * {INVPIO2!r} + {SHIFT!r}) - {SHIFT!r}
    # y0 + y1 = x - fn*pi/2, pi/2 = P1 + P2 + P3 + P3T: fn*P1, fn*P2, fn*P3 are exact
    # for |fn| <= 2^20, x - fn*P1 is exact, the next two subtractions are TwoSums whose
    # rounding errors are kept, so cancellation near multiples of pi/2 loses nothing.
    r = x - fn * {P1!r}
    p = fn * {P2!r}
    s1 = r - p
    b = s1 - r
    e1 = (r - (s1 - b)) - (p + b)
    p = fn * {P3!r}
    s2 = s1 - p
    b = s2 - s1
    e2 = (s1 - (s2 - b)) - (p + b)
    # subtract the tail rather than add it: keeps y0 = -0.0 for x = -0.0
    tail = fn * {P3T!r} - (e1 + e2)
    y0 = s2 - tail
    y1 = (s2 - y0) - tail
    # fdlibm __kernel_sin(y0, y1, 1) and FreeBSD __kernel_cos(y0, y1), Horner form.
    z = y0 * y0
    v = z * y0
    rs = {S2!r} + z * ({S3!r} + z * ({S4!r} + z * ({S5!r} + z * {S6!r})))
    ks = y0 - ((z * (0.5 * y1 - v * rs) - y1) - v * {S1!r})
    rc = z * ({C1!r} + z * ({C2!r} + z * ({C3!r} + z * ({C4!r} + z * ({C5!r} + z * {C6!r})))))
    hz = 0.5 * z
    w = 1.0 - hz
    kc = w + (((1.0 - w) - hz) + (z * rc - y0 * y1))
    # quadrant k = fn mod 4 in {{0, 1, 2, 3}}: (ks, kc), (kc, -ks), (-ks, -kc), (-kc, ks)
    j = fn - 4.0 * ((fn * 0.25 + {SHIFT!r}) - {SHIFT!r})
    k = j + 4.0 if j < 0.0 else j
    odd = abs(k - 2.0) == 1.0
    sm = kc if odd else ks
    cm = ks if odd else kc
    s = -sm if k > 1.5 else sm
    c = -cm if abs(k - 1.5) == 0.5 else cm
    return s, c
'''


def sincos_source() -> str:
    """The text of ``_sincos`` with every constant printed as its shortest repr."""
    names = dict(REDUCTION, SHIFT=SHIFT, limit=SINCOS_LIMIT)
    names.update({f"S{i}": c for i, c in enumerate(SIN_COEFFICIENTS, 1)})
    names.update({f"C{i}": c for i, c in enumerate(COS_COEFFICIENTS, 1)})
    return _TEMPLATE.format(**names)


SINCOS_SOURCE = sincos_source()


def sincos_function():
    """``_sincos`` as a plain Python function (SINCOS_SOURCE executed)."""
    namespace: dict = {}
    exec(compile(SINCOS_SOURCE, "<derive.trig SINCOS_SOURCE>", "exec"), namespace)  # noqa: S102 (our own text)
    return namespace["_sincos"]


# ------------------------------------------------------------------ errors in ulps


def ulp_of(ref) -> mpmath.mpf:
    """One unit in the last place of the double binade holding the exact value `ref`
    (2^-1074 in the subnormal range)."""
    if ref == 0:
        return mpmath.ldexp(1, -1074)
    _, exp = mpmath.frexp(ref)  # |ref| = m·2^exp, 0.5 <= m < 1
    return mpmath.ldexp(1, max(exp - 53, -1074))


def ulp_errors(sincos, xs) -> tuple[float, float]:
    """Largest |sin error| and |cos error| in ulps of ``sincos`` over finite `xs`,
    against mpmath at 50 digits (each double converted exactly)."""
    worst_s = worst_c = 0.0
    with mpmath.workdps(50):
        for x in xs:
            s, c = sincos(x)
            mx = mpmath.mpf(x)
            rs, rc = mpmath.sin(mx), mpmath.cos(mx)
            worst_s = max(worst_s, float(abs(mpmath.mpf(s) - rs) / ulp_of(rs)))
            worst_c = max(worst_c, float(abs(mpmath.mpf(c) - rc) / ulp_of(rc)))
    return worst_s, worst_c


def near_quadrant_multiples(
    count: int, rng: random.Random, limit: float = SINCOS_LIMIT, step: float = 0.5
) -> list[float]:
    """Doubles nearest to fn·step·π (step 0.5: multiples of π/2, 0.25: of π/4) and
    their neighbours, for fn spread over the range up to ``limit``: the hard cases of
    the reduction (cancellation) and of the quadrant choice (π/4 boundaries)."""
    top = int(limit / (step * math.pi))
    fns = sorted({*range(-8, 9), *(rng.randint(-top, top) for _ in range(count))})
    out = []
    with mpmath.workdps(50):
        for fn in fns:
            x = float(fn * step * mpmath.pi)
            out += [x, math.nextafter(x, math.inf), math.nextafter(x, -math.inf)]
    return [x for x in out if abs(x) <= limit]


def proof_points(rng: random.Random) -> list[float]:
    """A few thousand finite arguments: scene angles, hard reductions, tiny, large."""
    scene = [math.radians(rng.uniform(-360.0, 360.0)) for _ in range(800)]
    tiny = [s * 10.0 ** rng.uniform(-320, -5) for s in (1, -1) for _ in range(100)]
    tiny += [5e-324, -5e-324, 2.2250738585072014e-308, 1e-300, -1e-300]
    large = [rng.uniform(-SINCOS_LIMIT, SINCOS_LIMIT) for _ in range(400)]
    edges = [SINCOS_LIMIT, -SINCOS_LIMIT, 0.5 * SINCOS_LIMIT]
    return (
        scene
        + tiny
        + large
        + edges
        + near_quadrant_multiples(300, rng)
        + near_quadrant_multiples(100, rng, step=0.25)
    )


def _polynomial_errors() -> tuple[float, float]:
    """Max relative error of the sin and cos polynomials (exact coefficient values,
    exact arithmetic at 50 digits) over 2001 points of (0, π/4 + 2^-20]."""
    worst_s = worst_c = 0.0
    with mpmath.workdps(50):
        top = mpmath.pi / 4 + mpmath.ldexp(1, -20)
        for i in range(1, 2002):
            x = top * i / 2001
            z = x * x
            ps = x + x * z * mpmath.polyval([mpmath.mpf(c) for c in reversed(SIN_COEFFICIENTS)], z)
            pc = 1 - z / 2 + z * z * mpmath.polyval([mpmath.mpf(c) for c in reversed(COS_COEFFICIENTS)], z)
            worst_s = max(worst_s, float(abs(ps / mpmath.sin(x) - 1)))
            worst_c = max(worst_c, float(abs(pc / mpmath.cos(x) - 1)))
    return worst_s, worst_c


def _special_values_hold(sincos) -> bool:
    def same(a, b):
        return (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1, a) == math.copysign(1, b))

    nan = float("nan")
    cases = (
        (0.0, (0.0, 1.0)),
        (-0.0, (-0.0, 1.0)),
        (math.inf, (nan, nan)),
        (-math.inf, (nan, nan)),
        (nan, (nan, nan)),
    )  # a dict would merge 0.0 and -0.0
    return all(same(got, want) for x, expected in cases for got, want in zip(sincos(x), expected))


def proofs():
    """(claim, passed) pairs: constants, polynomial accuracy, ≤ 1 ulp, special values."""
    sincos = sincos_function()
    poly_s, poly_c = _polynomial_errors()
    err_s, err_c = ulp_errors(sincos, proof_points(random.Random(20240611)))
    ulp_claim = (
        f"sincos: max error vs 50-digit mpmath, ~3000 points, |x| <= {SINCOS_LIMIT:.4g}: "
        f"sin {err_s:.3f} ulp, cos {err_c:.3f} ulp (<= 1)"
    )
    return [
        (
            "sincos: π/2 = P1 + P2 + P3 + P3T and 2/π re-derived from π equal fdlibm's bits",
            all(REDUCTION[k] == _from_bits(b) for k, b in _FDLIBM_REDUCTION.items()),
        ),
        (
            "sincos: P1, P2, P3 have <= 33 significant bits (fn·P exact for |fn| <= 2^20)",
            all(math.frexp(REDUCTION[k])[0] * 2**33 % 1 == 0 for k in ("P1", "P2", "P3")),
        ),
        (
            f"sincos: polynomial relative errors on [0, π/4] (sin {poly_s:.1e}, cos {poly_c:.1e}) < 2^-57",
            max(poly_s, poly_c) < 2.0**-57,
        ),
        (ulp_claim, max(err_s, err_c) <= 1.0),
        ("sincos: (±0) -> (±0, 1), ±inf and NaN -> NaN", _special_values_hold(sincos)),
    ]
