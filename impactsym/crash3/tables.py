"""CRASH3/EDCRASH default stiffness by vehicle category and face, and class dimensions.

Data, not formulas: the tables of R. W. Day and R. L. Hargens, "An Overview of the
Way EDCRASH Computes Delta-V", SAE 870045, Tables 1-2 (citing the EDCRASH program
manual), shipped as ``impactsym/data/crash3_stiffness_categories.csv`` and
``crash3_class_dimensions.csv`` (see ``impactsym/data/README.md`` for the
misprints and how they are handled). Values are kept as published, in CRASH3's
US units (A lb/in, B lb/in², lengths in inches, k² in in²); :func:`stiffness`
converts to the scene's units.

Categories: 1-6 passenger cars by wheelbase (5 and 6 share one row), 7 vans and
"other" (pickup-based utilities), 8 pickups, 9 front-wheel-drive cars. Faces:
``front``, ``rear``, ``side``; side values exist for categories 1-6 only, rear
for 1-8. The table's G is never used: the crush energy always takes
G = A²/(2B) (derive/crash3.py), which also makes the category-2 rear misprint
of G harmless.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

__all__ = [
    "CATEGORIES",
    "CLASSES",
    "FACES",
    "INCH",
    "LBF",
    "Stiffness",
    "class_dimensions",
    "stiffness",
]

DATA = Path(__file__).resolve().parent.parent / "data"
FACES = ("front", "rear", "side")
CATEGORIES = tuple(range(1, 10))
LBF = 4.4482216152605  # N per pound-force (exact by definition)
INCH = 0.0254  # m per inch (exact by definition)
# Category 6 shares category 5's row in the source table.
_SAME_ROW = {6: 5}
_DESCRIPTION = {
    7: "vans and other (pickup-based utilities): front and rear only",
    8: "pickups: front and rear only",
    9: "front-wheel-drive cars: front only",
}


@dataclass(frozen=True)
class Stiffness:
    """A category's stiffness for one face: A [lb/in | N/m], B [lb/in² | N/m²]."""

    category: int
    face: str
    A: float
    B: float


@lru_cache(maxsize=1)
def _stiffness_table() -> dict[tuple[int, str], tuple[float, float]]:
    """(category, face) → (A lb/in, B lb/in²) as published."""
    with open(DATA / "crash3_stiffness_categories.csv", newline="") as handle:
        return {
            (int(row["category"]), row["face"]): (float(row["A_lb_per_in"]), float(row["B_lb_per_in2"]))
            for row in csv.DictReader(handle)
        }


def stiffness(category: int, face: str, units: str = "US") -> Stiffness:
    """The default A and B of a category (1-9) and face in the scene's units
    (US: lb/in, lb/in² as published; SI: N/m, N/m²). ValueError naming the
    missing combination (e.g. a pickup's side)."""
    if face not in FACES:
        raise ValueError(f"face must be one of {', '.join(FACES)}, got {face!r}")
    if category not in CATEGORIES:
        raise ValueError(f"category must be an integer 1-9, got {category!r}")
    key = (_SAME_ROW.get(category, category), face)
    if key not in _stiffness_table():
        raise ValueError(
            f"category {category} has no {face} stiffness ({_DESCRIPTION.get(category, 'no such row')})"
        )
    a, b = _stiffness_table()[key]
    if units == "SI":
        a, b = a * LBF / INCH, b * LBF / INCH**2
    return Stiffness(category, face, a, b)


@lru_cache(maxsize=1)
def _class_table() -> dict[str, dict[str, str]]:
    """Column (class_1 ... class_10_movable_barrier) → quantity → printed text."""
    with open(DATA / "crash3_class_dimensions.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    columns = [c for c in rows[0] if c != "quantity"]
    return {col: {row["quantity"]: row[col] for row in rows} for col in columns}


CLASSES = (1, 2, 3, 4, 5, 6, 7, 10)


def class_dimensions(vehicle_class: int) -> dict[str, float]:
    """Class default dimensions as published (inches, in², lb·s²/in, lb), for
    classes 1-6 (cars by wheelbase), 7 (vans) and 10 (movable barrier); the
    wheelbase range is left out (text). ``k_squared_in2`` is the yaw radius of
    gyration squared: yaw inertia = mass · k²."""
    column = next((c for c in _class_table() if c.split("_")[1] == str(vehicle_class)), None)
    if vehicle_class not in CLASSES or column is None:
        raise ValueError(f"class must be one of {', '.join(map(str, CLASSES))}, got {vehicle_class!r}")
    return {q: float(v) for q, v in _class_table()[column].items() if q != "wheelbase_range_in"}
