"""Issue 22 item 3: a flag is raised only past its bound by more than the
rounding error, with an absolute floor for bounds near zero (μ, μ_c both 0)."""

import numpy as np

from impactsym import reconstruct_batch, solve_batch
from impactsym.codes import FLAG_MU_BEYOND_CRITICAL


def _head_on_rows(n=400, seed=1):
    """Forward solves with μ = 0 where the impact points and the approach lie
    on the normal (so μ_c = 0 too), and the reconstruction of each from its
    final motion: μ and μ_c are zero up to rounding."""
    rng = np.random.default_rng(seed)
    g = rng.uniform(-np.pi, np.pi, n)
    nx, ny = np.cos(g), np.sin(g)
    a1, a2, s = rng.uniform(0.5, 2.5, n), rng.uniform(0.5, 2.5, n), rng.uniform(5, 30, n)
    zeros = np.zeros(n)
    masses = {key: rng.uniform(900, 4000, n) for key in ("m1", "m2", "I1", "I2")}
    points = dict(r1x=a1 * nx, r1y=a1 * ny, r2x=-a2 * nx, r2y=-a2 * ny, gamma=g)
    forward = solve_batch(
        dict(
            masses,
            v1x=s * nx,
            v1y=s * ny,
            w1=zeros,
            v2x=zeros,
            v2y=zeros,
            w2=zeros,
            **points,
            e=np.full(n, 0.2),
            mu=zeros,
            e_m=np.ones(n),
        ),
        model="rigid",
    )
    finals = {key: forward[key] for key in ("V1x", "V1y", "W1", "V2x", "V2y", "W2")}
    return reconstruct_batch(
        dict(masses, **finals, theta1=g, theta2=g + np.pi / 2, w1=zeros, w2=zeros, **points)
    )


def test_mu_and_mu_c_both_rounding_zero_are_not_flagged():
    out = _head_on_rows()
    assert (out["status"] == 0).all()
    assert np.abs(out["mu"]).max() < 1e-14 and np.abs(out["mu_c"]).max() < 1e-14
    assert not (out["flags"] & FLAG_MU_BEYOND_CRITICAL).any()


def test_mu_truly_beyond_critical_is_still_flagged():
    # a given μ of -1e-9 with μ_c > 0 is past the bound by far more than rounding
    one = dict(
        m1=[1200.0],
        m2=[1500.0],
        I1=[2000.0],
        I2=[2500.0],
        v1x=[10.0],
        v1y=[3.0],
        w1=[0.0],
        v2x=[0.0],
        v2y=[0.0],
        w2=[0.0],
        r1x=[1.0],
        r1y=[0.4],
        r2x=[-1.0],
        r2y=[0.2],
        gamma=[0.0],
        e=[0.2],
        mu=[-1e-9],
        e_m=[1.0],
    )
    assert solve_batch(one, model="rigid")["flags"][0] & FLAG_MU_BEYOND_CRITICAL
