"""The maintenance commands: validate (the models against published crash
tests) and compile (every batch driver for this machine)."""

from __future__ import annotations

import argparse
import time

from .. import _kernels


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
    """The models against RICSAC, IIHS and NHTSA crash tests (impactsym.validation)."""
    from .. import validation

    datasets = validation.report()
    figures = None
    if args.plots:
        paths = validation.plot(datasets, args.plots)
        figures = {path.stem: str(path) for path in paths}  # a dataset's own figure is named after it
    print(validation.markdown(datasets, figures) if args.markdown else validation.text_summary(datasets))
    return 0


def _add_compile(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--quiet", action="store_true", help="print nothing")


def _run_compile(args: argparse.Namespace) -> int:
    """Compile every batch driver once for this machine, the loops of
    exact percentiles and the draws' local fit."""
    from ..batch import selection  # imports numba: only this command needs it
    from ..runout import neighbours
    from ..runout.batch import compile_drivers

    start = time.perf_counter()
    count = (
        _kernels.compile_all(None if args.quiet else print)
        + selection.compile_loops()
        + compile_drivers()
        + neighbours.compile_loops()
    )
    if not args.quiet:
        print(f"compiled or loaded {count} batch drivers and loops in {time.perf_counter() - start:.0f} s")
    return 0
