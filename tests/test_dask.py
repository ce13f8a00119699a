"""engine="dask": sweep, sample and solve_batch equal the local engine exactly.

One test runs with no distributed client (dask's default scheduler: the
client lookup answers None, whatever ran before it); the others on a
two-worker LocalCluster (module fixture).
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import impactsym
from impactsym.batch import dask_engine, solve

distributed = pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[1]
US = ROOT / "examples" / "two_car_us.json"
SI = ROOT / "examples" / "intersection_si.toml"
DISTS = {"e": ("uniform", 0.0, 0.3), "m1": ("normal", 100.0, 40.0), "normal_angle": ("normal", 0.0, 4.0)}
GRID = {"e": np.linspace(0.0, 0.5, 11), "mu": [0.0, 0.1, "critical"], "m1": [80.0, -1.0, np.nan, 120.0]}


def assert_same(got, want) -> None:
    """Equal frames, floats to the bit (NaN where NaN), dtypes and index included."""
    pd.testing.assert_frame_equal(got, want, check_exact=True)


def test_without_a_client_dask_runs_on_its_default_scheduler(monkeypatch):
    monkeypatch.setattr(dask_engine, "_client", lambda: None)  # order-free: a cluster may exist
    local = impactsym.sweep(US, **GRID, chunk_size=9)
    assert_same(impactsym.sweep(US, **GRID, chunk_size=9, engine="dask"), local)


@pytest.fixture(scope="module")
def client():
    """Two single-threaded worker processes. Processes, not threads: the tasks
    and the plans they carry are then pickled and run in other interpreters,
    as on a real cluster (and each worker's numba kernels are its own); the
    kernels load from numba's cache, so start-up stays about two seconds."""
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c


@pytest.mark.slow  # a two-process LocalCluster whose workers each load the kernels
def test_sweep_on_the_cluster_equals_local(client):
    local = impactsym.sweep(US, **GRID)
    assert (local["status"] != 0).any() and (local["mu"] == "critical").any()
    assert_same(impactsym.sweep(US, **GRID, chunk_size=7, engine="dask"), local)


@pytest.mark.slow  # a two-process LocalCluster whose workers each load the kernels
def test_sample_on_the_cluster_equals_local_whatever_the_chunks(client):
    n = importlib.import_module("impactsym.batch.sweeps").BLOCK + 500
    local = impactsym.sample(SI, DISTS, n, seed=21, chunk_size=5000)
    dask = impactsym.sample(SI, DISTS, n, seed=21, chunk_size=9999, engine="dask")
    assert (local["status"] != 0).any()
    assert_same(dask, local)
    assert dask.attrs["seed"] == 21


@pytest.mark.slow  # a two-process LocalCluster whose workers each load the kernels
def test_streaming_on_the_cluster_writes_the_local_rows_in_order(client, tmp_path):
    local = impactsym.sweep(US, **GRID)
    summary = impactsym.sweep(US, **GRID, chunk_size=5, engine="dask", out=tmp_path / "g.csv")
    back = pd.read_csv(tmp_path / "g.csv", dtype={"status": "int32", "flags": "int32", "mu": object})
    assert_same(back.drop(columns="mu"), local.drop(columns="mu"))
    assert list(back["mu"]) == [str(mu) for mu in local["mu"]]
    assert_same(summary, impactsym.percentiles(local, q=(0, 50, 100)))
    local_sample = impactsym.sample(US, DISTS, 3000, seed=5)
    impactsym.sample(US, DISTS, 3000, seed=5, chunk_size=400, engine="dask", out=tmp_path / "s.parquet")
    assert_same(pd.read_parquet(tmp_path / "s.parquet"), local_sample)


def _columns(n: int) -> dict:
    """A mixed batch: random speeds and coefficients, some rows critical, some bad."""
    rng = np.random.default_rng(4)
    _family, _critical, base = impactsym.load_scene(US).to_inputs()
    columns = {
        **base,
        "v1x": rng.uniform(20, 60, n),
        "e": rng.uniform(0, 0.5, n),
        "mu": np.array(
            [("critical" if i % 5 == 0 else float(rng.uniform(0, 0.3))) for i in range(n)], dtype=object
        ),
    }
    columns["v1x"][7] = np.nan
    return columns


@pytest.mark.slow  # a two-process LocalCluster whose workers each load the kernels
def test_solve_batch_on_the_cluster_equals_local(client):
    columns = _columns(1000)
    local = impactsym.solve_batch(columns)
    via_engine = impactsym.solve_batch(columns, engine="dask")
    chunked = solve.solve_batch_dask(columns, chunk_size=130)
    for result in (via_engine, chunked):
        assert list(result) == list(local)
        for name, column in local.items():
            assert result[name].dtype == column.dtype, name
            np.testing.assert_array_equal(result[name], column, err_msg=name)
    assert local["status"][7] != 0


@pytest.mark.slow  # a two-process LocalCluster whose workers each load the kernels
def test_solve_batch_of_a_dataframe_keeps_its_index(client):
    columns = _columns(300)
    frame = pd.DataFrame(
        {k: np.broadcast_to(v, (300,)) for k, v in columns.items()},
        index=pd.Index(np.arange(300) * 3 + 1000, name="case"),
    )
    local = impactsym.solve_batch(frame, outputs="impulses")
    assert_same(solve.solve_batch_dask(frame, outputs="impulses", chunk_size=64), local)
    assert_same(impactsym.solve_batch(frame, outputs="impulses", engine="dask"), local)


def test_solve_batch_with_unequal_columns_raises_one_line():
    with pytest.raises(ValueError, match=r"^e: length 3 differs from the other columns \(2\)$"):
        solve.solve_batch_dask({"m1": np.ones(2), "e": np.ones(3)})


def test_without_dask_the_error_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "dask", None)
    with pytest.raises(ImportError, match=r"impactsym\[dask\]"):
        impactsym.sweep(US, e=[0.1, 0.2], engine="dask")
    with pytest.raises(ImportError, match=r"impactsym\[dask\]"):
        impactsym.solve_batch({"m1": np.ones(2)}, engine="dask")
