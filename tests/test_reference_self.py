"""Tests of the 50-digit reference solver against things independent of it.

The checks recompute physics from the reference's *outputs* with separately
written code (momentum about an arbitrary origin, contact velocities, kinetic
energies) or compare with the seed paper (Table 2, eqs 17 and 18). Tolerances are
far above the 50-digit rounding level (~1e-45 relative) and far below anything a
wrong equation, sign or frame would produce.
"""

import math

import numpy as np
import pytest
from mpmath import mp

from impactsym.testing import reference as R
from impactsym.testing import scenes

TIGHT = mp.mpf("1e-40")


@pytest.fixture(scope="module")
def rigid():
    """(rows, given-mu references, critical references) for random rigid scenes."""
    return _solved(scenes.random_realistic(40, 101), "rigid")


@pytest.fixture(scope="module")
def particle():
    """(rows, given-mu references, critical references) for random particle scenes."""
    return _solved(scenes.random_realistic(40, 102, model="particle"), "particle")


@pytest.fixture(scope="module")
def barrier():
    """(rows, given-mu references, critical references) for rigid scenes into a fixed barrier."""
    return _solved(scenes.random_realistic(20, 103, barrier=True), "rigid")


def _solved(columns, model):
    rows = [R.row_of(columns, i) for i in range(R.n_rows(columns))]
    refs = [R.solve_reference(row, model) for row in rows]
    crits = [R.solve_reference(row, model, critical=True) for row in rows]
    return rows, refs, crits


# ---------------------------------------------------------------- helpers (own algebra)


def _mp(row, key, default=0.0):
    return mp.mpf(row.get(key, default))


def _velocity_state(row, ref=None):
    """[(m, I, vx, vy, w, rx, ry)] per vehicle, initial (ref None) or final, as mpf."""
    out = []
    for i in (1, 2):
        if ref is None:
            v = (_mp(row, f"v{i}x"), _mp(row, f"v{i}y"), _mp(row, f"w{i}"))
        else:
            v = (ref[f"V{i}x"], ref[f"V{i}y"], ref[f"W{i}"])
        out.append(
            (_mp(row, f"m{i}"), _mp(row, f"I{i}", math.inf), *v, _mp(row, f"r{i}x"), _mp(row, f"r{i}y"))
        )
    return out


def _momenta(row, ref, origin):
    """Linear momentum (px, py) and angular momentum about ``origin``.

    The impact centre is put at ``origin + (1.7, -0.6)`` so that the centres of
    gravity are at c_i = impact centre - r_i; L = sum m_i c_i x v_i + I_i w_i.
    """
    px = py = L = mp.zero
    scale = mp.zero
    ox, oy = origin
    for m, I, vx, vy, w, rx, ry in _velocity_state(row, ref):
        cx, cy = ox + mp.mpf("1.7") - rx, oy - mp.mpf("0.6") - ry
        px += m * vx
        py += m * vy
        L += m * (cx * vy - cy * vx)
        scale += m * (abs(vx) + abs(vy)) * (1 + abs(cx) + abs(cy))
        if mp.isfinite(I):  # particles have no yaw inertia
            L += I * w
            scale += I * abs(w)
    return px, py, L, scale


def _relative_contact(row, ref, gamma):
    """(n, t) components of u2 - u1 (ref None) or U2 - U1, computed from scratch."""
    comps = []
    for _m, _I, vx, vy, w, rx, ry in _velocity_state(row, ref):
        comps.append((vx - w * ry, vy + w * rx))
    dx, dy = comps[1][0] - comps[0][0], comps[1][1] - comps[0][1]
    c, s = mp.cos(gamma), mp.sin(gamma)
    return c * dx + s * dy, -s * dx + c * dy


def _kinetic(row, ref):
    """Total kinetic energy of the non-fixed bodies, initial (ref None) or final."""
    T = mp.zero
    for m, I, vx, vy, w, _rx, _ry in _velocity_state(row, ref):
        if mp.isfinite(m):
            T += m * (vx**2 + vy**2) / 2
        if mp.isfinite(I):
            T += I * w**2 / 2
    return T


def _speed(row):
    return max(mp.hypot(_mp(row, "v1x"), _mp(row, "v1y")), mp.hypot(_mp(row, "v2x"), _mp(row, "v2y")))


# ---------------------------------------------------------------- seed Table 2


def test_table2_energy_loss():
    """Seed Table 2: T_L of the example particle impact, exact to 1e-9 relative."""
    columns, expected = scenes.table2_scenes()
    for i, tl in enumerate(expected):
        row = R.row_of(columns, i)
        ref = R.solve_reference(row, "particle")
        got = ref["TL"]
        if tl == 0:
            assert abs(got) < mp.mpf("1e-30"), f"row {i} ({row}): TL = {got}, expected 0"
        else:
            rel = abs(got - tl) / abs(tl)
            assert rel < 1e-9, f"row {i} (e={row['e']}, mu={row['mu']}): TL = {got}, expected {tl}"


