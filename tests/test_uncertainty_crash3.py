"""Uncertainty of CRASH3 with its options: energy "absorbed" and the Woolley correction.

Exact derivatives of the CRASH3 Jacobian kernels (crush energy with both
oblique corrections, delta-V with the energy dissipated or absorbed) against
an independent 50-digit mpmath CRASH3 written here from the published method
(the energy density (A + B c)²/(2B) integrated across the profile by
mpmath.quad; a 1-D impact of effective masses solved from momentum and
restitution), differentiated by mpmath.diff. Then the method (Monte Carlo and
linear sd) and the CLI and API with both options.

Tolerances, fixed before looking at results:
- derivatives: each entry within 1e-8 of the largest |entry| of its
  output's row (as tests/test_uncertainty.py); beyond the 45° cap the
  derivative with respect to the PDOF is exactly 0; at the cap exactly, the
  mean of mpmath's one-sided derivatives, within 1e-8 relative.
- Monte Carlo sd against the linear sd on a near-linear scene (sds of about
  1 % of the values, 40 000 draws): within 3 % (as tests/test_uncertainty.py).
"""

import copy
import json
import math
from pathlib import Path

import pytest
from mpmath import mp

import impactsym
from impactsym import _kernels
from tests.helpers import assert_gradient_close, mp_gradient, run_cli_subprocess

ROOT = Path(__file__).resolve().parents[1]
TWO_CAR = json.loads((ROOT / "examples" / "crash3_two_car_us.json").read_text())
CAP = mp.pi / 4


# --------------------------------------------------------------------------- independent reference


def _mp_energy(p: dict, n: int) -> dict:
    """Crush energy of an n-point profile by quadrature of (A + B c)²/(2B)
    across the width (crush linear between the depths), and the two
    oblique corrections at min(|α|, 45°)."""
    depths = [p[f"C{i}"] for i in range(1, n + 1)]
    step = p["width"] / (n - 1)

    def density(x):
        i = min(int(x / step), n - 2)
        c = depths[i] + (depths[i + 1] - depths[i]) * (x - i * step) / step
        return (p["A"] + p["B"] * c) ** 2 / (2 * p["B"])

    # Gauss-Legendre: exact for the quadratic density on each piece, and far cheaper at
    # 50 digits than the default tanh-sinh rule
    crush = mp.fsum(
        mp.quad(density, [i * step, (i + 1) * step], method="gauss-legendre") for i in range(n - 1)
    )
    a = min(abs(p["alpha"]), CAP)
    return {"E_crush": crush, "E": crush * (1 + mp.tan(a) ** 2), "E_woolley": crush / mp.cos(a)}


def _mp_delta_v(p: dict, energy: str) -> dict:
    """1-D impact of effective masses M_i = m_i k_i²/(k_i² + h_i²) closing at
    v_c along the PDOF, restitution e: the energy E fixes v_c (dissipated:
    E = M̄ v_c² (1 - e²)/2, the loss over the impact; absorbed: E = M̄ v_c²/2,
    the loss to maximum crush); the impulse is M̄ v_c (1 + e), ΔV_i = P/m_i."""
    M1 = p["m1"] * p["rg1"] ** 2 / (p["rg1"] ** 2 + p["h1"] ** 2)
    M2 = p["m2"] * p["rg2"] ** 2 / (p["rg2"] ** 2 + p["h2"] ** 2)
    mbar = M1 * M2 / (M1 + M2)
    lost = (1 - p["e"] ** 2) if energy == "dissipated" else 1
    vc = mp.sqrt(2 * p["E"] / (mbar * lost))
    P = mbar * vc * (1 + p["e"])
    dv1, dv2 = P / p["m1"], P / p["m2"]
    return {
        "P": P,
        "dV1": dv1,
        "dV2": dv2,
        "dV1x": -dv1 * mp.cos(p["gamma"] + p["alpha1"]),
        "dV2y": dv2 * mp.sin(p["gamma"] + p["alpha2"]),
        "dV1_eff": P / M1,
    }


ENERGY_POINT = {"A": 300.0, "B": 60.0, "width": 60.0, "C1": 9.0, "C2": 11.0, "C3": 12.0}
ENERGY_POINT.update(C4=12.5, C5=11.0, C6=8.0)


@pytest.mark.parametrize("n", [2, 4, 6])
@pytest.mark.parametrize("alpha_deg", [-30.0, 20.0, 60.0])
def test_energy_jacobian_matches_reference_with_both_corrections(n, alpha_deg):
    point = {k: v for k, v in ENERGY_POINT.items() if not (k.startswith("C") and int(k[1:]) > n)}
    point["alpha"] = math.radians(alpha_deg)
    ks = _kernels.JACOBIAN[f"crash3_energy_{n}"]
    got = _kernels.run_one(ks, point, ks.outputs)
    assert got["status"] == 0
    names, outputs = list(ks.inputs), ["E_crush", "E", "E_woolley"]
    assert_gradient_close(got, mp_gradient(lambda p: _mp_energy(p, n), point, names, outputs), names, outputs)
    if abs(alpha_deg) > 45:  # beyond the cap: exactly no dependence on the PDOF
        assert got["d_E__d_alpha"] == 0.0 and got["d_E_woolley__d_alpha"] == 0.0


