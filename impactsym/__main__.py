"""``python -m impactsym``: the command line of :mod:`impactsym.cli`."""

from .cli import run

run()
