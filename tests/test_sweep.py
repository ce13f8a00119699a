"""sweep, sample, percentiles: grid order and values, names, bad rows, seeds,
exact streamed summaries, Parquet/CSV streaming, progress, and the CLI."""

from __future__ import annotations

import copy
import importlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

import impactsym
from impactsym import _kernels
from tests.helpers import run_cli as run

sweeps = importlib.import_module("impactsym.batch.sweeps")
quantiles = importlib.import_module("impactsym.batch.quantiles")

ROOT = Path(__file__).resolve().parents[1]
US = ROOT / "examples" / "two_car_us.json"  # rigid, mu = 0.3
SI = ROOT / "examples" / "intersection_si.toml"  # rigid, mu = "critical"
US_SCENE = json.loads(US.read_text())
OUTPUTS = _kernels.OUTPUTS
DISTS = {
    "e": ("uniform", 0.0, 0.3),
    "mu": ("normal", 0.2, 0.05),
    "m1": ("normal", 100.0, 40.0),
    "normal_angle": ("triangular", -5.0, 0.0, 10.0),
}


def base_columns(path=US) -> dict:
    """The scene's kernel inputs as scalars (gamma in radians)."""
    _family, _critical, values = impactsym.load_scene(path).to_inputs()
    return dict(values)


def assert_same(got, want) -> None:
    """Equal frames, floats to the bit (NaN where NaN), dtypes and index included."""
    pd.testing.assert_frame_equal(got, want, check_exact=True)


def one_line_error(excinfo, name: str) -> None:
    message = str(excinfo.value)
    assert message.startswith(f"{name}:") and "\n" not in message, message


def test_import_impactsym_loads_none_of_the_sweep_extras():
    code = (
        "import sys, impactsym; "
        "bad = {'pandas', 'pyarrow', 'tqdm', 'xarray', 'dask', 'distributed'} & set(sys.modules); "
        "sys.exit(sorted(bad) if bad else 0)"
    )
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr


# --------------------------------------------------------------------------- grid order and values


def test_grid_rows_are_c_order_and_equal_solve_batch_on_explicit_columns():
    e, mu, angle = [0.1, 0.25, 0.5], [0.0, 0.1], [-5.0, 0.0, 7.5]
    df = impactsym.sweep(US, e=e, mu=mu, normal_angle=angle, chunk_size=5)  # 18 rows, 4 chunks
    E, MU, A = (axis.ravel() for axis in np.meshgrid(e, mu, angle, indexing="ij"))
    assert list(df.columns[:3]) == ["e", "mu", "normal_angle"]
    np.testing.assert_array_equal(df["e"], E)
    np.testing.assert_array_equal(df["mu"], MU)
    np.testing.assert_array_equal(df["normal_angle"], A)
    assert list(df.index) == list(range(18))
    columns = {**base_columns(), "e": E, "mu": MU, "gamma": np.radians(A)}
    expected = impactsym.solve_batch(columns)
    # the mu output (the ratio used) is the mu column itself when mu is varied
    assert list(df.columns[3:]) == [name for name in OUTPUTS if name != "mu"] + ["status", "flags"]
    for name in df.columns[3:]:
        np.testing.assert_array_equal(df[name].to_numpy(), expected[name], err_msg=name)
        assert df[name].dtype == expected[name].dtype


def _scene_with(e, mu, angle, m1):
    scene = copy.deepcopy(US_SCENE)
    scene["impact"].update(restitution=e, impulse_ratio=mu, normal_angle=angle)
    scene["vehicles"][0]["mass"] = m1
    return scene


