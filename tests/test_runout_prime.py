"""The first use's second process (impactsym/runout/prime.py): the kernels it
compiles are the ones the row functions ask numba's cache for, a first use
loads them from there, and it starts only when it can help."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from impactsym.runout import _door, prime
from impactsym.runout.batch import input_table, run_row

ROOT = Path(__file__).resolve().parents[1]
SLIDE = {"m": 1500.0, "I": 2500.0, "L": 2.7, "a": 1.2, "track": 1.5, "mu": 0.7}
SLIDE |= {"x": 0.0, "y": 0.0, "psi": 0.0, "vx": 9.0, "vy": 1.0, "w": 0.8}
SLIDE |= {"state_fl": 1.0, "state_fr": 1.0, "steer_fl": 0.1}  # locked front, rolling rear, a steered wheel


def test_the_second_process_starts_once_and_only_when_it_can_help(monkeypatch):
    """Not again in the same process, not with IMPACTSYM_PRIME=0, not on a
    cache that already holds the kernels (this test session's), and the
    second process's program refuses another copy of the generated module."""
    run_row(input_table(SLIDE)[0], sens=True)  # the cache holds the PRIME kernels now
    monkeypatch.setattr(prime, "_asked", False)
    assert not prime._cold(_door.jit())
    assert prime.ahead() is None
    monkeypatch.setattr(prime, "_asked", False)
    monkeypatch.setattr(prime, "_cold", lambda jit: True)
    monkeypatch.setenv("IMPACTSYM_PRIME", "0")
    assert prime.ahead() is None
    assert prime.ahead() is None and prime._asked  # asked once: never again
    assert prime.main([str(ROOT / "elsewhere" / "runout_jit.py")]) == 1


def test_no_process_to_be_had_is_no_error(monkeypatch):
    """A cold cache where no second process can start (Popen fails): the run-out
    runs as without one."""

    def refuse(*args, **kwargs):
        raise OSError("no processes left")

    monkeypatch.setattr(prime, "_asked", False)
    monkeypatch.setattr(prime, "_cold", lambda jit: True)
    monkeypatch.setattr(prime.subprocess, "Popen", refuse)
    monkeypatch.delenv("IMPACTSYM_PRIME", raising=False)
    assert prime.ahead() is None
    _, _, status, _, _ = run_row(input_table(SLIDE)[0], sens=True)
    assert status == 0


FIRST_USE = textwrap.dedent(
    """
    import json, sys
    from impactsym.runout import _door, prime
    from impactsym.runout.batch import input_table, run_row, runout_batch
    values = json.loads(sys.argv[1])
    row = input_table(values)[0]
    second = prime.ahead()
    assert second is not None, "the cache was cold: a second process should start"
    second.wait()
    y, t, status, steps, _ = run_row(row, sens=True)
    runout_batch(values)  # the forward driver: the same kernels, no other signature
    jit = _door.jit()
    stats = {name: [sum(getattr(jit, name).stats.cache_hits.values()),
                    sum(getattr(jit, name).stats.cache_misses.values()),
                    len(getattr(jit, name).signatures)] for name, _ in jit.PRIME}
    print(json.dumps({"rc": second.returncode, "y": list(y), "t": t, "status": status, "stats": stats}))
    """
)


@pytest.mark.slow
@pytest.mark.parametrize("h", [0.0, 0.5], ids=["static", "transfer"])
def test_a_first_use_loads_the_primed_kernels_and_gets_the_same_run_out(tmp_path, h):
    """On an empty numba cache the second process compiles the PRIME kernels;
    the first use then loads every one of them (a cache hit, no miss: the
    declared argument types are the ones the row function asks for), the
    forward batch driver asks for no other, and the run-out with sensitivities
    equals this process's bit for bit."""
    values = SLIDE | {"h": h}
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), IMPACTSYM_PRIME="1")
    proc = subprocess.run(
        [sys.executable, "-c", FIRST_USE, json.dumps(values)],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    assert out["rc"] == 0
    assert all(s == [1, 0, 1] for s in out["stats"].values()), out["stats"]
    y, t, status, _, _ = run_row(input_table(values)[0], sens=True)
    assert status == out["status"] == 0
    assert np.array_equal(y, np.array(out["y"])) and t == out["t"]