def test_table2_mu_max():
    """Seed eq 18: mu_max = r/(1+e) = 1/(1+e) for the Table 2 scenes (r = 1 exactly)."""
    columns, _ = scenes.table2_scenes()
    for i, mu_max in enumerate(scenes.TABLE2_MU_MAX):
        ref = R.solve_reference(R.row_of(columns, i), "particle")
        with mp.workdps(R.DPS):
            assert abs(ref["mu_c"] - mu_max) < TIGHT, f"row {i}: mu_c = {ref['mu_c']}"


def test_particle_closed_forms(particle):
    """Seed eqs 17 and 18 for random particle scenes.

    mu_c = r/(1+e) with r = (v2t - v1t)/(v2n - v1n); T_L = mbar (1+e) gn^2/2 *
    [(1-e) + 2 mu r - mu^2 (1+e)] with mbar = m1 m2/(m1 + m2).
    """
    rows, refs, crits = particle
    with mp.workdps(R.DPS):
        for i, (row, ref, crit) in enumerate(zip(rows, refs, crits)):
            gn, gt = _relative_contact(row, None, _mp(row, "gamma"))
            r = gt / gn
            e, mu = _mp(row, "e"), _mp(row, "mu")
            mbar = _mp(row, "m1") * _mp(row, "m2") / (_mp(row, "m1") + _mp(row, "m2"))
            tl = mbar * (1 + e) * gn**2 / 2 * ((1 - e) + 2 * mu * r - mu**2 * (1 + e))
            assert abs(ref["mu_c"] - r / (1 + e)) <= TIGHT * (1 + abs(r)), f"row {i}: mu_c"
            assert abs(crit["mu"] - r / (1 + e)) <= TIGHT * (1 + abs(r)), f"row {i}: critical mu"
            scale = _kinetic(row, None)
            assert abs(ref["TL"] - tl) <= TIGHT * scale, f"row {i}: TL {ref['TL']} vs eq 17 {tl}"


# ---------------------------------------------------------------- conservation laws


@pytest.mark.parametrize("mode", ["given", "critical"])
def test_momentum_conservation(rigid, particle, mode):
    """Linear momentum and angular momentum about two different origins are conserved."""
    for name, (rows, refs, crits) in (("rigid", rigid), ("particle", particle)):
        sols = refs if mode == "given" else crits
        with mp.workdps(R.DPS):
            for i, (row, ref) in enumerate(zip(rows, sols)):
                for origin in ((mp.zero, mp.zero), (mp.mpf(-40), mp.mpf("13.25"))):
                    px0, py0, L0, s0 = _momenta(row, None, origin)
                    px1, py1, L1, s1 = _momenta(row, ref, origin)
                    scale = s0 + s1
                    for what, a, b in (("px", px0, px1), ("py", py0, py1), ("L", L0, L1)):
                        assert abs(a - b) <= TIGHT * scale, (
                            f"{name} row {i} {mode}: {what} not conserved, "
                            f"{mp.nstr(a, 20)} -> {mp.nstr(b, 20)}"
                        )


def test_impulse_matches_velocity_changes(rigid, barrier):
    """m1 (V1 - v1) = Pn n + Pt t and I1 (W1 - w1) = r1 x P + M (vehicle 1)."""
    for rows, refs, _ in (rigid, barrier):
        with mp.workdps(R.DPS):
            for i, (row, ref) in enumerate(zip(rows, refs)):
                g = _mp(row, "gamma")
                Px = ref["Pn"] * mp.cos(g) - ref["Pt"] * mp.sin(g)
                Py = ref["Pn"] * mp.sin(g) + ref["Pt"] * mp.cos(g)
                m1, I1 = _mp(row, "m1"), _mp(row, "I1")
                scale = mp.hypot(Px, Py)
                assert abs(m1 * (ref["V1x"] - _mp(row, "v1x")) - Px) <= TIGHT * scale, f"row {i}"
                assert abs(m1 * (ref["V1y"] - _mp(row, "v1y")) - Py) <= TIGHT * scale, f"row {i}"
                moment = _mp(row, "r1x") * Py - _mp(row, "r1y") * Px + ref["M"]
                lever = mp.hypot(_mp(row, "r1x"), _mp(row, "r1y"))
                assert abs(I1 * (ref["W1"] - _mp(row, "w1")) - moment) <= TIGHT * (
                    scale * lever + abs(ref["M"])
                ), f"row {i}: angular impulse"


