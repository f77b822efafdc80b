"""``uvms-pin identify DATA_DIR --fit NAMES --out DIR``: hydrodynamic parameters of the trial
vehicle's hull fitted to the pool trials' roll and pitch, checked on the held-out ones.

The fit (`uvms_pin.apps.validation.fit`) runs on the identification trials
(`IDENTIFICATION_TRIALS`); the model it starts from and the identified one are then both
simulated on every trial, and the held-out trials say whether the fit generalises. Writes
``identification.json``, the identified vehicle as a URDF (`IDENTIFIED_VEHICLE`, usable by
``uvms-pin validate pool --vehicle`` and anywhere a vehicle URDF goes) and, with figures, one
``identified<trial>.png`` per held-out trial. An identified ``arm_delay`` or ``imu_yaw``
(properties of the recording, not of the vehicle) is in the JSON; ``validate pool
--arm-delay``, ``--imu-yaw`` take them.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from uvms_pin.apps.validation.figures import identified_figure
from uvms_pin.apps.validation.fit import FitResult, fit_parameters
from uvms_pin.apps.validation.parameters import DEFAULT_FIT, hydro_body, parse_parameters
from uvms_pin.apps.validation.pool import (
    IDENTIFICATION_TRIALS,
    STEP_S,
    TRIAL_VEHICLE,
    TrialComparison,
    compare_trial,
    trial_setup,
)
from uvms_pin.apps.validation.run import check_step
from uvms_pin.apps.validation.sensitivity import SensitiveModel
from uvms_pin.apps.validation.trials import check_trials_fit, load_trial, split_trials
from uvms_pin.model.mount.text import urdf_text
from uvms_pin.model.resources import shipped_path
from uvms_pin.model.urdf.write_hydro import urdf_with_hydro
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.atomic import write_json_atomic, write_text_atomic

__all__ = ["DEFAULT_FIT", "IDENTIFIED_VEHICLE", "run_identification", "split_trials"]

HULL = "base_link"
IDENTIFIED_VEHICLE = "bluerov2_heavy_identified.urdf"


def _rmse_table(before: TrialComparison, after: TrialComparison) -> dict:
    roll0, pitch0 = before.rmse_deg("simulated")
    roll1, pitch1 = after.rmse_deg("simulated")
    published = before.rmse_deg("published")
    return {
        "start_roll_rmse_deg": roll0,
        "start_pitch_rmse_deg": pitch0,
        "identified_roll_rmse_deg": roll1,
        "identified_pitch_rmse_deg": pitch1,
        "published_roll_rmse_deg": published[0] if np.isfinite(published[0]) else None,
        "published_pitch_rmse_deg": published[1] if np.isfinite(published[1]) else None,
    }


def _means(rows: list[dict]) -> dict:
    keys = ("start_roll", "start_pitch", "identified_roll", "identified_pitch")
    return {f"mean_{k}_rmse_deg": float(np.mean([r[f"{k}_rmse_deg"] for r in rows])) for k in keys}


def _summary(fit: FitResult, tables: dict[str, dict], training: Sequence[str]) -> dict:
    held = [t for n, t in tables.items() if n not in training]
    used = [t for n, t in tables.items() if n in training]
    return {
        "link": fit.link,
        "parameters": {
            p.name: {
                "start": float(s),
                "identified": float(x),
                "sensitivity": "analytic" if p.analytic else "central differences",
                "unit": p.unit,
            }
            for p, s, x in zip(fit.parameters, fit.start, fit.values, strict=True)
        },
        "iterations": fit.iterations,
        "accepted_steps": len(fit.rms_deg) - 1,
        "stop_reason": fit.stop_reason,
        "converged": fit.converged,
        "gradient_cosine": fit.gradient_cosine,
        "fit_rms_deg": fit.rms_deg,
        "identification_trials": list(training),
        "held_out": _means(held),
        "identification": _means(used),
        "trials": tables,
    }


def run_identification(
    data_dir: str | Path,
    out_dir: str | Path | None,
    parameter_names: Sequence[str] = DEFAULT_FIT,
    *,
    start: UVMS,
    step_s: float = STEP_S,
    max_iterations: int = 50,
    figures: bool = True,
    progress: Callable[[str], None] | None = None,
    training: Sequence[str] = IDENTIFICATION_TRIALS,
) -> dict:
    """Fit ``parameter_names`` of the hull of ``start`` on the identification trials
    (``training``: their names, `split_trials`),
    compare start and identified model on every trial, write the results to ``out_dir``
    (nothing written when None). Every input is checked before the fit begins.

    Raises:
        ParameterError: an unknown parameter name, a bad step (`check_step`).
        DataError: missing or bad trial files.
    """
    parameters = parse_parameters(parameter_names)
    hydro_body(start, HULL)
    fitted_on, held_out = split_trials(data_dir, training)
    check_trials_fit(fitted_on + held_out)
    trials = [load_trial(p) for p in fitted_on + held_out]
    check_step(step_s, trials)
    setups = [trial_setup(t) for t in trials[: len(fitted_on)]]
    fit = fit_parameters(
        start, setups, parameters, HULL, step_s, max_iterations=max_iterations, progress=progress
    )
    fitted = SensitiveModel(start, parameters, HULL, fit.values)
    delay_s, yaw_rad = fitted.arm_delay_s, fitted.imu_yaw_rad
    tables, comparisons = {}, {}
    for trial in trials:
        pair = (
            compare_trial(start, trial, step_s),
            compare_trial(fit.uvms, trial, step_s, delay_s, yaw_rad),
        )
        tables[trial.name], comparisons[trial.name] = _rmse_table(*pair), pair
    result = {**_summary(fit, tables, training), "arm_delay_s": delay_s, "imu_yaw_rad": yaw_rad}
    if out_dir is not None:
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        vehicle = urdf_with_hydro(
            shipped_path(TRIAL_VEHICLE), HULL, hydro_body(fit.uvms, HULL).params
        )
        write_text_atomic(out / IDENTIFIED_VEHICLE, urdf_text(vehicle))
        if figures:
            for path in held_out:
                identified_figure(*comparisons[path.stem], out / f"identified{path.stem}.png")
        write_json_atomic(out / "identification.json", result)
    return result
