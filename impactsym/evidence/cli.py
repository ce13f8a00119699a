"""Command line of the evidence room: ``impactsym fit`` and ``impactsym edr``.

`add_parsers(subparsers)` adds both commands to an argparse sub-parser set
(each parser's default ``run`` is its run function); `COMMANDS` holds the same
as (help, add_arguments, run) for impactsym.cli's table. Bad input raises
SceneError, which the command line prints as one line with exit code 2.
"""

from __future__ import annotations

import argparse
import json

FIT_HELP = "fit the impact to mixed evidence (EDR, departure directions, speeds, energy) with intervals"
EDR_HELP = "read an EDR crash-pulse (or pre-crash speed) CSV: peak delta-V, direction, time, ended"


def add_fit_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scene", help="scene file (.json or .toml) with an evidence list")
    parser.add_argument("--json", action="store_true", help="print the JSON object of conventions.md")
    parser.add_argument("--draws", type=int, default=400, help="Monte Carlo draws for nonlinear intervals")
    parser.add_argument("--seed", type=int, default=0, help="seed of the Monte Carlo draws")
    parser.add_argument(
        "--method", choices=("auto", "gauss-newton"), default="auto",
        help="auto: closed form on linear evidence; gauss-newton: always iterate",
    )  # fmt: skip
    parser.add_argument("--plot", metavar="OUT.png", help="draw the normalised residuals per evidence item")
    parser.add_argument(
        "--scene-plot",
        metavar="OUT.png",
        help="draw the scene with the fitted motion and the departure directions",
    )


def add_edr_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("file", help="CSV with 'name [unit]' headers")
    parser.add_argument(
        "--units", choices=("SI", "US"), default="SI", help="units of the result (default SI)"
    )
    parser.add_argument(
        "--lateral-positive", choices=("right", "left"), default="right",
        help="sense of positive lateral values in the file (Bosch CDR: right, the default)",
    )  # fmt: skip
    parser.add_argument(
        "--integration", choices=("trapezoid", "sum"), default="trapezoid",
        help="integration of accelerations (default trapezoid)",
    )  # fmt: skip
    parser.add_argument("--json", action="store_true", help="print the JSON object of conventions.md")


def run_fit(args: argparse.Namespace) -> int:
    from .fit import fit

    if args.draws < 0:
        from ..errors import SceneError

        raise SceneError(f"--draws must be >= 0, got {args.draws}")
    result = fit(args.scene, draws=args.draws, seed=args.seed, method=args.method)
    if args.plot:
        from .report import residual_chart

        residual_chart(result, args.plot)
    if args.scene_plot:
        from .report import scene_picture

        scene_picture(result, args.scene, args.scene_plot)
    print(json.dumps(result.to_json_dict(), indent=2) if args.json else result.table())
    return 0


def run_edr(args: argparse.Namespace) -> int:
    from .edr import read_edr

    record = read_edr(args.file, args.lateral_positive, args.integration)
    out = record.to_json_dict(args.units)
    if args.json:
        print(json.dumps(out, indent=2))
        return 0
    unit = "m/s" if args.units == "SI" else "ft/s"
    if "delta_v" not in out:
        print(f"pre-crash speed at the crash: {out['speed']:.4g} {unit} ({out['samples']} samples)")
        return 0
    dv = out["delta_v"]
    print(f"EDR crash pulse, {out['samples']} samples (lateral positive left, vehicle axes)")
    for label, key, u in (
        ("delta-V longitudinal", "longitudinal", unit),
        ("delta-V lateral", "lateral", unit),
        ("delta-V magnitude", "magnitude", unit),
        ("direction (ccw from forward)", "direction", "deg"),
        ("time of maximum", "time_of_max", "ms"),
    ):
        print(f"  {label:<30}{dv[key]:>12.4g} {u}")
    print(f"  {'pulse ended in the record':<30}{'yes' if out['ended'] else 'no':>12}")
    for warning in out["warnings"]:
        print(f"warning: {warning}")
    return 0


COMMANDS = {"fit": (FIT_HELP, add_fit_arguments, run_fit), "edr": (EDR_HELP, add_edr_arguments, run_edr)}


def add_parsers(subparsers) -> None:
    """Add ``fit`` and ``edr`` to an argparse sub-parser set; each parser's
    default ``run`` is its run function."""
    for name, (help_text, add_arguments, run) in COMMANDS.items():
        parser = subparsers.add_parser(name, help=help_text, description=help_text)
        add_arguments(parser)
        parser.set_defaults(run=run)
