"""`python -m benchmarks body`: the per-row arithmetic benchmark runs and reports."""

from __future__ import annotations

import argparse
import re

import pytest

from benchmarks import body


def _run(capsys, *argv) -> list[tuple[str, float, float]]:
    parser = argparse.ArgumentParser()
    body.add_arguments(parser)
    assert body.main(parser.parse_args(argv)) == 0
    rows = re.findall(r"^\| (.+?) \| ([\d.]+) \| ([\d.]+) \|$", capsys.readouterr().out, re.M)
    return [(label, float(least), float(median)) for label, least, median in rows]


def test_each_case_gets_a_time_per_row(capsys):
    rows = _run(capsys, "--rows", "256", "--rounds", "2")
    assert [label[:3] for label, _, _ in rows] == ["(a)", "(b)", "(c)", "(d)"]
    assert all(0 < least <= median for _, least, median in rows)


@pytest.mark.slow
def test_a_before_after_compiles_both_bodies_and_times_them(capsys):
    rows = _run(capsys, "--against", "HEAD", "--rows", "256", "--rounds", "2")
    assert [label for label, _, _ in rows] == ["HEAD", "checkout"]
    assert all(0 < least <= median for _, least, median in rows)


@pytest.mark.slow
def test_bodies_that_differ_in_their_bits_are_refused():
    source = body._body_source((body.ROOT / "generated" / "planar_jit.py").read_text())
    wrong = source.replace("dV1 = _t", "dV1 = 2.0*_t", 1)
    assert wrong != source
    with pytest.raises(SystemExit, match="same bits"):
        body._body_runners({"checkout": source, "wrong": wrong}, 64)
