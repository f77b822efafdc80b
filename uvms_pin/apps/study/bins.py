"""The varied parameters of a study table, and the bins the report groups the runs by.

A parameter is a column of the table (its ``path``, as `spec.column_name` names it) with
three flags: ``numeric``; ``log``, better seen on a log scale (log-uniform or ``logspace``
in the study file, or positive values spanning more than a factor 50); ``grid``, its
values were listed (``values``, ``linspace``, ``logspace``), not drawn. Grid parameters,
text parameters and numeric ones with at most `N_BINS` distinct values are binned by
value; the others in `N_BINS` quantile bins, or log-spaced bins for log parameters.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np
import pandas as pd

from uvms_pin.apps.study.spec import column_name
from uvms_pin.results.format import cell_text

#: How many bins a drawn (not listed) numeric parameter is cut into.
N_BINS = 5


def report_parameters(table: pd.DataFrame, info: dict[str, Any]) -> list[dict[str, Any]]:
    """The varied parameters present in the table, with how to bin and scale them.

    ``info`` is the parsed study file (its ``[[parameter]]`` entries); without it every
    column with a dot in its name (a scenario key) counts as a parameter. Each entry:
    ``{"path": column, "numeric": bool, "log": bool, "grid": bool}``.
    """
    entries = info.get("parameter") or [{"path": c} for c in table.columns if "." in c]
    out = []
    for entry in entries:
        path = column_name(entry.get("path"), entry.get("apply", "set"))
        if path not in table.columns:
            continue
        column = table[path]
        # booleans are two categories, not numbers to scale or cut into ranges
        numeric = pd.api.types.is_numeric_dtype(column) and not pd.api.types.is_bool_dtype(column)
        log = bool(
            entry.get("distribution") == "log-uniform"
            or "logspace" in entry
            or (numeric and column.min() > 0 and column.max() / column.min() > 50)
        )
        grid = "values" in entry or "linspace" in entry or "logspace" in entry
        out.append({"path": path, "numeric": numeric, "log": log, "grid": grid})
    return out


def _label(value: Any) -> str:
    """A parameter value in a bin label: 3 significant digits ("nan" for NaN)."""
    return cell_text(value, 3, "nan")


def bins(values: pd.Series, param: dict[str, Any]) -> pd.Series:
    """Bin labels: the value itself for grids (or few distinct values), else N_BINS
    quantile bins (log-spaced edges for log parameters)."""
    if not param["numeric"] or param["grid"] or values.nunique() <= N_BINS:
        return values.map(_label)
    if param["log"]:
        edges = np.geomspace(values.min(), values.max(), N_BINS + 1)
    else:
        edges = np.unique(np.quantile(values, np.linspace(0, 1, N_BINS + 1)))
    labels = [f"{_label(a)}-{_label(b)}" for a, b in itertools.pairwise(edges)]
    cut = pd.cut(values, edges, labels=labels, include_lowest=True)
    return cut.astype(str)


def ordered_labels(values: pd.Series, labels: pd.Series) -> list[str]:
    """Bin labels in the order of their smallest parameter value."""
    first = {}
    for value, label in zip(values, labels, strict=True):
        key = value if isinstance(value, int | float) else str(value)
        if label not in first or key < first[label]:
            first[label] = key
    return sorted(first, key=lambda b: first[b])
