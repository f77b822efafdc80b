"""``validate pool`` end to end: every trial compared, the table, summary and figures written."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from uvms_pin.apps.validation.figures import trial_figure
from uvms_pin.apps.validation.pool import (
    STEP_S,
    compare_trial,
    summary,
    summary_csv,
    trial_uvms,
)
from uvms_pin.apps.validation.trials import check_trials_fit, find_trials, load_trial
from uvms_pin.errors import DataError
from uvms_pin.results.atomic import write_json_atomic, write_text_atomic


def run_pool_validation(
    data_dir: str | Path,
    out_dir: str | Path,
    *,
    trial_names: Sequence[str] | None = None,
    step_s: float = STEP_S,
    figures: bool = True,
    progress: Callable[[str], None] | None = None,
) -> dict:
    """Validate every trial of ``data_dir`` (or those named); write the results to ``out_dir``.

    Writes ``pool_validation.json`` (`summary`), ``pool_validation.csv`` (`summary_csv`) and,
    with ``figures``, ``<trial>.png`` per trial. Every trial file is read and checked before
    anything is simulated or written.

    Raises:
        DataError: a missing directory, no trials, an unknown trial name or a bad file.
    """
    files = find_trials(data_dir)
    if trial_names is not None:
        by_name = {p.stem: p for p in files}
        unknown = [n for n in trial_names if n not in by_name]
        if unknown:
            raise DataError(
                f"{data_dir}: no trial named {', '.join(unknown)} (have {', '.join(by_name)})"
            )
        files = [by_name[n] for n in trial_names]
    check_trials_fit(files)
    trials = [load_trial(p) for p in files]
    uvms = trial_uvms()
    comparisons = []
    for trial in trials:
        comparisons.append(compare_trial(uvms, trial, step_s))
        if progress is not None:
            roll, pitch = comparisons[-1].rmse_deg("simulated")
            progress(f"{trial.name}: roll RMSE {roll:.2f} deg, pitch RMSE {pitch:.2f} deg")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    result = summary(comparisons)
    if figures:
        for c in comparisons:
            trial_figure(c, out / f"{c.name}.png")
    write_text_atomic(out / "pool_validation.csv", summary_csv(comparisons))
    write_json_atomic(out / "pool_validation.json", result)
    return result