@pytest.mark.parametrize("row", [0, 5, 11, 15])
def test_rows_equal_impactsym_solve_of_the_same_scene(row):
    df = impactsym.sweep(
        US,
        restitution=[0.0, 0.3],
        impulse_ratio=[0.1, "critical"],
        normal_angle=[-3.0, 4.0],
        m1=[80.0, 120.0],
        chunk_size=3,
    )
    r = df.iloc[row]
    result = impactsym.solve(_scene_with(r["restitution"], r["impulse_ratio"], r["normal_angle"], r["m1"]))
    assert r["status"] == 0 and r["flags"] == result.flags
    got = [
        r["V1x"],
        r["V1y"],
        r["W1"],
        r["V2x"],
        r["V2y"],
        r["W2"],
        r["Pn"],
        r["Pt"],
        r["mu_c"],
        r["TL"],
        r["TLn"],
        r["TLt"],
        r["dV1"],
        r["dV2"],
    ]
    one, two = result.vehicles
    want = [
        *one.velocity,
        one.yaw_rate,
        *two.velocity,
        two.yaw_rate,
        result.Pn,
        result.Pt,
        result.mu_c,
        result.TL,
        result.TLn,
        result.TLt,
        one.delta_v_magnitude,
        two.delta_v_magnitude,
    ]
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * abs(result.TL))


def test_a_mu_axis_with_critical_is_an_object_column_solved_per_row():
    df = impactsym.sweep(US, mu=[0.1, "critical"], e=[0.2, 0.4])
    assert df["mu"].dtype == object and list(df["mu"]) == [0.1, 0.1, "critical", "critical"]
    critical = impactsym.sweep(US, mu="critical", e=[0.2, 0.4])
    sliding = impactsym.sweep(US, mu=0.1, e=[0.2, 0.4])
    for name in ("V1x", "W2", "TL", "mu_c", "status"):
        np.testing.assert_array_equal(df[name].to_numpy()[2:], critical[name].to_numpy(), err_msg=name)
        np.testing.assert_array_equal(df[name].to_numpy()[:2], sliding[name].to_numpy(), err_msg=name)
    np.testing.assert_array_equal(critical["mu"], critical["mu_c"])  # the ratio used is mu_c


def test_constants_given_as_scalars_equal_broadcast_arrays():
    mu = np.linspace(0.0, 0.3, 7)
    df = impactsym.sweep(US, e=0.35, v1x=60.0, mu=mu)
    assert list(df.columns[:1]) == ["mu"]  # constants are not columns
    columns = {**base_columns(), "e": np.full(7, 0.35), "v1x": np.full(7, 60.0), "mu": mu}
    expected = impactsym.solve_batch(columns)
    for name in ("V1x", "W1", "Pn", "TL", "dV2", "status", "flags"):
        np.testing.assert_array_equal(df[name].to_numpy(), expected[name], err_msg=name)


def test_a_scene_without_varied_values_is_one_row():
    df = impactsym.sweep(US)
    result = impactsym.solve(US)
    assert len(df) == 1 and df.columns[0] == "V1x"
    assert df["TL"][0] == pytest.approx(result.TL, rel=1e-13)


@pytest.mark.parametrize(
    "alias, kernel, given, converted",
    [
        ("normal_angle", "gamma", [-10.0, 0.0, 25.0], np.radians([-10.0, 0.0, 25.0])),
        ("restitution", "e", [0.0, 0.5], [0.0, 0.5]),
        ("impulse_ratio", "mu", [0.0, 0.2], [0.0, 0.2]),
        ("moment_restitution", "e_m", [0.0, 1.0], [0.0, 1.0]),
    ],
)
def test_scene_aliases_keep_their_name_and_units(alias, kernel, given, converted):
    by_alias = impactsym.sweep(US, **{alias: given})
    by_kernel = impactsym.sweep(US, **{kernel: np.asarray(converted)})
    assert by_alias.columns[0] == alias
    np.testing.assert_array_equal(by_alias[alias], given)  # degrees stay degrees
    for name in ("V1x", "V2y", "W1", "Pn", "TL", "status"):
        np.testing.assert_array_equal(by_alias[name], by_kernel[name], err_msg=name)


