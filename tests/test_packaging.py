"""Packaging and style: the wheel adds one import name and is whole (installed
in a fresh venv, every command runs outside the checkout and prints what the
checkout prints), the sdist carries the tests' inputs, and the code passes the
linter (ruff, configured in pyproject.toml)."""

from __future__ import annotations

import ast
import os
import shutil
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: Directories the tests (and the notebooks they run) read from a checkout or an sdist.
SDIST_DIRS = (
    "impactsym",
    "generated",
    "derive",
    "tests",
    "benchmarks",
    "examples",
    "notebooks",
)


def test_ruff_check_passes():
    """Style holds without review: ``ruff check .`` (rules and exclusions in pyproject.toml)."""
    proc = subprocess.run(
        [sys.executable, "-m", "ruff", "check", "--no-cache", "--output-format", "concise", "."],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_ruff_format_is_clean():
    """Layout holds without review: ``ruff format --check .`` (generated/ excluded)."""
    proc = subprocess.run(
        [sys.executable, "-m", "ruff", "format", "--check", "--no-cache", "."],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


@pytest.fixture(scope="module")
def dists(tmp_path_factory):
    """The sdist, and the wheel built from it (``python -m build``, no isolation:
    hatchling and build come with the test extra), as (sdist, wheel) paths."""
    out = tmp_path_factory.mktemp("dist")
    proc = subprocess.run(
        [sys.executable, "-m", "build", "--no-isolation", "--outdir", str(out), str(ROOT)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    (sdist,), (wheel,) = sorted(out.glob("*.tar.gz")), sorted(out.glob("*.whl"))
    return sdist, wheel


@pytest.mark.slow
def test_the_wheel_installs_only_the_impactsym_import_name(dists):
    _, wheel = dists
    names = zipfile.ZipFile(wheel).namelist()
    top = {name.split("/")[0] for name in names}
    info = {name for name in top if name.endswith(".dist-info")}
    assert top - info == {"impactsym"} and len(info) == 1 and next(iter(info)).startswith("impactsym-"), (
        sorted(top)
    )
    # generated/ is mapped into the package; derive/ (SymPy, build time only) is not shipped
    assert {"impactsym/_generated/__init__.py", "impactsym/_generated/planar.py"} <= set(names)
    assert not any("derive/" in name for name in names)
    # test support (mpmath, the test extra) stays in the checkout and the sdist
    assert not any(name.startswith("impactsym/testing/") for name in names)


@pytest.mark.slow
def test_the_wheel_ships_the_validation_data_once_and_no_test_dependency(dists):
    """What `validate` reads is in the wheel, each file once; no shipped module
    imports a test-only package (mpmath, pytest, hypothesis)."""
    _, wheel = dists
    archive = zipfile.ZipFile(wheel)
    names = archive.namelist()
    shipped = {name.rpartition("/")[2] for name in names if name.endswith(".csv")}
    data = ROOT / "impactsym" / "data"
    assert {path.name for path in data.rglob("*.csv")} == shipped
    assert len([n for n in names if n.endswith(".csv")]) == len(shipped)  # no table twice
    for name in (n for n in names if n.endswith(".py")):
        tree = ast.parse(archive.read(name), name)
        imported = {
            alias.name for node in ast.walk(tree) if isinstance(node, ast.Import) for alias in node.names
        }
        imported |= {
            node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module
        }
        assert not {m.split(".")[0] for m in imported} & {"mpmath", "pytest", "hypothesis"}, name


@pytest.mark.slow
def test_the_sdist_carries_what_the_tests_read(dists):
    sdist, _ = dists
    with tarfile.open(sdist) as tar:
        members = {Path(*Path(name).parts[1:]).as_posix() for name in tar.getnames()}
    wanted = {
        path.relative_to(ROOT).as_posix()
        for top in SDIST_DIRS
        for path in (ROOT / top).rglob("*")
        if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".pyc"
    }
    assert wanted <= members, sorted(wanted - members)[:10]


@pytest.mark.slow
def test_the_installed_wheel_solves_with_its_own_generated_code(dists, tmp_path):
    """Installed alone (no checkout on sys.path), the wheel finds its kernels in
    impactsym._generated and solves an example scene."""
    _, wheel = dists
    site = tmp_path / "site"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "--no-deps",
            "--no-index",
            "--quiet",
            "--target",
            str(site),
            str(wheel),
        ],
        check=True,
        timeout=300,
    )
    code = (
        "import sys; from pathlib import Path\n"
        "sys.path = [p for p in sys.path if not (Path(p or '.') / 'generated').is_dir()]\n"
        f"sys.path.insert(0, {str(site)!r})\n"
        "import impactsym\n"
        "from impactsym import _kernels\n"
        "assert impactsym.__file__.startswith(sys.path[0]), impactsym.__file__\n"
        "assert _kernels.generated.__name__ == 'impactsym._generated', _kernels.generated.__name__\n"
        f"print(impactsym.solve({str(ROOT / 'examples' / 'intersection_si.toml')!r}).TL)\n"
    )
    proc = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env={k: v for k, v in os.environ.items() if k != "PYTHONPATH"},
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert float(proc.stdout.strip().splitlines()[-1]) > 0.0


#: Every command, as a user runs it on their own files (copied from examples/ into a
#: folder outside the checkout). Each prints the same as from the checkout.
WHOLE_PACKAGE_RUNS = [
    ["--version"],
    ["solve", "two_car_us.json", "--json"],
    ["solve", "intersection_si.toml", "--plot", "scene.png"],
    ["invert", "invert_two_car_si.json"],
    ["reconstruct", "reconstruct_intersection_us_casefile.json"],
    [
        "reconstruct",
        "reconstruct_intersection_uncertain.json",
        "--uncertainty",
        "--draws",
        "2000",
        "--seed",
        "1",
    ],
    ["crash3", "crash3_two_car_us.json", "--json"],
    ["compare", "models_two_car_us.json"],
    ["sweep", "two_car_us.json", "--vary", "e=0:0.3:4", "--vary", "mu=0:0.5:3", "--no-progress"],
    ["sample", "two_car_us.json", "--dist", "e=uniform:0:0.3", "-n", "2000", "--seed", "12", "--no-progress"],
    # `validate` alone prints a summary of the same report (7 s a run since the
    # fit's grid-search rescue): the markdown form runs it all, with the figures
    ["validate", "--markdown", "--plots", "figures"],
    ["runout", "runout/sedan.json", "--json"],
    ["fit", "fit_intersection_us.json", "--json"],
    ["edr", "edr_cf09009b_pulse_g.csv", "--json"],
    # compiling every driver takes minutes: the installed command is checked to parse and start
    ["compile", "--help"],
]


@pytest.fixture(scope="module")
def installed(dists, tmp_path_factory):
    """A fresh venv with the wheel installed (pip, no index), seeing the already
    installed run-time dependencies (numpy, numba, the extras) through a .pth
    file instead of downloading them; and a work folder outside the checkout."""
    import numpy

    _, wheel = dists
    venv = tmp_path_factory.mktemp("venv")
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    python = venv / "bin" / "python"
    site = subprocess.run(
        [str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    Path(site, "installed_dependencies.pth").write_text(str(Path(numpy.__file__).parents[1]) + "\n")
    subprocess.run(
        [str(python), "-m", "pip", "install", "--no-deps", "--no-index", "--quiet", str(wheel)],
        check=True,
        timeout=300,
    )
    work = tmp_path_factory.mktemp("outside")
    for argv in WHOLE_PACKAGE_RUNS:
        for arg in argv:
            if (ROOT / "examples" / arg).is_file():
                (work / arg).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy(ROOT / "examples" / arg, work / arg)
    return venv / "bin" / "impactsym", work


def _run(command: list[str], cwd: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    return subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=900, env=env)


@pytest.mark.slow
@pytest.mark.parametrize("argv", WHOLE_PACKAGE_RUNS, ids=" ".join)
def test_every_command_runs_from_the_installed_wheel_outside_the_checkout(installed, argv, tmp_path):
    script, work = installed
    done = _run([str(script), *argv], work)
    assert done.returncode == 0, done.stderr[-3000:]
    where = _run([str(script.parent / "python"), "-c", "import impactsym; print(impactsym.__file__)"], work)
    assert not where.stdout.startswith(str(ROOT)), where.stdout  # the installed copy, not the checkout
    # The checkout prints the same (figures go to a folder of their own).
    mine = tmp_path / "checkout"
    shutil.copytree(work, mine, ignore=shutil.ignore_patterns("figures", "*.png"))
    here = subprocess.run(
        [sys.executable, "-m", "impactsym", *argv],
        cwd=mine,
        capture_output=True,
        text=True,
        timeout=900,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert here.returncode == 0, here.stderr[-3000:]
    assert done.stdout == here.stdout
    if "--plot" in argv or "--plots" in argv:
        made = work / argv[argv.index("--plot") + 1] if "--plot" in argv else work / "figures"
        theirs = len(list((mine / "figures").glob("*.png")))
        assert made.exists() and (made.is_file() or len(list(made.glob("*.png"))) == theirs > 0)
