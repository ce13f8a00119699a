"""`python -m benchmarks evidence`: `impactsym fit` end to end, as users run it.

Each case is a fresh `python -m impactsym ...` process (start-up, imports, scene
reading, the fit, JSON out), timed by wall clock and by the CPU time of the
child (user + sys: what the command costs on an idle machine; wall clock on a
shared machine also counts the wait for a core). Reported: the minimum over
--repeat runs, and each case's ratio to the baseline `impactsym solve` of the
seed-style two-car scene measured in the same run. Target (issue 24): linear
evidence ≤ 0.5 s end to end, with rest poses ≤ 2 s.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

DESCRIPTION = "impactsym fit end to end (CLI processes), against impactsym solve in the same run"
ROOT = Path(__file__).resolve().parents[1]
MPH = 5280 / 3600  # ft/s


def linear_scene() -> dict:
    """The intersection example's vehicles with linear evidence in plain numbers (US)."""
    scene = json.loads((ROOT / "examples" / "fit_intersection_us.json").read_text())
    scene["vehicles"][0].update(weight=3440, radius_of_gyration=4.04, impact_point=[7.22, -1.28])
    scene["vehicles"][1].update(weight=4362, radius_of_gyration=4.73, impact_point=[1.33, 3.94])
    scene["evidence"] = [
        {"vehicle": 0, "quantity": "speed", "value": 32 * MPH, "sd": 1 * MPH},
        {"vehicle": 0, "quantity": "delta_v_longitudinal", "value": -29 * MPH, "sd": 1 * MPH},
        {"vehicle": 0, "quantity": "delta_v_lateral", "value": 6 * MPH, "sd": 1 * MPH},
        {"vehicle": 1, "quantity": "speed", "value": 50 * MPH, "sd": 5 * MPH},
    ]
    return scene


def _run(args) -> tuple[float, float]:
    """(wall, child CPU) seconds of one `python -m impactsym args` process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "impactsym", *args], capture_output=True, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"impactsym {' '.join(args)} failed: {proc.stderr.strip()}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def add_arguments(parser) -> None:
    parser.add_argument("--repeat", type=int, default=5, help="runs per case (minimum reported)")


def main(args) -> int:
    os.environ.setdefault("PYTHONPATH", str(ROOT))
    with tempfile.TemporaryDirectory() as tmp:
        linear = Path(tmp) / "fit_linear.json"
        linear.write_text(json.dumps(linear_scene()))
        cases = {
            "baseline: solve two_car_us.json --json": ["solve", str(ROOT / "examples" / "two_car_us.json"), "--json"],
            "fit, linear evidence (plain numbers)": ["fit", str(linear), "--json"],
            "fit, example with unit strings (nonlinear, 400 draws)": [
                "fit", str(ROOT / "examples" / "fit_intersection_us.json"), "--json"
            ],
            "fit, CF09009B EDR pulse example": ["fit", str(ROOT / "examples" / "fit_cf09009b_edr_si.json"), "--json"],
            "fit, rest poses (400 draws, each rest pose refitted)": [
                "fit", str(ROOT / "examples" / "fit_rest_intersection_si.json"), "--json"
            ],
            "fit, rest poses linearised (--draws 0)": [
                "fit", str(ROOT / "examples" / "fit_rest_intersection_si.json"), "--json", "--draws", "0"
            ],
        }  # fmt: skip
        results = {}
        for name, argv in cases.items():
            runs = [_run(argv) for _ in range(args.repeat)]
            results[name] = (min(r[0] for r in runs), min(r[1] for r in runs))
    base = results[next(iter(cases))]
    print(f"{'case':<58}{'wall s':>9}{'cpu s':>9}{'wall/base':>11}{'cpu/base':>10}")
    for name, (wall, cpu) in results.items():
        print(f"{name:<58}{wall:>9.3f}{cpu:>9.3f}{wall / base[0]:>11.2f}{cpu / base[1]:>10.2f}")
    print(
        f"(minimum of {args.repeat} runs each; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores)"
    )
    return 0
