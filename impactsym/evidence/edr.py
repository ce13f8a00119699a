"""Event data recorder files: a crash pulse (delta-V) and a pre-crash speed table.

A CSV file with a header row naming each column and its unit in brackets
(conventions.md, "Reconstruction from evidence"):

- crash pulse: ``time [ms]`` and either cumulative ``longitudinal_delta_v [mph]``,
  ``lateral_delta_v [mph]`` or ``longitudinal_acceleration [g]``,
  ``lateral_acceleration [g]`` (any unit pint reads; ``g`` is standard gravity
  here, not the gram). Accelerations are integrated by the trapezoid rule from
  zero at the first sample.
- pre-crash table: ``time [s]`` and ``speed [mph]``.

Lateral values in the file are positive to the right (Bosch CDR reports) or to
the left (``lateral_positive``); results are in the vehicle's axes of
conventions.md: longitudinal forward, lateral LEFT, direction counter-clockwise
from forward. The peak is the sample where the resultant delta-V is largest.

A pulse has ended when the resultant delta-V changes by 0.8 km/h or less over
the last 20 ms of the record (the end of event of 49 CFR 563.5); a pulse still
running at the end understates the delta-V (a warning).
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import SceneError
from ..result import json_number
from ..scene.units import GRAVITY, STANDARD_GRAVITY, registry

END_WINDOW_MS = 20.0
END_CHANGE = 0.8 / 3.6  # m/s (0.8 km/h)
SPEED_UNIT = {"SI": "m/s", "US": "ft/s"}
PULSE_COLUMNS = {
    "delta_v": ("longitudinal_delta_v", "lateral_delta_v"),
    "acceleration": ("longitudinal_acceleration", "lateral_acceleration"),
}
_HEADER = re.compile(r"^\s*([A-Za-z_]+)\s*\[(.+)\]\s*$")


@dataclass
class Pulse:
    """A crash pulse in SI (time s, delta-V m/s, lateral positive left) and its peak."""

    time: np.ndarray
    longitudinal: np.ndarray
    lateral: np.ndarray
    peak: int
    ended: bool
    source: str
    warnings: list[str] = field(default_factory=list)

    def to_json_dict(self, units: str = "SI") -> dict:
        """The object ``impactsym edr --json`` prints (conventions.md)."""
        scale = 1.0 if units == "SI" else 1.0 / 0.3048
        lon, lat = self.longitudinal[self.peak] * scale, self.lateral[self.peak] * scale
        return {
            "units": units,
            "delta_v": {
                "longitudinal": json_number(float(lon)),
                "lateral": json_number(float(lat)),
                "magnitude": json_number(math.hypot(lon, lat)),
                "direction": json_number(math.degrees(math.atan2(lat, lon))),
                "time_of_max": json_number(float(self.time[self.peak] * 1000.0)),
            },
            "lateral_positive": "left",
            "ended": self.ended,
            "samples": len(self.time),
            "warnings": list(self.warnings),
        }


@dataclass
class PreCrash:
    """A pre-crash speed table in SI (time s, speed m/s)."""

    time: np.ndarray
    speed: np.ndarray
    source: str

    def at_crash(self) -> float:
        """The speed at the last sample before the crash (time ≤ 0, or the last sample)."""
        before = np.nonzero(self.time <= 0.0)[0]
        return float(self.speed[before[np.argmax(self.time[before])]] if before.size else self.speed[-1])

    def to_json_dict(self, units: str = "SI") -> dict:
        scale = 1.0 if units == "SI" else 1.0 / 0.3048
        speed = json_number(self.at_crash() * scale)
        return {"units": units, "speed": speed, "samples": len(self.time), "warnings": []}


def _unit_factor(unit: str, target: str, where: str) -> float:
    """The factor from `unit` to `target` (``g`` read as standard gravity)."""
    text = re.sub(r"(?<![A-Za-z_])g(?![A-Za-z_0-9])", "g_0", unit.strip())
    try:
        return float(registry().Quantity(1.0, text).to(target).magnitude)
    except Exception as exc:  # pint raises several kinds; its message is the reason
        raise SceneError(f"unit [{unit}] cannot be read as {target}: {exc}", where) from None


def _read_columns(path: Path) -> tuple[dict, dict]:
    """name -> values and name -> unit of a CSV with `name [unit]` headers."""
    try:
        text = path.read_text()
    except UnicodeDecodeError:
        raise SceneError("not a text CSV file", str(path)) from None
    rows = [r for r in csv.reader(text.splitlines()) if r and any(c.strip() for c in r)]
    if len(rows) < 2:
        raise SceneError("needs a header row and at least one sample", str(path))
    names, units = [], {}
    for cell in rows[0]:
        match = _HEADER.match(cell)
        if not match:
            raise SceneError(f"header {cell.strip()!r} is not 'name [unit]'", str(path))
        names.append(match.group(1))
        units[match.group(1)] = match.group(2)
    values = {name: [] for name in names}
    for line, row in enumerate(rows[1:], start=2):
        if len(row) != len(names):
            raise SceneError(f"line {line}: {len(row)} values for {len(names)} columns", str(path))
        for name, cell in zip(names, row):
            try:
                number = float(cell)
            except ValueError:
                raise SceneError(
                    f"line {line}: {name} = {cell.strip()!r} is not a number", str(path)
                ) from None
            if not math.isfinite(number):
                raise SceneError(f"line {line}: {name} is not finite", str(path))
            values[name].append(number)
    return {k: np.array(v) for k, v in values.items()}, units


def read_edr(
    path: str | Path, lateral_positive: str = "right", integration: str = "trapezoid"
) -> Pulse | PreCrash:
    """Read a crash-pulse or pre-crash CSV (see the module docstring).

    `integration` of an acceleration pulse: ``"trapezoid"`` (between samples) or
    ``"sum"`` (each sample times the interval, up to and including it: how a
    restraint module accumulates its own delta-V; it reproduces the CF09009B
    report's cumulative figures more closely, see tests/test_edr.py)."""
    path = Path(path)
    if integration not in INTEGRATIONS:
        raise SceneError(f"must be one of {', '.join(INTEGRATIONS)}, got {integration!r}", "integration")
    if lateral_positive not in ("right", "left"):
        raise SceneError(f'must be "right" or "left", got {lateral_positive!r}', "lateral_positive")
    values, units = _read_columns(path)
    if "time" not in values:
        raise SceneError("needs a 'time [unit]' column", str(path))
    time = values["time"] * _unit_factor(units["time"], "s", f"{path}: time")
    if np.any(np.diff(time) <= 0):
        raise SceneError("time must increase from row to row", str(path))
    if "speed" in values:
        speed = values["speed"] * _unit_factor(units["speed"], "m/s", f"{path}: speed")
        return PreCrash(time, speed, str(path))
    kind = next((k for k, cols in PULSE_COLUMNS.items() if all(c in values for c in cols)), None)
    if kind is None:
        wanted = " or ".join(" and ".join(cols) for cols in PULSE_COLUMNS.values())
        raise SceneError(f"needs columns {wanted} (or speed for a pre-crash table)", str(path))
    lon_name, lat_name = PULSE_COLUMNS[kind]
    target = "m/s" if kind == "delta_v" else "m/s**2"
    lon = values[lon_name] * _unit_factor(units[lon_name], target, f"{path}: {lon_name}")
    lat = values[lat_name] * _unit_factor(units[lat_name], target, f"{path}: {lat_name}")
    if lateral_positive == "right":
        lat = -lat
    if kind == "acceleration":
        lon, lat = INTEGRATIONS[integration](time, lon), INTEGRATIONS[integration](time, lat)
    return _pulse(time, lon, lat, str(path))


def _trapezoid(time: np.ndarray, accel: np.ndarray) -> np.ndarray:
    """Cumulative delta-V from zero at the first sample, by the trapezoid rule."""
    steps = np.diff(time) * (accel[1:] + accel[:-1]) / 2.0
    return np.concatenate([[0.0], np.cumsum(steps)])


def _sum(time: np.ndarray, accel: np.ndarray) -> np.ndarray:
    """Cumulative delta-V as the running sum of each sample times its interval
    (the first interval taken equal to the second)."""
    steps = np.diff(time, prepend=2 * time[0] - time[1]) if len(time) > 1 else np.zeros(1)
    return np.cumsum(steps * accel)


INTEGRATIONS = {"trapezoid": _trapezoid, "sum": _sum}


def _pulse(time, lon, lat, source) -> Pulse:
    resultant = np.hypot(lon, lat)
    peak = int(np.argmax(resultant))
    start = time[-1] - END_WINDOW_MS / 1000.0
    earlier = np.nonzero(time <= start + 1e-12)[0]
    warnings = []
    if earlier.size == 0:
        ended = False
        warnings.append(
            f"the record ({(time[-1] - time[0]) * 1000:g} ms) is shorter than the 20 ms end-of-event window"
        )
    else:
        i = earlier[-1]
        change = math.hypot(lon[-1] - lon[i], lat[-1] - lat[i])
        ended = change <= END_CHANGE
        if not ended:
            warnings.append(
                f"the pulse has not ended by the end of the record ({time[-1] * 1000:g} ms): delta-V changed "
                f"{change * 3.6:.2g} km/h over the last 20 ms; the recorded delta-V may understate the total"
            )
    return Pulse(time, lon, lat, peak, ended, source, warnings)


__all__ = ["GRAVITY", "STANDARD_GRAVITY", "Pulse", "PreCrash", "read_edr"]
