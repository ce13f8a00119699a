"""Delta-V from energy loss (seed eqs 27–29): the bridge from a crush-energy
estimate to the impulse-momentum model."""

from __future__ import annotations

import math

import numpy as np

from . import _kernels
from .codes import describe_status


def delta_v_from_energy(
    TL,
    m1,
    m2,
    *,
    e=0.0,
    mu=0.0,
    r=0.0,
    gamma=0.0,
    I1=math.inf,
    I2=math.inf,
    r1x=0.0,
    r1y=0.0,
    r2x=0.0,
    r2y=0.0,
):
    """Scalar delta-V of each vehicle from the energy loss `TL` (seed eqs 27–29).

    Planar impact without moment impulse (e_m = 1) with restitution `e`, impulse
    ratio `mu`, and `r` = gt/gn, the ratio of tangential to normal approach
    velocity at the impact centre (seed eq 17). Impact centre `r1 = (r1x, r1y)`,
    `r2` from each centre of gravity, normal angle `gamma` in radians; lever arms
    of zero (the default) give the particle relation. Consistent units (SI: J,
    kg, kg·m², m → m/s; US: ft·lb, slug, slug·ft², ft → ft/s).

    Scalars give a dict ``{"dV1", "dV2", "q"}`` and raise ValueError when no real
    delta-V exists; arrays (broadcast together) give arrays plus a ``status``
    column (see `impactsym.codes`).
    """
    args = dict(
        m1=m1, m2=m2, I1=I1, I2=I2, r1x=r1x, r1y=r1y, r2x=r2x, r2y=r2y, gamma=gamma, e=e, mu=mu, r=r, TL=TL
    )
    ks = _kernels.DELTA_V
    if all(np.ndim(v) == 0 for v in args.values()):
        *outs, status, _ = ks.scene(*[float(args[k]) for k in ks.inputs])
        if status:
            raise ValueError(f"delta_v_from_energy: {describe_status(status)}")
        return dict(zip(ks.outputs, outs))
    arrays = np.broadcast_arrays(*[np.asarray(args[k], dtype=np.float64) for k in ks.inputs])
    outs, status, _ = _kernels.run_batch(ks, [np.ascontiguousarray(a.ravel()) for a in arrays])
    return {**outs, "status": status}
