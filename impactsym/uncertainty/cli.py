"""``--uncertainty`` on solve, invert, reconstruct and crash3 (the CLI's part of uncertainty).

`add_arguments(parser)` adds ``--uncertainty``, ``--draws N``, ``--seed S``
and ``--sobol`` to a command's sub-parser (``--json`` and ``--plot`` are the
command's own: with ``--uncertainty``, ``--plot OUT.png`` draws the histograms
and the budget instead of the scene diagram). `run(args, command, result)`
prints the command's usual result with the uncertainty: JSON (the usual
object plus ``"uncertainty"``, conventions.md) or the tables for people.
"""

from __future__ import annotations

import argparse
import json
import sys

from ..residue import without_json_residue
from ..result import json_clean
from ..scene import SceneError
from .propagation import uncertainty
from .result import MIN_INTERVAL_DRAWS

DEFAULT_DRAWS = 10_000


def add_arguments(parser: argparse.ArgumentParser, plot: bool = False) -> None:
    """The uncertainty options of a command (`plot`: also add ``--plot``)."""
    group = parser.add_argument_group("uncertainty")
    group.add_argument(
        "--uncertainty",
        action="store_true",
        help="propagate the scene's distributions: Monte Carlo, linear sd, budget",
    )
    group.add_argument(
        "--draws",
        type=int,
        default=None,
        metavar="N",
        help=f"Monte Carlo draws (default {DEFAULT_DRAWS}, at least {MIN_INTERVAL_DRAWS})",
    )
    group.add_argument(
        "--seed",
        type=int,
        default=None,
        metavar="S",
        help="seed of the draws (default: fresh entropy, printed)",
    )
    group.add_argument(
        "--sobol", action="store_true", help="also Sobol first-order and total indices (SALib)"
    )
    if plot:
        group.add_argument("--plot", metavar="OUT.png", help="with --uncertainty: histograms and budget")


def warn_unused(args: argparse.Namespace) -> None:
    """Say on stderr which uncertainty options were given without ``--uncertainty``
    (they are read only with it)."""
    given = [
        name
        for name, value in (("--draws", args.draws), ("--seed", args.seed), ("--sobol", args.sobol or None))
        if value is not None
    ]
    if given and not args.uncertainty:
        print(
            f"impactsym: warning: {', '.join(given)} ignored: read only with --uncertainty", file=sys.stderr
        )


def run(args: argparse.Namespace, command: str, result, **options) -> int:
    """Print `result` with the uncertainty of `command` for ``args.scene``."""
    draws = DEFAULT_DRAWS if args.draws is None else args.draws
    if draws < MIN_INTERVAL_DRAWS:
        raise SceneError(
            f"{draws} draws cannot give a 90 % interval; give at least {MIN_INTERVAL_DRAWS}", "--draws"
        )
    try:
        u = uncertainty(args.scene, command=command, draws=draws, seed=args.seed, sobol=args.sobol, **options)
    except (ValueError, ImportError) as exc:  # a one-line reason, exit code 2
        raise SceneError(str(exc)) from None
    if getattr(args, "plot", None):
        from .plot import save_uncertainty_plot

        save_uncertainty_plot(u, args.plot, names=[v.name for v in result.vehicles], units=result.units)
    if args.json:
        both = without_json_residue({**result.to_json_dict(), "uncertainty": u.to_json_dict()})
        print(json.dumps(json_clean(both), indent=2, allow_nan=False))
    else:
        print(result.table())
        print()
        print(u.table())
    return 0
