"""`run_identification` keeps the held-out trials out of the fit and out of the
identification means (`uvms_pin.apps.validation.identification`): the fit and the trial
comparisons replaced by spies (the real fit has its own tests, tests/apps/validation/
test_fit.py), the split and the bookkeeping run for real on the shipped trials."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from test_sensitivity import DATA_DIR

from uvms_pin.apps.validation import identification
from uvms_pin.apps.validation.fit import FitResult
from uvms_pin.apps.validation.parameters import parameter_values
from uvms_pin.apps.validation.pool import IDENTIFICATION_TRIALS, trial_setup, trial_uvms
from uvms_pin.apps.validation.trials import find_trials, load_trial
from uvms_pin.errors import DataError


class _Comparison:
    """What `compare_trial` returns, as far as the summary reads it: a trial's RMSE [deg],
    its own number (start) and twice it (identified), roll (pitch: minus it)."""

    def __init__(self, value: float):
        self.value = value

    def rmse_deg(self, kind: str):
        if kind == "simulated":
            return self.value, -self.value
        # the published simulator's: odd trials have none (nan), even ones roll 10x, pitch 100x
        return (np.nan, np.nan) if self.value % 2 else (10.0 * self.value, 100.0 * self.value)


def test_the_fit_sees_only_the_identification_trials_and_the_means_keep_them_apart(
    monkeypatch,
):
    start = trial_uvms()
    names = [p.stem for p in find_trials(DATA_DIR)]
    held_out = [n for n in names if n not in IDENTIFICATION_TRIALS]
    assert held_out and len(IDENTIFICATION_TRIALS) < len(names)
    number = {name: float(k + 1) for k, name in enumerate(names)}
    fitted, identified = [], trial_uvms()  # (the fit's model: another object than start)

    def fit(uvms, setups, parameters_, link, step_s, **kw):
        fitted.append(setups)
        values = parameter_values(uvms, parameters_, link)
        return FitResult(parameters_, link, values, values, [1.0], 0, identified, "gradient", 0.0)

    def compare(uvms, trial, step_s, *delays):
        assert uvms is (identified if delays else start)
        return _Comparison(number[trial.name] * (2.0 if delays else 1.0))

    monkeypatch.setattr(identification, "fit_parameters", fit)
    monkeypatch.setattr(identification, "compare_trial", compare)
    result = identification.run_identification(
        DATA_DIR, None, ("linear_damping.roll",), start=start, figures=False
    )
    (setups,) = fitted
    assert len(setups) == len(IDENTIFICATION_TRIALS)
    for setup, name in zip(setups, IDENTIFICATION_TRIALS, strict=True):
        expected = trial_setup(load_trial(DATA_DIR / f"{name}.npz"))
        np.testing.assert_array_equal(setup.measured, expected.measured)
    for group, members in (("held_out", held_out), ("identification", IDENTIFICATION_TRIALS)):
        mean = float(np.mean([number[n] for n in members]))
        assert result[group]["mean_start_roll_rmse_deg"] == mean
        assert result[group]["mean_identified_roll_rmse_deg"] == 2.0 * mean
    assert set(result["trials"]) == set(names)
    for name, row in result["trials"].items():  # each trial's own numbers, roll and pitch
        value = number[name]
        assert (row["start_roll_rmse_deg"], row["start_pitch_rmse_deg"]) == (value, -value)
        published = (row["published_roll_rmse_deg"], row["published_pitch_rmse_deg"])
        assert published == ((None, None) if value % 2 else (10.0 * value, 100.0 * value))


def test_a_directory_of_only_the_identification_trials_has_nothing_to_hold_out(tmp_path):
    for name in IDENTIFICATION_TRIALS:
        shutil.copy(DATA_DIR / f"{name}.npz", tmp_path)
    with pytest.raises(DataError, match="no trial left to hold out"):
        identification.split_trials(tmp_path)
    training, held_out = identification.split_trials(DATA_DIR)
    assert [p.stem for p in training] == list(IDENTIFICATION_TRIALS)
    assert {p.stem for p in held_out}.isdisjoint(IDENTIFICATION_TRIALS) and held_out
