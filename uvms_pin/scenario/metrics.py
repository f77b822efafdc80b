"""``[metrics]``: your own metric functions, ``extra = ["package.module:function"]``.

Each function takes the rollout and returns named numbers (`uvms_pin.results.extra_metrics`);
they are imported now (with the scenario file's directory in front of ``sys.path``), so a
name that does not resolve is an error of the scenario, not of a finished run.
"""

from __future__ import annotations

from pathlib import Path

from uvms_pin.errors import ParameterError
from uvms_pin.results.extra_metrics import metric_function
from uvms_pin.scenario.schema import Table


def build_metrics(t: Table | None, scenario_dir: Path) -> tuple[str, ...]:
    """The references of ``[metrics] extra`` (none without the table), each resolved once."""
    if t is None:
        return ()
    references = t.pop_raw("extra", [])
    if not isinstance(references, list) or not all(isinstance(r, str) for r in references):
        raise t.error("extra", f"must be a list of 'package.module:function', got {references!r}")
    if len(set(references)) != len(references):
        raise t.error("extra", f"names a function twice: {references}")
    for reference in references:
        try:
            metric_function(reference, scenario_dir)
        except ParameterError as exc:
            raise t.error("extra", str(exc)) from exc
    t.finish()
    return tuple(references)
