"""Accuracy of ``impactsym.solve_batch`` against the independent 50-digit reference.

Every output of every row must lie within ``TOL`` (1e-12) of the reference, measured
relative to the output's natural scale (``reference.natural_scales``: largest speed
for velocities, |P| for impulses, the energy scale for the energy terms, ...). The
references are computed once per module (fixture ``suites``).
"""

from dataclasses import dataclass

import numpy as np
import pytest
from mpmath import mp

import impactsym
from impactsym.testing import reference as R
from impactsym.testing import scenes

TOL = 1e-12
N_RIGID = 200
N_PARTICLE = 200
N_BARRIER = 40
ENERGY_CREATED, TENSILE, MU_OUT_OF_RANGE = 1, 2, 4


@dataclass(repr=False)
class Suite:
    """Scenes of one kind with their references (given mu and critical mode)."""

    name: str
    model: str
    columns: dict
    rows: list
    given: list
    critical: list

    @property
    def n(self):
        return len(self.rows)

    def __repr__(self):
        return f"Suite({self.name!r}, {self.model!r}, {self.n} rows)"


def _suite(name, model, columns):
    rows = [R.row_of(columns, i) for i in range(R.n_rows(columns))]
    given = [R.solve_reference(row, model) for row in rows]
    critical = [R.solve_reference(row, model, critical=True) for row in rows]
    return Suite(name, model, columns, rows, given, critical)


@pytest.fixture(scope="module")
def suites():
    """Random rigid, particle and fixed-barrier scenes with 50-digit references."""
    return {
        "rigid": _suite("rigid", "rigid", scenes.random_realistic(N_RIGID, 2024)),
        "particle": _suite(
            "particle", "particle", scenes.random_realistic(N_PARTICLE, 2025, model="particle")
        ),
        "barrier": _suite("barrier", "rigid", scenes.random_realistic(N_BARRIER, 2026, barrier=True)),
    }


# ---------------------------------------------------------------- helpers


def _solve(columns, model, critical=False):
    """Call the package; return {key: float64 array} (critical: mu = "critical")."""
    cols = dict(columns, mu="critical") if critical else dict(columns)
    out = impactsym.solve_batch(cols, model=model)
    missing = [key for key in (*R.OUTPUTS, "status", "flags") if key not in out]
    assert not missing, f"solve_batch(model={model!r}) lacks outputs {missing}"
    return {key: np.asarray(out[key]) for key in (*R.OUTPUTS, "status", "flags")}


def _assert_status_ok(out, label):
    bad = np.flatnonzero(np.asarray(out["status"]) != 0)
    assert bad.size == 0, (
        f"{label}: {bad.size} rows not solved, first rows {bad[:10].tolist()} "
        f"with status {np.asarray(out['status'])[bad[:10]].tolist()}"
    )


def _worst_errors(suite, out, refs):
    """{output: (worst relative error, row, got, ref)} over the suite's rows."""
    worst = {}
    for i, (row, ref) in enumerate(zip(suite.rows, refs)):
        scales = R.natural_scales(row, ref, suite.model)
        got = {key: float(out[key][i]) for key in scales}
        for key, err in R.relative_errors(got, ref, scales).items():
            if key not in worst or not err <= worst[key][0]:
                worst[key] = (err, i, got[key], ref[key])
    return worst


def _assert_accurate(suite, out, refs, label):
    worst = _worst_errors(suite, out, refs)
    failures = {key: value for key, value in worst.items() if not value[0] <= TOL}
    report = "; ".join(
        f"{key}: {err:.3g} at row {i} (got {got!r}, ref {mp.nstr(ref, 17)})"
        for key, (err, i, got, ref) in sorted(failures.items(), key=lambda kv: -kv[1][0])
    )
    assert not failures, f"{label}: outputs beyond {TOL:g} of natural scale: {report}"


# ---------------------------------------------------------------- (a) random scenes


