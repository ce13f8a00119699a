"""Issue 22 item 12: every statement of docs/conventions.md about the values
a scene or command accepts, checked against the code. Each case quotes the
statement (the docs must still contain it) and what the code must do."""

import copy
import json
from pathlib import Path

import pytest

import impactsym
from impactsym import load_scene
from impactsym.cli import main
from impactsym.errors import SceneError

ROOT = Path(__file__).resolve().parents[1]
DOC = (ROOT / "docs" / "conventions.md").read_text()
TWO_CAR = json.loads((ROOT / "examples" / "two_car_us.json").read_text())
CRASH3 = json.loads((ROOT / "examples" / "crash3_two_car_us.json").read_text())
RECONSTRUCT = json.loads((ROOT / "examples" / "reconstruct_two_car_si.json").read_text())
OK = None


def _set(data, path, value):
    data = copy.deepcopy(data)
    *head, last = path
    target = data
    for step in head:
        target = target[step]
    if value is _DELETE:
        del target[last]
    else:
        target[last] = value
    return data


class _Deleted:
    """The field removed from the scene (a stable name in the test ids, which
    pytest-xdist's workers must collect alike)."""

    def __repr__(self) -> str:
        return "<deleted>"


_DELETE = _Deleted()

# (statement quoted from the docs, base scene, kind, change (path, value), the field an
# error must name, or OK when the scene must load)
CASES = [
    ('`"SI"` or `"US"` (any letter case)', TWO_CAR, "forward", (("units",), "us"), OK),
    ('`"SI"` or `"US"` (any letter case)', TWO_CAR, "forward", (("units",), "Si"), OK),
    ('`"SI"` or `"US"` (any letter case)', TWO_CAR, "forward", (("units",), "metric"), "units"),
    ('`"SI"` or `"US"` (any letter case)', TWO_CAR, "forward", (("units",), _DELETE), "units"),
    ('`"brach"` is `"rigid"`', TWO_CAR, "forward", (("model",), "brach"), OK),
    ('`"rigid"` (default)', TWO_CAR, "forward", (("model",), _DELETE), OK),
    ('`"rigid"` (default)', TWO_CAR, "forward", (("model",), "rigid_body"), "model"),
    ("list of exactly 2 tables", TWO_CAR, "forward", (("vehicles",), TWO_CAR["vehicles"][:1]), "vehicles"),
    ("list of exactly 2 tables", TWO_CAR, "forward", (("vehicles",), TWO_CAR["vehicles"] * 2), "vehicles"),
    (
        "at most one may be fixed",
        TWO_CAR,
        "forward",
        (("vehicles",), [{"fixed": True}, {"fixed": True}]),
        "vehicles",
    ),
    (
        "number, degrees, required",
        TWO_CAR,
        "forward",
        (("impact", "normal_angle"), _DELETE),
        "impact.normal_angle",
    ),
    ('number (signed μ) or `"critical"`', TWO_CAR, "forward", (("impact", "impulse_ratio"), "critical"), OK),
    ('number (signed μ) or `"critical"`', TWO_CAR, "forward", (("impact", "impulse_ratio"), -0.2), OK),
    (
        'number (signed μ) or `"critical"`',
        TWO_CAR,
        "forward",
        (("impact", "impulse_ratio"), "sticking"),
        "impact.impulse_ratio",
    ),
    (
        "an inverse scene needs a number",
        RECONSTRUCT,
        "inverse",
        (("impact",), {"normal_angle": -30.0, "restitution": 0.1, "impulse_ratio": "critical"}),
        "impact.impulse_ratio",
    ),
    ("non-empty string", TWO_CAR, "forward", (("vehicles", 0, "name"), ""), "vehicles[0].name"),
    (
        "positive number | every moving vehicle",
        TWO_CAR,
        "forward",
        (("vehicles", 1, "mass"), -5),
        "vehicles[1].mass",
    ),
    (
        "positive number | every moving vehicle",
        TWO_CAR,
        "forward",
        (("vehicles", 1, "mass"), 0),
        "vehicles[1].mass",
    ),
    (
        "`true` / `false` (default)",
        TWO_CAR,
        "forward",
        (("vehicles", 1, "fixed"), "yes"),
        "vehicles[1].fixed",
    ),
    ("| `A` | number ≥ 0 |", CRASH3, "crash3", (("vehicles", 0, "crush", "A"), 0.0), OK),
    ("| `A` | number ≥ 0 |", CRASH3, "crash3", (("vehicles", 0, "crush", "A"), -1.0), "vehicles[0].crush.A"),
    ("| `B` | number > 0 |", CRASH3, "crash3", (("vehicles", 0, "crush", "B"), 0.0), "vehicles[0].crush.B"),
    (
        "| `width` | number > 0 |",
        CRASH3,
        "crash3",
        (("vehicles", 0, "crush", "width"), 0.0),
        "vehicles[0].crush.width",
    ),
    (
        "list of 2, 4 or 6 numbers ≥ 0",
        CRASH3,
        "crash3",
        (("vehicles", 0, "crush", "depths"), [1, 2, 3]),
        "vehicles[0].crush.depths",
    ),
    (
        "list of 2, 4 or 6 numbers ≥ 0",
        CRASH3,
        "crash3",
        (("vehicles", 0, "crush", "depths"), [1, -2]),
        "vehicles[0].crush.depths",
    ),
    ("list of 2, 4 or 6 numbers ≥ 0", CRASH3, "crash3", (("vehicles", 0, "crush", "depths"), [0, 2]), OK),
    (
        "number, degrees, \\|α\\| < 90",
        CRASH3,
        "crash3",
        (("vehicles", 0, "crush", "pdof"), 90.0),
        "vehicles[0].crush.pdof",
    ),
    ("number, degrees, \\|α\\| < 90", CRASH3, "crash3", (("vehicles", 0, "crush", "pdof"), -89.0), OK),
]


def _error_field(data, kind):
    try:
        if kind == "crash3":
            impactsym.crash3(data)
        else:
            load_scene(data, kind=kind)
    except SceneError as exc:
        return exc.field or str(exc)
    return OK


@pytest.mark.parametrize("statement, base, kind, change, field", CASES, ids=lambda v: str(v)[:40])
def test_accepted_values_are_as_documented(statement, base, kind, change, field):
    assert statement in DOC, f"the docs no longer say {statement!r}"
    got = _error_field(_set(base, *change), kind)
    if field is OK:
        assert got is OK
    else:
        assert got is not OK and str(got).startswith(field), got


def test_sweep_prints_json_as_documented(capsys):
    statement = "`sweep --json` prints that summary as one JSON object"
    assert statement in DOC
    scene = ROOT / "examples" / "two_car_us.json"
    assert main(["sweep", str(scene), "--vary", "e=0.1:0.3:3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["rows"] == 3 and "dV1" in json.dumps(data)
    assert "No JSON: it prints" not in DOC and "(`sweep` prints a summary only)" not in DOC


def test_crash3_options_as_documented():
    for statement, options, error in [
        ('`"dissipated"` (default) or `"absorbed"`', {"energy": "absorbed"}, None),
        ('`"dissipated"` (default) or `"absorbed"`', {"energy": "stored"}, "crash3.energy"),
        ('`"crash3"` (default) or `"woolley"`', {"correction": "woolley"}, None),
        ('`"crash3"` (default) or `"woolley"`', {"correction": "none"}, "crash3.correction"),
    ]:
        assert statement in DOC
        data = {**CRASH3, "crash3": options}
        try:
            impactsym.crash3(data)
            got = None
        except SceneError as exc:
            got = exc.field
        assert got == error, (options, got)
