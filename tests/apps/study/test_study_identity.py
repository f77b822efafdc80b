"""A study directory holds one study (`uvms_pin.apps.study.identity`), checked before any write."""

from __future__ import annotations

import pytest
from study_helpers import SCENARIO, URDF, write_study

from uvms_pin.apps.study import StudyError, load_study
from uvms_pin.apps.study.identity import INPUTS_FILE, STUDY_COPY, study_inputs
from uvms_pin.apps.study.runner import base_row, load_results, run_study


def _instant(base, run, rollout_dir):
    """A run that records its row without simulating (the identity is what is tested)."""
    return base_row(run)


def _sweep(study_path, out):
    return run_study(load_study(study_path), out, workers=0, progress=False, run_fn=_instant)


def _files(out):
    return {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}


def test_the_record_names_the_study_settings_and_the_digests(tmp_path):
    study = load_study(write_study(tmp_path))
    _sweep(study.path, tmp_path / "out")
    inputs = study_inputs(study)
    assert inputs["model"].endswith("uvms_lbv150.urdf") and len(inputs["model_sha256"]) == 16
    assert (tmp_path / "out" / STUDY_COPY).read_text() == study.path.read_text()
    table = load_results(tmp_path / "out")
    assert set(table["base_sha256"]) == {inputs["base_sha256"]}


def test_a_changed_model_is_refused_and_nothing_is_written(tmp_path):
    write_study(tmp_path)
    model = tmp_path / "model.urdf"
    model.write_text(URDF.read_text())
    (tmp_path / "scenario.toml").write_text(SCENARIO.replace(str(URDF), str(model)))
    _sweep(tmp_path / "study.toml", tmp_path / "out")
    before = _files(tmp_path / "out")
    model.write_text(URDF.read_text().replace("<robot", "<!-- edited -->\n<robot", 1))
    with pytest.raises(StudyError, match=r"the model .*model.urdf changed"):
        _sweep(tmp_path / "study.toml", tmp_path / "out")
    assert _files(tmp_path / "out") == before


def test_a_directory_without_the_record_is_checked_against_its_copy_and_rows(tmp_path):
    """Directories written before study_inputs.json existed."""
    study_path = write_study(tmp_path)
    out = tmp_path / "out"
    _sweep(study_path, out)
    (out / INPUTS_FILE).unlink()
    _sweep(study_path, out)  # same study: resumes (and records)
    (out / INPUTS_FILE).unlink()
    (tmp_path / "scenario.toml").write_text(
        SCENARIO.replace("duration_s = 0.2", "duration_s = 0.4")
    )
    with pytest.raises(StudyError, match=r"base scenario .* changed"):
        _sweep(study_path, out)
    (tmp_path / "scenario.toml").write_text(SCENARIO)
    study_path.write_text(study_path.read_text().replace("seed = 11", "seed = 12"))
    with pytest.raises(StudyError, match="holds the results of another study"):
        _sweep(study_path, out)


def test_shortened_and_full_runs_never_share_a_table(tmp_path, monkeypatch):
    """UVMS_PIN_MAX_DURATION_S is part of what the rows come from: a resume with another
    cap (or none) is refused, before anything is written."""
    study_path = write_study(tmp_path)
    out = tmp_path / "out"
    monkeypatch.setenv("UVMS_PIN_MAX_DURATION_S", "0.1")
    _sweep(study_path, out)
    before = _files(out)
    monkeypatch.delenv("UVMS_PIN_MAX_DURATION_S")
    with pytest.raises(StudyError, match=r"UVMS_PIN_MAX_DURATION_S=0.1 .* None now"):
        _sweep(study_path, out)
    assert _files(out) == before
    monkeypatch.setenv("UVMS_PIN_MAX_DURATION_S", "0.1")
    _sweep(study_path, out)  # the same cap: resumes
