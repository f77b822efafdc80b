"""The report's parameters and bins: listed values by value, drawn values in quantile or
log-spaced bins, labels with 3 significant digits, ordered by value."""

from __future__ import annotations

import numpy as np
import pandas as pd

from uvms_pin.apps.study.bins import N_BINS, bins, ordered_labels, report_parameters


def test_parameters_come_from_the_study_file_or_the_dotted_columns():
    table = pd.DataFrame(
        {
            "environment.stiffness_N_m": [1.0, 1000.0],
            "disturbance.amplitude [x base]": [0.5, 2.0],
            "controller.type": ["ppc", "pi_force"],
            "status": ["ok", "ok"],
        }
    )
    info = {
        "parameter": [
            {"path": "environment.stiffness_N_m", "values": [1.0, 1000.0]},
            {"path": "disturbance.amplitude", "apply": "scale", "distribution": "uniform"},
            {"path": "not.in.table", "values": [1]},
        ]
    }
    params = report_parameters(table, info)
    assert params == [
        {"path": "environment.stiffness_N_m", "numeric": True, "log": True, "grid": True},
        {"path": "disturbance.amplitude [x base]", "numeric": True, "log": False, "grid": False},
    ]
    found = report_parameters(table, {})
    assert [p["path"] for p in found] == list(table.columns[:3])
    assert found[2]["numeric"] is False


def test_listed_values_are_their_own_bins():
    values = pd.Series([0.123456, 10.0, 0.123456, np.float32(2.5), float("nan")])
    labels = bins(values, {"numeric": True, "log": False, "grid": True})
    assert list(labels) == ["0.123", "10", "0.123", "2.5", "nan"]


def test_drawn_values_fall_in_quantile_or_log_bins():
    values = pd.Series(np.linspace(1.0, 100.0, 50))
    linear = bins(values, {"numeric": True, "log": False, "grid": False})
    assert linear.nunique() == N_BINS and linear.iloc[0] == "1-20.8"
    log = bins(values, {"numeric": True, "log": True, "grid": False})
    assert log.iloc[0] == "1-2.51" and log.iloc[-1] == "39.8-100"
    assert ordered_labels(values, log)[:2] == ["1-2.51", "2.51-6.31"]


def test_labels_are_ordered_by_their_smallest_value():
    values = pd.Series([30.0, 4.0, 100.0])
    assert ordered_labels(values, values.map(str)) == ["4.0", "30.0", "100.0"]
