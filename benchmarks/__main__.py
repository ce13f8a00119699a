"""``python -m benchmarks SUBCOMMAND [options]``: one entry point for every benchmark.

A subcommand is a module of this package with ``DESCRIPTION``, ``add_arguments(parser)``
and ``main(args) -> int``; register it in ``SUBCOMMANDS``.
"""

from __future__ import annotations

import argparse
import importlib
import sys

SUBCOMMANDS = {
    "accuracy": "benchmarks.accuracy",
    "body": "benchmarks.body",
    "drivers": "benchmarks.drivers",
    "evidence": "benchmarks.evidence",
    "inverse": "benchmarks.inverse",
    "performance": "benchmarks.performance",
    "uncertainty": "benchmarks.uncertainty",
    "trig": "benchmarks.trig",
    "runout": "benchmarks.runout",
    "laws": "benchmarks.laws",
}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, metavar="SUBCOMMAND")
    modules = {}
    for name, modname in SUBCOMMANDS.items():
        module = modules[name] = importlib.import_module(modname)
        module.add_arguments(sub.add_parser(name, help=module.DESCRIPTION, description=module.DESCRIPTION))
    args = parser.parse_args(argv)
    return modules[args.command].main(args)


if __name__ == "__main__":
    sys.exit(main())