# ---------------------------------------------------------------- constitutive equations


def test_restitution_ratio_and_moment(rigid):
    """n.(U2-U1) = -e n.(u2-u1); Pt = mu Pn; (W2-W1)(1-e_m) = e_m M (1/I1 + 1/I2)."""
    rows, refs, _ = rigid
    with mp.workdps(R.DPS):
        for i, (row, ref) in enumerate(zip(rows, refs)):
            g = _mp(row, "gamma")
            gn, _ = _relative_contact(row, None, g)
            Gn, _ = _relative_contact(row, ref, g)
            speed = _speed(row)
            assert abs(Gn + _mp(row, "e") * gn) <= TIGHT * speed, f"row {i}: restitution"
            P = mp.hypot(ref["Pn"], ref["Pt"])
            assert abs(ref["Pt"] - _mp(row, "mu") * ref["Pn"]) <= TIGHT * P, f"row {i}: ratio"
            em = _mp(row, "e_m")
            lhs = (ref["W2"] - ref["W1"]) * (1 - em)
            rhs = em * ref["M"] * (1 / _mp(row, "I1") + 1 / _mp(row, "I2"))
            yaw = abs(ref["W2"]) + abs(ref["W1"]) + abs(ref["M"]) / _mp(row, "I1")
            assert abs(lhs - rhs) <= TIGHT * yaw, f"row {i}: moment restitution"


def test_mu_c_makes_tangential_velocity_zero(rigid, particle, barrier):
    """Solving with mu = mu_c (impulse-ratio form) stops sliding: Gt = 0 at separation."""
    for name, (rows, _, crits) in (("rigid", rigid), ("particle", particle), ("barrier", barrier)):
        model = "particle" if name == "particle" else "rigid"
        for i, (row, crit) in enumerate(zip(rows, crits)):
            at_mu_c = R.solve_reference(dict(row, mu=crit["mu_c"]), model, critical=False)
            with mp.workdps(R.DPS):
                gn, gt = _relative_contact(row, None, _mp(row, "gamma"))
                Gn, Gt = _relative_contact(row, at_mu_c, _mp(row, "gamma"))
                assert abs(Gt) <= TIGHT * _speed(row), f"{name} row {i}: Gt = {Gt}"
                assert abs(Gn + _mp(row, "e") * gn) <= TIGHT * _speed(row)
                for key in ("V1x", "V1y", "W1", "V2x", "V2y", "W2"):
                    assert abs(at_mu_c[key] - crit[key]) <= TIGHT * (_speed(row) + 1), (
                        f"{name} row {i}: {key} of mu = mu_c differs from the critical solve"
                    )


# ---------------------------------------------------------------- energy


def test_energy_partition_sums_to_ke_difference(rigid, particle, barrier):
    """TLn + TLt + TLm = TL (a 50-digit kinetic-energy difference) to 40 digits of KE0."""
    for name, (rows, refs, crits) in (("rigid", rigid), ("particle", particle), ("barrier", barrier)):
        with mp.workdps(R.DPS):
            for i, row in enumerate(rows):
                for ref in (refs[i], crits[i]):
                    ke0 = _kinetic(row, None)
                    assert abs(ke0 - _kinetic(row, ref) - ref["TL"]) <= TIGHT * ke0, (
                        f"{name} row {i}: TL is not the kinetic-energy difference"
                    )
                    parts = ref["TLn"] + ref["TLt"] + ref["TLm"]
                    assert abs(parts - ref["TL"]) <= TIGHT * ke0, (
                        f"{name} row {i}: TLn+TLt+TLm = {parts} but TL = {ref['TL']}"
                    )


# ---------------------------------------------------------------- fixed body


def test_fixed_body_stays_put(barrier):
    """A fixed barrier (m2 = I2 = inf) keeps its velocity, also when it moves."""
    rows, refs, crits = barrier
    with mp.workdps(R.DPS):
        for i, row in enumerate(rows):
            moving = dict(row, v2x=1.25, v2y=-0.5, w2=0.125)
            cases = (
                (row, refs[i]),
                (row, crits[i]),
                (moving, R.solve_reference(moving)),
                (moving, R.solve_reference(moving, critical=True)),
            )
            for src, ref in cases:
                for key, init in (("V2x", "v2x"), ("V2y", "v2y"), ("W2", "w2")):
                    assert abs(ref[key] - _mp(src, init)) <= TIGHT, f"row {i}: {key} moved"