@pytest.mark.slow  # exhaustive accuracy: 50-digit references of every suite (minutes)
@pytest.mark.parametrize("name", ["rigid", "particle", "barrier"])
@pytest.mark.parametrize("critical", [False, True], ids=["given_mu", "critical"])
def test_outputs_match_reference(suites, name, critical):
    """Every output within 1e-12 of its natural scale of the 50-digit reference; status 0."""
    suite = suites[name]
    out = _solve(suite.columns, suite.model, critical)
    label = f"{name} ({'critical' if critical else 'given mu'}, {suite.n} rows)"
    _assert_status_ok(out, label)
    _assert_accurate(suite, out, suite.critical if critical else suite.given, label)


@pytest.mark.slow  # exhaustive accuracy: 50-digit references of every suite (minutes)
def test_critical_mu_equals_mu_c(suites):
    """In critical mode the reported mu is the package's own mu_c."""
    suite = suites["rigid"]
    out = _solve(suite.columns, "rigid", critical=True)
    diff = np.abs(out["mu"] - out["mu_c"]) / np.maximum(np.abs(out["mu_c"]), 1e-300)
    i = int(np.argmax(diff))
    assert diff[i] <= TOL, f"row {i}: mu {out['mu'][i]!r} != mu_c {out['mu_c'][i]!r}"


# ---------------------------------------------------------------- (b) seed Table 2


@pytest.fixture(scope="module")
def table2():
    columns, expected = scenes.table2_scenes()
    return columns, expected, _solve(columns, "particle")


def test_table2_energy_loss(table2):
    """Seed Table 2 T_L through solve_batch(model="particle"): 1e-9 relative, 1e-6 ft lb at 0."""
    columns, expected, out = table2
    _assert_status_ok(out, "Table 2")
    for i, tl in enumerate(expected):
        got = out["TL"][i]
        ok = abs(got) <= 1e-6 if tl == 0 else abs(got - tl) <= 1e-9 * abs(tl)
        assert ok, f"Table 2 row {i} (e={columns['e'][i]}, mu={columns['mu'][i]}): TL {got!r} != {tl}"


def test_table2_mu_out_of_range_flag(table2):
    """Flag 4 is set exactly for the four rows with mu > mu_max (the seed's starred values)."""
    columns, _, out = table2
    expected = columns["mu"] > scenes.TABLE2_MU_MAX
    got = (out["flags"] & MU_OUT_OF_RANGE) != 0
    assert np.array_equal(got, expected), (
        f"flag 4 rows {np.flatnonzero(got).tolist()}, expected {np.flatnonzero(expected).tolist()} "
        f"(mu_c = {out['mu_c'].tolist()})"
    )


def test_table2_energy_created_flag(table2):
    """Flag 1 is set for the negative-T_L rows; no row has flag 2 (all impulses compressive)."""
    _, expected, out = table2
    negative = np.flatnonzero(expected < 0)
    got = np.flatnonzero(out["flags"] & ENERGY_CREATED)
    assert set(negative) <= set(got), f"flag 1 rows {got.tolist()}, expected at least {negative.tolist()}"
    tensile = np.flatnonzero(out["flags"] & TENSILE)
    assert tensile.size == 0, f"flag 2 (tensile) set on rows {tensile.tolist()}"


def test_table2_physical_rows_not_flagged(table2):
    """Rows the seed calls physical (mu <= mu_max) carry no flag at all.

    Rows 0 and 4 have structurally zero energy parts (TLt with mu = 0, TLn with
    e = 1); a kernel must not flag round-off there as "energy created".
    """
    columns, _, out = table2
    physical = np.flatnonzero(columns["mu"] <= scenes.TABLE2_MU_MAX)
    flagged = [int(i) for i in physical if out["flags"][i] != 0]
    assert not flagged, (
        f"physical Table 2 rows {flagged} flagged {out['flags'][flagged].tolist()}; "
        f"TLn {out['TLn'][flagged].tolist()} TLt {out['TLt'][flagged].tolist()}"
    )


# ---------------------------------------------------------------- (c) conservation


