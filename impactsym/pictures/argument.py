"""``--plot PATH``, the diagram option of the CLI commands (checked when parsed)."""

from __future__ import annotations

import argparse
from pathlib import Path

from .._util import require

_FORMATS = (".png", ".svg", ".pdf", ".jpg", ".jpeg", ".eps", ".ps", ".webp", ".tif", ".tiff")


def _plot_path(text: str) -> Path:
    """``--plot`` argument type: a path with an image suffix, matplotlib installed."""
    path = Path(text)
    if path.suffix.lower() not in _FORMATS:
        raise argparse.ArgumentTypeError(
            f"--plot {text}: unknown image type {path.suffix or '(none)'!r} (use .png, .svg or .pdf)"
        )
    try:
        require("matplotlib", extra="plot", what="--plot", load=False)
    except ImportError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return path


def add_plot_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--plot PATH`` to a command's parser (``impactsym solve SCENE --plot out.png``).

    The value is checked when parsed: matplotlib must be installed and the
    suffix must be an image format matplotlib writes; otherwise argparse
    reports a usage error (one line, exit code 2 in the CLI).
    """
    parser.add_argument(
        "--plot",
        metavar="PATH",
        type=_plot_path,
        default=None,
        help="also draw the scene diagram to PATH (.png, .svg, .pdf; needs matplotlib)",
    )
