"""Starts for the draws' fits from their fitted neighbours: local quadratic
regression of the fitted separation state on where the draws lie (drawfit.py's
`_waves`, the Monte Carlo of ``reconstruct --uncertainty`` through the run-out).

Where the draws lie is drawfit.Neighbours.position: each input's deviation
scaled so that a unit moves the fitted state by about 1 m/s. For a draw at x
the start is the intercept of the least-squares fit

    p(x_j) ~ c0 + sum_a c_a (x_j - x)_a + sum_{a <= b} c_ab (x_j - x)_a (x_j - x)_b

over its K nearest fitted draws x_j (K = NEIGHBOURS_PER_TERM times the terms;
quadratic terms in the QUAD_DIMS inputs of largest spread, linear in the
rest; the offsets scaled by the farthest neighbour's distance, which keeps the
normal equations well scaled). A first-order step from the nearest fitted draw
(the rule before this module) misses the drawn rest pose by the fitted
state's curvature over the neighbour distance; the quadratic takes that
curvature out. Measured on the mixed-wheel example (docs/runout.md,
"`reconstruct --uncertainty` through the run-out"): a start within the draw's
tolerance for 76 % of the spinning sedan's rows and 94 % of the SUV's, against
0.7 % and 5.2 % from the nearest draw's step and 17 % and 29 % from a local
linear fit over 16 neighbours.

Written by hand (numba, over the run-out room's threads): no library we use
fits a local polynomial per query point at this rate (about 5 microseconds a
row for 28 terms and 56 neighbours, against 24-38 microseconds for the
run-out it saves: the mixed example's at 3e-7, docs/runout.md).

It imports numba (as every run-out kernel does) and scipy (on first use).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._util import require
from . import threads

QUAD_DIMS = 7  # inputs with quadratic terms (cost grows as terms^2 x neighbours)
# Neighbours per term of the local fit: 1.3 put a tenth fewer of the sedan's
# starts within tolerance; 1.5 saved in the fits what it cost in run-outs.
NEIGHBOURS_PER_TERM = 2
CHUNK = 2048  # rows per task on the threads
# Neighbours within (1 + QUERY_EPS) of the true k-th distance (cKDTree): the
# SUV's 7-input query half as long, the starts within tolerance unchanged
# (94.4 % against 94.1 %).
QUERY_EPS = 1.0


def terms(dims: int) -> int:
    """Terms of the local fit in `dims` inputs: 1 + dims + the quadratic ones."""
    q = min(dims, QUAD_DIMS)
    return 1 + dims + q * (q + 1) // 2


def predict(fitted: np.ndarray, states: np.ndarray, query: np.ndarray):
    """(starts (q, 3), nearest (q,)) for the draws at `query` (q, d) from the
    fitted draws at `fitted` (n, d) with states `states` (n, 3): the local
    quadratic's intercept and the index in `fitted` of the nearest; None when
    there are fewer fitted draws than neighbours the fit needs. Inputs that do
    not vary over `fitted` and `query` are left out."""
    varying = np.ptp(np.vstack([fitted, query]), axis=0) > 0
    order = np.argsort(-np.std(fitted[:, varying], axis=0), kind="stable")
    cols = np.flatnonzero(varying)[order]
    k = NEIGHBOURS_PER_TERM * terms(cols.size)
    if fitted.shape[0] < k:
        return None
    X = np.ascontiguousarray(fitted[:, cols])
    Q = np.ascontiguousarray(query[:, cols])
    tree = require("scipy.spatial", extra="uncertainty", what="the draws' neighbour search").cKDTree
    idx = tree(X).query(Q, k=k, eps=QUERY_EPS, workers=threads.workers())[1]
    idx = np.ascontiguousarray(idx, dtype=np.int64)
    P = np.ascontiguousarray(states, dtype=np.float64)
    out = np.empty((Q.shape[0], 3))
    quad = min(cols.size, QUAD_DIMS)

    def chunk(lo: int) -> None:
        _local_quadratic(X, P, Q, idx, quad, lo, min(lo + CHUNK, Q.shape[0]), out)

    list(threads.pool().map(chunk, range(0, Q.shape[0], CHUNK)))
    return out, idx[:, 0]


def compile_loops() -> int:
    """Compile (or load from numba's cache) the local fit with the signature
    `predict` calls it with (``impactsym compile``); returns how many (1)."""
    i = np.arange(32.0)
    where = np.column_stack([i, i * i % 7])  # 32 points in 2 inputs: 6 terms, 12 neighbours
    if predict(where, np.column_stack([i, i, i]), where[:2] + 0.5) is None:
        raise AssertionError("the local fit was not run")
    return 1


@numba.njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _local_quadratic(X, P, Q, idx, quad, lo, hi, out):  # pragma: no cover (compiled)
    """out[r] for rows lo..hi-1: the intercept of the least-squares quadratic
    in the first `quad` columns (linear in the rest) through the states P of
    the neighbours idx[r] of Q[r] in X (normal equations, Cholesky; the
    reassociation lets the dot products vectorise). A row whose normal
    equations are singular takes its nearest neighbour's state."""
    k = idx.shape[1]
    d = X.shape[1]
    m = 1 + d + quad * (quad + 1) // 2
    # the design, a term per row (dot products over contiguous neighbours): the
    # linear terms, the quadratic ones, the intercept last (_intercept)
    A = np.empty((m, k))
    Y = np.empty((3, k))
    L = np.empty((m, m))
    b = np.empty((m, 3))
    for r in range(lo, hi):
        far = 0.0
        for j in range(k):
            s = 0.0
            for c in range(d):
                t = X[idx[r, j], c] - Q[r, c]
                s += t * t
            far = max(far, s)
        scale = 1.0 / math.sqrt(far) if far > 0.0 else 1.0
        for j in range(k):
            n = idx[r, j]
            A[m - 1, j] = 1.0
            for c in range(d):
                A[c, j] = (X[n, c] - Q[r, c]) * scale
            for c in range(3):
                Y[c, j] = P[n, c]
        t = d
        for u in range(quad):
            for v in range(u, quad):
                for j in range(k):
                    A[t, j] = A[u, j] * A[v, j]
                t += 1
        for u in range(m):
            for v in range(u + 1):
                s = 0.0
                for j in range(k):
                    s += A[u, j] * A[v, j]
                L[u, v] = s
            for c in range(3):
                s = 0.0
                for j in range(k):
                    s += A[u, j] * Y[c, j]
                b[u, c] = s
        if _cholesky(L, m):
            for c in range(3):
                out[r, c] = _intercept(L, b, c, m)
        else:
            for c in range(3):
                out[r, c] = P[idx[r, 0], c]


# The triangular loops' dot products are reassociated too, so that they vectorise
# (with the intercept last, below, the solve 18 % of the local fit's time less).
@numba.njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _cholesky(L, m):  # pragma: no cover (compiled)
    """L's lower triangle overwritten by its Cholesky factor (a relative
    1e-12 added to the diagonal: a term that does not vary among the
    neighbours gets a zero coefficient); False if it is not positive definite."""
    for u in range(m):
        s = L[u, u] * (1.0 + 1e-12) + 1e-300
        for v in range(u):
            s -= L[u, v] * L[u, v]
        if not s > 0.0:
            return False
        L[u, u] = math.sqrt(s)
        for w in range(u + 1, m):
            s = L[w, u]
            for v in range(u):
                s -= L[w, v] * L[u, v]
            L[w, u] = s / L[u, u]
    return True


@numba.njit(cache=True, nogil=True, fastmath={"reassoc", "contract"})
def _intercept(L, b, c, m):  # pragma: no cover (compiled)
    """The last unknown of L L' x = b[:, c] (b[:, c] overwritten): forward
    substitution z = L^-1 b, then x[m-1] = z[m-1] / L[m-1, m-1], the last row
    of L' x = z. The design puts the intercept last so that no back
    substitution is needed."""
    for u in range(m):
        s = b[u, c]
        for v in range(u):
            s -= L[u, v] * b[v, c]
        b[u, c] = s / L[u, u]
    return b[m - 1, c] / L[m - 1, m - 1]
