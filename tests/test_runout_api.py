"""Run-out scene API, fit to rest and the `impactsym runout` command."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import pytest

from impactsym.errors import SceneError
from impactsym.runout import load_runout, runout
from impactsym.runout.fit import fit_rest
from tests.helpers import run_cli_subprocess

ROOT = Path(__file__).resolve().parents[1]
SEDAN = ROOT / "examples" / "runout" / "sedan.json"


def _scene():
    return json.loads(SEDAN.read_text())


def test_forward_scene_reports_the_contract_keys():
    res = runout(_scene())
    entry = res["vehicles"][0]
    assert set(entry) >= {"rest", "time", "distance", "rotation", "separation"}
    assert set(entry["separation"]) >= {"velocity", "speed", "yaw_rate"}
    assert entry["rotation"] == pytest.approx(entry["rest"]["heading"] - 30.0)
    assert entry["distance"] >= math.hypot(
        entry["rest"]["position"][0] + 1.2, entry["rest"]["position"][1] - 0.4
    )


def test_us_units_give_the_same_motion_in_feet():
    si = _scene()
    us = copy.deepcopy(si)
    ft, slug = 0.3048, 14.59390293720636
    us["units"] = "US"
    v = us["vehicles"][0]
    v["mass"] = si["vehicles"][0]["mass"] / slug
    v["yaw_inertia"] = si["vehicles"][0]["yaw_inertia"] / slug / ft**2
    for key in ("wheelbase", "cg_to_front_axle", "track"):
        v[key] = si["vehicles"][0][key] / ft
    v["separation"]["position"] = [p / ft for p in si["vehicles"][0]["separation"]["position"]]
    v["separation"]["velocity"] = [p / ft for p in si["vehicles"][0]["separation"]["velocity"]]
    us["runout"]["gravity"] = 9.80665 / ft
    a, b = runout(si)["vehicles"][0], runout(us)["vehicles"][0]
    assert b["rest"]["position"][0] * ft == pytest.approx(a["rest"]["position"][0], abs=1e-6)
    assert b["rest"]["heading"] == pytest.approx(a["rest"]["heading"], abs=1e-6)


@pytest.mark.parametrize(
    "edit, field",
    [
        (lambda s: s["runout"].pop("friction"), "runout.friction"),
        (lambda s: s["vehicles"][0].update(mass=-1), "vehicles[0].mass"),
        (lambda s: s["vehicles"][0].update(cg_to_front_axle=3.0), "vehicles[0].cg_to_front_axle"),
        (
            lambda s: s["vehicles"][0]["wheels"].update(front_left={"brak": 0.3}),
            "vehicles[0].wheels.front_left.brak",
        ),
        (
            lambda s: s["vehicles"][0]["wheels"].update(rear_left={"brake": 1.5}),
            "vehicles[0].wheels.rear_left.brake",
        ),
        (lambda s: s["vehicles"][0]["separation"].pop("yaw_rate"), "vehicles[0].separation.yaw_rate"),
        (
            lambda s: s["vehicles"][0]["separation"].update(velocity=[1.0, float("nan")]),
            "vehicles[0].separation.velocity[1]",
        ),
        (lambda s: s.update(runout={"friction": 0.7, "slip_angel_max": 10}), "runout.slip_angel_max"),
    ],
)
def test_bad_scenes_are_refused_with_one_line_naming_the_field(edit, field):
    scene = _scene()
    edit(scene)
    with pytest.raises(SceneError) as err:
        runout(scene)
    assert err.value.field == field and "\n" not in str(err.value)


@pytest.mark.parametrize(
    "wheels, velocity, w",
    [
        (
            {
                "front_left": "locked",
                "front_right": "locked",
                "rear_left": "rolling",
                "rear_right": "rolling",
            },
            [9.0, 2.0],
            1.2,
        ),
        ("locked", [7.0, -3.0], -0.8),
        (
            {
                "front_left": "locked",
                "front_right": "rolling",
                "rear_left": {"brake": 0.5},
                "rear_right": {"steer": -5},
            },
            [8.0, 3.0],
            1.2,
        ),
    ],
)
def test_fit_round_trip_recovers_the_separation_state(wheels, velocity, w):
    scene = _scene()
    v = scene["vehicles"][0]
    v["wheels"] = wheels
    v["separation"].update(velocity=velocity, yaw_rate=w)
    forward = runout(scene)["vehicles"][0]
    del v["separation"]["velocity"], v["separation"]["yaw_rate"]
    v["rest"] = forward["rest"]
    veh = load_runout(scene).vehicles[0]
    fit = fit_rest(veh)
    assert fit.converged
    found = [fit] + fit.alternatives
    best = min(found, key=lambda f: math.hypot(f.velocity[0] - velocity[0], f.velocity[1] - velocity[1]))
    assert math.hypot(best.velocity[0] - velocity[0], best.velocity[1] - velocity[1]) < 0.01
    assert abs(best.yaw_rate - w) < 0.01
    if best is not fit:  # the given state is not the reported one: the scene must say so
        assert runout(scene)["warnings"]
    entry = runout(scene)["vehicles"][0]
    assert entry["fit"]["residual"]["position"] < 1e-3 and entry["fit"]["iterations"] >= 0


def _cli(*args):
    return run_cli_subprocess("runout", *args)


def test_cli_json_path_and_plot(tmp_path):
    out = tmp_path / "runout.png"
    proc = _cli(str(SEDAN), "--json", "--path", "--plot", str(out))
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    entry = data["vehicles"][0]
    assert entry["path"][0][0] == 0.0 and len(entry["path"][0]) == 4
    assert entry["path"][-1][1] == pytest.approx(entry["rest"]["position"][0])
    assert out.stat().st_size > 10_000


def test_cli_bad_scene_exits_2_with_one_line(tmp_path):
    scene = _scene()
    scene["vehicles"][0]["mass"] = 0
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(scene))
    proc = _cli(str(path), "--json")
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "vehicles[0].mass" in proc.stderr


def test_chain_solve_then_reconstruct_from_rest_recovers_the_pre_impact_speeds():
    """pre-impact -> impact -> rest (solve_to_rest), then the rest poses back
    to the pre-impact motion (reconstruct_from_rest): the given speeds return."""
    from impactsym.runout.chain import reconstruct_from_rest, solve_to_rest

    scene = json.loads((ROOT / "examples" / "runout" / "chain_solve.json").read_text())
    forward = solve_to_rest(scene)
    for v, out in zip(scene["vehicles"], forward["vehicles"]):
        v["given"] = v.pop("velocity")
        v["rest"] = out["rest"]
    for key in ("restitution", "impulse_ratio", "moment_restitution"):
        scene["impact"].pop(key)
    given = [v.pop("given") for v in scene["vehicles"]]
    back = reconstruct_from_rest(scene)
    for v, g in zip(back["vehicles"], given):
        assert v["runout"]["fit"]["converged"]
        assert math.hypot(v["velocity"][0] - g[0], v["velocity"][1] - g[1]) < 0.01


def test_cli_chain_reconstruct(tmp_path):
    proc = _cli(
        str(ROOT / "examples" / "runout" / "chain_reconstruct.json"), "--chain", "reconstruct", "--json"
    )
    assert proc.returncode == 0, proc.stderr
    data = json.loads(proc.stdout)
    assert {"speed", "velocity", "runout"} <= set(data["vehicles"][0])


def test_linear_separation_sensitivity_matches_a_refit():
    """d(separation state)/d(rest pose, mu) from the integrated sensitivities
    against fitting again to a moved rest pose and a changed friction."""
    import numpy as np

    from impactsym.runout.interval import separation_sensitivity

    scene = _scene()
    v = scene["vehicles"][0]
    v["wheels"] = "locked"
    v["separation"].update(velocity=[9.0, 2.0], yaw_rate=1.0)
    rest = runout(scene)["vehicles"][0]["rest"]
    del v["separation"]["velocity"], v["separation"]["yaw_rate"]
    v["rest"] = rest
    veh = load_runout(scene).vehicles[0]
    base = fit_rest(veh)
    A = separation_sensitivity(veh, base)
    moved = copy.deepcopy(scene)
    moved["vehicles"][0]["rest"]["position"][0] += 0.05
    moved["runout"]["friction"] += 0.01
    again = fit_rest(load_runout(moved).vehicles[0])
    predicted = np.array([*base.velocity, base.yaw_rate]) + A @ [0.05, 0.0, 0.0, 0.01]
    assert np.allclose([*again.velocity, again.yaw_rate], predicted, atol=2e-3)


def test_fit_with_a_tyre_mark_direction_at_separation():
    """The direction of a wheel's mark at separation enters the fit as a fourth
    residual: consistent with the rest pose it is met and the state recovered;
    3 deg off, the least-squares fit spreads the misfit over the mark and the
    rest pose."""
    scene = _scene()
    v = scene["vehicles"][0]
    v["wheels"] = {
        "front_left": "locked",
        "front_right": "locked",
        "rear_left": "rolling",
        "rear_right": "rolling",
    }
    v["separation"].update(velocity=[9.0, 2.0], yaw_rate=1.0)
    rest = runout(scene)["vehicles"][0]["rest"]
    psi = math.radians(30.0)
    rx, ry = 1.1 * math.cos(psi) - 0.75 * math.sin(psi), 1.1 * math.sin(psi) + 0.75 * math.cos(psi)
    true_mark = math.degrees(math.atan2(2.0 + 1.0 * rx, 9.0 - 1.0 * ry))
    del v["separation"]["velocity"], v["separation"]["yaw_rate"]
    v["rest"] = rest
    v["separation"]["mark_directions"] = {"front_left": true_mark}
    entry = runout(scene)["vehicles"][0]
    assert entry["fit"]["converged"]
    assert entry["fit"]["residual"]["marks"]["front_left"] < 1e-3
    assert entry["separation"]["velocity"] == pytest.approx([9.0, 2.0], abs=0.01)
    v["separation"]["mark_directions"] = {"front_left": true_mark + 3.0}
    off = runout(scene)["vehicles"][0]
    assert off["fit"]["converged"]
    assert 0.01 < off["fit"]["residual"]["marks"]["front_left"] < 3.0
    assert off["fit"]["residual"]["position"] > 1e-3


def test_solve_and_reconstruct_commands_chain_through_the_runout():
    """conventions.md, "Chained": a solve scene with run-out data reports each
    vehicle's rest; a reconstruct scene with rest poses fits the run-outs first."""
    proc = run_cli_subprocess("solve", ROOT / "examples" / "runout" / "chain_solve.json", "--json")
    assert proc.returncode == 0, proc.stderr
    solved = json.loads(proc.stdout)
    assert all(set(v["rest"]) == {"position", "heading"} for v in solved["vehicles"])
    proc = run_cli_subprocess(
        "reconstruct", ROOT / "examples" / "runout" / "chain_reconstruct.json", "--json"
    )
    assert proc.returncode == 0, proc.stderr
    speeds = [v["speed"] for v in json.loads(proc.stdout)["vehicles"]]
    assert speeds == pytest.approx([17.0, 8.0], abs=0.01)


