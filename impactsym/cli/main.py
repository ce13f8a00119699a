"""The ``impactsym`` command line: the table of commands, the parser, and
``main``/``run`` with the exit codes (0 success, 2 bad input, 130 Ctrl-C, 143
SIGTERM, 1 when stdout's reader has gone)."""

from __future__ import annotations

import argparse
import io
import os
import sys
import warnings
from contextlib import suppress

from .._version import __version__
from ..evidence import cli as evidence_cli
from ..runout import cli as runout_cli
from ..scene import SceneError
from .common import EXIT_INTERRUPTED, EXIT_TERMINATED, PROG, Command, UsageError, _fail, _Parser
from .scene_commands import (
    _add_compare,
    _add_crash3,
    _add_solve,
    _run_compare,
    _run_crash3,
    _run_invert,
    _run_reconstruct,
    _run_solve,
)
from .signals import Terminated, terminate_as_exit
from .sweeps import _add_sample, _add_sweep, _run_sample, _run_sweep
from .tools import _add_compile, _add_validate, _run_compile, _run_validate

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
        "compile every batch kernel for this machine now (otherwise each compiles on its first use)",
        _add_compile,
        _run_compile,
    ),
    "validate": Command(
        "run the models against published crash tests (RICSAC, IIHS, NHTSA) and report the errors",
        _add_validate,
        _run_validate,
    ),
}
COMMANDS.update({name: Command(*spec) for name, spec in evidence_cli.COMMANDS.items()})
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
        with terminate_as_exit(), warnings.catch_warnings():
            warnings.showwarning = _one_line_warning  # no source paths on a terminal
            args = build_parser().parse_args(argv)
            code = COMMANDS[args.command].run(args)
            sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
            return code
    except BrokenPipeError:
        return _reader_gone()
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Terminated:
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


def _one_line_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """A warning from the library as one line on stderr, without its source."""
    print(f"{PROG}: warning: {message}", file=file or sys.stderr)


def run() -> None:
    """The console script and ``python -m impactsym``: `main`, then leave with
    its code. A command stopped by Ctrl-C or SIGTERM has done its cleanup
    (spill files, partial outputs) inside `main`, and leaves with os._exit,
    skipping the interpreter's finalisation: a signal that landed inside
    numba while it ran can surface again there (Python killing itself with
    SIGINT, exit -2 instead of 130: 5 runs in 6 of the interrupted-sweep test
    without it, tests/test_first_use.py)."""
    code = main()
    if code in (EXIT_INTERRUPTED, EXIT_TERMINATED):
        for stream in (sys.stdout, sys.stderr):
            with suppress(OSError, ValueError):
                stream.flush()
        os._exit(code)
    raise SystemExit(code)


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
