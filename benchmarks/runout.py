"""Run-out: run time against rest-pose error, kernels against scipy's solve_ivp.

Truth: solve_ivp DOP853 at rtol 1e-10, atol 1e-12 on the contract's equations
(impactsym/testing/runout_reference.py, written independently of derive/). The
kernel's batch driver (one thread) at several tolerances and solve_ivp RK45 at
several rtol (the user's alternative) run the same random realistic run-outs
(tests/runout_rows.py); the error of a row is the distance of its rest
position from the truth's. Also: run-outs per second of the parallel batch,
and the fit to rest per vehicle after first use.

With ``--against REV``: the same figures for the run-out of git revision REV
in the same process (its generated/runout_jit.py and impactsym/runout/fit.py
imported beside the checkout's), interleaved with this checkout's, so the
before/after ratios do not depend on how loaded the machine was.

    python -m benchmarks runout [--rows 6] [--batch 2000] [--against REV] [--out benchmarks/results]
    python -m benchmarks runout --grid-only [--fits 20]   (the fit with and without the grid search)
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DESCRIPTION = (
    "run-out: run time against rest-pose error, batch kernels vs scipy solve_ivp; fit to rest timing"
)
KERNEL_TOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
IVP_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
REPEATS = 5  # timings are the best of REPEATS (the machine is shared)
TIMING_COPIES = 20  # the timed batch repeats the compared rows this many times
ROOT = Path(__file__).resolve().parent.parent
NOW = "checkout"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--rows", type=int, default=6, help="run-outs compared with the reference (default 6)"
    )
    parser.add_argument("--batch", type=int, default=2000, help="rows of the throughput batch (default 2000)")
    parser.add_argument("--fits", type=int, default=20, help="random fit round trips (default 20)")
    parser.add_argument(
        "--out", type=Path, default=Path("benchmarks/results"), help="folder for runout.md/.png/.json"
    )
    parser.add_argument("--against", metavar="REV", help="also run git revision REV's run-out (same process)")
    parser.add_argument(
        "--via-only",
        action="store_true",
        help="only the round trips with an intermediate pose (printed, nothing written)",
    )
    parser.add_argument(
        "--grid-only",
        action="store_true",
        help="only the round trips of seeds 5 and 6 fitted without and with the grid search (printed)",
    )
    parser.add_argument(
        "--transfer-only",
        action="store_true",
        help="only load transfer against static loads: batch and first use (printed, nothing written)",
    )


class Version:
    """One run-out implementation: its kernels module and its fit module."""

    def __init__(self, label: str, jit, fit):
        self.label, self.jit, self.fit = label, jit, fit

    @contextlib.contextmanager
    def active(self):
        """The run-out room's door leads to this version's kernels meanwhile."""
        from impactsym.runout import _door

        saved = _door.jit
        _door.jit = lambda: self.jit
        try:
            yield self
        finally:
            _door.jit = saved


def _versions(rev: str | None, folder: Path) -> list:
    """This checkout's run-out, and REV's when asked."""
    from impactsym.runout import _door

    fit_now = importlib.import_module("impactsym.runout.fit")
    found = [Version(NOW, _door.jit(), fit_now)]
    if rev:
        from benchmarks.drivers import _old_module

        text = subprocess.run(
            ["git", "show", f"{rev}:impactsym/runout/fit.py"],
            cwd=ROOT,
            check=True,
            capture_output=True,
            text=True,
        ).stdout
        name = "impactsym.runout._fit_at_revision"  # relative imports resolve to this checkout's room
        path = folder / "fit_at_revision.py"
        path.write_text(text)
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        found.append(Version(rev, _RowsDriver(_old_module(rev, "runout", folder)), module))
    return found


class _RowsDriver:
    """An older kernels module seen through today's batch driver signature
    (`runout_batch(c, lo, hi, *outputs, tol, eps)`; before it, a prange
    driver and a serial twin over the whole table): rows lo..hi-1 go to its
    serial driver, the output slices being views."""

    def __init__(self, module):
        self.module = module

    def __getattr__(self, name):
        return getattr(self.module, name)

    def runout_batch(self, c, lo, hi, *args):
        if not hasattr(self.module, "runout_batch_serial"):
            return self.module.runout_batch(c, lo, hi, *args)
        *outputs, tol, eps = args
        return self.module.runout_batch_serial(c[lo:hi], *(o[lo:hi] for o in outputs), tol, eps)

    def whole(self, cols) -> dict | None:
        """The whole table through the older module's own parallel driver (its
        serial twin holds the GIL, so today's threads would not share it out);
        None when the module already has today's driver."""
        from impactsym.runout.batch import input_table

        if not hasattr(self.module, "runout_batch_serial"):
            return None
        table = input_table(cols)
        n = table.shape[0]
        out = {k: np.empty(n) for k in ("x_rest", "y_rest", "psi_rest", "t", "distance")}
        out["status"], out["steps"] = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
        self.module.runout_batch(table, *out.values(), self.module.TOL, self.module.EPS)
        return out