def _momentum_residuals(suite, out):
    """Worst relative residuals of linear / angular momentum and impulse balances.

    Computed in mpmath from the exact float64 outputs. The impact centre is at the
    origin, so the centres of gravity are at c_i = -r_i and
    L = sum m_i c_i x v_i + I_i w_i. Scales: sum m_i S (linear; S = the velocity
    scale), sum m_i |c_i| S + I_i Y (angular; Y = the yaw-rate scale).
    """
    worst = {}

    def note(what, value, i):
        if what not in worst or value > worst[what][0]:
            worst[what] = (value, i)

    rigid = suite.model == "rigid"
    with mp.workdps(R.DPS):
        for i, (row, ref) in enumerate(zip(suite.rows, suite.given)):
            scales = R.natural_scales(row, ref, suite.model)
            S, Y = scales["V1x"], scales["W1"]
            p = {k: mp.mpf(float(out[k][i])) for k in R.OUTPUTS}
            lin = [mp.zero, mp.zero]
            ang, lin_scale, ang_scale = mp.zero, mp.zero, mp.zero
            for j in (1, 2):
                m = mp.mpf(row[f"m{j}"])
                I = mp.mpf(row[f"I{j}"]) if rigid else mp.zero
                cx, cy = (-mp.mpf(row[f"r{j}x"]), -mp.mpf(row[f"r{j}y"])) if rigid else (0, 0)
                dvx = p[f"V{j}x"] - mp.mpf(row[f"v{j}x"])
                dvy = p[f"V{j}y"] - mp.mpf(row[f"v{j}y"])
                dw = p[f"W{j}"] - mp.mpf(row.get(f"w{j}", 0.0))
                lin[0] += m * dvx
                lin[1] += m * dvy
                ang += m * (cx * dvy - cy * dvx) + I * dw
                lin_scale += m * S
                ang_scale += m * mp.hypot(cx, cy) * S + I * Y
            note("linear momentum", float(mp.hypot(*lin) / lin_scale), i)
            if rigid:  # particles sit at the impact centre: L is identically 0
                note("angular momentum", float(abs(ang) / ang_scale), i)
            # vehicle 1 receives P = Pn n + Pt t and r1 x P + M
            g = mp.mpf(row["gamma"])
            Px = p["Pn"] * mp.cos(g) - p["Pt"] * mp.sin(g)
            Py = p["Pn"] * mp.sin(g) + p["Pt"] * mp.cos(g)
            m1 = mp.mpf(row["m1"])
            P_scale = scales["Pn"] + m1 * S
            res = mp.hypot(
                m1 * (p["V1x"] - mp.mpf(row["v1x"])) - Px, m1 * (p["V1y"] - mp.mpf(row["v1y"])) - Py
            )
            note("impulse on vehicle 1", float(res / P_scale), i)
    return worst


@pytest.mark.slow  # exhaustive accuracy: 50-digit references of every suite (minutes)
@pytest.mark.parametrize("name", ["rigid", "particle"])
def test_momentum_conserved(suites, name):
    """Linear and angular momentum of the package outputs are conserved to 1e-12."""
    suite = suites[name]
    out = _solve(suite.columns, suite.model)
    worst = _momentum_residuals(suite, out)
    bad = {k: v for k, v in worst.items() if not v[0] <= TOL}
    assert not bad, f"{name}: " + "; ".join(f"{k} residual {e:.3g} at row {i}" for k, (e, i) in bad.items())


# ---------------------------------------------------------------- (d) fixed barrier


@pytest.mark.slow  # exhaustive accuracy: 50-digit references of every suite (minutes)
@pytest.mark.parametrize("critical", [False, True], ids=["given_mu", "critical"])
def test_fixed_barrier_stays_put(suites, critical):
    """m2 = I2 = inf: V2 = v2 and W2 = w2 exactly (and the rest matches the reference)."""
    suite = suites["barrier"]
    out = _solve(suite.columns, "rigid", critical)
    _assert_status_ok(out, "barrier")
    for key, init in (("V2x", "v2x"), ("V2y", "v2y"), ("W2", "w2")):
        moved = np.flatnonzero(out[key] != suite.columns[init])
        assert moved.size == 0, (
            f"barrier {key} != {init} on rows {moved[:10].tolist()}: {out[key][moved[:3]].tolist()}"
        )
    _assert_accurate(suite, out, suite.critical if critical else suite.given, "barrier")


