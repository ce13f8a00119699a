"""Scene sets for the accuracy benchmark, and their 50-digit references.

* ``realistic_set()``: random two-car scenes (``impactsym.testing.scenes.random_realistic``,
  rigid model, given impulse ratio), the everyday workload.
* ``stress_set()``: a few hundred exactly constructed hard rows, each with a family
  label: near-elastic (``e = 1 - 2**-k``), near-grazing, extreme mass ratios and
  yaw inertias, ``mu`` at and just below ``mu_c``, ``e_m`` at and around its special
  values, extreme speed scales, central impacts.

Columns follow conventions.md (float64 arrays, SI units, ``gamma`` in radians).
References come from ``impactsym.testing.reference`` (the six equations solved as one linear
system at 50 digits on the exact float64 inputs), so a measured error is the
method's alone. A reference costs a few milliseconds a row, so nothing is cached.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from mpmath import mp

from impactsym.testing import reference as R
from impactsym.testing import scenes

INPUTS = tuple(R.RIGID_INPUTS)
REALISTIC_SEED = 20260611
REALISTIC_ROWS = 300
BASE_SEED = 7
ENERGY_FLOOR = 1e-10
"""The energy's self-relative error is reported only where |TL| >= ENERGY_FLOOR x the
initial kinetic energy (below it, TL is noise of the scene, not a quantity anyone
reads)."""


@dataclass
class SceneSet:
    """Scenes with their references: ``refs[i]``, ``scales[i]`` (natural scales of
    each output) and ``ke0[i]`` (initial kinetic energy) are mpf dicts/values for row i;
    ``family[i]`` labels the row (stress set) or is ``"realistic"``."""

    name: str
    columns: dict
    family: np.ndarray
    refs: list
    scales: list
    ke0: list

    @property
    def n(self) -> int:
        return R.n_rows(self.columns)


def with_references(name: str, columns: dict, family=None) -> SceneSet:
    """Attach references, natural scales and initial kinetic energies to ``columns``."""
    n = R.n_rows(columns)
    refs, scales, ke0 = [], [], []
    for i in range(n):
        row = R.row_of(columns, i)
        ref = R.solve_reference(row)
        refs.append(ref)
        scales.append(R.natural_scales(row, ref))
        ke0.append(R.initial_kinetic_energy(row))
    if family is None:
        family = np.full(n, name, dtype=object)
    return SceneSet(name, columns, np.asarray(family, dtype=object), refs, scales, ke0)


def realistic_set(n: int = REALISTIC_ROWS, seed: int = REALISTIC_SEED) -> dict:
    """``n`` random realistic rigid scenes (``impactsym.testing.scenes.random_realistic``)."""
    return scenes.random_realistic(n, seed=seed)


# ---------------------------------------------------------------- stress rows


def _bases(k: int) -> list[dict]:
    """``k`` realistic scenes (accepted, well-conditioned) as rows of Python floats."""
    cols = scenes.random_realistic(k, seed=BASE_SEED)
    return [R.row_of(cols, i) for i in range(k)]


def _mu_c(row: dict) -> float:
    """The critical impulse ratio of a row, from the 50-digit reference, as a float."""
    return float(R.mu_critical(row))


def _fraction_of_critical(row: dict, fraction: float) -> dict:
    """The row with ``mu = fraction * mu_c`` (mu_c of this row, from the reference)."""
    return dict(row, mu=fraction * _mu_c(row))


def rear_end(e: float, closing: float = 1.0, common: float = 30.0) -> dict:
    """A rear-end bump at highway speed: both cars head along +x at about ``common``
    m/s, car 1 (behind) ``closing`` m/s faster; normal along x, impulse ratio 0, no
    moment restitution loss (e_m = 1). Fast common motion, slow closing: the energy
    loss is a small difference of large kinetic energies."""
    return dict(
        m1=1500.0,
        m2=1200.0,
        I1=1500.0 * 1.3**2,
        I2=1200.0 * 1.25**2,
        v1x=common + closing,
        v1y=0.0,
        w1=0.0,
        v2x=common,
        v2y=0.0,
        w2=0.0,
        r1x=2.25,
        r1y=0.375,
        r2x=-2.125,
        r2y=0.25,
        gamma=0.0,
        e=e,
        mu=0.0,
        e_m=1.0,
    )


def _near_elastic(bases):
    """e = 1 - 2**-k, k = 10..40, mu = 0, e_m = 1: TL = (1 - e^2)(...) is tiny."""
    rows = []
    for k in range(10, 41):
        e = 1.0 - 2.0**-k
        rows.append(rear_end(e))
        rows.append(dict(bases[0], e=e, mu=0.0, e_m=1.0))
    return rows


def _grazing():
    """Normal along x, x-speeds equal but for 2**-30 of them, no yaw: the normal
    approach is 2**-30 of the speeds (formed exactly: the x-speeds differ in their last
    bits only). mu = 0, 0.5 (with mu_c's sign) and mu_c/2.

    Not mu = mu_c: at grazing, mu_c -> -Knn/Knt, so the sliding denominator
    D = Knn + mu Knt is ~1e-8 of Knn there and the outputs change by ~1e-8 relative
    when mu changes by one ulp. Every float64 method then errs by ~1e-8 (measured:
    the default kernel 2.5e-8, the linear solve 3.5e-8): that measures the scene's
    condition, not a method."""
    rows = []
    shapes = [  # (s, v1y, v2y, r1, r2)
        (20.0, 5.0, -10.0, (2.125, 0.625), (-1.875, -0.375)),
        (32.0, -12.0, 3.0, (1.5, -0.75), (-2.25, 0.5)),
        (8.0, 25.0, 24.0, (0.5, 0.875), (-0.25, -0.875)),
    ]
    for s, a, b, (r1x, r1y), (r2x, r2y) in shapes:
        for e, e_m in ((0.0, 1.0), (0.3, 0.0)):
            row = dict(
                m1=1400.0,
                m2=1700.0,
                I1=1400.0 * 1.2**2,
                I2=1700.0 * 1.4**2,
                v1x=s,
                v1y=a,
                w1=0.0,
                v2x=s - s * 2.0**-30,
                v2y=b,
                w2=0.0,
                r1x=r1x,
                r1y=r1y,
                r2x=r2x,
                r2y=r2y,
                gamma=0.0,
                e=e,
                mu=0.0,
                e_m=e_m,
            )
            mu_c = _mu_c(row)
            rows += [row, dict(row, mu=float(np.copysign(0.5, mu_c))), dict(row, mu=mu_c / 2)]
    return rows


def _mass_ratios(bases):
    """m2/m1 = 10**p, p = -9..9 (vehicle 2's yaw inertia scaled alike), e_m = 1 or 0,
    mu = mu_c / 2."""
    rows = []
    for base, e_m in ((bases[1], 1.0), (bases[2], 0.0)):
        for p in range(-9, 10):
            scale = base["m1"] * 10.0**p / base["m2"]
            row = dict(base, m2=base["m1"] * 10.0**p, I2=base["I2"] * scale, e_m=e_m)
            rows.append(_fraction_of_critical(row, 0.5))
    return rows


def _yaw_inertias(bases):
    """I1, I2 or both times 10**p, p = -8..8, e_m = 1 or 0, mu = mu_c / 2."""
    rows = []
    for base, e_m in ((bases[3], 1.0), (bases[4], 0.0)):
        for which in ("I1", "I2", "both"):
            for p in range(-8, 9):
                row = dict(base, e_m=e_m)
                for key in ("I1", "I2") if which == "both" else (which,):
                    row[key] = base[key] * 10.0**p
                rows.append(_fraction_of_critical(row, 0.5))
    return rows


def _mu_at_critical(bases):
    """mu = mu_c (rounded to float64) and mu = mu_c (1 - 1e-9): sliding just ends at
    separation (the sliding formulas meet the sticking ones)."""
    rows = []
    for base in bases:
        mu_c = _mu_c(base)
        rows += [dict(base, mu=mu_c), dict(base, mu=mu_c * (1.0 - 1e-9))]
    return rows


def _moment_restitution(bases):
    """e_m in {0, 1e-9, -1e-9, 1}, mu = mu_c / 2 of that e_m."""
    return [
        _fraction_of_critical(dict(base, e_m=e_m), 0.5) for base in bases for e_m in (0.0, 1e-9, -1e-9, 1.0)
    ]


def _speed_scales(bases):
    """Every velocity and yaw rate times 1e-6 or 1e6 (mu_c does not change)."""
    keys = ("v1x", "v1y", "w1", "v2x", "v2y", "w2")
    return [dict(base, **{k: base[k] * f for k in keys}) for base in bases for f in (1e-6, 1e6)]


def _central(bases):
    """Impact centre on the line of the normal through both centres of gravity
    (r_i = +-a_i n; exact for gamma = 0), mu = 0 or mu_c / 2."""
    rows = []
    for i, base in enumerate(bases):
        for gamma in (0.0, 0.7):
            nx, ny = np.cos(gamma), np.sin(gamma)
            a1, a2 = 2.0 + 0.125 * i, 1.75 + 0.0625 * i
            row = dict(base, gamma=gamma, r1x=a1 * nx, r1y=a1 * ny, r2x=-a2 * nx, r2y=-a2 * ny)
            if _closing(row) >= 0:  # time-reverse: every velocity flips, so gn does
                for k in ("v1x", "v1y", "w1", "v2x", "v2y", "w2"):
                    row[k] = -row[k]
            rows += [dict(row, mu=0.0), _fraction_of_critical(row, 0.5)]
    return rows


def _closing(row: dict) -> float:
    """n . (u2 - u1) at the impact centre, float64."""
    nx, ny = np.cos(row["gamma"]), np.sin(row["gamma"])
    u1 = R.contact_velocity(row["v1x"], row["v1y"], row["w1"], row["r1x"], row["r1y"])
    u2 = R.contact_velocity(row["v2x"], row["v2y"], row["w2"], row["r2x"], row["r2y"])
    return nx * (u2[0] - u1[0]) + ny * (u2[1] - u1[1])


FAMILIES = (
    (
        "near-elastic",
        "e = 1 - 2^-k, k = 10..40, mu = 0, e_m = 1 (a rear-end bump at 30 m/s "
        "closing at 1 m/s, and a realistic scene)",
    ),
    (
        "grazing",
        "normal along x, x-speeds equal but for 2^-30, no yaw; mu = 0, 0.5, mu_c/2 "
        "(not mu_c: there the scene's condition number is ~1e8 and every float64 method "
        "errs by ~1e-8)",
    ),
    ("mass ratio", "m2/m1 = 1e-9..1e9 (I2 scaled alike), e_m = 1 or 0, mu = mu_c/2"),
    ("yaw inertia", "I1, I2 or both x 1e-8..1e8, e_m = 1 or 0, mu = mu_c/2"),
    ("mu at mu_c", "mu = mu_c and mu_c (1 - 1e-9) (mu_c from the reference)"),
    ("e_m", "e_m in {0, 1e-9, -1e-9, 1}, mu = mu_c/2"),
    ("speed scale", "every velocity and yaw rate x 1e-6 or x 1e6"),
    ("central", "r1, r2 on the normal through both centres (gamma = 0 and 0.7), mu = 0 or mu_c/2"),
)


def stress_set() -> tuple[dict, np.ndarray]:
    """The hard rows as ``(columns, family)``: float64 columns of conventions.md and
    one family label (see ``FAMILIES``) per row. Deterministic."""
    bases = _bases(8)
    groups = {
        "near-elastic": _near_elastic(bases),
        "grazing": _grazing(),
        "mass ratio": _mass_ratios(bases),
        "yaw inertia": _yaw_inertias(bases),
        "mu at mu_c": _mu_at_critical(bases),
        "e_m": _moment_restitution(bases),
        "speed scale": _speed_scales(bases),
        "central": _central(bases),
    }
    assert tuple(groups) == tuple(name for name, _ in FAMILIES)
    rows = [row for group in groups.values() for row in group]
    family = np.array([name for name, group in groups.items() for _ in group], dtype=object)
    columns = {key: np.array([float(row[key]) for row in rows]) for key in INPUTS}
    return columns, family


def load_sets(realistic_rows: int = REALISTIC_ROWS) -> dict[str, SceneSet]:
    """Both sets with references: ``{"realistic": ..., "stress": ...}``. Every stress
    row is checked to approach (reference gn < 0) and to have a finite reference."""
    stress_cols, family = stress_set()
    sets = {
        "realistic": with_references("realistic", realistic_set(realistic_rows)),
        "stress": with_references("stress", stress_cols, family),
    }
    for s in sets.values():
        for i, ref in enumerate(s.refs):
            assert ref["gn"] < 0, f"{s.name} row {i} ({s.family[i]}) does not approach"
            assert all(mp.isfinite(ref[k]) for k in R.OUTPUTS), f"{s.name} row {i}"
    return sets
