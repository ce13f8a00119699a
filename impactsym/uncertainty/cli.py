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

from ..scene import SceneError
from .propagation import uncertainty
from ..residue import without_json_residue
from ..result import json_clean

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
        default=DEFAULT_DRAWS,
        metavar="N",
        help=f"Monte Carlo draws (default {DEFAULT_DRAWS})",
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


def run(args: argparse.Namespace, command: str, result, **options) -> int:
    """Print `result` with the uncertainty of `command` for ``args.scene``."""
    try:
        u = uncertainty(
            args.scene, command=command, draws=args.draws, seed=args.seed, sobol=args.sobol, **options
        )
    except (ValueError, ImportError) as exc:  # a one-line reason, exit code 2
        raise SceneError(str(exc)) from None
    if getattr(args, "plot", None):
        from .plot import save_uncertainty_plot

        save_uncertainty_plot(u, args.plot)
    if args.json:
        both = without_json_residue({**result.to_json_dict(), "uncertainty": u.to_json_dict()})
        print(json.dumps(json_clean(both), indent=2, allow_nan=False))
    else:
        print(result.table())
        print()
        print(u.table())
    return 0
