"""Issue 22 item 14: the README's first command installs what the README's
examples use. Each example runs with only the optional packages of the
extras that command installs (the others are made missing, as on a fresh
machine), and none stops with "pip install 'impactsym[...]'"; .ci/run stays
the README's test command."""

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import tomllib

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
FIRST, TESTS = re.findall(r"```bash\n(.*?)```", README, flags=re.DOTALL)[:2]

#: import names of the distributions the extras add (pyproject's names differ for some)
IMPORT_NAME = {"dask[distributed]": "dask", "SALib": "SALib", "pyyaml": "yaml"}

# What the README shows, as command lines run from the checkout (each is quoted
# from the README's text, so that a new example needs a line here).
EXAMPLES = [
    (
        "impactsym reconstruct examples/reconstruct_intersection_us_casefile.json",
        ["reconstruct", "examples/reconstruct_intersection_us_casefile.json"],
    ),
    (
        "impactsym solve examples/intersection_si.toml --plot docs/scene.png",
        ["solve", "examples/intersection_si.toml", "--plot", "{tmp}/scene.png"],
    ),
    (
        "impactsym compare SCENE [--markdown] [--plot]",
        ["compare", "examples/models_two_car_us.json", "--plot", "{tmp}/compare.png"],
    ),
    (
        "impactsym sweep SCENE --vary e=0:0.4:41",
        ["sweep", "examples/two_car_us.json", "--vary", "e=0:0.4:41", "-o", "{tmp}/rows.parquet", "--json"],
    ),
    (
        "impactsym sample SCENE --dist e=uniform:0:0.3 -n N --seed S",
        ["sample", "examples/two_car_us.json", "--dist", "e=uniform:0:0.3", "-n", "1000", "--seed", "1"],
    ),
    (
        "--uncertainty [--draws N] [--seed S] [--sobol] [--plot OUT.png]",
        [
            "reconstruct",
            "examples/reconstruct_intersection_uncertain.json",
            "--uncertainty",
            "--draws",
            "1000",
            "--seed",
            "1",
            "--sobol",
            "--plot",
            "{tmp}/u.png",
        ],
    ),
    ("impactsym validate [--markdown]", ["validate"]),
    ("impactsym runout examples/runout/sedan.json", ["runout", "examples/runout/sedan.json"]),
    ("impactsym fit examples/fit_intersection_us.json", ["fit", "examples/fit_intersection_us.json"]),
]

# Runs every example with the other extras' packages missing: an import of
# one raises ModuleNotFoundError and importlib.util.find_spec returns None.
RUNNER = r"""
import importlib.abc, importlib.util, json, sys
BLOCKED = set(json.loads(sys.argv[1]))
class Missing(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None
sys.meta_path.insert(0, Missing())
_find_spec = importlib.util.find_spec
importlib.util.find_spec = lambda name, package=None: (
    None if name.split(".")[0] in BLOCKED else _find_spec(name, package))
from impactsym.cli import main
codes = [main(args) for args in json.loads(sys.argv[2])]
import impactsym
u = impactsym.uncertainty("examples/reconstruct_intersection_uncertain.json", command="reconstruct",
                          draws=1000, seed=1)
u.summary
print("CODES", json.dumps(codes))
"""


def _extras(command: str) -> set[str]:
    found = re.search(r'pip install -e "\.\[([^\]]*)\]"', command)
    return set(found.group(1).split(",")) if found else set()


def _modules(requirements) -> set[str]:
    names = set()
    for requirement in requirements:
        name = re.split(r"[<>=!~; ]", requirement, maxsplit=1)[0]
        names.add(IMPORT_NAME.get(name, name).split("[")[0])
    return names


@pytest.mark.slow
def test_the_first_command_installs_what_the_examples_use(tmp_path):
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    installed = _extras(FIRST)
    assert installed, "the README's first command installs only the core"
    kept = _modules(r for extra in installed for r in extras[extra])
    blocked = (
        _modules(r for name, reqs in extras.items() if name not in ("test", "docs", "derive") for r in reqs)
        - kept
    )
    for quoted, _ in EXAMPLES:
        assert quoted in README, quoted
    runs = [[a.format(tmp=tmp_path) for a in args] for _, args in EXAMPLES]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    run = subprocess.run(
        [sys.executable, "-c", RUNNER, json.dumps(sorted(blocked)), json.dumps(runs)],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert "pip install 'impactsym[" not in run.stderr, run.stderr
    assert run.returncode == 0, run.stderr[-2000:]
    codes = json.loads(run.stdout.split("CODES", 1)[1])
    assert codes == [0] * len(EXAMPLES), (codes, run.stderr[-2000:])


def test_ci_runs_the_readme_test_command():
    ci = (ROOT / ".ci" / "run").read_text().strip().splitlines()[-1]
    assert ci == TESTS.strip()


def test_getting_started_has_the_same_first_command():
    page = (ROOT / "docs" / "getting-started.md").read_text(encoding="utf-8")
    assert FIRST in page
