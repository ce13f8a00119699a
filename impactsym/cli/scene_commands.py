"""The commands on one scene: solve, invert, reconstruct, crash3 and compare."""

from __future__ import annotations

import argparse
import json

from ..compare import compare
from ..crash3 import crash3
from ..inverse import invert
from ..plot import add_plot_argument, save_plot
from ..reconstruct import reconstruct
from ..residue import without_json_residue
from ..result import json_clean
from ..runout import cli as runout_cli
from ..single import solve
from ..uncertainty import cli as uncertainty_cli
from .common import UsageError, _add_scene


def _add_solve(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``solve``, ``invert``, ``reconstruct``: the scene, ``--json``,
    ``--plot PATH`` (the scene diagram)."""
    _add_scene(parser)
    add_plot_argument(parser)
    uncertainty_cli.add_arguments(parser)


def _print_result(result, as_json: bool) -> int:
    """Print a result as JSON or as a table; return exit code 0."""
    if as_json:
        print(json.dumps(json_clean(without_json_residue(result.to_json_dict())), indent=2, allow_nan=False))
    else:
        print(result.table())
    return 0


def _report(result, args: argparse.Namespace, command: str) -> int:
    """Draw the scene diagram (``--plot``), then print the result; with
    ``--uncertainty`` the result with its uncertainty (uncertainty_cli)."""
    if args.uncertainty:
        return uncertainty_cli.run(args, command, result)
    uncertainty_cli.warn_unused(args)
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
    uncertainty_cli.warn_unused(args)
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