def _fitted_state(vehicle) -> list[float]:
    f = fit_rest(vehicle, check_unique=False)
    assert f.converged
    return [*f.velocity, f.yaw_rate]


@pytest.mark.parametrize(
    "name, k", [("fit_tbone.json", 0), ("fit_tbone.json", 1), ("fit_intermediate.json", 0)]
)
def test_determination_matches_refits_to_moved_rest_poses(name, k):
    """`fit.determination` (d state/d rest pose from the fit's Jacobian, least
    squares with an intermediate pose) against central differences of fits to
    rest poses moved by 2 cm and 0.2 deg: each column within 5 % of its norm."""
    import dataclasses

    import numpy as np

    from impactsym.runout.fit import determination

    veh = load_runout(ROOT / "examples" / "runout" / name).vehicles[k]
    D = determination(veh, fit_rest(veh, check_unique=False))
    for j, h in enumerate((0.02, 0.02, math.radians(0.2))):
        ends = []
        for sign in (1.0, -1.0):
            rest = list(veh.rest)
            rest[j] += sign * h
            ends.append(np.array(_fitted_state(dataclasses.replace(veh, rest=tuple(rest)))))
        column = (ends[0] - ends[1]) / (2 * h)
        assert np.linalg.norm(D[:, j] - column) < 0.05 * np.linalg.norm(column), (j, D[:, j], column)