def _errors(rows, xs, ys, truth) -> np.ndarray:
    return np.array([math.hypot(xs[i] - truth[i][0], ys[i] - truth[i][1]) for i in range(len(rows))])


def _kernel_curves(rows, truth, versions) -> dict:
    """Per version and tolerance: seconds per run-out (one thread, best of
    REPEATS over a batch of TIMING_COPIES copies of the rows, the versions
    alternating) and the worst rest error."""
    from impactsym.runout import runout_batch
    from tests.runout_rows import rows_table

    table = rows_table(rows)
    timed = {key: np.tile(value, TIMING_COPIES) for key, value in table.items()}
    curves = {v.label: [] for v in versions}
    for v in versions:
        with v.active():
            runout_batch(table, parallel=False)  # compile / load
    for tol in KERNEL_TOLS:
        best = dict.fromkeys(curves, math.inf)
        for _ in range(REPEATS):
            for v in versions:
                with v.active():
                    start = time.perf_counter()
                    runout_batch(timed, tol=tol, parallel=False)
                    best[v.label] = min(best[v.label], time.perf_counter() - start)
        for v in versions:
            with v.active():
                out = runout_batch(table, tol=tol, parallel=False)
            err = _errors(rows, out["x_rest"], out["y_rest"], truth)
            curves[v.label].append(
                {
                    "tol": tol,
                    "seconds_per_runout": best[v.label] / (len(rows) * TIMING_COPIES),
                    "worst_error_m": float(err.max()),
                    "mean_steps": float(out["steps"].mean()),
                }
            )
    return curves


def _ivp_curve(rows, truth):
    from impactsym.testing.runout_reference import reference_runout

    curve = []
    for rtol in IVP_RTOLS:
        start = time.perf_counter()
        res = [reference_runout(r, rtol=rtol, atol=rtol * 1e-2, method="RK45") for r in rows]
        elapsed = time.perf_counter() - start
        err = _errors(rows, [r[0] for r in res], [r[1] for r in res], truth)
        curve.append(
            {"rtol": rtol, "seconds_per_runout": elapsed / len(rows), "worst_error_m": float(err.max())}
        )
    return curve


def _at_error(curve, error: float) -> float:
    """Seconds per run-out of the cheapest point of `curve` at least as accurate as `error`."""
    ok = [p["seconds_per_runout"] for p in curve if p["worst_error_m"] <= error]
    return min(ok) if ok else math.nan


def _throughput(n: int, versions) -> dict:
    """Run-outs per second of the parallel batch driver on `n` random rows (default
    tolerance), per version: the best of REPEATS calls, versions alternating."""
    from impactsym.runout import runout_batch
    from tests.runout_rows import realistic_row, rows_table

    rng = np.random.default_rng(11)
    table = rows_table([realistic_row(rng) for _ in range(n)])
    best = {v.label: math.inf for v in versions}

    def call(v):
        whole = v.jit.whole if isinstance(v.jit, _RowsDriver) else lambda _: None
        return whole(table) or runout_batch(table)

    for v in versions:
        with v.active():
            call(v)
    for _ in range(REPEATS):
        for v in versions:
            with v.active():
                start = time.perf_counter()
                out = call(v)
                best[v.label] = min(best[v.label], time.perf_counter() - start)
            assert (out["status"] == 0).all()
    return {label: n / seconds for label, seconds in best.items()}