def test_as_xarray_has_one_dimension_per_axis_in_the_order_given():
    df = impactsym.sweep(US, e=[0.1, 0.2, 0.3], normal_angle=[0.0, 5.0])
    ds = impactsym.sweep(US, e=[0.1, 0.2, 0.3], normal_angle=[0.0, 5.0], as_xarray=True)
    assert ds["TL"].dims == ("e", "normal_angle") and ds.attrs["units"] == "US"
    np.testing.assert_array_equal(ds["normal_angle"], [0.0, 5.0])
    np.testing.assert_array_equal(ds["TL"].values.ravel(), df["TL"])
    np.testing.assert_array_equal(ds["status"].values.ravel(), df["status"])


def test_as_xarray_without_xarray_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ImportError, match=r"impactsym\[xarray\]"):
        impactsym.sweep(US, e=[0.1], as_xarray=True)


# --------------------------------------------------------------------------- names and bad values

LIMPERT = {
    "model": "limpert",
    "units": "SI",
    "impact": {"normal_angle": 0.0},
    "vehicles": [
        {"mass": 1000.0, "yaw_inertia": 1500.0, "velocity": [15.0, 0.0], "impact_point": [2.0, 0.0]},
        {"mass": 1200.0, "yaw_inertia": 1800.0, "velocity": [0.0, 0.0], "impact_point": [-2.0, 0.0]},
    ],
}
PARTICLE = {
    "model": "particle",
    "units": "SI",
    "impact": {"normal_angle": 0.0, "restitution": 0.2, "impulse_ratio": 0.1},
    "vehicles": [{"mass": 1000.0, "velocity": [15.0, 0.0]}, {"mass": 1200.0, "velocity": [0.0, 0.0]}],
}


@pytest.mark.parametrize(
    "scene, values, name, words",
    [
        (US, {"e": [0.1], "speed": [1.0]}, "speed", "not an input of the rigid model"),
        (PARTICLE, {"I1": [1.0]}, "I1", "not an input of the particle model"),
        (LIMPERT, {"restitution": [0.1]}, "restitution", "the limpert model fixes e"),
        (LIMPERT, {"mu": "critical"}, "mu", "the limpert model fixes mu"),
        (US, {"e": [0.1], "restitution": 0.2}, "restitution", "sets e, which another name"),
        (US, {"e": "critical"}, "e", "expected a scalar or a 1-D sequence of numbers"),
        (US, {"e": []}, "e", "non-empty"),
        (US, {"e": np.zeros((2, 2))}, "e", "non-empty 1-D"),
        (US, {"mu": [0.1, "sticky"]}, "mu", 'numbers or "critical"'),
        (US, {"v1x": [1.0, None]}, "v1x", "values must be numbers"),
    ],
)
def test_bad_names_and_values_raise_one_line_naming_them(scene, values, name, words):
    with pytest.raises(ValueError) as excinfo:
        impactsym.sweep(scene, **values)
    one_line_error(excinfo, name)
    assert words in str(excinfo.value)


def test_bad_rows_keep_their_status_and_the_others_are_solved():
    masses = [90.0, -1.0, np.nan, 0.0, 130.0]
    df = impactsym.sweep(US, m1=masses, e=[0.1, 0.2], chunk_size=3)
    good = impactsym.sweep(US, m1=[90.0, 130.0], e=[0.1, 0.2])
    status = df["status"].to_numpy().reshape(5, 2)
    assert (status[[0, 4]] == 0).all()
    assert (status[1] == 2).all() and (status[2] == 1).all() and (status[3] == 2).all()
    bad = df["status"].to_numpy() != 0
    assert df.loc[bad, "TL"].isna().all() and (df.loc[bad, "flags"] == 0).all()
    for name in ("V1x", "TL", "dV1", "flags"):
        np.testing.assert_array_equal(df.loc[~bad, name].to_numpy(), good[name].to_numpy(), err_msg=name)


