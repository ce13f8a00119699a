"""An ``edr`` evidence item: the delta-V (or pre-crash speed) an EDR file records.

``{"vehicle": 1, "edr": "pulse.csv", "lateral_positive": "right" | "left",
"module": {"forward": a, "left": b}, "sd": "1 mph"}``: a crash pulse adds the
longitudinal and lateral delta-V at the module at the time of the resultant's
maximum (two observations, ``sd`` a number or a pair); a pre-crash table adds
the speed at the last sample before the crash. The file path is relative to
the scene file's folder.
"""

from __future__ import annotations

import math
from pathlib import Path

from ..errors import SceneError, show_value
from .edr import PreCrash, read_edr
from .items import Observation, module_at, sds, vehicle_index

TO_SCENE = {"SI": 1.0, "US": 1.0 / 0.3048}  # m/s -> scene speed unit


def edr_observations(item, k: int, units: str, names, fixed, source, warnings: list) -> list[Observation]:
    path = f"evidence[{k}]"
    for key in ("quantity", "value", "at"):
        if key in item:
            raise SceneError("an edr item takes its values from the file", f"{path}.{key}")
    i = vehicle_index(item.get("vehicle"), names, f"{path}.vehicle")
    if fixed[i]:
        raise SceneError("vehicle is fixed: it has no recorder to read", f"{path}.vehicle")
    name = item["edr"]
    if not isinstance(name, str):
        raise SceneError(f"must be a file name, got {show_value(name)}", f"{path}.edr")
    file = Path(name)
    if not file.is_absolute() and isinstance(source, (str, Path)):
        file = Path(source).parent / file
    try:
        record = read_edr(file, item.get("lateral_positive", "right"))
    except SceneError as exc:
        raise SceneError(str(exc), f"{path}.edr") from None
    except OSError as exc:
        raise SceneError(f"cannot read {file}: {exc.strerror}", f"{path}.edr") from None
    n, scale = i + 1, TO_SCENE[units]
    if isinstance(record, PreCrash):
        (sd,) = sds(item.get("sd"), f"{path}.sd", "speed", units, 1)
        return [
            Observation(
                k, f"vehicles[{i}].speed", record.at_crash() * scale, sd, ("linear", f"s{n}", (0.0, 0.0))
            )
        ]
    module = module_at(item, path, units)
    sd_lon, sd_lat = sds(item.get("sd"), f"{path}.sd", "speed", units, 2)
    warnings += [f"{path} ({file.name}): {w}" for w in record.warnings]
    peak = record.peak
    values = (record.longitudinal[peak] * scale, record.lateral[peak] * scale)
    # A pulse still running at the end of the record understates the delta-V:
    # each component is then a bound (the truth at least as far from 0), one-sided.
    sides = (0, 0) if record.ended else tuple(int(math.copysign(1, v)) for v in values)
    if not record.ended:
        warnings.append(f"{path}: the recorded delta-V is used as a one-sided bound (at least this large)")
    return [
        Observation(
            k, f"vehicles[{i}].delta_v_{part}", value, sd, ("linear", f"{out}{n}", module), one_sided=side
        )
        for part, out, value, sd, side in zip(
            ("longitudinal", "lateral"), ("dl", "dt"), values, (sd_lon, sd_lat), sides
        )
    ]
