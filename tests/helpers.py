"""Helpers the test modules share (each written once): the checkout's paths, the
command line run in-process or in a subprocess, a fresh matplotlib axes, and the
50-digit derivatives the uncertainty tests check the Jacobian kernels against."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
#: The command a bundled example is written for, by its name's prefix (examples/README.md);
#: every other top-level example is a forward scene for ``solve``.
EXAMPLE_COMMANDS = {"invert_": "invert", "reconstruct_": "reconstruct", "crash3_": "crash3", "fit_": "fit"}


def example_files() -> list[Path]:
    """Every top-level example scene (JSON or TOML), sorted."""
    return sorted(EXAMPLES.glob("*.json")) + sorted(EXAMPLES.glob("*.toml"))


def example_command(path: Path) -> str:
    """The command an example is for: ``solve`` unless its prefix names another."""
    return next((cmd for prefix, cmd in EXAMPLE_COMMANDS.items() if path.name.startswith(prefix)), "solve")


def forward_examples() -> list[Path]:
    """The examples that are forward scenes (``solve``)."""
    return [p for p in example_files() if example_command(p) == "solve"]


EXAMPLES = ROOT / "examples"


def run_cli(capsys, *argv) -> tuple[int, str, str]:
    """Run ``impactsym`` in-process; return (exit code, stdout, stderr)."""
    from impactsym.cli import main

    code = main([str(arg) for arg in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(capsys, *argv) -> str:
    """The stderr line of a command that must fail with exit 2 and print nothing else."""
    code, out, err = run_cli(capsys, *argv)
    assert code == 2, (code, out, err)
    assert out == "" and err.count("\n") == 1 and err.startswith("impactsym: error: "), err
    return err


def cli_argv(*argv) -> list[str]:
    """The command line of ``impactsym`` in a subprocess of this checkout."""
    return [sys.executable, "-m", "impactsym", *map(str, argv)]


def cli_env(**extra) -> dict:
    """The environment of such a subprocess: this checkout first on the path."""
    return {**os.environ, "PYTHONPATH": str(ROOT), **extra}


def run_cli_subprocess(*argv) -> subprocess.CompletedProcess:
    """Run ``impactsym`` in a subprocess from the checkout's root (text output)."""
    return subprocess.run(cli_argv(*argv), env=cli_env(), capture_output=True, text=True, cwd=ROOT)


def new_axes(**figure):
    """A fresh matplotlib axes on an Agg canvas (no pyplot, no display)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**figure)
    FigureCanvasAgg(fig)
    return fig.add_subplot()


def mp_gradient(func, point: dict, names, outputs, direction: int = 0) -> dict:
    """{output: {input: d output/d input}} by mpmath.diff at 50 digits. The
    reference rounds to 50 digits inside: a step of 1e-15 relative (error
    ~1e-30) instead of mpmath's default; each evaluation of `func` is made once
    and shared by the outputs, which mp.diff evaluates at the same points."""
    from mpmath import mp

    grads = {o: {} for o in outputs}
    with mp.workdps(50):
        for x in names:
            step = mp.mpf("1e-15") * max(1, abs(point[x]))
            values = {}

            def at(t, x=x, values=values):
                if t not in values:
                    values[t] = func({**point, x: t})
                return values[t]

            for o in outputs:
                grads[o][x] = mp.diff(lambda t, o=o: at(t)[o], mp.mpf(point[x]), h=step, direction=direction)
    return grads


def assert_gradient_close(got, want, names, outputs) -> None:
    """Each derivative ``got["d_<output>__d_<input>"]`` within 1e-8 of the
    largest derivative of its output's row in ``want`` (mp_gradient)."""
    for o in outputs:
        row = [float(want[o][x]) for x in names]
        scale = max(abs(v) for v in row)
        for x, w in zip(names, row):
            g = got.get(f"d_{o}__d_{x}", 0.0)
            assert abs(g - w) <= 1e-8 * scale, (o, x, g, w)
