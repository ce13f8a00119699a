"""The impact laws' Jacobian kernels (derive/jacobian.py): exact derivatives of the
branch a scene takes, against finite differences of the independent 50-digit
reference (impactsym/testing/laws.py) and, through the linear method of
--uncertainty, against Monte Carlo."""

from __future__ import annotations

import math

import pytest
from mpmath import mp

import impactsym
from impactsym import _kernels
from impactsym.laws._door import kernel
from impactsym.testing import laws as L
from impactsym.testing import reference

CASES = [
    ("kudlich_slibar", "full"),
    ("kudlich_slibar", "sliding"),
    ("coulomb", "newton"),
    ("coulomb", "poisson"),
    ("coulomb", "energetic"),
]
TOL = 1e-7
"""Largest accepted error of a derivative, in units of its output's natural scale
per natural unit of its input (finite differences with Richardson's step halving:
truncation O(h^4) at h = 1e-4 of the unit, below 1e-12; the reference has 50 digits)."""


def _reference(model, law, row):
    if model == "coulomb":
        return L.coulomb_reference(row, law)
    return L.kudlich_slibar_reference(row, law)


def _input_units(row) -> dict:
    """A natural unit of each input: masses and inertias themselves, speeds the
    largest speed, arms the largest arm, yaw rates speed / arm, angles, e and mu_f 1."""
    speed = max(math.hypot(row["v1x"], row["v1y"]), math.hypot(row["v2x"], row["v2y"]), 1.0)
    arm = max(math.hypot(row["r1x"], row["r1y"]), math.hypot(row["r2x"], row["r2y"]), 0.1)
    units = {}
    for name in row:
        if name[0] in "mI":
            units[name] = abs(row[name])
        elif name[0] == "v":
            units[name] = speed
        elif name[0] == "w":
            units[name] = speed / arm
        elif name[0] == "r":
            units[name] = arm
        else:
            units[name] = 1.0
    return units


def _difference(model, law, row, name, step):
    """Central difference of every reference output with respect to input `name`
    at the float steps row[name] +- step, in 50 digits (the exact float steps)."""
    up, down = dict(row), dict(row)
    up[name] += step
    down[name] -= step
    hi, lo = _reference(model, law, up), _reference(model, law, down)
    with mp.workdps(L.DPS):
        width = mp.mpf(up[name]) - mp.mpf(down[name])
        return {k: (hi[k] - lo[k]) / width for k in L.OUTPUTS}, (hi, lo)


def _class(ref, model):
    return ref["slip_class"] if model == "coulomb" else ref["sliding"]


def _rows(model, law, count):
    """Realistic rows, plus stress rows until every slip class (Coulomb) or both
    contacts (K-S sliding) appear."""
    c = L.realistic(40, 3)
    rows = [L.row_of(c, i) for i in range(count)]
    s = L.stress(200, 17)
    wanted = {"coulomb": {0, 1, 2}, "kudlich_slibar": {0, 1} if law == "sliding" else {0}}[model]
    seen = {_class(_reference(model, law, row), model) for row in rows}
    for i in range(len(s["e"])):
        if wanted <= seen:
            break
        row = L.row_of(s, i)
        kind = _class(_reference(model, law, row), model)
        if kind not in seen:
            seen.add(kind)
            rows.append(row)
    assert wanted <= seen, seen
    return rows


