"""Command line: ``impactsym <command> ...``.

Commands are registered in :data:`COMMANDS` as ``name -> Command``: its
``add_arguments`` fills the command's sub-parser, its ``run`` takes the parsed
arguments and returns the exit code.  Any bad input (a scene error, an
unreadable file, a wrong argument) prints one line ``impactsym: error:
<reason>`` on stderr and exits with code 2.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from typing import Callable

from .compare import compare
from .crash3 import crash3
from .scene import SceneError
from .inverse import invert
from .plot import add_plot_argument, save_plot
from .reconstruct import reconstruct
from .single import solve

__all__ = ["main", "build_parser", "Command", "COMMANDS"]

PROG = "impactsym"
EXIT_BAD_INPUT = 2


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
        raise UsageError(message)


def _add_scene(parser: argparse.ArgumentParser) -> None:
    """The scene file and ``--json``."""
    parser.add_argument("scene", help="scene file (.json or .toml)")
    parser.add_argument("--json", action="store_true", help="print the result as one JSON object")


def _add_solve(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``solve``, ``invert``, ``reconstruct``: the scene, ``--json``,
    ``--plot PATH`` (the scene diagram)."""
    _add_scene(parser)
    add_plot_argument(parser)


def _print_result(result, as_json: bool) -> int:
    """Print a result as JSON or as a table; return exit code 0."""
    if as_json:
        print(json.dumps(result.to_json_dict(), indent=2, allow_nan=False))
    else:
        print(result.table())
    return 0


def _report(result, args: argparse.Namespace) -> int:
    """Draw the scene diagram (``--plot``), then print the result."""
    if args.plot:
        save_plot(result, args.plot, scene=args.scene)
    return _print_result(result, args.json)


def _run_solve(args: argparse.Namespace) -> int:
    """Solve a scene; print JSON (``--json``) or a table."""
    return _report(solve(args.scene), args)


def _run_reconstruct(args: argparse.Namespace) -> int:
    """Reconstruct pre-impact speeds from final motion and headings; print JSON or a table."""
    return _report(reconstruct(args.scene), args)


def _run_invert(args: argparse.Namespace) -> int:
    """Recover the pre-impact motion of an inverse scene; print JSON or a table."""
    return _report(invert(args.scene), args)


def _add_crash3(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``crash3``: the scene file, ``--json`` and ``--restitution``."""
    _add_scene(parser)
    parser.add_argument("--restitution", type=float, default=0.0, metavar="E",
                        help="restitution e, 0 <= e < 1 (default 0: CRASH3's common velocity)")


def _run_crash3(args: argparse.Namespace) -> int:
    """CRASH3 delta-V from the vehicles' crush tables; print JSON or a table."""
    return _print_result(crash3(args.scene, restitution=args.restitution), args.json)


def _add_compare(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``compare``: the scene file, one output format, ``--plot``."""
    parser.add_argument("scene", help="scene file (.json or .toml)")
    form = parser.add_mutually_exclusive_group()
    form.add_argument("--json", action="store_true", help="print the comparison as one JSON object")
    form.add_argument("--markdown", action="store_true", help="print the table as markdown")
    parser.add_argument("--plot", metavar="OUT.png",
                        help="also save a bar chart of delta-V and energy loss by model")


def _run_compare(args: argparse.Namespace) -> int:
    """Run the scene through every model its data allow; print the table."""
    result = compare(args.scene)
    if args.plot:
        try:
            result.plot(args.plot)
        except ImportError:
            raise UsageError("--plot needs matplotlib (pip install 'impactsym[plot]')") from None
    if args.markdown:
        print(result.markdown())
        return 0
    return _print_result(result, args.json)


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
}


def build_parser() -> argparse.ArgumentParser:
    """The ``impactsym`` parser with one sub-parser per entry of :data:`COMMANDS`."""
    parser = _Parser(prog=PROG, description="Impact phase of planar vehicle collisions.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, command in COMMANDS.items():
        command.add_arguments(commands.add_parser(name, help=command.help, description=command.help))
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit code (0 success, 2 bad input)."""
    try:
        args = build_parser().parse_args(argv)
        return COMMANDS[args.command].run(args)
    except (UsageError, SceneError) as exc:
        return _fail(str(exc))
    except OSError as exc:
        return _fail(f"{exc.filename}: {exc.strerror}" if exc.filename else str(exc))
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else 0


def _fail(reason: str) -> int:
    """Print ``impactsym: error: <reason>`` as one line on stderr; return 2."""
    print(f"{PROG}: error: {' '.join(reason.split())}", file=sys.stderr)
    return EXIT_BAD_INPUT