def test_unknown_output_file_type_is_refused_before_any_work(tmp_path):
    with pytest.raises(ValueError) as excinfo:
        impactsym.sweep(US, e=[0.1], out=tmp_path / "rows.xlsx")
    one_line_error(excinfo, "out")
    assert not (tmp_path / "rows.xlsx").exists()


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"engine": "spark"}, "engine"),
        ({"chunk_size": 0}, "chunk_size"),
        ({"outputs": "speeds"}, "outputs"),
    ],
)
def test_bad_run_options_raise_one_line_and_write_nothing(tmp_path, kwargs, name):
    with pytest.raises(ValueError) as excinfo:
        impactsym.sweep(US, e=[0.1, 0.2], out=tmp_path / "rows.csv", **kwargs)
    one_line_error(excinfo, name)
    assert list(tmp_path.iterdir()) == []


# --------------------------------------------------------------------------- Monte Carlo


def test_samples_are_reproducible_and_independent_of_chunk_size():
    n = 2 * sweeps.BLOCK + 123
    whole = impactsym.sample(US, DISTS, n, seed=7)
    assert whole.attrs["seed"] == 7 and len(whole) == n
    for chunk_size in (1000, sweeps.BLOCK - 1, sweeps.BLOCK + 17):
        assert_same(impactsym.sample(US, DISTS, n, seed=7, chunk_size=chunk_size), whole)
    other = impactsym.sample(US, DISTS, 100, seed=8)
    assert not np.array_equal(other["e"], whole["e"][:100])


def test_row_i_does_not_depend_on_n_and_blocks_are_different_streams():
    long = impactsym.sample(US, DISTS, sweeps.BLOCK + 50, seed=3)
    short = impactsym.sample(US, DISTS, 50, seed=3)
    assert_same(short, long.iloc[:50])
    assert not np.array_equal(long["e"][:50], long["e"][sweeps.BLOCK :])


def test_draws_follow_the_documented_streams():
    """Block b, parameter by parameter in the order given, from
    PCG64(SeedSequence(seed, spawn_key=(b,)))."""
    df = impactsym.sample(US, DISTS, sweeps.BLOCK + 10, seed=11)
    for block in (0, 1):
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence(11, spawn_key=(block,))))
        draws = [
            rng.uniform(0.0, 0.3, sweeps.BLOCK),
            rng.normal(0.2, 0.05, sweeps.BLOCK),
            rng.normal(100.0, 40.0, sweeps.BLOCK),
            rng.triangular(-5.0, 0.0, 10.0, sweeps.BLOCK),
        ]
        rows = slice(block * sweeps.BLOCK, min(len(df), (block + 1) * sweeps.BLOCK))
        for name, drawn in zip(DISTS, draws):
            column = df[name].to_numpy()[rows]
            np.testing.assert_array_equal(column, drawn[: len(column)], err_msg=name)


def test_without_a_seed_the_reported_entropy_reproduces_the_sample():
    first = impactsym.sample(US, {"e": ("lognormal", -2.0, 0.5)}, 300)
    again = impactsym.sample(US, {"e": ("lognormal", -2.0, 0.5)}, 300, seed=first.attrs["seed"])
    assert_same(first, again)
    assert (first["e"] > 0).all()


def test_drawn_rows_equal_solve_batch_on_the_drawn_columns():
    df = impactsym.sample(
        SI,
        {"restitution": ("uniform", 0.0, 0.4), "normal_angle": ("normal", 10.0, 3.0)},
        500,
        seed=2,
        chunk_size=128,
    )
    columns = {
        **base_columns(SI),
        "mu": "critical",
        "e": df["restitution"].to_numpy(),
        "gamma": np.radians(df["normal_angle"].to_numpy()),
    }
    expected = impactsym.solve_batch(columns)
    for name in ("V1x", "W2", "Pt", "mu", "mu_c", "TL", "status", "flags"):
        np.testing.assert_array_equal(df[name].to_numpy(), expected[name], err_msg=name)