def _transfer_throughput(n: int) -> dict:
    """Run-outs per second of the parallel batch on `n` random rows with load transfer
    (h drawn in [0.4, 0.6] m, the _lt kernels) and on the same rows with static loads
    (h = 0), alternating, best of REPEATS; after one call each (first use)."""
    from impactsym.runout import runout_batch
    from tests.runout_rows import realistic_row, rows_table

    rng = np.random.default_rng(11)
    rows = [realistic_row(rng) for _ in range(n)]
    heights = rng.uniform(0.4, 0.6, n)
    tables = {
        "static": rows_table(rows),
        "transfer": rows_table([r | {"h": h} for r, h in zip(rows, heights)]),
    }
    best = dict.fromkeys(tables, math.inf)
    for table in tables.values():
        runout_batch(table)
    for _ in range(REPEATS):
        for label, table in tables.items():
            start = time.perf_counter()
            out = runout_batch(table)
            best[label] = min(best[label], time.perf_counter() - start)
            assert (out["status"] == 0).all()
    rates = {label: n / seconds for label, seconds in best.items()}
    return rates | {"ratio": rates["transfer"] / rates["static"]}


_FIRST_USE = (
    "import json, sys, time; t = time.perf_counter(); import impactsym; "
    "impactsym.runout(json.loads(sys.argv[1])); print(time.perf_counter() - t)"
)


def _first_use() -> dict:
    """Seconds of import + impactsym.runout on examples/runout/fit_tbone.json (both cars
    fitted to rest) in a fresh process with an empty numba cache: as given (static
    loads) and with cg_height 0.55 m on both cars (the _lt kernels), each with the
    second compiling process (impactsym/runout/prime.py) and without it
    (IMPACTSYM_PRIME=0), the four alternating, twice."""
    scene = json.loads((Path(__file__).resolve().parents[1] / "examples/runout/fit_tbone.json").read_text())
    moved = json.loads(json.dumps(scene))
    for v in moved["vehicles"]:
        v["cg_height"] = 0.55
    runs = {
        "static": (scene, "1"),
        "transfer": (moved, "1"),
        "static, one process": (scene, "0"),
        "transfer, one process": (moved, "0"),
    }
    out = {label: [] for label in runs}
    for _ in range(2):
        for label, (data, prime) in runs.items():
            with tempfile.TemporaryDirectory() as cache:
                proc = subprocess.run(
                    [sys.executable, "-c", _FIRST_USE, json.dumps(data)],
                    capture_output=True,
                    text=True,
                    env=dict(os.environ, NUMBA_CACHE_DIR=cache, IMPACTSYM_PRIME=prime),
                    timeout=600,
                    check=True,
                )
            out[label].append(float(proc.stdout.strip().splitlines()[-1]))
    return out


def _transfer_line(t: dict) -> str:
    line = (
        f"Load transfer (cg_height, h in [0.4, 0.6] m): {t['transfer']:.0f} run-outs/s against "
        f"{t['static']:.0f} with static loads on the same rows, ratio {t['ratio']:.2f}."
    )
    if "first_use_s" in t:
        f = t["first_use_s"]
        line += (
            " First use (fit_tbone.json, empty numba cache, fresh process): "
            + "; ".join(f"{label} {', '.join(f'{x:.2f}' for x in runs)} s" for label, runs in f.items())
            + " (static: as given; transfer: with cg_height; one process: IMPACTSYM_PRIME=0)."
        )
    return line


FIT_CASES = ("all locked", "front locked, rear rolling", "sedan.json: locked, rolling, braked 0.5, steered")


def _fit_timing(versions) -> dict:
    """Fit to rest after first use of examples/runout/sedan.json under three wheel
    setups: best of 5 (versions alternating), with and without the uniqueness starts."""
    from impactsym.runout import load_runout, runout

    scene = json.loads((ROOT / "examples/runout/sedan.json").read_text())
    setups = (
        "locked",
        {"front_left": "locked", "front_right": "locked", "rear_left": "rolling", "rear_right": "rolling"},
        scene["vehicles"][0]["wheels"],
    )
    cases = []
    for label, wheels in zip(FIT_CASES, setups):
        s = json.loads(json.dumps(scene))
        s["vehicles"][0]["wheels"] = wheels
        rest = runout(s)["vehicles"][0]["rest"]
        del s["vehicles"][0]["separation"]["velocity"], s["vehicles"][0]["separation"]["yaw_rate"]
        s["vehicles"][0]["rest"] = rest
        veh = load_runout(s).vehicles[0]
        row = {"wheels": label}
        times = {v.label: [math.inf, math.inf] for v in versions}
        fits = {}
        for v in versions:
            with v.active():
                fits[v.label] = v.fit.fit_rest(veh)  # first use
        for _ in range(5):
            for v in versions:
                with v.active():
                    for k, unique in enumerate((True, False)):
                        start = time.perf_counter()
                        v.fit.fit_rest(veh, check_unique=unique)
                        times[v.label][k] = min(times[v.label][k], time.perf_counter() - start)
        for v in versions:
            fit = fits[v.label]
            row[v.label] = {
                "ms": times[v.label][0] * 1e3,
                "ms_one_start": times[v.label][1] * 1e3,
                "iterations": fit.iterations,
                "converged": fit.converged,
                "velocity": fit.velocity,
                "yaw_rate": fit.yaw_rate,
            }
        cases.append(row)
    return {"cases": cases}


