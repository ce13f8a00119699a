"""`impactsym runout SCENE [--json] [--path] [--plot OUT.png] [--exhaustive [--speed-max V] [--yaw-rate-max W]]`.

Registered in impactsym/cli.py's COMMANDS (help, add_arguments, run). A bad
scene raises SceneError, which the command line prints as one line (exit 2).
"""

from __future__ import annotations

import argparse
import json

from ..errors import SceneError
from ..residue import without_json_residue
from ..result import json_clean, table_cell
from .api import READING, misreading, reading, runout

HELP = "post-impact run-out: each vehicle from separation to rest, or its separation velocity fitted to rest"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """The command's arguments."""
    parser.add_argument("scene", help="scene file (.json or .toml) with a runout object")
    parser.add_argument("--json", action="store_true", help="print the result as one JSON object")
    parser.add_argument("--path", action="store_true", help="add each vehicle's path [[t, x, y, psi], ...]")
    parser.add_argument("--plot", metavar="OUT.png", help="draw the paths, outlines, tyre marks and poses")
    parser.add_argument(
        "--chain",
        choices=("solve", "reconstruct"),
        help="solve: pre-impact -> impact -> rest (solve --json plus each rest); reconstruct: rest -> fitted "
        "separation -> pre-impact (reconstruct --json plus each run-out)",
    )
    parser.add_argument(
        "--exhaustive",
        action="store_true",
        help="also search a grid of separation states over the plausible range for every state that reaches a "
        "fitted vehicle's rest pose (seconds per vehicle)",
    )
    parser.add_argument(
        "--speed-max", type=float, metavar="V", help="the grid's largest separation speed (scene units/s)"
    )
    parser.add_argument(
        "--yaw-rate-max", type=float, metavar="W", help="the grid's largest |yaw rate| (rad/s)"
    )


def add_parser(subparsers) -> argparse.ArgumentParser:
    """Add the ``runout`` sub-command to an argparse sub-parser set."""
    parser = subparsers.add_parser("runout", help=HELP, description=HELP)
    add_arguments(parser)
    return parser


def run(args: argparse.Namespace) -> int:
    """Run the command; 0 on success (bad input raises SceneError)."""
    from .scene import load_runout

    if args.chain:
        given = {
            "--exhaustive": args.exhaustive,
            "--speed-max": args.speed_max,
            "--yaw-rate-max": args.yaw_rate_max,
        }
        for flag, value in given.items() if args.chain == "solve" else ():
            if value is not None and value is not False:
                raise SceneError("the grid search fits separation states: --chain reconstruct", flag)
        return _run_chain(args)
    scene = load_runout(args.scene)
    result = _with_grid_flags(args, lambda **grid: runout(scene, path=bool(args.path or args.plot), **grid))
    if args.plot:
        from .plot import plot_runout

        plot_runout(scene, result, args.plot)
    if not args.path:
        for entry in result["vehicles"]:
            entry.pop("path", None)
    if args.json:
        print(json.dumps(json_clean(result)))
    else:
        print(table(result))
    return 0


def _with_grid_flags(args: argparse.Namespace, call):
    """`call` with the grid-search keywords of `args`; a bad one is named as the
    command line spells it (--speed-max, not speed_max)."""
    grid = {"speed_max": args.speed_max, "yaw_rate_max": args.yaw_rate_max}
    try:
        return call(exhaustive=args.exhaustive, **grid)
    except SceneError as err:
        if err.field not in grid:
            raise
        raise SceneError(str(err)[len(err.field) + 2 :], "--" + err.field.replace("_", "-")) from None


def chained(args: argparse.Namespace) -> bool:
    """Whether the ``solve``/``reconstruct`` scene of `args` carries run-out data
    (a top-level ``runout`` object): then `run_chained` answers the command."""
    from .scene import has_runout

    return has_runout(args.scene)


def run_chained(args: argparse.Namespace, command: str) -> int:
    """``solve``/``reconstruct`` of a scene with run-out data (conventions.md,
    "Chained"): the command's JSON with each vehicle's run-out attached."""
    if getattr(args, "uncertainty", None):
        if command != "reconstruct":
            raise SceneError("through the run-out only for reconstruct (rest poses)", "--uncertainty")
        return _run_chained_uncertainty(args)
    if getattr(args, "plot", None):
        raise SceneError("draw a chained scene's run-outs with impactsym runout SCENE --plot", "--plot")
    from .chain import reconstruct_from_rest, solve_to_rest
    from .leaves import nominal_data

    if command == "solve":
        result = solve_to_rest(args.scene)
    else:  # distributions on the run-out's leaves: the nominal scene, as every plain command
        result = reconstruct_from_rest(nominal_data(args.scene)[0])
    result = without_json_residue(result)
    print(json.dumps(json_clean(result), indent=2) if args.json else _chain_table(result))
    return 0


def _run_chained_uncertainty(args: argparse.Namespace) -> int:
    """``reconstruct SCENE --uncertainty`` of a scene with rest poses (uncertain.py)."""
    from ..uncertainty.cli import DEFAULT_DRAWS
    from ..uncertainty.result import MIN_INTERVAL_DRAWS
    from .uncertain import chained_uncertainty, uncertainty_json

    if getattr(args, "plot", None):
        raise SceneError("not drawn for a scene with rest poses; leave out --plot", "--plot")
    draws = DEFAULT_DRAWS if args.draws is None else args.draws
    if draws < MIN_INTERVAL_DRAWS:
        raise SceneError(
            f"{draws} draws cannot give a 90 % interval; give at least {MIN_INTERVAL_DRAWS}", "--draws"
        )
    try:
        chained, u = chained_uncertainty(args.scene, draws=draws, seed=args.seed, sobol=args.sobol)
    except (ValueError, ImportError) as exc:  # a one-line reason, exit code 2
        raise SceneError(str(exc)) from None
    if args.json:
        print(json.dumps(json_clean(uncertainty_json(chained, u)), indent=2, allow_nan=False))
    else:
        print(_chain_table(without_json_residue(chained.result)))
        print()
        print(u.table())
    return 0