def test_loosely_determined_yaw_rate_is_named_in_the_warnings():
    """The mixed-wheel chain example's sedan (front wheels locked, rear rolling)
    turns back to its rest heading whatever its yaw rate: a degree of rest
    heading moves the fitted yaw rate by more than LOOSE, and the warning
    quotes the reported determination; the T-bone's fits are not named."""
    from impactsym.runout.api import LOOSE, READING
    from impactsym.runout.chain import reconstruct_from_rest
    from impactsym.runout.leaves import nominal_data

    data, _, _ = nominal_data(ROOT / "examples" / "runout" / "chain_reconstruct_uncertain.json")
    out = reconstruct_from_rest(data)
    d = out["vehicles"][0]["runout"]["fit"]["determination"]
    assert d["per_heading"]["yaw_rate"] * READING[1] > LOOSE["yaw_rate"]
    named = [w for w in out["warnings"] if "determines the separation yaw rate only loosely" in w]
    assert len(named) == 1 and named[0].startswith("vehicles[0] (sedan)")
    assert f"by {d['per_heading']['yaw_rate'] * READING[1]:.2g} rad/s" in named[0]
    tbone = runout(ROOT / "examples" / "runout" / "fit_tbone.json")
    assert not [w for w in tbone["warnings"] if "loosely" in w]
    assert all(set(v["fit"]["determination"]) == {"per_position", "per_heading"} for v in tbone["vehicles"])


