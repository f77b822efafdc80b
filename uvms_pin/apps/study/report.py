"""A study's table -> figures (PNG, `figures`) and ``report.md`` (`markdown`).

The numbers come from `statistics` (over the parameter bins of `bins`); runs stopped
before the force funnel's transient ended are first kept out of the after-transient
metrics. The study file copied into the directory (``study.toml``) says which columns
are parameters, how they were sampled, and the optional [report] metrics and heatmaps.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

from uvms_pin.apps.study.bins import report_parameters
from uvms_pin.apps.study.figures import write_figures
from uvms_pin.apps.study.identity import STUDY_COPY
from uvms_pin.apps.study.markdown import EXCLUSION_MARK, exclusion_note, report_markdown
from uvms_pin.apps.study.runner import load_results
from uvms_pin.apps.study.statistics import exclude_unfinished_transients
from uvms_pin.errors import StudyError
from uvms_pin.results.atomic import write_text_atomic

REPORT_FILE = "report.md"
FIGURES_DIR = "figures"
DEFAULT_METRICS = (
    "force_error_rms_after_transient_N",
    "funnel_margin_min_first",
    "funnel_margin_min_second",
    "commanded_vehicle_force_peak_N",
    "vehicle_saturation_fraction",
    "simulated_time_s",
)
#: a tracking [task]'s metrics, summarised by default where the runs judged one
TASK_METRICS = (
    "task_position_error_rms_m",
    "task_orientation_error_rms_rad",
    "task_settling_time_s",
)


def _study_info(directory: Path) -> dict[str, Any]:
    """The study file copied into ``directory``, parsed ({} if absent or unreadable)."""
    path = directory / STUDY_COPY
    if not path.is_file():
        return {}
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError:
        return {}


def write_report(directory: str | Path) -> list[Path]:
    """Write ``report.md`` and its figures (``figures/*.png``) into a study directory.

    Returns the paths, ``report.md`` first. Raises `StudyError` if the directory holds no
    study table.
    """
    directory = Path(directory)
    table = load_results(directory)
    if not len(table):
        raise StudyError(f"{directory}: the study table is empty (no run finished yet)")
    table, excluded, transient_end = exclude_unfinished_transients(table)
    info = _study_info(directory)
    head = info.get("study", {})
    options = info.get("report", {})
    params = report_parameters(table, info)
    judged = [m for m in TASK_METRICS if m in table.columns and table[m].notna().any()]
    chosen = options.get("metrics") or (*DEFAULT_METRICS, *judged)
    metrics = [m for m in chosen if m in table.columns]
    figures_dir = directory / FIGURES_DIR
    figures_dir.mkdir(exist_ok=True)
    figures, heatmaps = write_figures(table, params, metrics, options, figures_dir)

    text = report_markdown(table, head, params, metrics, heatmaps, figures, directory)
    text = text.replace(EXCLUSION_MARK, exclusion_note(excluded, transient_end))
    report = directory / REPORT_FILE
    write_text_atomic(report, text)
    return [report, *figures]