def _fit_random(n: int, version, seed: int = 5, **options) -> dict:
    """Round trips on random realistic run-outs (`seed`): forward, then fitted
    (fit_rest's keyword `options`, e.g. the grid search's) to the rest
    pose reached. Counts fits that converged, that recovered the generating
    state (0.01 m/s, 0.01 rad/s; the reported state or a named alternative),
    that reached the rest pose from another state without naming the
    generating one, and the named alternatives that are spurious (run forward
    at the default tolerance, they miss the rest pose by more than 1 mm or
    0.01 deg, or they repeat another state found within 0.01 m/s and 0.01 rad/s)."""
    from impactsym.runout.batch import run_row
    from impactsym.runout.scene import RunoutVehicle
    from tests.runout_rows import realistic_row

    rng = np.random.default_rng(seed)
    counts = {"rows": n, "converged": 0, "recovered": 0, "other_state_unnamed": 0, "alternatives": 0}
    counts["spurious_alternatives"] = 0
    times = []
    with version.active():
        for _ in range(n):
            row = realistic_row(rng)
            y, _, _, _, _ = run_row(_values(row))
            fixed = {k: v for k, v in row.items() if k not in ("vx", "vy", "w")}
            veh = RunoutVehicle("r", fixed, (row["x"], row["y"]), row["psi"], None, None, (y[0], y[1], y[2]))
            start = time.perf_counter()
            fit = version.fit.fit_rest(veh, **options)
            times.append(time.perf_counter() - start)
            found = [fit, *fit.alternatives]
            hit = any(_same(f, (row["vx"], row["vy"], row["w"])) for f in found)
            counts["converged"] += fit.converged
            counts["recovered"] += fit.converged and hit
            counts["other_state_unnamed"] += fit.converged and not hit
            counts["alternatives"] += len(fit.alternatives)
            for i, alt in enumerate(fit.alternatives):
                ya, _, status, _, _ = run_row(
                    _values(dict(row, vx=alt.velocity[0], vy=alt.velocity[1], w=alt.yaw_rate))
                )
                missed = (
                    status != 0
                    or math.hypot(ya[0] - y[0], ya[1] - y[1]) > 1e-3
                    or abs(ya[2] - y[2]) > math.radians(0.01)
                )
                repeated = any(_same(g, (*alt.velocity, alt.yaw_rate)) for g in found[: i + 1])
                counts["spurious_alternatives"] += missed or repeated
    counts["median_ms"] = float(np.median(times) * 1e3)
    counts["max_ms"] = float(np.max(times) * 1e3)
    return counts


