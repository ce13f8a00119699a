"""derive/trig.py's SINCOS_SOURCE: accuracy against 50-digit mpmath, special values,
plain Python and numba bit-identical, and SIMD code in a numba prange loop.

Tolerances fixed before measuring: ≤ 1 ulp for sin and cos over every finite |x| ≤
SINCOS_LIMIT (the contract of derive/trig.py), exact where the correctly rounded value
is exact (sin 0, cos 0, sin x = x and cos x = 1 for |x| < 2^-27), |sin² + cos² - 1| ≤
4·2^-52 (two 1-ulp errors, each scaled by 2|s| or 2|c|, plus two roundings).

Run ``pytest tests/test_sincos.py -s`` to see the max ulp errors measured; the
exhaustive part (every multiple of π/2 up to the limit) is ``-m slow``.
"""

from __future__ import annotations

import math
import random
import re

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from derive import trig

LIMIT = trig.SINCOS_LIMIT
sincos_py = trig.sincos_function()
sincos_jit = numba.njit(sincos_py)
_inlined = numba.njit(inline="always")(sincos_py)


@numba.njit(parallel=True)
def sincos_prange(x, s, c):
    for i in numba.prange(x.size):
        s[i], c[i] = _inlined(x[i])


@numba.njit(parallel=True)
def libm_prange(x, s, c):
    for i in numba.prange(x.size):
        s[i] = math.sin(x[i])
        c[i] = math.cos(x[i])


def batch(xs):
    x = np.ascontiguousarray(xs, dtype=np.float64)
    s, c = np.empty_like(x), np.empty_like(x)
    sincos_prange(x, s, c)
    return s, c


def _bits(a):
    return np.asarray(a, dtype=np.float64).view(np.uint64)


def _check(name, xs):
    """Max ulp errors of the plain-Python function over xs (≤ 1 asserted), after
    asserting the numba prange batch and the scalar njit give the same bits."""
    xs = [float(x) for x in xs]
    s, c = batch(xs)
    py = np.array([sincos_py(x) for x in xs])
    assert np.array_equal(_bits(py[:, 0]), _bits(s)) and np.array_equal(_bits(py[:, 1]), _bits(c)), (
        f"{name}: numba batch differs from plain Python"
    )
    err_s, err_c = trig.ulp_errors(sincos_py, xs)
    print(f"\n{name}: {len(xs)} points, max error sin {err_s:.3f} ulp, cos {err_c:.3f} ulp")
    assert err_s <= 1.0 and err_c <= 1.0, f"{name}: sin {err_s} ulp, cos {err_c} ulp"
    return err_s, err_c


# ------------------------------------------------------------------ accuracy


def test_scene_angles():
    """Angles a scene gives: degrees in [-360, 360] (every integer and half degree,
    and random ones), converted to radians as the runtime does."""
    rng = random.Random(1)
    degrees = [d / 2 for d in range(-720, 721)] + [rng.uniform(-360, 360) for _ in range(4000)]
    _check("scene angles [-2pi, 2pi]", [math.radians(d) for d in degrees])


def test_near_multiples_of_half_and_quarter_pi():
    """Nearest doubles (and their neighbours) to k·π/2 (cancellation in the reduction)
    and k·π/4 (quadrant boundaries): |k| <= 256 all, larger k at random."""
    import mpmath

    rng = random.Random(2)
    xs = trig.near_quadrant_multiples(1500, rng) + trig.near_quadrant_multiples(1500, rng, step=0.25)
    with mpmath.workdps(50):
        for k in range(-256, 257):
            x = float(k * mpmath.pi / 4)
            xs += [x, math.nextafter(x, math.inf), math.nextafter(x, -math.inf)]
    _check("near k*pi/2 and k*pi/4", xs)


def test_tiny_arguments():
    rng = random.Random(3)
    xs = [sgn * 10.0 ** rng.uniform(-323, -1) for sgn in (1, -1) for _ in range(1000)]
    xs += [
        5e-324,
        -5e-324,
        2.2250738585072014e-308,
        -2.2250738585072014e-308,
        1e-300,
        -1e-300,
        2.0**-27,
        -(2.0**-27),
        2.0**-26,
        1e-8,
    ]
    _check("tiny |x| (subnormal .. 0.1)", xs)


def test_large_arguments_up_to_the_limit():
    rng = random.Random(4)
    xs = [sgn * 10.0 ** rng.uniform(0, math.log10(LIMIT)) for sgn in (1, -1) for _ in range(1500)]
    xs += [rng.uniform(-LIMIT, LIMIT) for _ in range(1500)]
    xs += [LIMIT, -LIMIT, math.nextafter(LIMIT, 0.0)]
    _check("large |x| up to SINCOS_LIMIT", xs)


@settings(deadline=None, max_examples=300)
@given(st.floats(min_value=-LIMIT, max_value=LIMIT, allow_nan=False))
def test_any_finite_argument_within_one_ulp(x):
    err_s, err_c = trig.ulp_errors(sincos_py, [x])
    assert err_s <= 1.0 and err_c <= 1.0
    assert _bits(sincos_jit(x)).tolist() == _bits(sincos_py(x)).tolist()


def test_limit_is_where_the_quadrant_count_reaches_2_pow_20():
    assert abs(LIMIT * 2 / math.pi) <= 2**20
    assert 0.999 * 2**20 * math.pi / 2 < LIMIT


# ------------------------------------------------------------------ special values