def test_fixed_body_is_the_heavy_limit(barrier):
    """m2 = I2 = inf agrees with m2 = I2 = 1e35 to ~1e-30 (exact inverse masses)."""
    rows, refs, _ = barrier
    for i, (row, ref) in enumerate(zip(rows[:8], refs[:8])):
        heavy = R.solve_reference(dict(row, m2=1e35, I2=1e35))
        scales = R.natural_scales(row, ref)
        errors = R.relative_errors({k: float(heavy[k]) for k in scales}, ref, scales)
        worst = max(errors, key=errors.get)
        # float(heavy) rounds to double: allow the 1e-16 of that rounding
        assert errors[worst] < 1e-15, f"row {i}: {worst} differs by {errors[worst]:.2e}"
        with mp.workdps(R.DPS):
            assert abs(heavy["V1x"] - ref["V1x"]) < mp.mpf("1e-28") * scales["V1x"], f"row {i}"


def test_particle_into_wall_closed_form():
    """Particle at (10, 3) m/s into a wall along x: V1 = (-e*10, 3 + mu*Pn/m1)."""
    row = dict(m1=2.0, m2=math.inf, v1x=10.0, v1y=3.0, v2x=0.0, v2y=0.0, gamma=0.0, e=0.25, mu=0.125)
    ref = R.solve_reference(row, "particle")
    with mp.workdps(R.DPS):
        pn = -2 * (1 + mp.mpf(0.25)) * 10  # m1 (1+e) gn, gn = -10
        expect = dict(
            V1x=-mp.mpf(2.5),
            V1y=3 + mp.mpf(0.125) * pn / 2,
            V2x=0,
            V2y=0,
            Pn=pn,
            Pt=mp.mpf(0.125) * pn,
            mu_c=mp.mpf(6) / 25,
        )  # sticking: Pt = -m1*3, Pn = -25
        for key, value in expect.items():
            assert abs(ref[key] - value) < TIGHT * 10, f"{key}: {ref[key]} != {value}"
        tl = (ref["V1x"] ** 2 + ref["V1y"] ** 2 - 109) * -1  # m1/2 = 1
        assert abs(ref["TL"] - tl) < TIGHT * 109, f"TL {ref['TL']} != {tl}"


# ---------------------------------------------------------------- the helpers themselves


def test_checks_detect_a_wrong_solution(rigid):
    """The conservation check above fails for a 1e-12 perturbation (so it is not vacuous)."""
    rows, refs, _ = rigid
    row, ref = rows[0], dict(refs[0])
    with mp.workdps(R.DPS):
        ref["V1x"] += mp.mpf("1e-12") * _speed(row)
        px0, _, _, s0 = _momenta(row, None, (0, 0))
        px1, _, _, s1 = _momenta(row, ref, (0, 0))
        assert abs(px0 - px1) > TIGHT * (s0 + s1)


def test_relative_errors_and_scales(rigid, particle):
    """A float64-rounded reference scores ~1e-16; a 1e-10 perturbation ~1e-10; NaN -> inf."""
    for model, (rows, refs, _) in (("rigid", rigid), ("particle", particle)):
        row, ref = rows[0], refs[0]
        scales = R.natural_scales(row, ref, model)
        assert set(scales) >= set(R.OUTPUTS)
        got = {k: float(ref[k]) for k in scales}
        errors = R.relative_errors(got, ref, scales)
        assert max(errors.values()) < 1e-15, errors
        bumped = dict(got, V1x=got["V1x"] + 1e-10 * float(scales["V1x"]))
        assert 0.9e-10 < R.relative_errors(bumped, ref, scales)["V1x"] < 1.1e-10
        assert R.relative_errors(dict(got, TL=math.nan), ref, scales)["TL"] == math.inf
    assert float(R.natural_scales(rows[0], refs[0], "particle")["M"]) == pytest.approx(1e-300)


def test_precision_is_not_leaked(rigid):
    """The reference works in a local workdps context and leaves mp.dps alone."""
    before = mp.dps
    R.solve_reference(rigid[0][0])
    R.natural_scales(rigid[0][0], rigid[1][0])
    assert mp.dps == before


def test_nan_input_is_rejected(rigid):
    with pytest.raises(ValueError):
        R.solve_reference(dict(rigid[0][0], e=math.nan))


def test_generator_contract():
    """Scenes approach, mu lies between 0 and mu_c, columns are float64 and complete."""
    c = scenes.random_realistic(30, 7)
    assert sorted(c) == sorted(R.RIGID_INPUTS)
    assert all(v.dtype == np.float64 and v.shape == (30,) for v in c.values())
    gn, _ = scenes._closing(c, "rigid")
    assert np.all(gn < 0)
    for i in range(30):
        mu_c = float(R.mu_critical(R.row_of(c, i)))
        assert 0 <= c["mu"][i] / mu_c <= 1 or c["mu"][i] == 0, f"row {i}"
    assert set(np.unique(c["e_m"][c["e_m"] > 0])) <= {1.0}
