"""Every notebook in notebooks/ runs top to bottom without an error.

Each notebook is executed with nbclient in a fresh ``python3`` kernel, with the
repository root as working directory (so ``examples/...`` and the ``derive``
package resolve as they do for a reader who opens the notebook there). The
kernel must be this interpreter's environment: jupyter_client resolves the
``python3`` kernelspec shipped by ipykernel to ``sys.executable``, and a first,
injected cell checks ``sys.prefix`` so a stray user-level kernelspec pointing
at another Python fails loudly instead of testing a different install.
"""

import sys
from pathlib import Path

import nbclient
import nbformat
import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((REPO_ROOT / "notebooks").glob("*.ipynb"))
CELL_TIMEOUT = 300  # seconds, per cell

# Minutes: each notebook runs in a fresh kernel (the full suite runs them; the fast loop does not).
pytestmark = pytest.mark.slow

ENVIRONMENT_CHECK = (
    "import sys as _sys\n"
    f"assert _sys.prefix == {sys.prefix!r}, "
    "f'notebook kernel runs in {_sys.prefix}, tests in ' + " + repr(sys.prefix) + "\n"
    "del _sys"
)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_notebook_runs(path):
    nb = nbformat.read(path, as_version=4)
    nb.cells.insert(0, nbformat.v4.new_code_cell(ENVIRONMENT_CHECK))
    client = nbclient.NotebookClient(
        nb,
        timeout=CELL_TIMEOUT,
        kernel_name="python3",
        resources={"metadata": {"path": str(REPO_ROOT)}},
    )
    # Raises nbclient.exceptions.CellExecutionError (with the cell and traceback)
    # on the first cell that raises.
    client.execute()


def test_notebooks_exist():
    """The parametrised test above would silently collect nothing without them."""
    assert {p.name for p in NOTEBOOKS} >= {"01_particle.ipynb", "02_planar.ipynb"}
