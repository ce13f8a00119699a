"""The documentation site builds without a warning and covers what it promises.

The build test runs the documented command (Sphinx, warnings as errors) into a
temporary directory. The other tests check the pages against the code and the
README, so that a new scene key, JSON key, status code, public name, notebook
or report shows up as a failure until it is documented.
"""

import contextlib
import io
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

import impactsym
from impactsym.cli import main

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
CONVENTIONS = (DOCS / "conventions.md").read_text(encoding="utf-8")


def _build(out: Path) -> subprocess.CompletedProcess:
    """The build command of docs/index.md, into ``out``."""
    return subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(DOCS), str(out)],
        check=False,
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=os.environ.copy(),
        timeout=600,
    )


@pytest.mark.slow
def test_site_builds_without_warnings(tmp_path):
    out = tmp_path / "html"
    proc = _build(out)
    assert proc.returncode == 0, f"sphinx failed:\n{proc.stdout}\n{proc.stderr}"
    assert proc.stderr.strip() == "", proc.stderr
    # Every notebook is a page, every report and topic page is built.
    for notebook in sorted((ROOT / "notebooks").glob("*.ipynb")):
        assert (out / "notebooks" / f"{notebook.stem}.html").is_file(), notebook.name
    for page in sorted(DOCS.glob("*.md")):
        assert (out / f"{page.stem}.html").is_file(), page.name
    # Every report of benchmarks/results is included (not copied) in a page of
    # docs/reports: the longest word of its title appears in the built page.
    for report in sorted((ROOT / "benchmarks" / "results").glob("*.md")):
        title = report.read_text(encoding="utf-8").splitlines()[0].lstrip("# ")
        word = max(re.findall(r"\w+", title), key=len)
        page = out / "reports" / f"{report.stem}.html"
        assert page.is_file(), f"no docs/reports/{report.stem}.md for {report.name}"
        assert word in page.read_text(encoding="utf-8"), (report.name, word)
    # The page every README-reader meets first carries the README's picture.
    assert (out / "_images" / "scene.png").is_file()


def _fenced_bash(text: str) -> list[str]:
    return re.findall(r"```bash\n(.*?)```", text, flags=re.DOTALL)


def test_getting_started_has_the_readme_commands():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    page = (DOCS / "getting-started.md").read_text(encoding="utf-8")
    install, tests = _fenced_bash(readme)[:2]
    assert "pip install -e " in install and "pytest" in tests
    assert install in _fenced_bash(page)
    assert tests in _fenced_bash(page)


def test_build_command_is_stated():
    index = (DOCS / "index.md").read_text(encoding="utf-8")
    assert "python -m sphinx -W --keep-going -b html docs docs/_build/html" in index
    assert "docs/_build/" in (ROOT / ".gitignore").read_text(encoding="utf-8").split()


def test_api_page_lists_every_public_name():
    page = (DOCS / "reference" / "api.md").read_text(encoding="utf-8")
    missing = [name for name in impactsym.__all__ if not re.search(rf"impactsym\.{re.escape(name)}\b", page)]
    assert missing == []


def test_conventions_list_every_status_and_flag():
    rows = set(re.findall(r"^\| (\d+) \|", CONVENTIONS, flags=re.MULTILINE))
    assert {str(code) for code in impactsym.STATUS_MESSAGES} <= rows
    assert {str(bit) for bit in impactsym.FLAG_MESSAGES} <= rows


def _keys(value) -> set[str]:
    """Every mapping key in a nested JSON/TOML value."""
    if isinstance(value, dict):
        return set(value).union(*(_keys(v) for v in value.values()))
    if isinstance(value, list):
        return set().union(*(_keys(v) for v in value))
    return set()


def _documented(key: str) -> bool:
    return f"`{key}`" in CONVENTIONS or f'"{key}"' in CONVENTIONS


EXAMPLES = sorted([*(ROOT / "examples").glob("*.json"), *(ROOT / "examples").glob("*.toml")])


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_conventions_document_every_scene_key_of_the_examples(path):
    text = path.read_text(encoding="utf-8")
    data = json.loads(text) if path.suffix == ".json" else tomllib.loads(text)
    assert sorted(key for key in _keys(data) if not _documented(key)) == []


def _command(path: Path) -> str:
    """The command an example is for, from its name (examples/README.md)."""
    for command in ("invert", "reconstruct", "crash3", "fit"):
        if path.name.startswith(command):
            return command
    return "compare" if path.name.startswith("models") else "solve"


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_conventions_document_every_json_key_of_the_commands(path):
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        assert main([_command(path), str(path), "--json"]) == 0
    keys = _keys(json.loads(stdout.getvalue()))
    assert sorted(key for key in keys if not _documented(key)) == []
