"""What the study report computes: the Wilson interval, rank correlations, failure rates
per parameter bin and over 2-D grids, which pair of parameters gets a heatmap."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from uvms_pin.apps.study.statistics import (
    bin_failure_rates,
    correlation_rows,
    heatmap_pairs,
    metric_rows,
    rank_correlation,
    status_rows,
    violation_rate_grid,
    wilson_interval,
)

GRID_A = {"path": "a", "numeric": True, "log": False, "grid": True}
GRID_B = {"path": "b", "numeric": True, "log": False, "grid": True}


def _table() -> pd.DataFrame:
    """Eight runs on a 2 x 2 grid of (a, b): only a = 2, b = 20 fails, twice."""
    return pd.DataFrame(
        {
            "status": ["ok", "ok", "ok", "ok", "ok", "ok", "FunnelViolation", "error"],
            "a": [1.0, 1.0, 2.0, 2.0, 1.0, 1.0, 2.0, 2.0],
            "b": [10.0, 10.0, 10.0, 10.0, 20.0, 20.0, 20.0, 20.0],
            "m": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, math.nan],
        }
    )


def test_wilson_interval():
    assert all(math.isnan(x) for x in wilson_interval(0, 0))
    lo, hi = wilson_interval(5, 10)
    assert lo == pytest.approx(0.2366, abs=1e-4) and hi == pytest.approx(0.7634, abs=1e-4)
    assert wilson_interval(10, 10)[1] == 1.0 and wilson_interval(0, 10)[0] == 0.0


def test_rank_correlation_needs_three_finite_varying_rows():
    x = pd.Series([1.0, 2.0, 3.0, 4.0])
    assert rank_correlation(x, pd.Series([10.0, 20.0, 30.0, 40.0])) == pytest.approx(1.0)
    assert rank_correlation(x, pd.Series([4.0, 3.0, 2.0, 1.0])) == pytest.approx(-1.0)
    assert math.isnan(rank_correlation(x, pd.Series([1.0, math.nan, math.nan, 2.0])))
    assert math.isnan(rank_correlation(x, pd.Series([5.0, 5.0, 5.0, 5.0])))


def test_status_rows_list_every_status():
    rows = status_rows(_table())
    assert [r["status"] for r in rows] == ["ok", "FunnelViolation", "diverged", "error"]
    assert [r["runs"] for r in rows] == [6, 1, 0, 1]
    assert rows[0]["fraction"] == pytest.approx(0.75)


def test_failure_rates_per_bin_and_over_the_grid():
    table = _table()
    order, rates, counts = bin_failure_rates(table, GRID_A)
    assert order == ["1", "2"] and rates == [0.0, 0.5] and counts == [4, 4]
    # bins of unequal size: each its own count (six runs, four with a = 1)
    assert bin_failure_rates(table.iloc[:6], GRID_A)[2] == [4, 2]
    frame, count = violation_rate_grid(table, GRID_A, GRID_B)
    assert list(frame.columns) == ["1", "2"] and list(frame.index) == ["10", "20"]
    np.testing.assert_array_equal(frame.to_numpy(), [[0.0, 0.0], [0.0, 1.0]])
    np.testing.assert_array_equal(count, [[2, 2], [2, 2]])


def test_an_empty_grid_cell_has_no_rate():
    frame, count = violation_rate_grid(_table().iloc[:6], GRID_A, GRID_B)
    assert math.isnan(frame.loc["20", "2"]) and count[1, 1] == 0


def test_heatmap_pairs_asked_then_grid_then_most_correlated():
    table = _table()
    table["c"] = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 5.0, 6.0]  # rises with failure
    drawn = {"numeric": True, "log": False, "grid": False}
    params = [GRID_A, GRID_B, {"path": "c", **drawn}]
    assert heatmap_pairs(table, params, {"heatmaps": [["c", "a"], ["a", "zz"]]}) == [("c", "a")]
    assert heatmap_pairs(table, params, {}) == [("a", "b")]
    table["d"] = [1.0, 2.0] * 4  # one failure at each value: no correlation
    drawn_params = [{"path": "d", **drawn}, {"path": "c", **drawn}]
    assert heatmap_pairs(table, drawn_params, {}) == [("c", "d")]
    assert heatmap_pairs(table, drawn_params[:1], {}) == []


def test_correlation_and_metric_rows():
    table = _table()
    text = {"path": "s", "numeric": False, "log": False, "grid": True}
    table["s"] = "x"
    rows = correlation_rows(table, [GRID_B, text], ["m"])
    assert [r["parameter"] for r in rows] == ["b"]  # text parameters have no rank
    assert rows[0]["failure"] > 0 and rows[0]["m"] > 0
    summary = metric_rows(table, ["m"])
    assert [r["runs"] for r in summary] == ["all (7)", "ok (6)"]
    assert summary[0]["max"] == 0.7 and summary[1]["median"] == pytest.approx(0.35)