def _same(got, want):
    return all(
        (math.isnan(g) and math.isnan(w)) or (g == w and math.copysign(1, g) == math.copysign(1, w))
        for g, w in zip(got, want)
    )


@pytest.mark.parametrize("fn", [sincos_py, sincos_jit], ids=["python", "numba"])
@pytest.mark.parametrize(
    ("x", "want"),
    [
        (0.0, (0.0, 1.0)),
        (-0.0, (-0.0, 1.0)),
        (math.inf, (math.nan, math.nan)),
        (-math.inf, (math.nan, math.nan)),
        (math.nan, (math.nan, math.nan)),
        (5e-324, (5e-324, 1.0)),
        (-5e-324, (-5e-324, 1.0)),
        (1e-300, (1e-300, 1.0)),
        (-1e-300, (-1e-300, 1.0)),
        (1e-9, (1e-9, 1.0)),
        (-(2.0**-28), (-(2.0**-28), 1.0)),
    ],
    ids=repr,
)
def test_special_and_exact_values(fn, x, want):
    assert _same(fn(x), want), fn(x)


def test_special_values_inside_a_simd_batch():
    """NaN, ±inf and ±0 among finite values in the vectorised loop (and its remainder)."""
    specials = [0.0, -0.0, math.inf, -math.inf, math.nan, 1.0, -1.0, 3.0]
    xs = np.array(specials * 5 + [0.5])
    s, c = batch(xs)
    for x, got_s, got_c in zip(xs, s, c):
        assert _same((got_s, got_c), sincos_py(float(x)))
    assert np.isnan(s[np.isinf(xs) | np.isnan(xs)]).all() and np.isnan(c[~np.isfinite(xs)]).all()


@settings(deadline=None, max_examples=300)
@given(st.floats(min_value=-LIMIT, max_value=LIMIT, allow_nan=False))
def test_pythagoras_and_symmetry(x):
    s, c = sincos_py(x)
    assert abs(s * s + c * c - 1.0) <= 4 * 2.0**-52
    ms, mc = sincos_py(-x)
    assert _same((ms, mc), (-s, c)), "sin must be odd and cos even, bit for bit"


# ------------------------------------------------------------------ numba


def test_python_and_numba_are_bitwise_identical():
    rng = np.random.default_rng(5)
    xs = np.concatenate(
        [
            rng.uniform(-7, 7, 3001),
            rng.uniform(-LIMIT, LIMIT, 3001),
            np.ldexp(rng.uniform(-1, 1, 1001), rng.integers(-1074, 0, 1001)),
        ]
    )
    s, c = batch(xs)
    py = np.array([sincos_py(float(x)) for x in xs])
    scalar = np.array([sincos_jit(float(x)) for x in xs[:500]])
    assert np.array_equal(_bits(s), _bits(py[:, 0])) and np.array_equal(_bits(c), _bits(py[:, 1]))
    assert np.array_equal(_bits(scalar), _bits(py[:500]))


_PACKED = re.compile(r"\bv(?:add|sub|mul|div|f[n]?m(?:add|sub)\w*)pd\b")
_LIBM_CALL = re.compile(r"\$(?:__)?(?:sin|cos|sincos)\b|call\w*\s+(?:__)?(?:sin|cos|sincos)(?:@PLT)?\b")


def _asm(dispatcher):
    x = np.linspace(-3, 3, 64)
    dispatcher(x, np.empty_like(x), np.empty_like(x))
    return "\n".join(dispatcher.inspect_asm().values())


def test_prange_loop_is_simd_and_calls_no_libm():
    """The loop over _sincos compiles to packed double arithmetic with no sin/cos call;
    the same loop with math.sin/math.cos does call libm (so the check can fail)."""
    asm = _asm(sincos_prange)
    packed = len(_PACKED.findall(asm))
    print(
        f"\nprange _sincos loop: {packed} packed float64 arithmetic instructions, "
        f"{len(re.findall(r'vblendvpd', asm))} vblendvpd (quadrant selects)"
    )
    assert packed >= 40, packed
    assert not _LIBM_CALL.search(asm)
    assert _LIBM_CALL.search(_asm(libm_prange))


def test_proofs_pass():
    failed = [claim for claim, ok in trig.proofs() if not ok]
    assert not failed


def test_source_is_deterministic_and_exactly_the_derived_constants():
    assert trig.sincos_source() == trig.SINCOS_SOURCE
    for value in (*trig.REDUCTION.values(), *trig.SIN_COEFFICIENTS, *trig.COS_COEFFICIENTS):
        assert repr(value) in trig.SINCOS_SOURCE and float(repr(value)) == value


# ------------------------------------------------------------------ exhaustive (slow)


@pytest.mark.slow
def test_every_multiple_of_half_pi_up_to_the_limit():
    """The nearest double to k·π/2 for every k in [0, 2^20] (the worst cancellations of
    the reduction in the domain; negative k follow by the symmetry test), and 2e5
    uniform arguments. About 5 min on the busy shared 2-core machine."""
    import mpmath

    with mpmath.workdps(40):
        half_pi = mpmath.pi / 2
        xs = [float(k * half_pi) for k in range(2**20 + 1)]
    xs = [x for x in xs if x <= LIMIT]
    _check("every nearest k*pi/2, k <= 2^20", xs)
    rng = np.random.default_rng(6)
    _check("uniform |x| <= LIMIT", rng.uniform(-LIMIT, LIMIT, 200_000))
