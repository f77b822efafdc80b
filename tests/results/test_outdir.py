"""Output directories: checked before work, locked while written, never mixed."""

from __future__ import annotations

import pytest
from conftest import ROOT

from uvms_pin.errors import OutputError
from uvms_pin.results.outdir import COMPARISON, RUN, STUDY, check_writable, claim, claim_file


def test_check_writable_refuses_files_and_paths_under_them_and_creates_nothing(tmp_path):
    (tmp_path / "f").write_text("mine")
    with pytest.raises(OutputError, match="is a file"):
        check_writable(tmp_path / "f")
    with pytest.raises(OutputError, match=r"is under a file \(.*f\)"):
        check_writable(tmp_path / "f" / "a" / "b")
    assert check_writable(tmp_path / "new" / "deeper") == tmp_path / "new" / "deeper"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f"]


def test_a_claimed_directory_is_locked_against_a_second_writer(tmp_path):
    with claim(tmp_path / "out", RUN) as out:
        with pytest.raises(OutputError, match="being written by another uvms-pin process"):
            with claim(out, RUN):
                pass
        with pytest.raises(OutputError, match="being written"):
            with claim_file(out / "replay.html"):
                pass
    with claim(tmp_path / "out", RUN):  # released at the end of the block
        (tmp_path / "out" / "rollout.json").write_text("{}")


def test_a_claim_that_wrote_nothing_leaves_no_directory(tmp_path):
    with pytest.raises(RuntimeError), claim(tmp_path / "out", RUN):
        raise RuntimeError("the scenario failed")
    assert not (tmp_path / "out").exists()


def test_outputs_are_refused_and_overwrite_removes_only_uvms_pin_files(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    for name in ("rollout.npz", "rollout.json", "replay.html", "force.png"):
        (out / name).write_text("earlier run")
    (out / ".rollout.json.1a2b3c4d.tmp").write_text("an interrupted write")
    (out / "notes.txt").write_text("mine")
    (out / ".notes.txt.swp.tmp").write_text("my editor's")
    (out / "photo.png").write_text("mine too")
    with pytest.raises(OutputError, match=r"already holds a run's outputs.*--overwrite"):
        with claim(out, RUN):
            pass
    assert (out / "rollout.npz").exists()
    with claim(out, RUN, overwrite=True):
        pass
    assert sorted(p.name for p in out.iterdir()) == [".notes.txt.swp.tmp", "notes.txt", "photo.png"]


def test_another_commands_results_are_refused_even_with_overwrite(tmp_path):
    study = tmp_path / "study"
    (study / "parts").mkdir(parents=True)
    (study / "results.parquet").write_text("table")
    for kind in (RUN, COMPARISON):
        with pytest.raises(OutputError, match="holds a study's results"):
            with claim(study, kind, overwrite=True):
                pass
    assert (study / "results.parquet").read_text() == "table"
    with claim(study, STUDY):  # a sweep resumes into its own directory
        pass
    with claim(study, STUDY, overwrite=True):
        pass
    assert not (study / "results.parquet").exists() and not (study / "parts").exists()


def test_the_comparison_overwrite_removes_its_models_directory_once_empty(tmp_path):
    out = tmp_path / "arms"
    (out / "models").mkdir(parents=True)
    (out / "models" / "ur5.urdf").write_text("<robot/>")
    (out / "comparison.csv").write_text("arm\n")
    with claim(out, COMPARISON, overwrite=True):
        pass
    assert list(out.iterdir()) == []


def test_run_outputs_are_exactly_the_files_a_run_writes(tmp_path):
    """RUN lists the outputs by name: a new figure must be added there (or --overwrite
    would leave it stale). The sea-state scenario writes every figure but one (flow.png
    too); the surfacing scenario started at the waterline writes surface.png; a tracking
    task writes tracking.png; an estimator estimate.png; free objects objects.png; cameras and
    sonars perception.npz and perception.png."""
    from uvms_pin.apps.outputs import write_outputs
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    text = (ROOT / "scenarios" / "sea_state_force_tracking.toml").read_text()
    text = text.replace("../models/", f"{ROOT}/models/").replace(
        "duration_s = 10.0", "duration_s = 0.04"
    )
    (tmp_path / "s.toml").write_text(text)
    out = tmp_path / "out"
    out.mkdir()
    figures = write_outputs(simulate(load_scenario(tmp_path / "s.toml")), out)
    assert any(p.name == "force.png" for p in figures)  # the paper figures are there too
    at_the_surface = load_scenario(
        ROOT / "scenarios" / "surfacing.toml",
        {"scenario.duration_s": 0.2, "initial.position_world_m": [0.0, 0.0, -0.05]},
    )
    figures = write_outputs(simulate(at_the_surface), out / "surfacing")
    assert "surface.png" in {p.name for p in figures}
    tracking = load_scenario(
        ROOT / "scenarios" / "lbv150_ee_circle.toml", {"scenario.duration_s": 0.1}
    )
    figures = write_outputs(simulate(tracking, progress=False), out / "tracking")
    assert "tracking.png" in {p.name for p in figures}
    estimating = load_scenario(
        ROOT / "scenarios" / "estimator_station_keeping.toml", {"scenario.duration_s": 0.1}
    )
    figures = write_outputs(simulate(estimating, progress=False), out / "estimating")
    assert "estimate.png" in {p.name for p in figures}
    gripping = load_scenario(
        ROOT / "scenarios" / "gripper_close.toml", {"scenario.duration_s": 0.04}
    )
    figures = write_outputs(simulate(gripping, progress=False), out / "gripping")
    assert "objects.png" in {p.name for p in figures}
    seeing = load_scenario(ROOT / "scenarios" / "seabed_survey.toml", {"scenario.duration_s": 0.2})
    figures = write_outputs(simulate(seeing, progress=False), out / "seeing")
    assert "perception.png" in {p.name for p in figures}
    written = {p.name for p in out.iterdir() if p.is_file()}
    for sub in ("surfacing", "tracking", "estimating", "gripping", "seeing"):
        written |= {p.name for p in (out / sub).iterdir()}
    assert written | {"replay.html"} == set(RUN.patterns)  # replay.html: with --html


@pytest.mark.parametrize("empty", ["", "  "])
def test_an_empty_out_is_not_the_current_directory(tmp_path, monkeypatch, empty):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError, match="an empty path; give a directory"):
        check_writable(empty)
    with pytest.raises(OutputError, match="an empty path"), claim(empty, RUN):
        pass
    assert list(tmp_path.iterdir()) == []


