"""Study files: parsing, deterministic seeds and draws, and bad files failing before any run."""

from __future__ import annotations

import numpy as np
import pytest
from study_helpers import STUDY, write_study

from uvms_pin.apps.cli.main import main
from uvms_pin.apps.study import StudyError, load_study
from uvms_pin.errors import UvmsPinError


def test_runs_are_the_grid_times_the_samples_with_derived_seeds(tmp_path):
    study = load_study(write_study(tmp_path))
    runs = study.runs()
    assert len(runs) == 2 * 3
    assert [r.values["plant.buoyancy_scale"] for r in runs] == [1.0] * 3 + [3.0] * 3
    # the two grid points share the samples' draws and seeds (common random numbers)
    for a, b in zip(runs[:3], runs[3:], strict=True):
        assert a.seed == b.seed and a.values["plant.mass_scale"] == b.values["plant.mass_scale"]
    assert len({r.seed for r in runs[:3]}) == 3
    assert len({r.run_id for r in runs}) == 6
    for r in runs:
        assert 0.8 <= r.plant["mass_scale"] <= 1.0 and r.plant["damping_scale"] == 1.0
        assert 0.0 <= r.values["initial.joint_positions_rad[3]"] <= 0.4
        assert r.overrides["scenario.seed"] == r.seed
        # "scale" multiplies the base [0.15, 0.15, 0.15, 0, 0, 0]; index 3 replaces one joint
        factor = r.values["disturbance.amplitude"]
        np.testing.assert_allclose(
            r.overrides["disturbance.amplitude"], [0.15 * factor] * 3 + [0] * 3
        )
        joints = r.overrides["initial.joint_positions_rad"]
        assert (
            joints[:3] == [-0.2, 0.5, -0.3]
            and joints[3] == r.values["initial.joint_positions_rad[3]"]
        )


#: (path, apply, value) of each parameter of the study below
COMBINED = (
    ("disturbance.amplitude", "add", 0.05),
    ("disturbance.period_s", "scale", 3.0),
    ("control.period_s", "add", 0.003),
    ("environment.stiffness_N_m[1]", "scale", 2.5),
)
ADDED_AND_SCALED = (
    '[study]\nname = "combined"\nbase = "scenario.toml"\nseed = 3\nsamples = 1\n'
    + "".join(
        f'\n[[parameter]]\npath = "{path}"\napply = "{apply}"\nvalues = [{value!r}]\n'
        for path, apply, value in COMBINED
    )
)


def test_add_and_scale_apply_to_numbers_and_to_each_entry_of_a_list(tmp_path):
    """``apply = "add"`` adds the value to the base (a number, or each entry of a list),
    ``"scale"`` multiplies it (a number, or one indexed entry): the base scenario's
    amplitude [0.15, 0.15, 0.15, 0, 0, 0], period 7 s, control period 2 ms, stiffness
    [2, 2, 2]."""
    (run,) = load_study(write_study(tmp_path, ADDED_AND_SCALED, "combined.toml")).runs()
    overrides = run.overrides
    np.testing.assert_allclose(overrides["disturbance.amplitude"], [0.2] * 3 + [0.05] * 3)
    assert overrides["disturbance.period_s"] == pytest.approx(21.0)
    assert overrides["control.period_s"] == pytest.approx(0.005)
    np.testing.assert_allclose(overrides["environment.stiffness_N_m"], [2.0, 5.0, 2.0])


def test_draws_do_not_depend_on_other_parameters_or_the_sample_count(tmp_path):
    base = load_study(write_study(tmp_path)).runs()
    more = STUDY.replace("samples = 3", "samples = 5") + (
        '\n[[parameter]]\npath = "plant.damping_scale"\ndistribution = "uniform"\nlow = 0.5\nhigh = 1.5\n'
    )
    extended = load_study(write_study(tmp_path, more, "more.toml")).runs()
    by_key = {(r.values["plant.buoyancy_scale"], r.sample): r for r in extended}
    for r in base:
        other = by_key[(r.values["plant.buoyancy_scale"], r.sample)]
        assert other.seed == r.seed
        for path, value in r.values.items():
            assert other.values[path] == value
    again = load_study(write_study(tmp_path)).runs()
    assert [r.run_id for r in again] == [r.run_id for r in base]


