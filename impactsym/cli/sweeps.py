"""The batch commands: sweep (a grid around a scene) and sample (Monte Carlo
draws), with their run options, summaries and outputs."""

from __future__ import annotations

import argparse
import json

import numpy as np

from ..batch.resources import check_axis
from ..batch.sweeps import (
    CHUNK_SIZE,
    PERCENTILES,
    SWEEP_PERCENTILES,
    GridPlan,
    SamplePlan,
    percentiles,
    summarize,
    summary_columns,
    write_frame,
)
from ..batch.sweeps import sweep as solve_sweep
from ..codes import describe_status
from ..result import UNIT_LABELS, json_clean, json_number, table_cell
from .common import UsageError, _api_errors

_OUTPUT_TIERS = ("all", "velocities", "impulses", "energy")
_SUMMARY_LABELS = {"p0": "min", "p50": "median", "p100": "max"}


def _add_run_options(parser: argparse.ArgumentParser) -> None:
    """Options shared by ``sweep`` and ``sample``: output file, tier, chunks, engine, progress."""
    parser.add_argument(
        "-o", "--out", metavar="OUT.parquet|OUT.csv", help="write every row to this file, chunk by chunk"
    )
    parser.add_argument(
        "--outputs", choices=_OUTPUT_TIERS, default="all", help="outputs to compute (default all)"
    )
    parser.add_argument(
        "--chunk-size",
        type=int,
        default=CHUNK_SIZE,
        metavar="N",
        help=f"rows per chunk (default {CHUNK_SIZE})",
    )
    parser.add_argument(
        "--engine",
        choices=("local", "dask"),
        default="local",
        help="local, or dask: chunks as tasks on dask's scheduler (the dask extra)",
    )
    parser.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")