def test_an_identification_is_known_by_the_files_identify_writes(tmp_path):
    """The identification's kind names the vehicle file identify writes (a rename of one
    would leave an earlier identification unrecognised, then mixed with a new one)."""
    from uvms_pin.apps.validation.identification import IDENTIFIED_VEHICLE
    from uvms_pin.results.outdir import IDENTIFICATION

    assert IDENTIFIED_VEHICLE in IDENTIFICATION.markers
    (tmp_path / IDENTIFIED_VEHICLE).write_text("<robot/>")
    (tmp_path / "identified_alt_002-0.png").write_bytes(b"png")
    assert IDENTIFICATION.holds(tmp_path)
    assert [p.name for p in IDENTIFICATION.present(tmp_path)] == [
        "bluerov2_heavy_identified.urdf", "identified_alt_002-0.png",
    ]  # fmt: skip


def test_a_pool_validation_owns_the_figure_of_each_trial_its_record_lists(tmp_path):
    """A pool validation's figures are named after its trials: the ones its
    pool_validation.json lists are its own (an overwrite removes them), a file it does not
    list is not, and a listed name that is a path (``../x``, ``a/b``) names nothing."""
    import json

    from uvms_pin.results.outdir import POOL_VALIDATION

    out = tmp_path / "validation"
    out.mkdir()
    trials = {"alt_002-0": {}, "../outside": {}, "sub/trial": {}, 7: {}}
    (out / "pool_validation.json").write_text(json.dumps({"trials": trials}))
    for name in ("alt_002-0.png", "mine.png", "pool_validation.csv"):
        (out / name).write_bytes(b"x")
    (tmp_path / "outside.png").write_bytes(b"x")
    (out / "sub").mkdir()
    (out / "sub" / "trial.png").write_bytes(b"x")
    assert POOL_VALIDATION.holds(out)
    present = [p.relative_to(out).as_posix() for p in POOL_VALIDATION.present(out)]
    assert present == ["alt_002-0.png", "pool_validation.csv", "pool_validation.json"]
    (out / "pool_validation.json").write_text("not json")  # unreadable: the patterns alone
    present = [p.name for p in POOL_VALIDATION.present(out)]
    assert present == ["pool_validation.csv", "pool_validation.json"]
