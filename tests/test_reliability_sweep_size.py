"""Issue 22 item 8: a one-axis sweep of 10⁹ points is refused up front by the
resource check (before any axis is built), and a killed run's temporary
folder is removed at the next start."""

import os
import subprocess
import sys
import tempfile
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from impactsym import sweep
from impactsym.batch import resources as _resources
from impactsym.batch.spill import SPILL_PREFIX, spill_folder
from impactsym.cli import main

SCENE = Path(__file__).resolve().parents[1] / "examples" / "two_car_us.json"
GIB = 1 << 30


@pytest.fixture
def sixteen_gib(monkeypatch):
    """A machine with 16 GiB available: the verdict must not depend on this one."""
    monkeypatch.setattr(_resources, "available_memory", lambda: 16 * GIB)


def test_a_billion_point_axis_is_refused_before_it_is_built(sixteen_gib, capsys):
    tracemalloc.start()
    try:
        code = main(["sweep", str(SCENE), "--vary", "e=0:1:1000000000"])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "1,000,000,000" in err and "memory" in err
    assert peak < 64 << 20  # nothing close to the 8 GB of one copy of the axis


def test_the_api_refuses_an_axis_whose_copies_do_not_fit(sixteen_gib, monkeypatch):
    monkeypatch.setattr(_resources, "available_memory", lambda: 64 << 20)
    with pytest.raises(ValueError, match="e: .* values need about"):
        sweep(SCENE, e=np.linspace(0, 1, 2_000_000), out=None)


def test_an_ordinary_axis_still_runs(sixteen_gib):
    assert len(sweep(SCENE, e=np.linspace(0.1, 0.5, 7))) == 7


def _dead_pid():
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_killed_runs_spill_folder_is_removed_at_the_next_start():
    stale = Path(tempfile.mkdtemp(prefix=f"{SPILL_PREFIX}{_dead_pid()}-"))
    (stale / "values.bin").write_bytes(b"\0" * 1024)
    alive = Path(tempfile.mkdtemp(prefix=f"{SPILL_PREFIX}{os.getppid()}-"))  # a live process's
    try:
        with spill_folder() as folder:
            assert Path(folder).name.startswith(f"{SPILL_PREFIX}{os.getpid()}-")
            assert not stale.exists()
            assert alive.exists()
        assert not Path(folder).exists()
    finally:
        alive.rmdir()


def test_sigkill_during_a_sweep_then_the_next_run_cleans_up(tmp_path):
    env = {**os.environ, "TMPDIR": str(tmp_path)}
    code = (
        "import os, signal, impactsym.batch.spill as s\n"
        "with s.spill_folder() as f:\n"
        "    open(os.path.join(f, 'x'), 'wb').write(b'0' * 4096)\n"
        "    os.kill(os.getpid(), signal.SIGKILL)\n"
    )
    subprocess.run([sys.executable, "-c", code], env=env, check=False)
    assert list(tmp_path.glob(f"{SPILL_PREFIX}*"))  # left behind by the killed run
    run = subprocess.run(
        [sys.executable, "-m", "impactsym", "sweep", str(SCENE), "--vary", "e=0.1:0.3:3"],
        env=env,
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert not list(tmp_path.glob(f"{SPILL_PREFIX}*"))
