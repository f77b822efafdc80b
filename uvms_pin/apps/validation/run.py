"""``validate pool`` end to end: every trial compared, the table, summary and figures written."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from uvms_pin.apps.validation.figures import trial_figure
from uvms_pin.apps.validation.pool import (
    STEP_S,
    compare_trial,
    summary,
    summary_csv,
    trial_uvms,
)
from uvms_pin.apps.validation.trials import load_trial, select_trials
from uvms_pin.errors import ParameterError
from uvms_pin.results.atomic import write_json_atomic, write_text_atomic

#: RK4 steps a validation may take over all its trials (~0.2 ms each in pure Python: ~30 min)
MAX_STEPS = 10**7


def check_step(step_s: float, trials) -> None:
    """``step_s`` is the largest RK4 step: each IMU interval (they jitter, ~0.001-0.12 s) is
    split into equal steps no longer than it. A step longer than every interval would
    silently be each interval's own length, whatever it is.

    Raises:
        ParameterError: a step that is not positive and finite, longer than the longest
            IMU interval of the trials, or so short the trials take more than `MAX_STEPS`.
    """
    if not (math.isfinite(step_s) and step_s > 0.0):
        raise ParameterError(f"--step must be a positive number of seconds, got {step_s}")
    longest = max(float(np.max(np.diff(t.imu_time_s))) for t in trials)
    if step_s > longest:
        raise ParameterError(
            f"--step {step_s:g} s is longer than the longest IMU interval ({longest:.4g} s): "
            "each interval is integrated in steps no longer than --step, so every one would "
            f"be a single step of its own length, as with --step {longest:.4g}; give at most that"
        )
    steps = sum(math.ceil((t.imu_time_s[-1] - t.imu_time_s[0]) / step_s) for t in trials)
    if steps > MAX_STEPS:
        raise ParameterError(
            f"--step {step_s:g} s: {steps:.3g} RK4 steps over the {len(trials)} trials, more "
            f"than {MAX_STEPS:.0e} (half an hour or more); {STEP_S:g} s (the default) is "
            "within 0.002 deg of 0.02 s"
        )


def run_pool_validation(
    data_dir: str | Path,
    out_dir: str | Path,
    *,
    trial_names: Sequence[str] | None = None,
    step_s: float = STEP_S,
    figures: bool = True,
    progress: Callable[[str], None] | None = None,
    vehicle_urdf: str | Path | None = None,
    arm_delay_s: float = 0.0,
    imu_yaw_rad: float = 0.0,
) -> dict:
    """Validate every trial of ``data_dir`` (or those named); write the results to ``out_dir``.

    Writes ``pool_validation.json`` (`summary`), ``pool_validation.csv`` (`summary_csv`) and,
    with ``figures``, ``<trial>.png`` per trial. Every trial file is read and checked before
    anything is simulated or written. ``vehicle_urdf``: another trial vehicle (e.g. the one
    ``uvms-pin identify --out`` writes) in place of the shipped one; ``arm_delay_s``: how
    late the encoder stream is on the IMU's clock (identified by ``identify --fit arm_delay``);
    ``imu_yaw_rad``: the IMU's mounting yaw on the hull (``identify --fit imu_yaw``).

    Raises:
        DataError: a missing directory, no trials, an unknown trial name or a bad file.
    """
    trials = [load_trial(p) for p in select_trials(data_dir, trial_names)]
    check_step(step_s, trials)
    uvms = trial_uvms(vehicle_urdf)
    comparisons = []
    for trial in trials:
        comparisons.append(compare_trial(uvms, trial, step_s, arm_delay_s, imu_yaw_rad))
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