def _fit_random_via(n: int) -> dict:
    """Round trips with an intermediate pose (this checkout; earlier versions
    have none): the same random run-outs as `_fit_random`, each fitted to its
    rest pose and the pose (position and heading) at the middle accepted step
    of its forward path. Counts fits that converged, that reported the
    generating state (0.01 m/s, 0.01 rad/s: the evidence should choose it, not
    merely name it), and the alternatives named."""
    from impactsym.runout import via
    from impactsym.runout.batch import run_row
    from impactsym.runout.fit import fit_rest
    from impactsym.runout.scene import RunoutVehicle
    from tests.runout_rows import realistic_row

    rng = np.random.default_rng(5)
    counts = {"rows": n, "converged": 0, "reported_generating": 0, "alternatives": 0}
    times = []
    for _ in range(n):
        row = realistic_row(rng)
        y, _, _, _, path = run_row(_values(row), path_points=via.PATH_ROWS, path_columns=8)
        mid = path[path.shape[0] // 2]
        fixed = {k: v for k, v in row.items() if k not in ("vx", "vy", "w")}
        veh = RunoutVehicle(
            "r",
            fixed,
            (row["x"], row["y"]),
            row["psi"],
            None,
            None,
            (y[0], y[1], y[2]),
            via=((mid[1], mid[2], mid[3]),),
        )
        start = time.perf_counter()
        fit = fit_rest(veh)
        times.append(time.perf_counter() - start)
        counts["converged"] += fit.converged
        counts["reported_generating"] += fit.converged and _same(fit, (row["vx"], row["vy"], row["w"]))
        counts["alternatives"] += len(fit.alternatives)
    counts["median_ms"] = float(np.median(times) * 1e3)
    counts["max_ms"] = float(np.max(times) * 1e3)
    return counts


def _via_line(fv: dict) -> str:
    return (
        f"Fit round trips with an intermediate pose (checkout; the pose at the middle step of the path) on "
        f"{fv['rows']} random realistic run-outs: {fv['converged']} converged, {fv['reported_generating']} "
        f"reported the generating state, {fv['alternatives']} alternatives named; median {fv['median_ms']:.1f} ms, "
        f"max {fv['max_ms']:.1f} ms per fit."
    )


def _grid_round_trips(n: int) -> None:
    """The round trips of seeds 5 and 6 (`_fit_random`), fitted as usual and
    with the grid search (`exhaustive`), this checkout; printed."""
    now = _versions(None, ROOT)[0]
    _fit_random(1, now, exhaustive=True)  # first use
    for seed in (5, 6):
        for label, options in (("fit", {}), ("fit + grid search", {"exhaustive": True})):
            c = _fit_random(n, now, seed, **options)
            print(
                f"seed {seed}, {label}: {c['rows']} round trips, {c['converged']} converged, {c['recovered']} "
                f"recovered the generating state, {c['other_state_unnamed']} reached the rest pose from another "
                f"state without naming it, {c['alternatives']} alternatives named ({c['spurious_alternatives']} "
                f"spurious); median {c['median_ms']:.0f} ms, max {c['max_ms']:.0f} ms per fit"
            )


def _same(f, p) -> bool:
    return math.hypot(f.velocity[0] - p[0], f.velocity[1] - p[1]) < 0.01 and abs(f.yaw_rate - p[2]) < 0.01


def _closed_forms() -> list[dict]:
    """The closed-form cases of tests/test_runout_model.py, with their errors."""
    from tests.test_runout_model import BASE, G, _one, _row

    psi, out = BASE["psi"], []
    for v in (5.0, 20.0, 35.0):
        y = _one(_row(1.0, vx=v * math.cos(psi), vy=v * math.sin(psi)))[0]
        got, exp = math.hypot(y[0] - 1.0, y[1] + 2.0), v * v / (2 * 0.8 * G)
        out.append({"case": f"locked slide from {v:g} m/s", "run_out": got, "closed_form": exp, "unit": "m"})
    for w in (-4.0, 1.5, 6.0):
        y = _one(_row(1.0, a=1.35, w=w))[0]
        exp = 2400.0 * w * w / (2 * 0.8 * 1450.0 * G * math.hypot(1.35, 0.75))
        out.append(
            {
                "case": f"locked spin from {w:g} rad/s",
                "run_out": abs(y[2] - psi),
                "closed_form": exp,
                "unit": "rad",
            }
        )
    for v in (3.0, 10.0):
        y = _one(_row(0.0, vx=v * math.cos(psi), vy=v * math.sin(psi)))[0]
        got, exp = math.hypot(y[0] - 1.0, y[1] + 2.0), v * v / (2 * 0.01 * G)
        out.append(
            {"case": f"rolling resistance from {v:g} m/s", "run_out": got, "closed_form": exp, "unit": "m"}
        )
    return out


def _reference_check() -> dict:
    """The rows of tests/test_runout_reference.py: worst rest errors against DOP853 rtol 1e-10."""
    from impactsym.runout import runout_batch
    from impactsym.testing.runout_reference import reference_runout
    from tests.runout_rows import realistic_row, rows_table

    rng = np.random.default_rng(2024)
    rows = [realistic_row(rng) for _ in range(10)]
    out = runout_batch(rows_table(rows))
    worst = {"position_m": 0.0, "heading_deg": 0.0, "share_of_allowance": 0.0}
    for i, row in enumerate(rows):
        x, y, psi, _, dist = reference_runout(row)
        err = math.hypot(out["x_rest"][i] - x, out["y_rest"][i] - y)
        worst["position_m"] = max(worst["position_m"], err)
        worst["heading_deg"] = max(worst["heading_deg"], abs(math.degrees(out["psi_rest"][i] - psi)))
        worst["share_of_allowance"] = max(worst["share_of_allowance"], err / (1e-3 + 1e-5 * dist))
    return worst


def _columns():
    from impactsym.runout.batch import columns

    return columns()


def _values(row: dict) -> np.ndarray:
    """The kernel row of a realistic_row dict; ``h`` (cg height, a later column than
    some versions --against loads have) 0: the static loads every version runs."""
    return np.array([row.get(c, 0.0) if c == "h" else row[c] for c in _columns()])


def main(args: argparse.Namespace) -> int:

    from impactsym.testing.runout_reference import reference_runout
    from tests.runout_rows import realistic_row

    if args.via_only:
        _fit_random_via(2)  # first use
        print(_via_line(_fit_random_via(args.fits)))
        return 0
    if args.grid_only:
        _grid_round_trips(args.fits)
        return 0
    if args.transfer_only:
        print(_transfer_line(_transfer_throughput(args.batch) | {"first_use_s": _first_use()}))
        return 0
    load_before = os.getloadavg()
    rng = np.random.default_rng(2024)
    rows = [realistic_row(rng) for _ in range(args.rows)]
    start = time.perf_counter()
    truth = [reference_runout(r) for r in rows]
    truth_seconds = (time.perf_counter() - start) / len(rows)
    with tempfile.TemporaryDirectory(prefix="impactsym_runout_") as tmp:
        versions = _versions(args.against, Path(tmp))
        kernel, ivp = _kernel_curves(rows, truth, versions), _ivp_curve(rows, truth)
        ratios = {
            label: [
                {
                    "tol": p["tol"],
                    "error": p["worst_error_m"],
                    "ratio": _at_error(ivp, p["worst_error_m"]) / p["seconds_per_runout"],
                }
                for p in curve
            ]
            for label, curve in kernel.items()
        }
        result = {
            "command": "python -m benchmarks runout "
            + f"--rows {args.rows} --batch {args.batch} --fits {args.fits}"
            + (f" --against {args.against}" if args.against else ""),
            "versions": [v.label for v in versions],
            "rows": len(rows),
            "truth_seconds_per_runout": truth_seconds,
            "kernel": kernel,
            "solve_ivp_RK45": ivp,
            "ratios_at_equal_error": ratios,
            "runouts_per_second_parallel": _throughput(args.batch, versions),
            "load_transfer": _transfer_throughput(args.batch) | {"first_use_s": _first_use()},
            "runouts_per_second_one_thread_default_tol": {
                label: 1.0 / next(p for p in curve if p["tol"] == 1e-8)["seconds_per_runout"]
                for label, curve in kernel.items()
            },
            "fit": _fit_timing(versions),
            "fit_random": {v.label: _fit_random(args.fits, v) for v in versions},
            "fit_random_via": _fit_random_via(args.fits),
            "closed_forms": _closed_forms(),
            "reference_10_rows": _reference_check(),
            "load_average": {"start": load_before, "end": os.getloadavg()},
        }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "runout.json").write_text(json.dumps(result, indent=1))
    _chart(kernel, ivp, args.out / "runout.png")
    (args.out / "runout.md").write_text(_markdown(result))
    print(_markdown(result))
    return 0