@pytest.mark.parametrize(
    "dists, name, words",
    [
        ({"e": ("beta", 1, 2)}, "e", "unknown distribution 'beta'"),
        ({"e": ("uniform", 0.0)}, "e", "uniform takes 2 finite numbers"),
        ({"e": ("uniform", 0.3, 0.1)}, "e", "low <= high"),
        ({"mu": ("normal", 0.2, -0.1)}, "mu", "non-negative standard deviation"),
        ({"m1": ("triangular", 1.0, 5.0, 3.0)}, "m1", "left <= mode <= right"),
        ({"m1": ("lognormal", 1.0, float("nan"))}, "m1", "finite numbers"),
        ({"v1x": 30.0}, "v1x", "expected a tuple"),
        ({"slip": ("uniform", 0, 1)}, "slip", "not an input of the rigid model"),
    ],
)
def test_bad_distributions_raise_one_line_naming_the_parameter(dists, name, words):
    with pytest.raises(ValueError) as excinfo:
        impactsym.sample(US, dists, 10, seed=1)
    one_line_error(excinfo, name)
    assert words in str(excinfo.value)


@pytest.mark.parametrize("kwargs, name", [({"n": 0}, "n"), ({"n": 2.5}, "n"), ({"seed": -1}, "seed")])
def test_bad_n_and_seed_raise_one_line(kwargs, name):
    with pytest.raises(ValueError) as excinfo:
        impactsym.sample(US, {"e": ("uniform", 0, 1)}, **{"n": 10, **kwargs})
    one_line_error(excinfo, name)


# --------------------------------------------------------------------------- percentiles


def test_percentiles_equal_numpy_over_solved_rows_with_counts():
    df = impactsym.sample(US, DISTS, 5000, seed=5)  # some masses drawn negative
    summary = impactsym.percentiles(df)
    solved = df["status"] == 0
    assert 0 < (~solved).sum() < 500
    codes, rows = np.unique(df.loc[~solved, "status"], return_counts=True)
    assert summary.attrs["counts"] == {
        "rows": 5000,
        "solved": int(solved.sum()),
        "not_solved": int((~solved).sum()),
        "flagged": int((df["flags"] != 0).sum()),
        "not_solved_by_status": dict(zip(codes.tolist(), rows.tolist())),
    }
    assert list(summary.index) == ["dV1", "dV2", "TL"]
    assert list(summary.columns) == ["p5", "p25", "p50", "p75", "p95"]
    for name in summary.index:
        np.testing.assert_array_equal(
            summary.loc[name].to_numpy(), np.percentile(df.loc[solved, name], [5, 25, 50, 75, 95])
        )
    odd = impactsym.percentiles(df, columns=["mu_c"], q=[0, 2.5, 100])
    np.testing.assert_array_equal(odd.loc["mu_c"], np.percentile(df.loc[solved, "mu_c"], [0, 2.5, 100]))


def test_percentiles_of_no_solved_row_are_nan():
    df = impactsym.sweep(US, m1=[-1.0, -2.0])
    summary = impactsym.percentiles(df)
    assert summary.isna().all().all() and summary.attrs["counts"]["not_solved"] == 2


def test_order_statistics_select_exactly_through_radix_passes(tmp_path, monkeypatch):
    """Small budgets force every 16-bit pass, and groups of equal keys."""
    monkeypatch.setattr(quantiles.OrderStatistics, "SORT_BUDGET", 64)
    monkeypatch.setattr(quantiles.OrderStatistics, "READ_BLOCK", 1000)
    rng = np.random.default_rng(0)
    values = np.concatenate(
        [
            rng.normal(0, 1e3, 4000),
            np.full(700, 2.5),
            -np.logspace(-300, 300, 500),
            np.zeros(300),
            rng.uniform(-1, 1, 3000) * 1e-6,
        ]
    )
    rng.shuffle(values)
    stats = quantiles.OrderStatistics(tmp_path / "values.f8")
    for part in np.array_split(values, 7):
        stats.add(part)
    ranks = [0, 1, 2500, 4321, 4999, 5000, 6000, values.size - 1]
    found = stats.select(ranks)
    np.testing.assert_array_equal([found[r] for r in ranks], np.sort(values)[ranks])
    summary = quantiles._interpolate(stats, (0, 5, 33.3, 50, 97.5, 100))
    np.testing.assert_array_equal(summary, np.percentile(values, [0, 5, 33.3, 50, 97.5, 100]))


