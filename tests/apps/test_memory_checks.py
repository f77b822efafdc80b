"""What a command allocates is checked against the memory available before it is allocated:
a study's grids and run list, a study table read back, the logs a comparison keeps, the trials
a validation loads (as ``run`` checks its log). The available memory is set by monkeypatching
`uvms_pin.checks.available_memory_bytes`, so each limit is tested exactly where it falls."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest
from conftest import ROOT

import uvms_pin.checks as checks
from uvms_pin.errors import DataError, ParameterError, ScenarioError, StudyError

URDF = ROOT / "models" / "uvms_lbv150.urdf"
DATA = ROOT / "data" / "hinsdale2023"


def _available(monkeypatch, n_bytes: int) -> None:
    monkeypatch.setattr(checks, "available_memory_bytes", lambda: n_bytes)


def _study(tmp_path: Path, grid: str, samples: int = 1) -> Path:
    text = (ROOT / "scenarios" / "passive_current.toml").read_text()
    (tmp_path / "base.toml").write_text(text.replace('"uvms_lbv150"', f'"{URDF}"'))
    path = tmp_path / "study.toml"
    path.write_text(
        textwrap.dedent(f"""
        [study]
        base = "base.toml"
        seed = 1
        samples = {samples}
        [[parameter]]
        path = "water.current_world_m_s[0]"
        {grid}
        """)
    )
    return path


def test_a_grid_is_checked_before_its_points_are_made(tmp_path):
    """1e12 points (48 TB): refused from the count, whatever the machine."""
    from uvms_pin.apps.study import load_study

    with pytest.raises(StudyError) as info:
        load_study(_study(tmp_path, "linspace = [1, 1000, 1000000000000]"))
    message = str(info.value)
    assert (
        "study.toml: parameter[0] 'water.current_world_m_s[0]': linspace: 1000000000000 points"
        in message
    )
    assert "GiB" in message and "give fewer" in message


def test_the_run_list_is_checked_before_it_is_made(tmp_path, monkeypatch):
    from uvms_pin.apps.study import load_study

    # 100 points x 50 samples = 5000 runs x (8192 + 512) bytes = 43.5 MB
    path = _study(tmp_path, "linspace = [0.0, 0.1, 100]", samples=50)
    _available(monkeypatch, 2 * 44 * 10**6)
    load_study(path)
    _available(monkeypatch, 2 * 43 * 10**6)
    with pytest.raises(StudyError, match=r"the study's 5000 runs \(100 points x 50 samples\)"):
        load_study(path)


def test_a_study_table_is_checked_before_it_is_read(tmp_path, monkeypatch):
    import pandas as pd

    from uvms_pin.apps.study.runner import load_results

    out = tmp_path / "out"
    (out / "parts").mkdir(parents=True)
    table = pd.DataFrame({"run_id": [f"{k:016x}" for k in range(1000)], "run_index": range(1000)})
    table.to_parquet(out / "results.parquet")
    assert len(load_results(out)) == 1000
    _available(monkeypatch, 10_000)
    with pytest.raises(StudyError, match=r"results.parquet \(1000 rows, 2 columns\) read into"):
        load_results(out)


def test_a_comparison_keeps_every_log_so_all_must_fit(monkeypatch):
    from uvms_pin.apps.compare.runs import controller_scenarios

    path = ROOT / "scenarios" / "realistic_force_tracking.toml"
    one = controller_scenarios(path, ["ppc"])["ppc"]
    log = one.settings.log_bytes(one.uvms.nq, one.uvms.nv, len(one.uvms.surface_bodies))
    _available(monkeypatch, 2 * log + 10)  # one log fits, two do not
    controller_scenarios(path, ["ppc"])
    with pytest.raises(ScenarioError, match="the logs of the 2 runs"):
        controller_scenarios(path, ["ppc", "pi_force"])


def test_arms_run_in_parallel_must_fit_together(tmp_path, monkeypatch):
    from uvms_pin.apps.arms.compare import CompareSettings, compare_arms
    from uvms_pin.scenario.load import load_scenario

    path = ROOT / "scenarios" / "realistic_force_tracking.toml"
    base = load_scenario(path)
    log = base.settings.log_bytes(base.uvms.nq, base.uvms.nv)
    _available(monkeypatch, 3 * log)  # one run's log fits, two arms' at a time do not
    with pytest.raises(ScenarioError, match=r"the logs of 2 arm runs at a time .* lower --jobs"):
        compare_arms(path, ["reference", "ur3"], tmp_path / "o", CompareSettings(), jobs=2)
    assert not any((tmp_path / "o").iterdir())  # refused before any arm ran


def test_trials_are_checked_before_they_are_loaded(tmp_path, monkeypatch):
    from uvms_pin.apps.validation.run import run_pool_validation

    _available(monkeypatch, 4 * 72_824)  # the trial's arrays: 72824 bytes, x4 in use
    with pytest.raises(DataError, match=r"the 1 trial files .*\(--trials\)"):
        run_pool_validation(DATA, tmp_path / "o", trial_names=["_alt_011-1"])
    assert not (tmp_path / "o").exists()


def test_a_runs_log_counts_the_wet_fractions_a_free_surface_adds(monkeypatch):
    """Under a free surface every sample logs one wet fraction per hull: the estimate holds
    them (the arrays a run really logs fit in it), and a memory that fits the log without
    them but not with them refuses the scenario before it runs."""
    import numpy as np

    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    path = ROOT / "scenarios" / "surfacing.toml"
    short = {"scenario.duration_s": 0.5, "initial.position_world_m": [0.0, 0.0, -0.05]}
    scenario = load_scenario(path, short)
    nq, nv, hulls = scenario.uvms.nq, scenario.uvms.nv, len(scenario.uvms.surface_bodies)
    assert hulls > 0
    settings = scenario.settings
    with_hulls = settings.log_bytes(nq, nv, hulls)
    assert with_hulls - settings.log_bytes(nq, nv) == settings.n_log * 8 * hulls
    rollout = simulate(scenario, progress=False)
    assert rollout.signals["wet_fraction"].shape == (settings.n_log, hulls)
    logged = sum(a.nbytes for a in (rollout.time_s, rollout.q, rollout.v, rollout.tau))
    logged += sum(np.asarray(a).nbytes for a in rollout.signals.values())
    assert logged <= with_hulls
    _available(monkeypatch, 2 * with_hulls - 2)  # the log without the hulls fits
    with pytest.raises(ScenarioError, match="the log of this run"):
        load_scenario(path, short)
    load_scenario(path, {**short, "water.free_surface": False})  # no wet fractions logged


def test_a_vector_env_of_a_billion_environments_is_refused_from_its_estimate():
    """The issue's example: 10^9 environments ended in a MemoryError traceback; refused now,
    within a second of the single environment's set-up, saying how much and how much there is."""
    import time

    gym = pytest.importorskip("gymnasium")
    import uvms_pin.apps.gym  # noqa: F401

    start = time.perf_counter()
    with pytest.raises(ParameterError) as info:
        gym.make_vec(
            "uvms_pin/ForceTracking-v0", num_envs=10**9, vectorization_mode="vector_entry_point"
        )
    assert time.perf_counter() - start < 5.0
    message = str(info.value)
    assert "1000000000 environments on 1 threads" in message
    assert "GiB, more than half of the" in message and "lower num_envs" in message