@pytest.mark.parametrize("sign", [1, -1])
def test_energy_derivative_at_the_cap_is_the_mean_of_the_one_sided_ones(sign):
    """At |α| = 45° exactly the corrected energy has a kink (slope below, flat
    above): the kernel returns the mean of the two one-sided derivatives."""
    point = {**ENERGY_POINT, "alpha": sign * math.radians(45.0)}
    assert abs(point["alpha"]) == math.pi / 4  # the float 45° is the float π/4: the kink itself
    ks = _kernels.JACOBIAN["crash3_energy_6"]
    got = _kernels.run_one(ks, point, ks.outputs)
    assert got["status"] == 0
    for out in ("E", "E_woolley"):
        with mp.workdps(50):
            at = {k: mp.mpf(v) for k, v in point.items()}
            at["alpha"] = sign * CAP
            sides = [
                mp_gradient(lambda p: _mp_energy(p, 6), at, ["alpha"], [out], direction=d)[out]["alpha"]
                for d in (-1, 1)
            ]
        assert (float(sides[0]) == 0.0) != (float(sides[1]) == 0.0)  # one side flat, one not
        want = float((sides[0] + sides[1]) / 2)
        assert got[f"d_{out}__d_alpha"] == pytest.approx(want, rel=1e-8)


DV_POINT = {
    "m1": 1500.0,
    "m2": 1200.0,
    "rg1": 1.3,
    "rg2": 1.2,
    "h1": 0.4,
    "h2": -0.3,
    "E": 150_000.0,
    "e": 0.2,
    "gamma": 0.3,
    "alpha1": 0.2,
    "alpha2": -0.1,
}


@pytest.mark.parametrize("energy", ["dissipated", "absorbed"])
def test_delta_v_jacobian_matches_reference(energy):
    name = "crash3_delta_v" + ("_absorbed" if energy == "absorbed" else "")
    ks = _kernels.JACOBIAN[name]
    got = _kernels.run_one(ks, DV_POINT, ks.outputs)
    assert got["status"] == 0
    names, outputs = list(ks.inputs), ["P", "dV1", "dV2", "dV1x", "dV2y", "dV1_eff"]
    want = mp_gradient(lambda p: _mp_delta_v(p, energy), DV_POINT, names, outputs)
    assert_gradient_close(got, want, names, outputs)


# --------------------------------------------------------------------------- the method


def _near_linear_scene(energy: str, correction: str, pdof: float = 20.0) -> dict:
    """The two-car US CRASH3 example with about 1 % uncertainty on the crush,
    stiffness and masses and ±1° on the PDOFs (oblique, so the correction
    matters)."""
    data = copy.deepcopy(TWO_CAR)
    data["crash3"] = {"restitution": 0.3, "energy": energy, "correction": correction}
    for v in data["vehicles"]:
        crush = v["crush"]
        for key in ("A", "B", "width"):
            crush[key] = {"normal": [crush[key], 0.01 * crush[key]]}
        crush["depths"][1] = {"normal": [crush["depths"][1], 0.01 * crush["depths"][1]]}
        crush["pdof"] = {"normal": [pdof, 1.0]}
        v["mass"] = {"normal": [v["mass"], 0.01 * v["mass"]]}
    return data


def _nominal(data: dict) -> dict:
    out = copy.deepcopy(data)
    for v in out["vehicles"]:
        for table in (v, v["crush"]):
            for key, value in table.items():
                if isinstance(value, dict) and "normal" in value:
                    table[key] = value["normal"][0]
        v["crush"]["depths"] = [d["normal"][0] if isinstance(d, dict) else d for d in v["crush"]["depths"]]
    return out


OPTIONS = [("absorbed", "crash3"), ("dissipated", "woolley"), ("absorbed", "woolley")]


@pytest.mark.parametrize("energy,correction", OPTIONS)
def test_monte_carlo_and_linear_sd_agree_with_each_option(energy, correction):
    data = _near_linear_scene(energy, correction)
    u = impactsym.uncertainty(data, command="crash3", draws=40_000, seed=13)
    nominal = impactsym.crash3(_nominal(data))
    assert nominal.options.energy == energy and nominal.options.correction == correction
    assert u.accepted > 0.99 * u.n_draws
    for i, vehicle in enumerate(nominal.vehicles):
        # The options reach the propagation: its nominal is crash3's with them.
        assert u.outputs[f"vehicles[{i}].crush_energy"]["nominal"] == pytest.approx(
            vehicle.crush_energy, rel=1e-12
        )
        assert u.outputs[f"vehicles[{i}].delta_v_magnitude"]["nominal"] == pytest.approx(
            vehicle.delta_v_magnitude, rel=1e-12
        )
    for path in ("vehicles[0].delta_v_magnitude", "vehicles[1].delta_v_magnitude", "energy_total", "impulse"):
        out = u.outputs[path]
        assert out["sd_linear"] > 0
        assert abs(out["sd"] / out["sd_linear"] - 1) < 0.03, (path, out)
        assert abs(sum(u.budget[path].values()) - 1) < 1e-12


