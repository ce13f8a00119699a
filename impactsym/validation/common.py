"""What every validation dataset shares: the data folder, its CSV reader, the
comparison of a model with a reference and its statistics.

The data ship inside the package (``impactsym/data/validation/``, sources,
units and known defects in its ``README.md``), so an installed wheel validates
outside a checkout.
"""

from __future__ import annotations

import csv
import math
import statistics
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

DATA_DIR = Path(__file__).resolve().parent.parent / "data" / "validation"


@dataclass(frozen=True)
class Comparison:
    """Model against reference on some rows: percent errors and their statistics."""

    dataset: str
    model: str
    quantity: str
    reference: str
    rows: tuple[tuple[str, float, float], ...]  # (label, model value, reference value)

    @property
    def errors(self) -> list[float]:
        return [100.0 * (m - r) / r for _, m, r in self.rows]

    def stats(self) -> dict[str, Any]:
        return stats(self.errors)


@dataclass
class Dataset:
    """One dataset's tables (rows of dicts) and comparisons, with its notes."""

    name: str
    title: str
    tables: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    comparisons: list[Comparison] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def stats(errors: list[float]) -> dict[str, Any]:
    """n, median |error|, worst |error| and median signed error (bias), in percent."""
    if not errors:
        return {"n": 0, "median": math.nan, "worst": math.nan, "bias": math.nan}
    return {
        "n": len(errors),
        "median": statistics.median(abs(x) for x in errors),
        "worst": max(abs(x) for x in errors),
        "bias": statistics.median(errors),
    }


# ---------------------------------------------------------------- data


@cache
def read(name: str, data_dir: Path = DATA_DIR) -> tuple[dict[str, str], ...]:
    """A CSV of the validation folder as row dicts (text kept as published);
    lines starting with ``#`` are the file's comments (source, units, defects)."""
    with open(data_dir / f"{name}.csv", newline="", encoding="utf-8") as handle:
        return tuple(csv.DictReader(line for line in handle if not line.startswith("#")))


def num(text: str) -> float | None:
    """A published number (U+2212 minus accepted); None for an empty cell."""
    text = text.strip().replace("\u2212", "-")
    return float(text) if text else None


def wrap(angle: float) -> float:
    """An angle in degrees wrapped to (-180, 180]."""
    return -((-angle + 180.0) % 360.0 - 180.0) + 0.0  # + 0.0: no -0.0


def fmt(value: Any, digits: int = 2) -> str:
    """A table cell: blank for None, yes/blank for a bool, n/a for NaN, thousands
    separated from 1000 up, else `digits` decimals."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else ""
    if isinstance(value, float):
        if math.isnan(value):
            return "n/a"
        return f"{value:,.0f}" if abs(value) >= 1000 else f"{value:.{digits}f}"
    return str(value)