BAD = [
    # (replace this, with this, the entry the message must name, and a word of the reason)
    (
        'path = "environment.stiffness_N_m"',
        'path = "environment.stifness_N_m"',
        "parameter[0] 'environment.stifness_N_m'",
        "unknown",
    ),
    ("values = [1.0, 3.0]", "values = []", "parameter[1] 'plant.buoyancy_scale'", "empty"),
    ("values = [1.0, 3.0]", "values = [-1.0, 3.0]", "parameter[1] 'plant.buoyancy_scale'", ">= 0"),
    (
        'distribution = "log-uniform"\nlow = 10.0\nhigh = 100.0',
        "values = [-5.0, 50.0]",
        "parameter[0] 'environment.stiffness_N_m'",
        ">= 0",
    ),
    (
        "low = 10.0\nhigh = 100.0",
        "low = 10.0\nhigh = 1.0",
        "parameter[0] 'environment.stiffness_N_m'",
        "empty range",
    ),
    (
        "low = 0.8\nhigh = 1.0",
        "low = 1.3\nhigh = 1.3",
        "parameter[2] 'plant.mass_scale'",
        "empty range",
    ),
    ("low = 0.8\nhigh = 1.0", "low = -0.5\nhigh = 1.3", "parameter[2] 'plant.mass_scale'", "> 0"),
    (
        'apply = "scale"\ndistribution = "log-uniform"',
        'apply = "scale"\ndistribution = "gamma"',
        "parameter[3] 'disturbance.amplitude'",
        "unknown distribution",
    ),
    (
        "low = 0.5\nhigh = 2.0",
        "low = 0.0\nhigh = 2.0",
        "parameter[3] 'disturbance.amplitude'",
        "low > 0",
    ),
    (
        'path = "plant.mass_scale"',
        'path = "plant.colour_scale"',
        "parameter[2] 'plant.colour_scale'",
        "unknown plant factor",
    ),
    (
        "joint_positions_rad[3]",
        "joint_positions_rad[7]",
        "parameter[4] 'initial.joint_positions_rad[7]'",
        "out of range",
    ),
    (
        "mean = 0.2",
        "mean = 9.0\nlow = 8.0\nhigh = 10.0",
        "parameter[4]",
        None,
    ),  # duplicate key -> TOML error
    (
        "std = 0.1\nlow = 0.0\nhigh = 0.4",
        "std = 0.1\nlow = 3.0\nhigh = 3.1",
        "parameter[4] 'initial.joint_positions_rad[3]'",
        "joint limits",
    ),
    ('base = "scenario.toml"', 'base = "missing.toml"', "study.base", "not found"),
    ("values = [1.0, 3.0]", 'values = [1.0, "3"]', "parameter[1]", "mixes kinds"),
    ("values = [1.0, 3.0]", "values = [true, false]", "parameter[1]", "plant factor needs numbers"),
    ("values = [1.0, 3.0]", "values = [{a = 1}]", "parameter[1]", "not a finite number"),
]


@pytest.mark.parametrize(("old", "new", "entry", "reason"), BAD)
def test_bad_study_files_fail_naming_the_entry(tmp_path, old, new, entry, reason):
    assert old in STUDY
    path = write_study(tmp_path, STUDY.replace(old, new, 1))
    with pytest.raises(StudyError) as info:
        load_study(path)
    assert isinstance(info.value, UvmsPinError)
    message = str(info.value)
    assert str(path) in message
    if reason is None:  # not valid TOML: the file is named, no entry can be
        assert "TOML" in message
        return
    assert entry in message and reason in message, message


def test_a_bad_study_runs_nothing_from_the_command_line(tmp_path, capsys):
    path = write_study(
        tmp_path, STUDY.replace("low = 10.0\nhigh = 100.0", "low = -5.0\nhigh = 100.0")
    )
    out = tmp_path / "out"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "0"]) == 2
    assert "parameter[0] 'environment.stiffness_N_m'" in capsys.readouterr().err
    assert not out.exists()


def test_a_negative_stiffness_inside_a_random_range_is_found_without_drawing_it(tmp_path):
    text = STUDY.replace(
        'distribution = "log-uniform"\nlow = 10.0', 'distribution = "uniform"\nlow = -1.0'
    )
    with pytest.raises(StudyError, match=r"parameter\[0\] 'environment.stiffness_N_m' = -1.0"):
        load_study(write_study(tmp_path, text))


def test_a_string_apply_other_than_set_and_a_bad_string_fail_before_any_run(tmp_path):
    """apply = "scale" needs numbers; a string the scenario does not know (an integrator
    that does not exist) is found by loading the base with it, naming the parameter."""
    choices = STUDY.replace(
        '[[parameter]]\npath = "plant.buoyancy_scale"',
        '[[parameter]]\npath = "integrator.method"\nvalues = ["rk4", "leapfrog"]\n\n'
        '[[parameter]]\npath = "plant.buoyancy_scale"',
        1,
    )
    with pytest.raises(StudyError, match="leapfrog"):
        load_study(write_study(tmp_path, choices))
    scaled = choices.replace('values = ["rk4", "leapfrog"]', 'apply = "scale"\nvalues = ["rk4"]')
    with pytest.raises(StudyError, match="apply = 'scale' needs numbers"):
        load_study(write_study(tmp_path, scaled))
