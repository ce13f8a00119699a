"""What every command shares: the Command record, the parser that raises
instead of exiting, one-line errors (exit code 2) and the scene argument."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass

from ..scene import SceneError

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


@contextmanager
def _api_errors():
    """Turn the API's one-line ValueError and ImportError into a usage error."""
    try:
        yield
    except SceneError:
        raise
    except (ValueError, ImportError) as exc:
        raise UsageError(str(exc)) from None


def _fail(reason: str) -> int:
    """Print ``impactsym: error: <reason>`` as one line on stderr; return 2."""
    print(f"{PROG}: error: {' '.join(reason.split())}", file=sys.stderr)
    return EXIT_BAD_INPUT