@pytest.mark.parametrize("model, law", CASES)
def test_every_derivative_matches_the_50_digit_reference(model, law):
    ks = kernel(model, law)
    jac = _kernels.JACOBIAN[ks.name]
    checked = skipped = 0
    worst = 0.0
    for row in _rows(model, law, 6):
        row = {k: row[k] for k in ks.inputs}
        got = _kernels.run_one(jac, row, jac.outputs + tuple(jac.constants))
        assert got["status"] == 0
        base = _reference(model, law, row)
        full = dict(row, mu=0.0, e_m=1.0)
        with mp.workdps(L.DPS):
            scales = reference.natural_scales(full, dict(base, M=mp.zero, TLm=mp.zero, mu_c=mp.zero))
        units = _input_units(row)
        for name in ks.inputs:
            h = 1e-4 * units[name]
            d1, ends1 = _difference(model, law, row, name, h)
            d2, ends2 = _difference(model, law, row, name, h / 2)
            same_branch = all(_class(r, model) == _class(base, model) for r in (*ends1, *ends2))
            for out in L.OUTPUTS:
                with mp.workdps(L.DPS):
                    rich = (4 * d2[out] - d1[out]) / 3
                    spread = abs(d2[out] - d1[out])
                size = units[name] / float(scales[out])
                # a phase switch within the steps (the difference is then not a derivative)
                if not same_branch or float(spread) * size > 1e-4:
                    skipped += 1
                    continue
                error = abs(got[f"d_{out}__d_{name}"] - float(rich)) * size
                worst = max(worst, error)
                checked += 1
                assert error <= TOL, (row, name, out, got[f"d_{out}__d_{name}"], float(rich))
    print(f"\n{ks.name}: {checked} derivatives checked, {skipped} across a switch, worst {worst:.1e}")
    assert skipped <= 0.02 * (checked + skipped)


def _narrow_scene(model: str, law: str, friction: float) -> dict:
    """An eccentric car-to-car scene with narrow input distributions (the
    linear method's regime)."""
    law_key = {"coulomb": "restitution_law", "kudlich_slibar": "contact"}[model]
    return {
        "model": model,
        "units": "SI",
        "impact": {
            "normal_angle": {"normal": [10.0, 0.5]},
            "restitution": {"uniform": [0.29, 0.31]},
            "friction": {"normal": [friction, friction / 50]},
            law_key: law,
        },
        "vehicles": [
            {
                "mass": {"normal": [1500.0, 15.0]},
                "yaw_inertia": 2500.0,
                "velocity": [20.0, 2.0],
                "yaw_rate": 0.0,
                "impact_point": [2.2, 0.6],
            },
            {
                "mass": 2200.0,
                "yaw_inertia": 4200.0,
                "velocity": [-5.0, 8.0],
                "yaw_rate": 0.1,
                "impact_point": [-0.4, -1.0],
            },
        ],
    }


@pytest.mark.parametrize(
    "model, law, friction",
    [("coulomb", "newton", 0.5), ("coulomb", "energetic", 0.5), ("kudlich_slibar", "sliding", 0.02)],
)
def test_linear_sd_and_budget_agree_with_monte_carlo(model, law, friction):
    scene = _narrow_scene(model, law, friction)
    if model == "kudlich_slibar":  # the sliding contact applies on this scene
        nominal = impactsym.solve({**scene, "impact": {**scene["impact"], "friction": friction}})
        assert nominal.mu == pytest.approx(-friction, rel=1e-12)
    u = impactsym.uncertainty(scene, draws=20_000, seed=11)
    assert u.accepted > 0.99 * u.n_draws
    for path in (
        "energy_loss.total",
        "vehicles[0].delta_v_magnitude",
        "impulse.normal",
        "impulse.tangential",
    ):
        out = u.outputs[path]
        assert out["sd_linear"] > 0, (path, out)
        assert abs(out["sd"] / out["sd_linear"] - 1) < 0.03, (path, out)
        assert abs(sum(u.budget[path].values()) - 1) < 1e-12


@pytest.mark.slow
def test_the_branch_taken_proof_catches_a_wrong_derivative():
    """derive/jacobian.py's proof of a switching kernel (on the branch each point
    takes) fails when one derivative formula of a phase is off."""
    import random
    from dataclasses import replace

    from derive import jacobian
    from derive.kernel import Block

    index = next(i for i, k in enumerate(jacobian.BASES) if k.name == "coulomb_newton")
    knl, base = jacobian.KERNELS[index], jacobian.BASES[index]
    assert base.name in jacobian.SWITCHING
    assert jacobian._agrees(knl, base, random.Random(1), points=1)
    blocks = list(knl.blocks)
    at = next(i for i, b in enumerate(blocks) if any(s.name == "d_pf__d_e" for s, _ in b.assigns))
    blocks[at] = Block(
        tuple((s, x * 1.000001 if s.name == "d_pf__d_e" else x) for s, x in blocks[at].assigns),
        blocks[at].guard,
    )
    assert not jacobian._agrees(replace(knl, blocks=tuple(blocks)), base, random.Random(1), points=1)