def test_streamed_summary_equals_the_in_memory_one(tmp_path, monkeypatch):
    monkeypatch.setattr(quantiles.OrderStatistics, "SORT_BUDGET", 100)
    df = impactsym.sample(US, DISTS, 3000, seed=9)
    streamed = impactsym.sample(US, DISTS, 3000, seed=9, chunk_size=700, out=tmp_path / "s.parquet")
    assert_same(streamed, impactsym.percentiles(df))
    assert streamed.attrs["counts"] == impactsym.percentiles(df).attrs["counts"]
    assert streamed.attrs["seed"] == 9


# --------------------------------------------------------------------------- streaming to files


def _grid(**kw):
    return impactsym.sweep(US, e=np.linspace(0, 1, 9), mu=[0.0, 0.1, 0.2], m1=[100.0, -1.0, 150.0], **kw)


def test_chunked_parquet_equals_the_in_memory_frame(tmp_path):
    path = tmp_path / "grid.parquet"
    summary = _grid(chunk_size=10, out=path, progress=False)
    df = _grid()
    assert_same(pd.read_parquet(path), df)
    assert pq.ParquetFile(path).num_row_groups == 9  # 81 rows in chunks of 10
    assert_same(summary, impactsym.percentiles(df, q=(0, 50, 100)))


def test_chunked_csv_equals_the_in_memory_frame(tmp_path):
    path = tmp_path / "grid.csv"
    _grid(chunk_size=10, out=path)
    df = _grid()
    text = path.read_text()
    assert text.count("e,mu,m1,V1x") == 1 and len(text.splitlines()) == 82
    back = pd.read_csv(path, dtype={"status": "int32", "flags": "int32"})
    assert_same(back, df)


def test_a_mu_column_with_critical_is_text_in_files(tmp_path):
    df = impactsym.sweep(US, mu=[0.1, "critical"], e=[0.2, 0.4])
    impactsym.sweep(US, mu=[0.1, "critical"], e=[0.2, 0.4], out=tmp_path / "g.parquet", chunk_size=3)
    back = pd.read_parquet(tmp_path / "g.parquet")
    assert list(back["mu"]) == ["0.1", "0.1", "critical", "critical"]
    assert_same(back.drop(columns="mu"), df.drop(columns="mu"))


def test_sample_to_csv_equals_the_in_memory_sample(tmp_path):
    path = tmp_path / "s.csv"
    impactsym.sample(US, DISTS, 2000, seed=4, chunk_size=300, out=path)
    back = pd.read_csv(path, dtype={"status": "int32", "flags": "int32"})
    assert_same(back, impactsym.sample(US, DISTS, 2000, seed=4))


def test_progress_false_is_silent_and_true_draws_a_bar(capsys):
    _grid(chunk_size=10, progress=False)
    assert capsys.readouterr().err == ""
    _grid(chunk_size=10, progress=True)
    err = capsys.readouterr().err
    assert "100%" in err and "81" in err


def test_progress_by_default_only_on_a_terminal_for_large_work(monkeypatch, capsys):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    bar = sweeps._progress_bar(sweeps.PROGRESS_ROWS + 1, None)
    assert bar is not None
    bar.close()
    assert sweeps._progress_bar(sweeps.PROGRESS_ROWS, None) is None
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    assert sweeps._progress_bar(sweeps.PROGRESS_ROWS + 1, None) is None


