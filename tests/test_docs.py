"""The repository documents itself: docs/ covers every scenario key, and nothing points
outside the repository."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from conftest import ROOT

from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.load import load_scenario, scenario_from_dict
from uvms_pin.scenario.schema import Table
from uvms_pin.scenario.toml import read_toml

DOCS = ROOT / "docs"
SCENARIOS = ROOT / "scenarios"

# variants that make the reader visit every branch: both contact models, a fixed-step and
# an adaptive integrator, no controller and the PPC with every optional key asked for
_VARIANTS = [
    ("paper_force_tracking.toml", {}),
    ("realistic_force_tracking.toml", {}),
    (
        "realistic_force_tracking.toml",
        {
            "actuation.thruster": [
                {
                    "position_body_m": [0.0, 0.0, 0.0],
                    "direction_body": [1.0, 0.0, 0.0],
                    "curve": "quadratic",
                    "max_forward_N": 20.0,
                    "max_reverse_N": 15.0,
                    "deadband": 0.05,
                    "time_constant_s": 0.05,
                    "rate_limit_N_s": 200.0,
                }
            ]
        },
    ),
    ("passive_still_water.toml", {"controller.type": "pi_force"}),
    ("passive_still_water.toml", {"controller.type": "impedance"}),
    (
        "passive_still_water.toml",
        {
            "controller": {
                "type": "joint_hold",
                "positions_rad": {"arm_joint1": 0.1},
                "stiffness_Nm_rad": 2.0,
                "damping_Nms_rad": 0.1,
                "vehicle_wrench_body": [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            }
        },
    ),
    (
        "passive_still_water.toml",
        {
            "controller.type": "computed_torque",
            "controller.model_error": {
                "mass_scale": 1.3,
                "added_mass_scale": 1.3,
                "damping_scale": 0.7,
                "buoyancy_scale": 1.0,
            },
        },
    ),
    ("passive_current.toml", {}),
    ("mpc_station_keeping.toml", {"controller.model_error": {"damping_scale": 1.2}}),
    ("mpc_force_tracking.toml", {"controller.model_error": {"mass_scale": 1.1}}),
    (
        "mpc_force_tracking.toml",
        {
            "controller.contact": {
                "type": "plane",
                "normal_world": [-1.0, 0.0, 0.0],
                "stiffness_N_m": 100.0,
                "damping_N_s_m": 5.0,
                "anchor_world_m": [0.5, 0.0, -2.0],
            }
        },
    ),
    (
        "sea_state_force_tracking.toml",
        {"water.sea.spreading_exponent": 4.0, "water.sea.seed": 3, "water.sea.water_depth_m": 30.0},
    ),
    (
        "passive_current.toml",
        {
            "water.waves": {"amplitude_m": 0.1, "period_s": 4.0},
            "water.current": {
                "type": "gauss_markov",
                "mean_velocity_world_m_s": [0.1, 0, 0],
                "std_m_s": 0.05,
                "time_constant_s": 10.0,
                "bound_m_s": 0.1,
                "seed": 1,
                "sample_period_s": 0.5,
            },
        },
    ),
    (
        "passive_current.toml",
        {
            "water.waves": {
                "amplitude_m": 0.1,
                "period_s": 4.0,
                "heading_rad": 0.2,
                "water_depth_m": 20.0,
                "phase_rad": 0.1,
            },
            "water.current": {
                "type": "profile",
                "velocity_world_m_s": [0.2, 0, 0],
                "depths_m": [0, 10],
                "factors": [1, 0.5],
            },
        },
    ),
    (
        "passive_still_water.toml",
        {
            "control.period_s": 0.002,
            "joints.use_model_friction": True,
            "joints.viscous_Nms": [0.1, 0.1, 0.1, 0.1],
            "joints.coulomb_Nm": [0.05, 0.05, 0.05, 0.05],
            "joints.coulomb_velocity_rad_s": 0.02,
            "joints.torque_time_constant_s": [0.01, 0.01, 0.01, 0.01],
            "sensors.imu": {
                "gyro_noise_rad_s_rthz": 1e-3,
                "gyro_bias_walk_rad_s2_rthz": 1e-5,
                "accel_noise_m_s2_rthz": 1e-2,
                "accel_bias_walk_m_s3_rthz": 1e-4,
            },
            "sensors.depth": {"noise_Pa": 50.0},
            "sensors.dvl": {
                "noise_m_s": 0.01,
                "min_altitude_m": 0.3,
                "max_altitude_m": 50.0,
                "dropout_probability": 0.05,
                "seabed_depth_m": 30.0,
            },
            "sensors.usbl": {
                "noise_m": 0.1,
                "period_s": 1.0,
                "latency_s": 0.5,
                "dropout_probability": 0.1,
            },
        },
    ),
    (
        "passive_still_water.toml",
        {
            "environment.type": "plane",
            "environment.stiffness_N_m": 100.0,
            "controller.type": "none",
            "control.period_s": 0.002,
            "integrator.method": "semi_implicit_euler",
        },
    ),
    (
        "seabed_landing.toml",
        {
            "world.objects": [
                {"type": "plane", "point_world_m": [0, 0, -10], "normal_world": [0, 0, 1]},
                {
                    "type": "box",
                    "name": "crate",
                    "size_m": [1, 1, 1],
                    "position_world_m": [3, 0, -9],
                    "rpy_rad": [0, 0, 0.3],
                    "fixed": True,
                    "friction_static": 0.8,
                    "friction_kinetic": 0.7,
                },
                {"type": "sphere", "radius_m": 0.5, "position_world_m": [-3, 0, -9.5]},
                {
                    "type": "ellipsoid",
                    "semi_axes_m": [0.4, 0.3, 0.2],
                    "position_world_m": [-5, 0, -9],
                },
                {
                    "type": "cylinder",
                    "radius_m": 0.2,
                    "length_m": 4.0,
                    "position_world_m": [0, 3, -9.8],
                    "rpy_rad": [1.5708, 0, 0],
                },
                {
                    "type": "mesh",
                    "path": "meshes/rock.obj",
                    "scale": [1, 1, 1],
                    "position_world_m": [0, -3, -9.8],
                },
            ],
            "world.contact": {
                "stiffness_N_m": 1e4,
                "dissipation_s_m": 0.5,
                "friction_static": 0.6,
                "friction_kinetic": 0.5,
                "tangential_stiffness_N_m": 1e4,
                "tangential_damping_N_s_m": 20.0,
            },
            "joints.hard_stops": True,
            "joints.stop_stiffness_Nm_rad": 500.0,
            "joints.stop_damping_Nm_s_rad": 2.0,
        },
    ),
]

_PPC_LEVEL = {
    "type": "task_priority",
    "dynamic_level": "ppc",
    "position_gain_per_s": 1.0,
    "orientation_gain_per_s": 1.0,
    "attitude_gain_per_s": 1.0,
    "joint_limit_margin_rad": 0.1,
    "joint_limit_gain_per_s": 2.0,
    "manipulability_threshold": 0.01,
    "manipulability_gain": 1.0,
    "pinv_damping": 0.001,
    "passive_velocities": [3, 4],
    "velocity_weights": [1.0] * 10,
    "k_zeta": [1.0] * 10,
    "rho0_zeta": [2.0] * 10,
    "rho_inf_zeta": [1.0] * 10,
    "l_zeta_per_s": [1.0] * 10,
}
_RESOLVED_ACCELERATION = {
    "type": "resolved_acceleration",
    "position_gain_per_s2": [4.0] * 6,
    "velocity_gain_per_s": [4.0] * 6,
    "null_space_damping_per_s": 2.0,
    "velocity_weights": [1.0] * 10,
    "model_error": {"mass_scale": 1.1},
}
# the tracking tasks: every path, both targets and frames, both tracking controllers
#: a free object held by the jaw from 1 s to 5 s (`attached_to`, `attach_at_s`, `release_at_s`)
_HELD_BALL = {
    "type": "sphere", "name": "held", "radius_m": 0.03, "density_kg_m3": 2000.0,
    "position_world_m": [1.0, 0.0, -9.0], "attached_to": "alpha_jaw_link", "attach_at_s": 1.0,
    "release_at_s": 5.0,
}  # fmt: skip

_VARIANTS += [
    ("valve_panel.toml", {}),
    ("gripper_close.toml", {"gripper.joints": ["alpha_jaw_finger_130_joint", "alpha_jaw_finger_139_joint"]}),
    ("gripper_close.toml", {"gripper.by_controller": True, "controller": {"type": "none"}}),
    ("lbv150_ee_circle.toml", {"metrics.extra": []}),
    (
        "lbv150_ee_circle.toml",
        {
            "task": {"type": "helix", "radius_m": 0.1, "period_s": 20.0, "rise_per_turn_m": 0.05,
                     "ee_frame": "ee", "start_m": [0.5, 0.0, -0.4], "rpy_rad": [0.0, 0.0, 0.0],
                     "frame": "vehicle"},
            "controller": _PPC_LEVEL,
            "baselines": {},
        },
        True,
    ),
    (
        "lbv150_ee_circle.toml",
        {
            "task": {"type": "lemniscate", "half_width_m": 0.1, "period_s": 20.0},
            "controller": _RESOLVED_ACCELERATION,
        },
        True,
    ),
    (
        "lbv150_ee_circle.toml",
        {"task": {"type": "min_jerk", "displacement_m": [0.1, 0, 0], "duration_s": 5.0,
                  "start_s": 1.0}},
        True,
    ),
    (
        "lbv150_ee_circle.toml",
        {"task": {"type": "waypoints", "offsets_m": [[0, 0, 0], [0.1, 0, 0]], "times_s": [0, 4],
                  "target": "vehicle", "transient_s": 1.0, "settle_tolerance_m": 0.02}},
        True,
    ),
    ("lbv150_ee_circle.toml", {"task": {"type": "hold", "target": "vehicle"}}, True),
    ("two_robots.toml", {}),
    ("push_object.toml", {"world.objects": [_HELD_BALL]}),
    (
        "estimator_station_keeping.toml",
        {"estimator.draw_initial_error": False, "estimator.gyro_noise_rad_s_rthz": 1e-3,
         "estimator.gyro_bias_walk_rad_s2_rthz": 1e-5, "estimator.accel_noise_m_s2_rthz": 1e-2,
         "estimator.accel_bias_walk_m_s3_rthz": 1e-4, "estimator.dvl_noise_m_s": 0.02,
         "estimator.depth_noise_m": 0.02, "estimator.usbl_noise_m": 0.2},
    ),
]  # fmt: skip
# (file, overrides[, True: the dict's tables replace the file's whole tables instead])

_READERS = (
    "number",
    "optional_number",
    "integer",
    "string",
    "boolean",
    "vector",
    "table",
    "tables",
    "has",
    "pop_raw",
)


def scenario_keys_read() -> set[str]:
    """Every dotted key the scenario reader asks for while loading the variants
    (``actuation.thruster[i].name`` for entries of an array of tables)."""
    seen: set[str] = set()
    table_class = Table
    originals = {name: getattr(table_class, name) for name in _READERS}

    def recording(name):
        original = originals[name]

        def method(self, key, *args, **kwargs):
            where = re.sub(r"\[\d+\]", "[i]", self.where)
            seen.add(f"{where}.{key}" if where else key)
            return original(self, key, *args, **kwargs)

        return method

    with pytest.MonkeyPatch.context() as patch:
        for name in _READERS:
            patch.setattr(table_class, name, recording(name))
        for file, overrides, *replace in _VARIANTS:
            if replace:
                raw = {**read_toml(SCENARIOS / file, ScenarioError), **overrides}
                scenario_from_dict(raw, SCENARIOS / file)
            else:
                load_scenario(SCENARIOS / file, overrides)
    return seen


def _documented_rows(text: str) -> set[str]:
    """Keys in the first column of the Markdown tables: ``| `key` | ...``."""
    return set(re.findall(r"^\| `([\w.\[\]]+)` \|", text, flags=re.MULTILINE))


def test_every_scenario_key_the_reader_accepts_is_documented():
    text = (DOCS / "scenarios.md").read_text()
    keys = scenario_keys_read()
    assert len(keys) > 60  # the variants reach every table and key
    missing = sorted(k for k in keys if f"`{k}`" not in text and f"`[{k}]`" not in text)
    assert not missing, f"docs/scenarios.md does not document: {missing}"


def test_scenarios_doc_lists_no_key_the_reader_does_not_know():
    rows = _documented_rows((DOCS / "scenarios.md").read_text())
    assert rows, "no key table found in docs/scenarios.md"
    unknown = sorted(rows - scenario_keys_read())
    assert not unknown, f"docs/scenarios.md documents keys the reader never reads: {unknown}"


def test_studies_doc_names_every_factor_distribution_and_mode():
    from uvms_pin.apps.study.spec import APPLY_MODES, DISTRIBUTIONS, PLANT_FACTORS, PLANT_PREFIX

    text = (DOCS / "studies.md").read_text()
    names = [PLANT_PREFIX + f for f in PLANT_FACTORS] + list(DISTRIBUTIONS) + list(APPLY_MODES)
    assert not [n for n in names if f"`{n}`" not in text and f'"{n}"' not in text]


# ---- the repository is self-contained --------------------------------------------------

# built from pieces so that this file does not match itself
_OUTSIDE = re.compile("|".join(re.escape(p) for p in ("../" + "shared", "DESIGN" + ".md", "/work/" + "shared")))  # fmt: skip
_TEXT_SUFFIXES = {".md", ".py", ".toml", ".ipynb", ".urdf", ".txt", ".cfg", ".yml", ".yaml"}


def _repository_text_files() -> list[Path]:
    skip = {".git", ".venv", "out", "build", "node_modules", "__pycache__"}
    files = []
    for path in ROOT.rglob("*"):
        parts = set(path.relative_to(ROOT).parts)
        if path.is_file() and path.suffix in _TEXT_SUFFIXES and not parts & skip:
            if not any(p.endswith(".egg-info") for p in parts):
                files.append(path)
    files.append(ROOT / "Makefile")
    return files


def test_nothing_points_to_notes_outside_the_repository():
    hits = []
    for path in _repository_text_files():
        for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if _OUTSIDE.search(line):
                hits.append(f"{path.relative_to(ROOT)}:{number}: {line.strip()}")
    assert not hits, "point to docs/ instead:\n" + "\n".join(hits)


def _anchors(markdown: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces -> hyphens."""
    headings = re.findall(r"^#+ (.+)$", markdown.read_text(), flags=re.MULTILINE)
    return {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-") for h in headings}


def test_relative_links_in_the_docs_resolve():
    broken = []
    for doc in [ROOT / "README.md", *sorted(DOCS.glob("*.md"))]:
        links = re.findall(r"\]\(([^)#\s]+)(?:#([^)]*))?\)", doc.read_text())
        for target, anchor in links:
            path = doc.parent / target
            if "://" in target:
                continue
            if not path.exists():
                broken.append(f"{doc.relative_to(ROOT)} -> {target}")
            elif anchor and anchor not in _anchors(path):
                broken.append(f"{doc.relative_to(ROOT)} -> {target}#{anchor}")
    assert not broken, broken