def test_the_options_change_the_answer_and_its_spread():
    """Woolley's 1/cos α grows more slowly with α than 1 + tan²α; for the same
    crush energy, the absorbed reading gives |P| = (1 + e)·√(2 E m̄) and the
    dissipated √(2 E m̄ (1 + e)/(1 - e)): a ratio √(1 - e²). (This test first
    expected the inverse ratio, a slip in the writing of it: the ratio is the
    one derive/crash3.py proves and the mpmath reference above uses.)"""
    runs = {
        opts: impactsym.uncertainty(_near_linear_scene(*opts), command="crash3", draws=2000, seed=1)
        for opts in [("dissipated", "crash3"), *OPTIONS]
    }
    energy = {k: r.outputs["vehicles[0].crush_energy"] for k, r in runs.items()}
    budget = {k: r.budget["vehicles[0].crush_energy"]["vehicles[0].crush.pdof"] for k, r in runs.items()}
    assert energy[("dissipated", "woolley")]["nominal"] < energy[("dissipated", "crash3")]["nominal"]
    assert 0 < budget[("dissipated", "woolley")] < budget[("dissipated", "crash3")]
    impulse = {k: r.outputs["impulse"]["nominal"] for k, r in runs.items()}
    ratio = impulse[("absorbed", "crash3")] / impulse[("dissipated", "crash3")]
    assert ratio == pytest.approx(math.sqrt(1 - 0.3**2), rel=1e-12)


@pytest.mark.parametrize("correction", ["crash3", "woolley"])
def test_beyond_the_cap_the_pdof_does_not_move_the_energy(correction):
    data = _nominal(_near_linear_scene("dissipated", correction))
    data["vehicles"][0]["crush"]["pdof"] = {"normal": [60.0, 2.0]}  # every draw beyond 45°
    u = impactsym.uncertainty(data, command="crash3", draws=2000, seed=2)
    energy = u.outputs["vehicles[0].crush_energy"]
    assert energy["sd"] == 0.0 and energy["sd_linear"] == 0.0
    # ... but it still turns the PDOF line, hence the moment arm and the delta-V.
    assert u.outputs["vehicles[0].delta_v_magnitude"]["sd_linear"] > 0


def test_cli_uncertainty_with_both_options(tmp_path):
    data = _near_linear_scene("dissipated", "crash3")
    del data["crash3"]
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(data))
    flags = ("--energy", "absorbed", "--correction", "woolley", "--restitution", "0.4")
    run = run_cli_subprocess(
        "crash3", scene, "--uncertainty", "--draws", "2000", "--seed", "3", "--json", *flags
    )
    assert run.returncode == 0, run.stderr
    obj = json.loads(run.stdout)
    assert obj["options"] == {"restitution": 0.4, "energy": "absorbed", "correction": "woolley"}
    u = obj["uncertainty"]
    for i, vehicle in enumerate(obj["vehicles"]):
        for key in ("crush_energy", "delta_v_magnitude", "delta_v_effective_mass"):
            assert u["outputs"][f"vehicles[{i}].{key}"]["nominal"] == pytest.approx(vehicle[key], rel=1e-12)
            assert u["outputs"][f"vehicles[{i}].{key}"]["sd_linear"] > 0
    api = impactsym.uncertainty(
        scene, command="crash3", draws=2000, seed=3, restitution=0.4, energy="absorbed", correction="woolley"
    )
    assert api.to_json_dict()["outputs"] == u["outputs"]
    table = run_cli_subprocess("crash3", scene, "--uncertainty", "--draws", "500", "--seed", "3", *flags)
    assert table.returncode == 0, table.stderr
    assert "absorbed" in table.stdout and "woolley" in table.stdout


def test_a_bad_option_is_a_one_line_error(tmp_path):
    scene = tmp_path / "scene.json"
    scene.write_text(json.dumps(_near_linear_scene("dissipated", "crash3")))
    run = run_cli_subprocess("crash3", scene, "--uncertainty", "--draws", "100", "--correction", "wooley")
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1 and "correction" in run.stderr
    with pytest.raises(ValueError, match="crash3.energy"):
        impactsym.uncertainty(
            {**_near_linear_scene("dissipated", "crash3"), "crash3": {"energy": "x"}}, "crash3"
        )