# --------------------------------------------------------------------------- command line


def test_cli_sweep_prints_a_summary(capsys):
    code, out, err = run(
        capsys, "sweep", US, "--vary", "e=0:0.4:5", "--vary", "mu=0,0.1,critical", "--vary", "v1x=55"
    )
    assert (code, err) == (0, "")
    df = impactsym.sweep(US, e=np.linspace(0, 0.4, 5), mu=[0.0, 0.1, "critical"], v1x=55.0)
    lines = out.splitlines()
    assert lines[0] == f"rows 15: solved 15, flagged {(df['flags'] != 0).sum()}, not solved 0"
    assert lines[1].split() == ["min", "median", "max"]
    assert lines[2].split()[:2] == ["dV1", "[ft/s]"]
    assert float(lines[4].split()[-1]) == pytest.approx(df["TL"].max(), rel=1e-5)


def test_cli_sweep_writes_the_rows(tmp_path, capsys):
    path = tmp_path / "grid.parquet"
    code, out, err = run(
        capsys,
        "sweep",
        US,
        "--vary",
        "e=0:0.4:5",
        "--vary",
        "normal_angle=-5:5:3",
        "-o",
        path,
        "--chunk-size",
        "4",
        "--outputs",
        "velocities",
        "--no-progress",
    )
    assert (code, err) == (0, "")
    assert out.splitlines()[0] == f"wrote 15 rows to {path}"
    expected = impactsym.sweep(
        US, e=np.linspace(0, 0.4, 5), normal_angle=[-5.0, 0.0, 5.0], outputs="velocities"
    )
    assert_same(pd.read_parquet(path), expected)


@pytest.mark.parametrize(
    "argv, words",
    [
        (["--vary", "e=0:0.4"], "--vary e=0:0.4: expected NAME=START:STOP:NUM"),
        (["--vary", "e0.1"], "--vary e0.1: expected NAME=START:STOP:NUM"),
        (["--vary", "e=0:1:x"], "NUM a positive integer"),
        (["--vary", "e=0,zero"], "'zero' is not a number"),
        (["--vary", "e=0,1", "--vary", "e=2,3"], "--vary e: given twice"),
        (["--vary", "speed=1,2"], "speed: not an input of the rigid model"),
        (["--vary", "e=0,1", "-o", "rows.txt"], "out: unknown file type '.txt'"),
        (["--vary", "e=0,1", "--vary", "mu=0,1", "--vary", "m1=1,2", "--plot", "p.png"], "1 or 2 varied"),
        (["--vary", "e=0,1", "--color", "TL"], "--color: only with --plot"),
        (["--vary", "e=0,1", "--engine", "ray"], "invalid choice"),
    ],
)
def test_cli_sweep_bad_arguments_exit_2_with_one_line(capsys, tmp_path, monkeypatch, argv, words):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "sweep", US, *argv)
    assert code == 2 and out == ""
    assert err.startswith("impactsym: error: ") and err.count("\n") == 1 and words in err, err
    assert list(tmp_path.iterdir()) == []