def test_a_batch_estimate_counts_environments_and_threads(monkeypatch):
    from uvms_pin.sim.batched_plant import THREAD_BYTES, batch_bytes, check_batch_fits

    one = batch_bytes(100, 11, 10, 1, 1)
    per_env = batch_bytes(100, 11, 10, 2, 1) - one  # a reset's share counted once a batch
    assert batch_bytes(100, 11, 10, 4, 2) == one + 3 * per_env + THREAD_BYTES
    assert batch_bytes(100, 11, 10, 2, 10**18) == batch_bytes(100, 11, 10, 2, 2)
    _available(monkeypatch, 2 * batch_bytes(100, 11, 10, 8, 2))
    check_batch_fits(100, 11, 10, 8, 2)
    with pytest.raises(ParameterError, match="9 environments on 2 threads"):
        check_batch_fits(100, 11, 10, 9, 2)


def test_world_objects_are_counted_before_they_are_built(tmp_path, monkeypatch):
    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.scenario.objects import objects_bytes

    text = (ROOT / "scenarios" / "push_object.toml").read_text()
    path = tmp_path / "push.toml"
    path.write_text(text.replace('"../models/', f'"{ROOT}/models/').replace("object_push:", "x:"))
    _available(monkeypatch, 2 * objects_bytes(2, 1) - 1)  # the seabed and one free box
    with pytest.raises(ScenarioError, match=r"push.toml: world.objects: 2 objects \(1 free\)"):
        load_scenario(path)