def _chart(kernel: dict, ivp, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for label, curve in kernel.items():
        ax.loglog(
            [p["worst_error_m"] for p in curve],
            [p["seconds_per_runout"] for p in curve],
            "o-" if label == NOW else "^--",
            label=f"impactsym batch kernel, one thread, tol 1e-4..1e-10 ({label})",
        )
    ax.loglog(
        [p["worst_error_m"] for p in ivp],
        [p["seconds_per_runout"] for p in ivp],
        "s-",
        label="scipy solve_ivp RK45, rtol 1e-3..1e-10",
    )
    ax.axvline(1e-3, color="0.5", ls=":", lw=1)
    ax.set_xlabel("worst rest-position error against DOP853 rtol 1e-10 [m]")
    ax.set_ylabel("run time per run-out [s]")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.15))
    ax.grid(True, which="both", alpha=0.3)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def _markdown(r: dict) -> str:
    labels = r["versions"]
    load = r["load_average"]
    lines = [
        f"# Run-out benchmark (`{r['command']}`)",
        "",
        f"Load average (1, 5, 15 min) at the start {', '.join(f'{x:.1f}' for x in load['start'])}, "
        f"at the end {', '.join(f'{x:.1f}' for x in load['end'])} (2 cores, shared).",
        "",
        f"{r['rows']} random realistic run-outs; truth: solve_ivp DOP853 rtol 1e-10 "
        f"({r['truth_seconds_per_runout']:.2f} s per run-out). Versions: "
        + ", ".join(labels)
        + " (same process, alternating).",
        "",
        "| kernel tol | version | s per run-out (1 thread) | worst rest error [m] | mean steps "
        "| solve_ivp RK45 at equal error / kernel |",
        "|---|---|---|---|---|---|",
    ]
    for i, tol in enumerate(KERNEL_TOLS):
        for label in labels:
            p, q = r["kernel"][label][i], r["ratios_at_equal_error"][label][i]
            lines.append(
                f"| {tol:.0e} | {label} | {p['seconds_per_runout']:.2e} | {p['worst_error_m']:.2e} | "
                f"{p['mean_steps']:.0f} | {q['ratio']:.0f} |"
            )
    lines += ["", "| solve_ivp RK45 rtol | s per run-out | worst rest error [m] |", "|---|---|---|"]
    lines += [
        f"| {p['rtol']:.0e} | {p['seconds_per_runout']:.2e} | {p['worst_error_m']:.2e} |"
        for p in r["solve_ivp_RK45"]
    ]
    lines += [
        "",
        "| version | run-outs/s, parallel batch (2 threads) | run-outs/s, one thread | "
        "worst / least ratio to RK45 over the sweep |",
        "|---|---|---|---|",
    ]
    for label in labels:
        ratios = [q["ratio"] for q in r["ratios_at_equal_error"][label]]
        lines.append(
            f"| {label} | {r['runouts_per_second_parallel'][label]:.0f} | "
            f"{r['runouts_per_second_one_thread_default_tol'][label]:.0f} | {min(ratios):.0f} / {max(ratios):.0f} |"
        )
    lines += [
        "",
        "| fit to rest (after first use) | version | ms (scan + uniqueness starts) | ms (one start) "
        "| iterations | converged |",
        "|---|---|---|---|---|---|",
    ]
    for c in r["fit"]["cases"]:
        for label in labels:
            f = c[label]
            lines.append(
                f"| {c['wheels']} | {label} | {f['ms']:.1f} | {f['ms_one_start']:.1f} | {f['iterations']} | "
                f"{f['converged']} |"
            )
    lines += [
        "",
        "| closed form (tests/test_runout_model.py) | run-out | closed form | error |",
        "|---|---|---|---|",
    ]
    lines += [
        f"| {c['case']} | {c['run_out']:.7g} {c['unit']} | {c['closed_form']:.7g} {c['unit']} | "
        f"{c['run_out'] - c['closed_form']:.1e} {c['unit']} |"
        for c in r["closed_forms"]
    ]
    ref = r["reference_10_rows"]
    lines += [
        "",
        f"Against solve_ivp DOP853 rtol 1e-10 on the 10 rows of tests/test_runout_reference.py: worst "
        f"rest-position error {ref['position_m']:.2e} m, heading {ref['heading_deg']:.1e} deg, "
        f"{100 * ref['share_of_allowance']:.1f} % of the allowance 1 mm + 1e-5 of the path.",
        "",
    ]
    for label in labels:
        fr = r["fit_random"][label]
        lines.append(
            f"Fit round trips ({label}) on {fr['rows']} random realistic run-outs: {fr['converged']} converged, "
            f"{fr['recovered']} recovered the generating state (reported or named as an alternative), "
            f"{fr['other_state_unnamed']} reached the rest pose from another state without naming the "
            f"generating one; {fr['alternatives']} alternatives named, {fr['spurious_alternatives']} of them "
            f"spurious; median {fr['median_ms']:.1f} ms, max {fr['max_ms']:.1f} ms per fit."
        )
    if "fit_random_via" in r:
        lines.append(_via_line(r["fit_random_via"]))
    if "load_transfer" in r:
        lines.append(_transfer_line(r["load_transfer"]))
    return "\n".join(lines) + "\n"
