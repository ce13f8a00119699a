"""Packaging and style: the wheel adds one import name, the sdist carries the
tests' inputs, and the code passes the linter (ruff, configured in pyproject.toml)."""

from __future__ import annotations

import os
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
    assert {
        "impactsym/_generated/__init__.py",
        "impactsym/_generated/planar.py",
        "impactsym/testing/reference.py",
    } <= set(names)
    assert not any("derive/" in name for name in names)


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
