"""The result of an uncertainty propagation: streaming statistics, the summary, JSON, tables."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..batch.quantiles import percentiles
from ..residue import without_json_residue

__all__ = ["Uncertainty", "Stats", "KEEP", "HISTOGRAM_BINS", "MIN_INTERVAL_DRAWS", "PERCENTILES"]

#: Accepted draws kept for the caller (`Uncertainty.draws`); statistics use every draw.
KEEP = 1 << 20
#: Bins of the streaming histograms that give percentiles beyond KEEP accepted draws.
HISTOGRAM_BINS = 1 << 16
PERCENTILES = (5.0, 50.0, 95.0)
#: Fewest accepted draws for a 90 % interval: with N draws the 5th and 95th
#: percentiles sit N/20 order statistics in from the extremes; at 100 that is
#: 5 draws each side, below it p5 and p95 are little more than min and max.
MIN_INTERVAL_DRAWS = 100


class Stats:
    """Count, mean, sd (sums shifted by the nominal value) and percentiles of
    one output over accepted draws: exact from the values kept in memory up to
    `KEEP` draws, beyond that from a `HISTOGRAM_BINS`-bin histogram whose
    range is set by the first KEEP values and more (widened by half their span
    each side; values outside it are counted and bounded by the running min
    and max)."""

    def __init__(self, shift: float):
        self.shift = shift if math.isfinite(shift) else 0.0
        self.n, self.s1, self.s2 = 0, 0.0, 0.0
        self.kept: list[np.ndarray] = []
        self.kept_n = 0
        self.edges = self.hist = None
        self.low_count = self.high_count = 0
        self.lo, self.hi = math.inf, -math.inf

    def add(self, x: np.ndarray, owned: bool = False) -> None:
        """Add the values `x` (`owned`: the caller hands them over, they are
        kept without a copy)."""
        if x.size == 0:
            return
        d = x - self.shift
        self.n += x.size
        self.s1 += float(d.sum())
        d *= d
        self.s2 += float(d.sum())
        low, high = float(x.min()), float(x.max())  # NaN if any value is NaN
        self.lo = low if math.isnan(low) or low < self.lo else self.lo
        self.hi = high if math.isnan(high) or high > self.hi else self.hi
        if self.hist is None and self.n <= KEEP:
            self.kept.append(x if owned else x.copy())
            self.kept_n = self.n
            return
        if self.hist is None:  # past KEEP: the histogram starts from the values kept
            first = np.concatenate(self.kept + [x])
            span = max(float(first.max() - first.min()), abs(self.shift) * 1e-12, 1e-300)
            self.edges = (float(first.min()) - span / 2, float(first.max()) + span / 2)
            self.hist = np.zeros(HISTOGRAM_BINS, dtype=np.int64)
            self.kept, x = [], first
        a, b = self.edges
        pos = (x - a) * (HISTOGRAM_BINS / (b - a))
        inside = (pos >= 0) & (pos < HISTOGRAM_BINS)
        self.low_count += int(np.count_nonzero(pos < 0))
        self.high_count += int(np.count_nonzero(pos >= HISTOGRAM_BINS))
        self.hist += np.bincount(pos[inside].astype(np.intp), minlength=HISTOGRAM_BINS)

    @property
    def mean(self) -> float:
        return self.shift + self.s1 / self.n if self.n else math.nan

    @property
    def sd(self) -> float:
        if self.n < 2:
            return math.nan
        var = (self.s2 - self.s1 * self.s1 / self.n) / (self.n - 1)
        return math.sqrt(max(var, 0.0))

    def percentiles(self, q=PERCENTILES) -> list[float]:
        if self.n == 0:
            return [math.nan] * len(q)
        if self.hist is None:  # exact: numpy.percentile's values, without sorting
            return [float(v) for v in percentiles(self.kept, tuple(q), (self.lo, self.hi))]
        return [self._from_histogram(p) for p in q]

    def _from_histogram(self, p: float) -> float:
        rank = p / 100.0 * (self.n - 1)
        if rank < self.low_count:
            return self.lo
        cum = np.cumsum(self.hist) + self.low_count
        k = int(np.searchsorted(cum, rank, side="right"))
        if k >= HISTOGRAM_BINS:
            return self.hi
        a, b = self.edges
        width = (b - a) / HISTOGRAM_BINS
        before = cum[k - 1] if k else self.low_count
        frac = (rank - before + 0.5) / max(self.hist[k], 1)
        return float(a + (k + min(max(frac, 0.0), 1.0)) * width)


# --------------------------------------------------------------------------- the result


@dataclass
class Uncertainty:
    """The uncertainty of a command's answers (scene units).

    `summary`: DataFrame, one row per output: nominal, mean, sd, p5, p50, p95,
    sd_linear and the three largest budget shares. `budget`: output → input →
    share of the linearised variance. `draws`: DataFrame of (at most `KEEP`)
    accepted draws, inputs then outputs. `rejected`: reason → count. `notes`:
    what the flags at the nominal values mean given the draws. `sobol`: output
    → {"S1": {input: index}, "ST": {...}} or None."""

    command: str
    n_draws: int
    accepted: int
    rejected: dict
    inputs: tuple[str, ...]
    outputs: dict
    budget: dict
    kept: list = field(repr=False)
    notes: list = field(default_factory=list)
    sobol: dict | None = None
    seed: int | None = None
    _draws: Any = field(default=None, repr=False)

    @property
    def draws(self):
        """The accepted draws (at most `KEEP`) as a DataFrame, built on first use."""
        if self._draws is None:
            self._draws = _frame(self.kept)
        return self._draws

    @property
    def summary(self):
        import pandas as pd

        rows = {}
        for path, o in self.outputs.items():
            top = sorted(self.budget.get(path, {}).items(), key=lambda kv: -abs(kv[1]))[:3]
            rows[path] = {
                **{k: o[k] for k in ("nominal", "mean", "sd", "p5", "p50", "p95", "sd_linear")},
                "budget": ", ".join(f"{name} {share:.0%}" for name, share in top),
            }
        return pd.DataFrame.from_dict(rows, orient="index")

    def to_json_dict(self) -> dict:
        """The ``"uncertainty"`` object of conventions.md (non-finite → null)."""

        def num(x):
            return float(x) if x is not None and math.isfinite(x) else None

        outputs = {
            path: {
                **{k: num(o[k]) for k in ("nominal", "mean", "sd", "p5", "p50", "p95", "sd_linear")},
                "budget": {k: num(v) for k, v in self.budget.get(path, {}).items()},
            }
            for path, o in self.outputs.items()
        }
        out = {
            "draws": self.n_draws,
            "accepted": self.accepted,
            "rejected": dict(self.rejected),
            "inputs": list(self.inputs),
            "outputs": outputs,
        }
        if self.notes:
            out["notes"] = list(self.notes)
        if self.sobol is not None:
            out["sobol"] = self.sobol
        return out

    def table(self, units: str | None = None) -> str:
        """Nominal, mean, 90 % interval and the three largest budget shares per output."""
        lines = [
            f"uncertainty ({self.command}): {self.n_draws} draws, {self.accepted} accepted"
            + (f", seed {self.seed}" if self.seed is not None else "")
        ]
        if self.rejected:
            lines.append("rejected: " + ", ".join(f"{k} {v}" for k, v in self.rejected.items()))
        lines += [f"note: {n}" for n in self.notes]
        width = max(len(p) for p in self.outputs) + 2
        lines += [
            "",
            (f"{'output':<{width}}{'nominal':>12}{'mean':>12}{'90 % interval':>26}  largest budget shares"),
        ]
        shown = ("nominal", "mean", "p5", "p95")  # rounding residue shown as 0 (impactsym.residue)
        outputs = {p: {k: o[k] for k in shown if o[k] is not None} for p, o in self.outputs.items()}
        outputs = without_json_residue({"uncertainty": {"outputs": outputs}})["uncertainty"]["outputs"]
        for path, o in self.outputs.items():
            o = {**o, **outputs[path]}
            top = sorted(self.budget.get(path, {}).items(), key=lambda kv: -abs(kv[1]))[:3]
            interval = f"[{_cell(o['p5'])}, {_cell(o['p95'])}]"
            lines.append(
                f"{path:<{width}}{_cell(o['nominal']):>12}{_cell(o['mean']):>12}"
                f"{interval:>26}  " + ", ".join(f"{n} {s:.0%}" for n, s in top)
            )
        return "\n".join(lines)


def _cell(x) -> str:
    return "n/a" if x is None or not math.isfinite(x) else f"{x:.5g}"


def _frame(kept: list):
    import pandas as pd

    if not kept:
        return pd.DataFrame()
    columns = {k: np.concatenate([part[k] for part in kept])[:KEEP] for k in kept[0]}
    return pd.DataFrame(columns)