@pytest.mark.slow  # exhaustive accuracy: 50-digit references of every suite (minutes)
def test_moving_fixed_body_keeps_its_velocity(suites):
    """A fixed body given a velocity keeps it exactly (inverse masses are exactly 0)."""
    suite = suites["barrier"]
    cols = dict(
        suite.columns, v2x=np.full(suite.n, 1.25), v2y=np.full(suite.n, -0.5), w2=np.full(suite.n, 0.125)
    )
    out = _solve(cols, "rigid")
    ok = (out["V2x"] == 1.25) & (out["V2y"] == -0.5) & (out["W2"] == 0.125)
    ok |= out["status"] != 0  # rows that no longer approach may be refused
    assert ok.all(), f"fixed body moved on rows {np.flatnonzero(~ok)[:10].tolist()}"


# ---------------------------------------------------------------- flags of random scenes


def _expected_flags(ref, scales, margin=1e-9):
    """(must_set, must_clear) bit masks implied by a reference row; ambiguous bits in neither.

    Bit 1 (energy created): set when TL or a part < -margin * energy scale; clear when
    every part is > margin * scale (rows with a part near 0, e.g. mu = 0 or e_m = 1,
    are left to the kernel's own tolerance).
    Bit 2 (tensile): Pn > 0 beyond margin * |P| sets it, Pn < 0 beyond it clears it.
    """
    must_set = must_clear = 0
    energy = scales["TL"]
    parts = [ref[k] for k in R.ENERGY_KEYS]
    if any(part < -margin * energy for part in parts):
        must_set |= ENERGY_CREATED
    elif all(part > margin * energy for part in parts):
        must_clear |= ENERGY_CREATED
    if ref["Pn"] > margin * scales["Pn"]:
        must_set |= TENSILE
    elif ref["Pn"] < -margin * scales["Pn"]:
        must_clear |= TENSILE
    return must_set, must_clear


@pytest.mark.slow  # exhaustive accuracy: 50-digit references of every suite (minutes)
@pytest.mark.parametrize("critical", [False, True], ids=["given_mu", "critical"])
def test_flags_match_reference(suites, critical):
    """Flags 1 and 2 agree with the reference wherever it is unambiguous; flag 4 is clear
    (mu is a fraction of mu_c, or mu_c itself in critical mode)."""
    problems = []
    for name in ("rigid", "particle", "barrier"):
        suite = suites[name]
        out = _solve(suite.columns, suite.model, critical)
        refs = suite.critical if critical else suite.given
        for i, (row, ref) in enumerate(zip(suite.rows, refs)):
            must_set, must_clear = _expected_flags(ref, R.natural_scales(row, ref, suite.model))
            must_clear |= MU_OUT_OF_RANGE
            flags = int(out["flags"][i])
            if flags & must_set != must_set or flags & must_clear:
                problems.append(
                    f"{name} row {i}: flags {flags}, must set {must_set}, "
                    f"must clear {must_clear} (TL parts "
                    f"{[mp.nstr(ref[k], 6) for k in R.ENERGY_KEYS]}, "
                    f"Pn {mp.nstr(ref['Pn'], 6)})"
                )
    assert not problems, f"{len(problems)} rows with wrong flags: " + "; ".join(problems[:5])


@pytest.mark.slow  # exhaustive accuracy: 50-digit references of every suite (minutes)
def test_mu_out_of_range_flag_set(suites):
    """mu = 1.5 mu_c and mu = -0.5 mu_c (wrong sign) both set flag 4."""
    suite = suites["rigid"]
    mu_c = np.array([float(ref["mu_c"]) for ref in suite.given])
    usable = np.abs(mu_c) > 1e-6
    for factor in (1.5, -0.5):
        cols = dict(suite.columns, mu=factor * mu_c)
        out = _solve(cols, "rigid")
        missing = np.flatnonzero(usable & ((out["flags"] & MU_OUT_OF_RANGE) == 0) & (out["status"] == 0))
        assert missing.size == 0, f"mu = {factor} mu_c: flag 4 missing on rows {missing[:10].tolist()}"
