"""Your own metrics: functions of the rollout returning named numbers, named in a scenario as
``[metrics] extra = ["package.module:function"]`` and added to ``metrics.json``, study
tables and reports.

The contract: ``function(rollout) -> Mapping[str, float]``, names that are not already
built-in metric names. The rollout records the references (metadata ``extra_metrics``) and
the directory they resolve in (the scenario file's, put in front of ``sys.path``), so the
metrics of a saved rollout are computed the same way.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from uvms_pin.errors import ParameterError
from uvms_pin.results.named import resolve_reference, users_code_failed

if TYPE_CHECKING:
    from uvms_pin.results.rollout_data import RolloutData

__all__ = ["extra_metrics", "metric_function"]

#: The metadata keys: the references, the directory they are resolved in.
REFERENCES_KEY = "extra_metrics"
DIRECTORY_KEY = "extra_metrics_dir"


def metric_function(reference: str, search_dir: str | Path | None = None) -> Callable:
    """The callable ``"package.module:function"`` names (ParameterError if it is none)."""
    function = resolve_reference(reference, search_dir, what="metric", form="function")
    if not callable(function):
        raise ParameterError(
            f"metric '{reference}': is a {type(function).__name__}, not a function of the rollout"
        )
    return function


def extra_metrics(rollout: RolloutData, built_in: Mapping[str, Any]) -> dict[str, float]:
    """The metrics of every function the rollout's metadata names, in order.

    Raises:
        ParameterError: naming the metric function: it cannot be imported, raised, returned
            something other than a mapping of names to real numbers, or a name that a
            built-in metric or an earlier function already has.
    """
    references = rollout.metadata.get(REFERENCES_KEY) or []
    search_dir = rollout.metadata.get(DIRECTORY_KEY)
    out: dict[str, float] = {}
    for reference in references:
        function = metric_function(reference, search_dir)
        try:
            values = function(rollout)
        except Exception as exc:  # the user's function: named, with its own frames
            raise users_code_failed(
                f"metric '{reference}' raised {type(exc).__name__}: {exc}", exc
            ) from exc
        out.update(_checked(reference, values, {**built_in, **out}))
    return out


def _checked(reference: str, values: Any, taken: Mapping[str, Any]) -> dict[str, float]:
    if not isinstance(values, Mapping):
        raise ParameterError(
            f"metric '{reference}' must return a mapping name -> number, "
            f"got {type(values).__name__}"
        )
    out = {}
    for name, value in values.items():
        if not isinstance(name, str) or not name:
            raise ParameterError(f"metric '{reference}': a metric name must be text, got {name!r}")
        if name in taken:
            raise ParameterError(f"metric '{reference}': '{name}' is already a metric (rename it)")
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise ParameterError(
                f"metric '{reference}': '{name}' must be a real number, got {value!r}"
            )
        if math.isnan(float(value)):
            raise ParameterError(f"metric '{reference}': '{name}' is NaN")
        out[name] = float(value)
    return out