def test_a_mesh_is_weighed_before_it_is_read(tmp_path, monkeypatch):
    from uvms_pin.hydro.mesh import MESH_BYTES_PER_TRIANGLE, load_mesh_geometry, mesh_bytes

    stl = tmp_path / "huge.stl"  # a binary STL header declaring 2^32 - 1 triangles
    stl.write_bytes(b"\0" * 80 + (2**32 - 1).to_bytes(4, "little") + b"\0" * 50)
    assert mesh_bytes(stl) == (2**32 - 1) * MESH_BYTES_PER_TRIANGLE
    with pytest.raises(ParameterError, match=r"mesh '.*huge.stl' \(134 bytes\) would take"):
        load_mesh_geometry(stl)
    rock = ROOT / "scenarios" / "meshes" / "rock.obj"
    _available(monkeypatch, 2 * mesh_bytes(rock) - 1)
    with pytest.raises(ParameterError, match="simplify the mesh"):
        load_mesh_geometry(rock, (1.0, 1.0, 1.1))


def test_a_gym_camera_is_weighed_before_its_spaces_are_made(monkeypatch):
    gym = pytest.importorskip("gymnasium")
    from uvms_pin.apps.gym.camera import CameraObservation

    env = gym.make("uvms_pin/StationKeeping-v0")
    camera = {"name": "cam", "width": 8192, "height": 8192, "rate_hz": 10.0}
    # a frame (8192^2 x 9 bytes) and the image space's bounds (2 x 8192^2 x 3): 1.0 GiB
    _available(monkeypatch, 2 * 15 * 8192**2 - 1)
    with pytest.raises(
        ParameterError, match=r"a 8192 x 8192 camera observation would take 0\.938 GiB"
    ):
        CameraObservation(env, camera)


def test_a_runs_log_estimate_holds_the_base_arrays_exactly_and_the_ppcs_signals():
    """The estimate's base (time, q, v, tau, three wrenches, two energies) is what a run's
    base arrays take, byte for byte; the PPC's signals, the most a shipped controller logs,
    fit in its allowance of 10 (6 + nv) columns (with the thrusters' and the wet fractions)."""
    import numpy as np

    from uvms_pin.scenario.load import load_scenario
    from uvms_pin.sim.run import simulate

    scenario = load_scenario(ROOT / "scenarios" / "realistic_force_tracking.toml",
                             {"scenario.duration_s": 0.2})  # fmt: skip
    uvms, settings = scenario.uvms, scenario.settings
    rollout = simulate(scenario, progress=False)
    base = [rollout.time_s, rollout.q, rollout.v, rollout.tau, rollout.wrench_contact_world,
            rollout.wrench_measured_world, rollout.wrench_disturbance_body,
            rollout.kinetic_energy_J, rollout.potential_energy_J]  # fmt: skip
    assert sum(a.nbytes for a in base) == settings.log_bytes(uvms.nq, uvms.nv) - (
        settings.n_log * 8 * 10 * (6 + uvms.nv)
    )
    hulls = len(uvms.surface_bodies)
    signals = sum(np.asarray(a).nbytes for a in rollout.signals.values())
    assert signals > 0.5 * settings.n_log * 8 * 10 * (6 + uvms.nv)  # the allowance is used
    assert sum(a.nbytes for a in base) + signals <= settings.log_bytes(uvms.nq, uvms.nv, hulls)
