"""Command line: ``impactsym <command> ...``.

Commands are registered in :data:`COMMANDS` as ``name -> Command``: its
``add_arguments`` fills the command's sub-parser, its ``run`` takes the parsed
arguments and returns the exit code.  Any bad input (a scene error, an
unreadable file, a wrong argument) prints one line ``impactsym: error:
<reason>`` on stderr and exits with code 2.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from contextlib import contextmanager, suppress
from dataclasses import dataclass

import numpy as np

from . import _kernels, uncertainty_cli, warmup
from ._version import __version__
from .codes import describe_status
from .compare import compare
from .crash3 import crash3
from .inverse import invert
from .plot import add_plot_argument, save_plot
from .reconstruct import reconstruct
from .result import UNIT_LABELS, json_clean, json_number, table_cell
from .runout import cli as runout_cli
from .scene import SceneError
from .single import solve
from .sweep import (
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
from .sweep import sweep as solve_sweep

__all__ = ["COMMANDS", "Command", "build_parser", "main"]

PROG = "impactsym"
EXIT_BAD_INPUT = 2
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports a command stopped by Ctrl-C
EXIT_TERMINATED = 143  # 128 + SIGTERM


@dataclass(frozen=True)
class Command:
    """A subcommand: one-line help, how to add its arguments, how to run it."""

    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], int]


class UsageError(Exception):
    """A command-line argument problem (raised instead of argparse's exit)."""


class _Parser(argparse.ArgumentParser):
    """An argument parser that raises :class:`UsageError` instead of printing usage and exiting."""

    def error(self, message: str):
        raise UsageError(_once(message))


def _once(message: str) -> str:
    """argparse's ``argument --plot: <reason>`` without the option's name
    when the reason already starts with it (``--plot out.txt: unknown image
    type``): the name is said once."""
    head, sep, reason = message.partition(": ")
    names = head.removeprefix("argument ").split("/")
    if sep and head.startswith("argument ") and reason.startswith(tuple(names)):
        return reason
    return message


def _add_scene(parser: argparse.ArgumentParser) -> None:
    """The scene file and ``--json``."""
    parser.add_argument("scene", help="scene file (.json or .toml)")
    parser.add_argument("--json", action="store_true", help="print the result as one JSON object")


def _add_solve(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``solve``, ``invert``, ``reconstruct``: the scene, ``--json``,
    ``--plot PATH`` (the scene diagram)."""
    _add_scene(parser)
    add_plot_argument(parser)
    uncertainty_cli.add_arguments(parser)


def _print_result(result, as_json: bool) -> int:
    """Print a result as JSON or as a table; return exit code 0."""
    if as_json:
        print(json.dumps(json_clean(result.to_json_dict()), indent=2, allow_nan=False))
    else:
        print(result.table())
    return 0


def _report(result, args: argparse.Namespace, command: str) -> int:
    """Draw the scene diagram (``--plot``), then print the result; with
    ``--uncertainty`` the result with its uncertainty (uncertainty_cli)."""
    if args.uncertainty:
        return uncertainty_cli.run(args, command, result)
    if args.plot:
        save_plot(result, args.plot, scene=args.scene)
    return _print_result(result, args.json)


def _run_solve(args: argparse.Namespace) -> int:
    """Solve a scene; print JSON (``--json``) or a table."""
    if runout_cli.chained(args):  # run-out data: pre-impact -> impact -> rest
        return runout_cli.run_chained(args, "solve")
    return _report(solve(args.scene), args, "solve")


def _run_reconstruct(args: argparse.Namespace) -> int:
    """Reconstruct pre-impact speeds from final motion and headings; print JSON or a table."""
    if runout_cli.chained(args):  # rest poses: fitted run-outs -> impact
        return runout_cli.run_chained(args, "reconstruct")
    return _report(reconstruct(args.scene), args, "reconstruct")


def _run_invert(args: argparse.Namespace) -> int:
    """Recover the pre-impact motion of an inverse scene; print JSON or a table."""
    return _report(invert(args.scene), args, "invert")


def _add_crash3(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``crash3``: the scene file, ``--json`` and the CRASH3 options
    (``--restitution``, ``--energy``, ``--correction``), which override the
    scene's ``"crash3"`` object. Values are checked by :func:`crash3` so that a
    bad one is the same one-line error as in a scene."""
    _add_scene(parser)
    parser.add_argument(
        "--restitution",
        type=float,
        default=None,
        metavar="E",
        help="restitution e (default: the scene's, else 0: CRASH3's common velocity)",
    )
    parser.add_argument(
        "--energy",
        default=None,
        metavar="MODE",
        help="what the crush energy is: dissipated (over the impact, default) or "
        "absorbed (to maximum crush; total delta-V = (1 + e) x approach)",
    )
    parser.add_argument(
        "--correction",
        default=None,
        metavar="NAME",
        help="oblique correction: crash3 (1 + tan^2 alpha, default) or woolley "
        "(1/cos alpha); both capped at 45 degrees as EDCRASH does",
    )
    add_plot_argument(parser)  # the CRASH3 diagram; with --uncertainty, histograms and budget
    uncertainty_cli.add_arguments(parser)


def _run_crash3(args: argparse.Namespace) -> int:
    """CRASH3 delta-V from the vehicles' crush tables; print JSON or a table."""
    result = crash3(args.scene, restitution=args.restitution, energy=args.energy, correction=args.correction)
    if args.uncertainty:
        return uncertainty_cli.run(
            args,
            "crash3",
            result,
            restitution=result.restitution,
            energy=result.options.energy,
            correction=result.options.correction,
        )
    if args.plot:
        save_plot(result, args.plot, scene=args.scene)
    return _print_result(result, args.json)


def _add_compare(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``compare``: the scene file, one output format, ``--plot``."""
    parser.add_argument("scene", help="scene file (.json or .toml)")
    form = parser.add_mutually_exclusive_group()
    form.add_argument("--json", action="store_true", help="print the comparison as one JSON object")
    form.add_argument("--markdown", action="store_true", help="print the table as markdown")
    parser.add_argument(
        "--plot", metavar="OUT.png", help="also save a bar chart of delta-V and energy loss by model"
    )


def _run_compare(args: argparse.Namespace) -> int:
    """Run the scene through every model its data allow; print the table."""
    result = compare(args.scene)
    if args.plot:
        try:
            result.plot(args.plot)
        except ImportError as exc:
            raise UsageError(str(exc)) from None
    if args.markdown:
        print(result.markdown())
        return 0
    return _print_result(result, args.json)


# --------------------------------------------------------------------------- sweep and sample

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
    from .plot import save_sweep

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


@contextmanager
def _api_errors():
    """Turn the API's one-line ValueError and ImportError into a usage error."""
    try:
        yield
    except SceneError:
        raise
    except (ValueError, ImportError) as exc:
        raise UsageError(str(exc)) from None


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


def _add_validate(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``validate``: ``--markdown`` and ``--plots DIR``."""
    parser.add_argument(
        "--markdown",
        action="store_true",
        help="print the whole report (statistics, per-row tables) as markdown",
    )
    parser.add_argument(
        "--plots",
        metavar="DIR",
        default=None,
        help="save the predicted-versus-measured plots (PNG) in DIR (needs matplotlib)",
    )


def _run_validate(args: argparse.Namespace) -> int:
    """The models against RICSAC, IIHS and NHTSA crash tests (impactsym/validation.py)."""
    from . import validation

    datasets = validation.report()
    figures = None
    if args.plots:
        paths = validation.plot(datasets, args.plots)
        figures = {ds.name: str(path) for ds, path in zip(datasets, paths)}
    print(validation.markdown(datasets, figures) if args.markdown else validation.text_summary(datasets))
    return 0


def _add_compile(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--quiet", action="store_true", help="print nothing")
    parser.add_argument("--claimed", action="store_true", help=argparse.SUPPRESS)


def _run_compile(args: argparse.Namespace) -> int:
    """Compile every batch driver once for this machine (impactsym.warmup),
    and the loops of exact percentiles."""
    from . import _selection  # imports numba: only this command needs it

    where, digest = _kernels.generated.__file__, _kernels.generated_digest()
    start = time.perf_counter()
    try:
        count = _kernels.compile_all(None if args.quiet else print) + _selection.compile_loops()
    except BaseException:
        warmup.release(where, digest)
        raise
    warmup.finish(where, digest)
    if not args.quiet:
        print(
            f"compiled or loaded {count} batch drivers and loops in {time.perf_counter() - start:.0f} s; "
            f"cache: {warmup.cache_dir(where)}"
        )
    return 0


COMMANDS: dict[str, Command] = {
    "solve": Command(
        "solve the impact of a scene (initial motion -> final motion, impulses, energy loss)",
        _add_solve,
        _run_solve,
    ),
    "invert": Command(
        "recover the pre-impact motion from the post-impact motion and e, mu, e_m",
        _add_solve,
        _run_invert,
    ),
    "reconstruct": Command(
        "reconstruct pre-impact speeds from post-impact motion and pre-impact headings",
        _add_solve,
        _run_reconstruct,
    ),
    "crash3": Command(
        "CRASH3: delta-V from the vehicles' crush profiles (and the PDOF inconsistency)",
        _add_crash3,
        _run_crash3,
    ),
    "compare": Command(
        "run a scene through every model its data allow (Limpert, Macmillan, IMPAC, Brach, "
        "particle, CRASH3) and tabulate them",
        _add_compare,
        _run_compare,
    ),
    "sweep": Command(
        "solve a grid of parameter values around a scene (-o: stream every row to Parquet/CSV)",
        _add_sweep,
        _run_sweep,
    ),
    "sample": Command(
        "Monte Carlo: draw inputs from distributions around a scene, print percentiles",
        _add_sample,
        _run_sample,
    ),
    "compile": Command(
        "compile every batch kernel for this machine now (otherwise done once in the background "
        "after the first batch)",
        _add_compile,
        _run_compile,
    ),
    "validate": Command(
        "run the models against published crash tests (RICSAC, IIHS, NHTSA) and report the errors",
        _add_validate,
        _run_validate,
    ),
}
COMMANDS["runout"] = Command(runout_cli.HELP, runout_cli.add_arguments, runout_cli.run)


def build_parser() -> argparse.ArgumentParser:
    """The ``impactsym`` parser with one sub-parser per entry of :data:`COMMANDS`."""
    parser = _Parser(prog=PROG, description="Impact phase of planar vehicle collisions.")
    parser.add_argument("--version", action="version", version=f"{PROG} {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, command in COMMANDS.items():
        command.add_arguments(commands.add_parser(name, help=command.help, description=command.help))
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code (0 success, 2 bad input,
    130 interrupted by Ctrl-C; a reader that stops reading, as ``| head``
    does, ends the command quietly with 1)."""
    try:
        with _terminate_as_exit():
            args = build_parser().parse_args(argv)
            code = COMMANDS[args.command].run(args)
            sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
            return code
    except BrokenPipeError:
        return _reader_gone()
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except _Terminated:
        print(f"{PROG}: terminated", file=sys.stderr)
        return EXIT_TERMINATED
    except (UsageError, SceneError) as exc:
        return _fail(str(exc))
    except ImportError as exc:  # an optional dependency the scene or option needs
        return _fail(str(exc))
    except OSError as exc:
        return _fail(f"{exc.filename}: {exc.strerror}" if exc.filename else str(exc))
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else 0


def run() -> None:
    """The console script and ``python -m impactsym``: `main`, then leave with
    its code. A command stopped by Ctrl-C or SIGTERM has done its cleanup
    (spill files, partial outputs) inside `main`, and leaves with os._exit,
    skipping the interpreter's finalisation: a signal that landed inside
    numba or llvmlite can surface again there (an "Exception ignored"
    message, or Python killing itself with SIGINT, exit -2 instead of 130;
    about 1 run in 6 on a loaded machine)."""
    code = main()
    if code in (EXIT_INTERRUPTED, EXIT_TERMINATED):
        for stream in (sys.stdout, sys.stderr):
            with suppress(OSError, ValueError):
                stream.flush()
        os._exit(code)
    raise SystemExit(code)


class _Terminated(SystemExit):
    """SIGTERM, raised as an exit so that every ``finally`` and ``with`` on
    the way out runs (a sweep's spill folder is removed, a partial output
    file deleted) instead of the process dying where it stands."""


def _raise_terminated(signum, frame):
    if not _deferred(signum, frame):
        raise _Terminated(EXIT_TERMINATED)


def _raise_interrupted(signum, frame):
    if not _deferred(signum, frame):
        raise KeyboardInterrupt


# Python functions that C code calls through ctypes while numba loads or
# compiles a driver: llvmlite's object-cache hooks (ExecutionEngine). Python
# prints and drops an exception raised in a ctypes callback, as in a finaliser.
_CTYPES_CALLBACKS = ("_raw_object_cache_notify", "_raw_object_cache_getbuffer")


def _deferred(signum, frame) -> bool:
    """True when the signal landed where Python prints and drops an exception,
    so Ctrl-C would be lost: inside a finaliser (``__del__``; numba and llvmlite
    free compiler objects there) or a ctypes callback (`_CTYPES_CALLBACKS`,
    reached while numba loads a driver from its cache). The signal is sent
    again 50 ms later, when that code has returned."""
    while frame is not None:
        code = frame.f_code
        if code.co_name == "__del__" or (
            code.co_name in _CTYPES_CALLBACKS and "llvmlite" in code.co_filename
        ):
            threading.Timer(0.05, os.kill, (os.getpid(), signum)).start()
            return True
        frame = frame.f_back
    return False


@contextmanager
def _terminate_as_exit():
    """SIGTERM raises :class:`_Terminated` while the command runs (the main
    thread only: a signal handler cannot be set elsewhere); the previous
    handler is restored after."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    # SIGINT as KeyboardInterrupt whatever the disposition inherited from the
    # parent (a script's background job inherits it ignored): Ctrl-C or
    # `kill -INT` always stops a command cleanly, spill files removed.
    previous_int = signal.signal(signal.SIGINT, _raise_interrupted)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
        signal.signal(signal.SIGINT, previous_int)


def _reader_gone() -> int:
    """stdout's reader has gone (``impactsym solve x.json --json | head -c 10``):
    say nothing, and point stdout at devnull so that Python's final flush does
    not fail again (the recipe of Python's signal documentation)."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, io.UnsupportedOperation):
        pass  # stdout is not a file descriptor (captured in-process): nothing to flush
    return 1


def _fail(reason: str) -> int:
    """Print ``impactsym: error: <reason>`` as one line on stderr; return 2."""
    print(f"{PROG}: error: {' '.join(reason.split())}", file=sys.stderr)
    return EXIT_BAD_INPUT
