"""notebooks/06_models.ipynb against the measured small-overlap barrier crashes.

The notebook runs the Ford Fusion rows of impactsym/data/validation/small_overlap_barrier_tests.csv
through the general model (barrier fixed, μ = percent-of-critical × μ_c) and asserts
its own tolerance. This test executes it, reads its prediction table back, and checks
the tolerance stated here (chosen after seeing the data, README "Models"): for every
Fusion row |ΔV| and the longitudinal ΔV within 8 %, the lateral ΔV within 20 %, the
yaw-rate change within 30 %; median |ΔV| and yaw-rate errors within 3 %.
"""

import json
import sys
from pathlib import Path

import nbclient
import nbformat
import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK = REPO_ROOT / "notebooks" / "06_models.ipynb"
TOLERANCE = {"|dv| err %": 8.0, "dvx err %": 8.0, "dvy err %": 20.0, "dyaw err %": 30.0}
MEDIAN_TOLERANCE = {"|dv| err %": 3.0, "dyaw err %": 3.0}
FUSION_TESTS = {
    "CF10017",
    "CF10023",
    "CF11016",
    "CF10020",
    "CF10028",
    "CF11002",
    "CF11004",
    "CF11012",
    "CF11013",
}
MARKER = "VALIDATION-JSON:"


@pytest.fixture(scope="module")
def fusion_table():
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nb.cells.insert(
        0, nbformat.v4.new_code_cell(f"import sys as _sys\nassert _sys.prefix == {sys.prefix!r}\ndel _sys")
    )
    nb.cells.append(nbformat.v4.new_code_cell(f"print({MARKER!r} + fusion_table.to_json(orient='records'))"))
    nbclient.NotebookClient(
        nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(REPO_ROOT)}}
    ).execute()
    text = "".join(o.get("text", "") for o in nb.cells[-1].outputs)
    return json.loads(text.split(MARKER, 1)[1])


def test_every_fusion_row_is_predicted(fusion_table):
    assert {row["test"] for row in fusion_table} == FUSION_TESTS


@pytest.mark.parametrize("column", sorted(TOLERANCE))
def test_predictions_within_tolerance(fusion_table, column):
    errors = sorted(abs(row[column]) for row in fusion_table)
    assert errors[-1] <= TOLERANCE[column], (column, errors)
    if column in MEDIAN_TOLERANCE:
        assert errors[len(errors) // 2] <= MEDIAN_TOLERANCE[column], (column, errors)


def test_errors_are_against_the_measured_file(fusion_table):
    """The table's measured columns are the file's (magnitudes, signed as predicted)."""
    import csv

    with open(REPO_ROOT / "impactsym" / "data" / "validation" / "small_overlap_barrier_tests.csv") as handle:
        measured = {row["test_id"]: row for row in csv.DictReader(handle)}
    for row in fusion_table:
        source = measured[row["test"]]
        assert abs(row["dvx meas"]) == float(source["dvx_ftps"])
        assert abs(row["dvy meas"]) == float(source["dvy_ftps"])
        assert row["dyaw meas"] == float(source["dyaw_degps"])