def test_cli_sample_prints_percentiles_and_json(tmp_path, capsys):
    args = [
        "sample",
        US,
        "--dist",
        "e=uniform:0:0.3",
        "--dist",
        "m1=normal:100:40",
        "-n",
        "3000",
        "--seed",
        "12",
    ]
    code, out, err = run(capsys, *args, "--json")
    assert (code, err) == (0, "")
    data = json.loads(out)
    df = impactsym.sample(US, {"e": ("uniform", 0, 0.3), "m1": ("normal", 100, 40)}, 3000, seed=12)
    summary = impactsym.percentiles(df)
    assert data["seed"] == 12 and data["units"] == "US"
    assert {k: data[k] for k in ("rows", "solved", "not_solved", "flagged")} == {
        k: summary.attrs["counts"][k] for k in ("rows", "solved", "not_solved", "flagged")
    }
    assert data["not_solved_by_status"] == {
        str(k): v for k, v in summary.attrs["counts"]["not_solved_by_status"].items()
    }
    assert data["percentiles"]["TL"]["95"] == summary.loc["TL", "p95"]
    code, out, err = run(capsys, *args, "-o", tmp_path / "s.csv")
    assert (code, err) == (0, "")
    lines = out.splitlines()
    assert lines[0] == f"wrote 3000 rows to {tmp_path / 's.csv'}" and lines[1].endswith("seed 12")
    reasons = [line for line in lines[2:] if line.startswith("  not solved, status ")]
    assert len(reasons) == len(summary.attrs["counts"]["not_solved_by_status"]) > 0
    assert lines[2 + len(reasons)].split() == ["p5", "p25", "median", "p75", "p95"]
    back = pd.read_csv(tmp_path / "s.csv", dtype={"status": "int32", "flags": "int32"})
    assert_same(back, df)


@pytest.mark.parametrize(
    "argv, words",
    [
        (["--dist", "e=uniform:0", "-n", "10"], "e: uniform takes 2 finite numbers"),
        (["--dist", "e=uniform", "-n", "10"], "expected NAME=KIND:P1:P2"),
        (["--dist", "e=gauss:0:1", "-n", "10"], "unknown distribution 'gauss'"),
        (["--dist", "e=uniform:0:a", "-n", "10"], "'a' is not a number"),
        (["--dist", "e=uniform:0:1", "-n", "0"], "n: must be a positive integer"),
        (["--dist", "e=uniform:0:1"], "-n"),
    ],
)
def test_cli_sample_bad_arguments_exit_2_with_one_line(capsys, argv, words):
    code, out, err = run(capsys, "sample", US, *argv)
    assert code == 2 and out == ""
    assert err.startswith("impactsym: error: ") and err.count("\n") == 1 and words in err, err


def test_cli_sweep_plot_draws_a_heatmap(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    path = tmp_path / "map.png"
    code, out, err = run(
        capsys,
        "sweep",
        US,
        "--vary",
        "e=0:0.4:5",
        "--vary",
        "mu=0:0.3:4",
        "--plot",
        path,
        "--color",
        "dV1",
        "-o",
        tmp_path / "map.csv",
    )
    assert (code, err) == (0, "")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    back = pd.read_csv(tmp_path / "map.csv", dtype={"status": "int32", "flags": "int32"})
    assert_same(back, impactsym.sweep(US, e=np.linspace(0, 0.4, 5), mu=np.linspace(0, 0.3, 4)))


def test_a_spill_write_asks_no_path_like_question_a_ctrl_c_could_land_in(tmp_path, monkeypatch):
    """numpy's ndarray.tofile asks whether the file is path-like (Python code of
    os.PathLike's ABC) and turns a KeyboardInterrupt raised there into a
    TypeError: a Ctrl-C during a sweep's spill once printed that traceback (CI,
    tests/test_first_use.py). With every path-like question raising
    KeyboardInterrupt, the spill still writes and reads back its values."""
    import os

    from impactsym.batch.quantiles import OrderStatistics

    def interrupted(cls, other):
        raise KeyboardInterrupt

    stats = OrderStatistics(tmp_path / "spill.bin")
    monkeypatch.setattr(os.PathLike, "__subclasshook__", classmethod(interrupted))
    os.PathLike._abc_caches_clear()
    try:
        with open(tmp_path / "other.bin", "wb") as other, pytest.raises(KeyboardInterrupt):
            isinstance(other, os.PathLike)  # the question itself is interrupted
        values = np.arange(1000.0)[::-1]
        stats.add(values)
        assert stats.select([0, 499, 999]) == {0: 0.0, 499: 499.0, 999: 999.0}
    finally:
        monkeypatch.undo()
        os.PathLike._abc_caches_clear()
