"""Sphinx configuration of the impactsym documentation.

Build (from the repository root; no network, notebooks are not executed):

    python -m sphinx -W --keep-going -b html docs docs/_build/html

Pages are Markdown (MyST). Notebooks are rendered by myst-nb from the outputs
stored in them, never executed here: tests/test_notebooks.py executes them.
Topic pages dropped into docs/ (docs/<topic>.md) join the user guide through
the glob in index.md without an edit here.
"""

import json
import re
import runpy
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# autodoc imports the package from this checkout, never from an installed copy.
sys.path.insert(0, str(ROOT))

project = "impactsym"
author = "impactsym contributors"
# The version is written once, in impactsym/_version.py (pyproject.toml reads it too).
release = runpy.run_path(str(ROOT / "impactsym" / "_version.py"))["__version__"]
version = release

extensions = [
    "myst_nb",  # Markdown pages (MyST) and notebooks
    "sphinx.ext.autodoc",
    "numpydoc",  # plain docstrings render as written; numpy sections if one has them
    "sphinx.ext.mathjax",
]

exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints"]

# MyST: $...$ and $$...$$ math, ::: fences for admonitions, anchors for
# headings (links to #sections).
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence"]
myst_heading_anchors = 3
# A heading that skips a level (## then ####) renders fine; it is style, not an error.
suppress_warnings = ["myst.header"]

# Notebooks: render the stored outputs; never run a kernel at build time.
nb_execution_mode = "off"

# Docstrings: `name` in a docstring is code, as it reads in the source.
default_role = "code"
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
# Reading docstrings needs no compiler: numba is replaced by a stand-in while
# autodoc imports the package (kernels are never called at build time).
autodoc_mock_imports = ["numba"]
autodoc_default_options = {"members": True, "undoc-members": False}
# Members are listed by autodoc (:members:), not again in a numpydoc table.
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
# Only the build's warnings decide; numpydoc's style checks are not run.
numpydoc_validation_checks = set()

html_theme = "alabaster"
html_title = f"impactsym {release}"
# MathJax is loaded from a CDN by the reader's browser; the build itself needs no network.

# The docstrings are plain text, where |x| is an absolute value (|ΔV|, |P|,
# |e_m|), never a reStructuredText substitution. Escape such bars before
# docutils reads them, outside ``literals`` and `code` spans (where a backslash
# would be shown). Everything else in a docstring is left as written.
_CODE_SPAN = re.compile(r"(``.+?``|`[^`]+`)")
_BAR = re.compile(r"(?<!\\)\|")


def _escape_bars(line: str) -> str:
    pieces = _CODE_SPAN.split(line)
    return "".join(p if i % 2 else _BAR.sub(r"\\|", p) for i, p in enumerate(pieces))


def _plain_docstring(app, what, name, obj, options, lines):
    lines[:] = [_escape_bars(line) for line in lines]


def _copy_notebooks() -> None:
    """The notebooks live in notebooks/ (tests execute them there); the site renders
    copies in docs/notebooks/ (git-ignored), made afresh at every build. A copy,
    not a link: a link made packaging tools ship the notebooks under docs/ only."""
    here = Path(__file__).resolve().parent
    target = here / "notebooks"
    if target.is_symlink():
        target.unlink()
    shutil.rmtree(target, ignore_errors=True)
    target.mkdir()
    for notebook in sorted((here.parent / "notebooks").glob("*.ipynb")):
        shutil.copy2(notebook, target / notebook.name)


_copy_notebooks()


def _python_notebook(app, docname, source):
    """Every notebook of impactsym is Python: one saved without kernel metadata
    gets ``language_info`` = python, so its cells are highlighted instead of
    warning "No source code lexer found" (the file itself is left as it is)."""
    if not str(app.env.doc2path(docname)).endswith(".ipynb"):
        return
    notebook = json.loads(source[0])
    metadata = notebook.setdefault("metadata", {})
    if "language_info" not in metadata and "kernelspec" not in metadata:
        metadata["language_info"] = {"name": "python"}
        source[0] = json.dumps(notebook)


def setup(app):
    app.connect("autodoc-process-docstring", _plain_docstring)
    app.connect("source-read", _python_notebook)