def _run_chain(args: argparse.Namespace) -> int:
    """``--chain``: the impact command's JSON with the run-outs attached."""
    from .chain import reconstruct_from_rest, solve_to_rest

    if args.plot:
        raise SceneError("--plot draws a plain run-out; leave out --chain to draw it", "--plot")
    if args.chain == "solve":
        result = solve_to_rest(args.scene, path=args.path)
    else:
        result = _with_grid_flags(
            args, lambda **grid: reconstruct_from_rest(args.scene, path=args.path, **grid)
        )
    result = without_json_residue(result)
    print(json.dumps(json_clean(result)) if args.json else _chain_table(result))
    return 0


def _chain_table(result: dict) -> str:
    lines = []
    for v in result["vehicles"]:
        ro = v.get("runout")
        velocity = v.get("velocity")
        shown = "[" + ", ".join(table_cell(x) for x in velocity) + "]" if velocity else velocity
        head = f"{v.get('name', '')}: velocity {shown}"
        if ro is None:
            lines.append(head)
            continue
        sep, rest = ro["separation"], ro["rest"]
        lines += [
            head,
            f"  separation velocity [{sep['velocity'][0]:.3f}, {sep['velocity'][1]:.3f}], "
            f"yaw rate {sep['yaw_rate']:.4f} rad/s",
            f"  rest [{rest['position'][0]:.3f}, {rest['position'][1]:.3f}], heading {rest['heading']:.2f} deg",
        ]
        if "search" in ro.get("fit", {}):
            lines.append(_search_line(ro["fit"]["search"], "ft" if result["units"] == "US" else "m"))
    lines += [f"warning: {w}" for w in result.get("warnings", [])]
    return "\n".join(lines)


def table(result: dict) -> str:
    """The result for people: one block per vehicle."""
    unit = "ft" if result["units"] == "US" else "m"
    lines = []
    for v in result["vehicles"]:
        sep, rest = v["separation"], v["rest"]
        fitted = " (fitted to rest)" if "fit" in v else ""
        lines += [
            f"{v['name']}",
            f"  separation{fitted}: velocity [{sep['velocity'][0]:.3f}, {sep['velocity'][1]:.3f}] {unit}/s "
            f"(speed {sep['speed']:.3f}), yaw rate {sep['yaw_rate']:.4f} rad/s",
            f"  rest: position [{rest['position'][0]:.3f}, {rest['position'][1]:.3f}] {unit}, "
            f"heading {rest['heading']:.2f} deg",
            f"  time {v['time']:.3f} s, distance {v['distance']:.3f} {unit}, rotation {v['rotation']:.2f} deg",
        ]
        if "cg_height" in v:
            lines.append(
                f"  wheel loads: quasi-static load transfer, centre of gravity {v['cg_height']:.3g} {unit} high"
            )
        res = v.get("fit", v).get("residual")
        if res is not None:
            extra = f", {v['fit']['iterations']} iterations" if "fit" in v else ""
            lines.append(
                f"  residual against the measured rest: {res['position']:.2g} {unit}, "
                f"{res['heading']:.2g} deg{extra}"
            )
        if "search" in v.get("fit", {}):
            lines.append(_search_line(v["fit"]["search"], unit))
        if "determination" in v.get("fit", {}):
            moves = misreading(v["fit"]["determination"], result["units"])
            shown = ", ".join(
                f"{key.replace('_', ' ')} {m[0]:.2g} / {m[1]:.2g} {u}"
                for (key, m), u in zip(moves.items(), (f"{unit}/s", "deg", "rad/s"))
                if m is not None
            )
            lines.append(
                f"  a rest pose {reading(result['units']):.2g} {unit} / {READING[1]:g} deg off "
                f"moves the fit by: {shown}"
            )
    lines += [f"warning: {w}" for w in result["warnings"]]
    return "\n".join(lines)


def _search_line(search: dict, unit: str) -> str:
    """The grid search of a fitted vehicle, one line (and its refinement's)."""
    n = search["states"]
    line = (
        f"  grid search: {search['runouts']} run-outs, speed up to {search['speed_max']:.3g} {unit}/s "
        f"(spacing {search['spacing']['speed']:.2g}), yaw rate within +-{search['yaw_rate_max']:.3g} rad/s "
        f"(spacing {search['spacing']['yaw_rate']:.2g}), Newton from {search['starts']} of its "
        f"{search['minima']} local minima"
    )
    r = search.get("refined")
    if r and r["open_cells"]:
        line += (
            f" and {r['starts']} state{'' if r['starts'] == 1 else 's'} reached from its {r['open_cells']} open "
            f"cells refined {r['levels']} level{'' if r['levels'] == 1 else 's'} deep (to spacing {r['spacing']['speed']:.2g}, "
            f"{r['spacing']['yaw_rate']:.2g}; {r['runouts']} run-outs, {r['still_open']} cells still open)"
        )
    return line + f": {n} state{' reaches' if n == 1 else 's reach'} the rest pose"