def _add_sweep(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``sweep``: the scene, ``--vary`` (repeatable), run options, ``--plot``."""
    parser.add_argument("scene", help="base scene file (.json or .toml)")
    parser.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="NAME=VALUES",
        help="NAME=START:STOP:NUM (NUM values, both ends included), NAME=V1,V2,... "
        "(mu may list 'critical') or NAME=V (a constant); repeat for a grid, "
        "the first varying slowest. Names: kernel inputs (e, mu, e_m, gamma "
        "[rad], m1, v1x, ...) or normal_angle [deg], restitution, "
        "impulse_ratio, moment_restitution",
    )
    parser.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    _add_run_options(parser)
    parser.add_argument(
        "--plot", metavar="OUT.png", help="also draw the sweep (1 or 2 varied parameters; needs matplotlib)"
    )
    parser.add_argument("--color", metavar="NAME", help="output drawn by --plot (default TL)")


def _number(text: str, option: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise UsageError(f"{option}: {text!r} is not a number") from None


def _grid_value(text: str, option: str):
    """``critical`` or a number."""
    return text if text == "critical" else _number(text, option)


def _parse_vary(text: str):
    """``NAME=START:STOP:NUM`` (inclusive linspace), ``NAME=V1,V2,...`` or ``NAME=V``."""
    name, sep, spec = text.partition("=")
    option = f"--vary {text}"
    if not sep or not name.strip() or not spec.strip():
        raise UsageError(f"{option}: expected NAME=START:STOP:NUM, NAME=V1,V2,... or NAME=V")
    name = name.strip()
    if ":" in spec:
        parts = spec.split(":")
        if len(parts) != 3 or not parts[2].strip().isdigit() or int(parts[2]) < 1:
            raise UsageError(f"{option}: expected NAME=START:STOP:NUM with NUM a positive integer")
        start, stop = (_number(part, option) for part in parts[:2])
        if not (np.isfinite(start) and np.isfinite(stop)):
            raise UsageError(f"{option}: START and STOP must be finite numbers")
        with _api_errors():
            check_axis(name, int(parts[2]))  # before the axis is built
        return name, np.linspace(start, stop, int(parts[2]))
    if "," in spec:
        return name, [_grid_value(part.strip(), option) for part in spec.split(",")]
    return name, _grid_value(spec.strip(), option)


def _named(pairs, option: str) -> dict:
    """``pairs`` as a dict; a name given twice is an error."""
    values = {}
    for name, value in pairs:
        if name in values:
            raise UsageError(f"{option} {name}: given twice")
        values[name] = value
    return values


def _run_options(args: argparse.Namespace) -> dict:
    """Keyword arguments of the run: engine, chunk size, progress bar."""
    return {
        "engine": args.engine,
        "chunk_size": args.chunk_size,
        "progress": False if args.no_progress else None,
    }


def _run_sweep(args: argparse.Namespace) -> int:
    """Solve a grid around the scene; write the rows (``-o``) and print a summary."""
    values = _named((_parse_vary(text) for text in args.vary), "--vary")
    varied = [name for name, value in values.items() if np.ndim(value) == 1]
    if args.plot and not 1 <= len(varied) <= 2:
        raise UsageError(
            f"--plot draws a sweep of 1 or 2 varied parameters, got {len(varied)}"
            + (f" ({', '.join(varied)})" if varied else "")
        )
    if args.color and not args.plot:
        raise UsageError("--color: only with --plot")
    if args.chunk_size < 1:
        raise UsageError(f"--chunk-size: must be a positive integer, got {args.chunk_size}")
    with _api_errors():
        plan = GridPlan.build(args.scene, values, args.outputs)
        if args.plot:
            summary = _sweep_and_plot(args, values, varied, plan.units)
        else:
            summary = summarize(plan, out=args.out, q=SWEEP_PERCENTILES, **_run_options(args))
    if args.json:
        print(json.dumps(json_clean(_summary_json(summary, plan.units)), indent=2, allow_nan=False))
    else:
        _print_summary(summary, plan.units, args.out)
    return 0


def _sweep_and_plot(args: argparse.Namespace, values: dict, varied: list, units: str):
    """The sweep in memory: draw it, write it (``-o``), return its summary."""
    from ..plot import save_sweep

    frame = solve_sweep(args.scene, outputs=args.outputs, **_run_options(args), **values)
    save_sweep(
        frame,
        args.plot,
        x=varied[0],
        y=varied[1] if len(varied) == 2 else None,
        color=args.color,
        units=units,
    )
    if args.out:
        write_frame(frame, args.out, tuple(varied))
    return percentiles(frame, summary_columns(args.outputs), q=SWEEP_PERCENTILES)


def _add_sample(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``sample``: the scene, ``--dist`` (repeatable), ``-n``, ``--seed``, run options."""
    parser.add_argument("scene", help="base scene file (.json or .toml)")
    parser.add_argument(
        "--dist",
        action="append",
        default=[],
        metavar="NAME=KIND:P1:P2[:P3]",
        help="a drawn input: uniform:LOW:HIGH, normal:MEAN:SD, "
        "triangular:LEFT:MODE:RIGHT or lognormal:MEAN_OF_LOG:SD_OF_LOG "
        "(names as for sweep); repeat for more",
    )
    parser.add_argument("-n", type=int, required=True, metavar="N", help="number of scenes to draw")
    parser.add_argument("--seed", type=int, metavar="S", help="seed (default: fresh entropy, printed)")
    parser.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    _add_run_options(parser)


def _parse_dist(text: str):
    """``NAME=KIND:P1:P2[:P3]`` -> (name, (kind, p1, p2[, p3]))."""
    name, sep, spec = text.partition("=")
    option = f"--dist {text}"
    kind, *params = spec.split(":")
    if not sep or not name.strip() or not kind or not params:
        raise UsageError(f"{option}: expected NAME=KIND:P1:P2[:P3], e.g. e=uniform:0:0.3")
    return name.strip(), (kind, *(_number(p, option) for p in params))


def _run_sample(args: argparse.Namespace) -> int:
    """Draw and solve ``-n`` scenes; write the rows (``-o``) and print percentiles."""
    dists = _named((_parse_dist(text) for text in args.dist), "--dist")
    if args.chunk_size < 1:
        raise UsageError(f"--chunk-size: must be a positive integer, got {args.chunk_size}")
    with _api_errors():
        plan = SamplePlan.build(args.scene, dists, args.n, args.seed, args.outputs)
        summary = summarize(plan, out=args.out, q=PERCENTILES, **_run_options(args))
    if args.json:
        print(
            json.dumps(
                json_clean(_summary_json(summary, plan.units, plan.entropy)), indent=2, allow_nan=False
            )
        )
    else:
        _print_summary(summary, plan.units, args.out, seed=plan.entropy)
    return 0


def _unit(column: str, units: str) -> str:
    labels = UNIT_LABELS[units]
    if column.startswith("TL"):
        return labels["energy"]
    return labels["yaw_rate"] if column[0] in "Ww" else labels["velocity"]


def _print_summary(summary, units: str, out, seed=None) -> None:
    """Counts, why rows were not solved, then one line per summarised output
    with its percentiles (none when no row was solved: there is nothing to
    summarise)."""
    counts = summary.attrs["counts"]
    if out:
        print(f"wrote {counts['rows']} rows to {out}")
    print(
        f"rows {counts['rows']}: solved {counts['solved']}, flagged {counts['flagged']}, "
        f"not solved {counts['not_solved']}" + (f"; seed {seed}" if seed is not None else "")
    )
    for status, rows in counts.get("not_solved_by_status", {}).items():
        print(f"  not solved, status {status}: {rows} rows: {describe_status(status)}")
    if counts["solved"] == 0 and counts["rows"]:
        print("no row was solved: no statistics (the reasons are above)")
        return
    if summary.empty:
        return
    heads = [_SUMMARY_LABELS.get(label, label) for label in summary.columns]
    print(f"{'':<14}" + "".join(f"{head:>14}" for head in heads))
    for column, row in summary.iterrows():
        label = f"{column} [{_unit(column, units)}]"
        print(f"{label:<14}" + "".join(f"{table_cell(value):>14}" for value in row))


def _summary_json(summary, units: str, seed=None) -> dict:
    """The sweep or sample summary as a JSON object (percentile keys are the
    q values; ``not_solved_by_status`` maps status codes to row counts; a
    sample also gives its ``seed``)."""
    counts = dict(summary.attrs["counts"])
    counts["not_solved_by_status"] = {
        str(code): rows for code, rows in counts.get("not_solved_by_status", {}).items()
    }
    return {
        "units": units,
        **({"seed": seed} if seed is not None else {}),
        **counts,
        "percentiles": {
            column: {label[1:]: json_number(float(value)) for label, value in row.items()}
            for column, row in summary.iterrows()
        },
    }