def test_determination_in_us_units_says_the_same_in_feet():
    """The T-bone in US units: a rest pose misread by 0.1 m and 1 deg moves the
    striking car's fitted speed by the same m/s (reported in ft/s), its
    direction and yaw rate by the same amounts (1 %), and the table prints
    that line. (The struck car rolls for 5.8 s on four rolling wheels: its
    heading column moves by 15 % between the SI and US fits, states 5e-6 rad/s
    apart, from the integrated sensitivities' noise, docs/runout.md.)"""
    from impactsym.runout.api import misreading
    from impactsym.runout.cli import table

    si = json.loads((ROOT / "examples" / "runout" / "fit_tbone.json").read_text())
    us = copy.deepcopy(si)
    ft, slug = 0.3048, 14.59390293720636
    us["units"] = "US"
    us["runout"]["gravity"] = 9.80665 / ft
    for v in us["vehicles"]:
        v["mass"] /= slug
        v["yaw_inertia"] /= slug * ft**2
        for key in ("wheelbase", "cg_to_front_axle", "track"):
            v[key] /= ft
        v["separation"]["position"] = [p / ft for p in v["separation"]["position"]]
        v["rest"]["position"] = [p / ft for p in v["rest"]["position"]]
    a, b = runout(si), runout(us)
    for va, vb in zip(a["vehicles"][:1], b["vehicles"][:1]):
        ma = misreading(va["fit"]["determination"], "SI")
        mb = misreading(vb["fit"]["determination"], "US")
        assert [x * ft for x in mb["speed"]] == pytest.approx(ma["speed"], rel=0.01)
        assert mb["direction"] == pytest.approx(ma["direction"], rel=0.01)
        assert mb["yaw_rate"] == pytest.approx(ma["yaw_rate"], rel=0.01)
    assert "a rest pose 0.33 ft / 1 deg off moves the fit by: speed" in table(b)
