"""Defects a first use found (issue 15, sections 2 and 3): each one pinned here.

Every test feeds the careless input a newcomer would and asserts the one-line
answer (exit 2, the field named) or the quiet behaviour the issue asks for.
"""

import json
from pathlib import Path

import pytest

import impactsym
from impactsym.cli import main
from impactsym.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
SCENE = json.loads((EXAMPLES / "two_car_us.json").read_text())


def run(capsys, *argv):
    """Run ``impactsym`` in-process; return (exit code, stdout, stderr)."""
    code = main([str(arg) for arg in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(capsys, *argv) -> str:
    """The stderr line of a command that must fail with exit 2 and print nothing else."""
    code, out, err = run(capsys, *argv)
    assert code == 2, (code, out, err)
    assert out == "" and err.count("\n") == 1 and err.startswith("impactsym: error: "), err
    return err


# --------------------------------------------------------------------------- 1. scene files

def test_deeply_nested_json_is_one_line(tmp_path, capsys):
    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000)
    assert "nested too deeply" in one_line_error(capsys, "solve", path)


def test_duplicate_json_key_is_refused_naming_it(tmp_path, capsys):
    path = tmp_path / "dup.json"
    text = json.dumps(SCENE)
    # A second "units" would relabel every number of the scene.
    path.write_text(text[:-1] + ', "units": "SI"}')
    err = one_line_error(capsys, "solve", path)
    assert '"units"' in err and "twice" in err


def test_duplicate_key_deep_in_the_scene_is_refused(tmp_path, capsys):
    path = tmp_path / "dup.json"
    path.write_text('{"units": "SI", "impact": {"restitution": 0.1, "restitution": 0.9}}')
    assert '"restitution"' in one_line_error(capsys, "solve", path)


def test_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.json"
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps(SCENE).encode())
    assert impactsym.solve(path).to_json_dict() == impactsym.solve(SCENE).to_json_dict()


@pytest.mark.parametrize("spelling", ["us", "Us", "US"])
def test_units_in_any_letter_case(spelling):
    assert load_scene({**SCENE, "units": spelling}).units == "US"


def test_unknown_units_still_refused():
    with pytest.raises(impactsym.SceneError, match="units: unknown units 'metric'"):
        load_scene({**SCENE, "units": "metric"})


def test_version(capsys):
    code, out, err = run(capsys, "--version")
    assert (code, err) == (0, "")
    assert out.strip() == f"impactsym {impactsym.__version__}"
    assert impactsym.__version__.count(".") >= 1
