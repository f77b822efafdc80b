"""The repository documents itself: docs/ covers every scenario key, and nothing points
outside the repository."""

from __future__ import annotations

import dataclasses
import inspect
import re
from functools import cache
from pathlib import Path

import numpy as np
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


#: the readers that take a ``default`` (the value a key absent from the file takes)
_DEFAULTED = ("number", "integer", "string", "boolean", "vector", "seed")


@cache
def scenario_reads() -> dict[str, set]:
    """Every dotted key the scenario reader asks for while loading the variants
    (``actuation.thruster[i].name`` for entries of an array of tables), with the defaults it
    was read with (None: required; none recorded for a reader that takes no default)."""
    seen: dict[str, set] = {}
    table_class = Table
    originals = {name: getattr(table_class, name) for name in (*_READERS, "seed")}

    def recording(name):
        original = originals[name]
        signature = inspect.signature(original)

        def method(self, key, *args, **kwargs):
            where = re.sub(r"\[\d+\]", "[i]", self.where)
            defaults = seen.setdefault(f"{where}.{key}" if where else key, set())
            if name in _DEFAULTED:
                default = signature.bind(self, key, *args, **kwargs).arguments.get("default")
                defaults.add(_hashable(default))
            return original(self, key, *args, **kwargs)

        return method

    with pytest.MonkeyPatch.context() as patch:
        for name in originals:
            patch.setattr(table_class, name, recording(name))
        for file, overrides, *replace in _VARIANTS:
            if replace:
                raw = {**read_toml(SCENARIOS / file, ScenarioError), **overrides}
                scenario_from_dict(raw, SCENARIOS / file)
            else:
                load_scenario(SCENARIOS / file, overrides)
    return seen


def _hashable(value):
    """A default as a set holds it: a vector as a tuple of floats."""
    if isinstance(value, (list, tuple, np.ndarray)):
        return tuple(float(v) for v in value)
    return value


def scenario_keys_read() -> set[str]:
    """Every dotted key the scenario reader asks for while loading the variants."""
    return set(scenario_reads())


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


def _literal(text: str):
    """A table's default as a value (a number, true/false, "a string", [numbers]); None
    for a default said in words ("the model's", "none", ...)."""
    text = text.strip()
    if re.fullmatch(r"-?\d+(\.\d*)?(e-?\d+)?", text):
        return float(text)
    if text in ("true", "false"):
        return text == "true"
    if re.fullmatch(r'"[^"<>]*"', text):  # not "thruster<i>": a pattern
        return text[1:-1]
    if re.fullmatch(r"\[[-\d., e]+\]", text):
        return tuple(float(v) for v in text[1:-1].split(","))
    return None


def _table_rows(text: str) -> list[tuple[str, str, str, str]]:
    """(section, key, its default, its meaning) of each row ``| `key` | type | default |
    meaning |`` under its ``## section``; a row of several keys, ``| `a`, `b` | ... | 1.0,
    0.1 | ... |``, gives each its own default when the counts agree, else "" (unread)."""
    found, section = [], ""
    for line in text.splitlines():
        if line.startswith("## "):
            section = line[3:].strip()
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("| `") or len(cells) < 4:
            continue
        keys = re.findall(r"`([\w.\[\]]+)`", cells[0])
        values = cells[2].split(", ") if len(keys) > 1 else [cells[2]]
        if len(values) != len(keys):
            values = [""] * len(keys)
        meaning = "|".join(cells[3:])
        found += [(section, k, v, meaning) for k, v in zip(keys, values, strict=True)]
    return found


def _controller_parameter_defaults() -> dict[str, set]:
    """``controller.<name>`` -> the defaults of the controllers' parameters (their records'
    fields, their constructors' keywords: the PPC's, the baselines', the tracking laws'),
    which a ``[controller]`` table fills."""
    import importlib
    import pkgutil

    import uvms_pin.control as control

    out: dict[str, set] = {}
    for info in pkgutil.walk_packages(control.__path__, "uvms_pin.control."):
        for value in vars(importlib.import_module(info.name)).values():
            if not isinstance(value, type) or value.__module__ != info.name:
                continue  # a class the module imports is read where it is defined
            factories = (
                {f.name: f.default_factory for f in dataclasses.fields(value)}
                if dataclasses.is_dataclass(value)
                else {}
            )
            for name, parameter in inspect.signature(value.__init__).parameters.items():
                factory = factories.get(name, dataclasses.MISSING)
                # a field's default_factory: what it makes
                default = parameter.default if factory is dataclasses.MISSING else factory()
                if default is inspect.Parameter.empty or default is None:
                    continue
                if isinstance(default, dict):
                    continue  # a table of values: no key's literal default
                out.setdefault(f"controller.{name}", set()).add(_hashable(default))
    return out


def _said_defaults(rows: list[tuple[str, str, str]]) -> dict[str, list]:
    """Each key's documented defaults: its row's default column, and "default N" in its
    meaning or "`key` default N" in another row's (a key read by several controllers)."""
    said: dict[str, list] = {}
    for key, text, meaning in rows:
        short = re.escape(key.rsplit(".", 1)[-1])
        mentions = re.findall(rf"(?:^|[^`\w]|`{short}` )default (-?\d+(?:\.\d+)?)", meaning)
        for other, _, elsewhere in rows:  # "`k_zeta` default 10" in another key's row
            if other != key:
                mentions += re.findall(rf"`{short}` default (-?\d+(?:\.\d+)?)", elsewhere)
        said.setdefault(key, []).extend(
            v for v in (_literal(text), *map(float, mentions)) if v is not None
        )
    return said


def test_every_default_docs_scenarios_gives_is_the_one_the_reader_takes():
    """A key absent from the file takes the default its row says. Each literal default in
    docs/scenarios.md is one the code gives the key (the reader's, or the controller's that
    the ``[controller]`` table fills); each default the reader gives is one the key's rows
    say (their default column, or "default N" in their meaning, as a key read by several
    controllers is documented); a key said to be "required" is read without one."""
    reads, records = scenario_reads(), _controller_parameter_defaults()
    rows = [row[1:] for row in _table_rows((DOCS / "scenarios.md").read_text())]
    said = _said_defaults(rows)
    checked, wrong = 0, []
    for key, text, _ in rows:
        read = {d for d in reads.get(key, ()) if d is not None}
        if text == "required":
            if read and None not in reads[key]:
                wrong.append(f"{key}: documented as required, read with default {read}")
            continue
        documented, given = _literal(text), read | records.get(key, set())
        if documented is not None and given:
            checked += 1
            if not any(_same_default(documented, d) for d in given):
                wrong.append(
                    f"{key}: documented default {text}, the code's {sorted(given, key=str)}"
                )
    for key, values in said.items():
        if not values:
            continue  # said in words ("the model's", "the file name")
        for default in {d for d in reads.get(key, ()) if d is not None}:
            checked += 1
            if not any(_same_default(v, default) for v in values):
                wrong.append(f"{key}: the reader's default {default}, documented {values}")
    assert checked >= 200, f"only {checked} documented defaults compared"
    assert not wrong, "docs/scenarios.md and the code disagree:\n" + "\n".join(wrong)


def _same_default(documented, read) -> bool:
    if isinstance(documented, bool) or isinstance(read, bool):
        return documented is read
    if isinstance(documented, str) or isinstance(read, str):
        return documented == read
    if isinstance(documented, float) and isinstance(read, tuple):
        documented = (documented,) * len(read)  # one number for every entry of a vector
    if isinstance(documented, tuple) != isinstance(read, tuple):
        return False
    documented, read = np.atleast_1d(documented), np.atleast_1d(read)
    # the table's digits: pi / 6 is documented as 0.5236
    return documented.shape == read.shape and np.allclose(documented, read, rtol=1e-4, atol=0)


#: a controller's parameter named as a documented key that the key does not set (it is read
#: for other controllers): (key, the parameter's default) -> whose it is
_NAMED_AS_A_KEY = {
    ("controller.damping", 0.001): "the task-priority law's damped pseudo-inverse "
    "(`TaskPrioritySpec.damping`, the scenario's pinv_damping)",
    ("controller.position_gain_per_s2", 25.0): "computed torque's motion task "
    "(`InnerLoopGains`, built in Python only)",
}


def test_every_controllers_default_for_a_documented_key_is_a_documented_one():
    """What a ``[controller]`` table without the key gives is the controller's own default:
    each controller's (every class of uvms_pin.control, constructor keywords and record
    fields) default for a documented key is one of the defaults the docs give it, not only
    some controller's; the few parameters that share a key's name without being what it
    sets are named (`_NAMED_AS_A_KEY`)."""
    said = _said_defaults([row[1:] for row in _table_rows((DOCS / "scenarios.md").read_text())])
    checked, wrong = 0, []
    for key, defaults in _controller_parameter_defaults().items():
        values = said.get(key)
        if not values:
            continue  # not a documented key, or its default said in words
        for default in defaults:
            if (key, default) in _NAMED_AS_A_KEY:
                continue
            checked += 1
            if not any(_same_default(v, default) for v in values):
                wrong.append(f"{key}: a controller's default {default}, documented {values}")
    assert checked >= 40, f"only {checked} controller defaults compared"
    assert not wrong, "docs/scenarios.md and the controllers disagree:\n" + "\n".join(wrong)


def _agrees(default, text: str) -> bool | None:
    """Whether a field's ``default`` is the documented ``text`` (a bare word for a string
    field; `_same_default` otherwise); None when the text says it in words."""
    if isinstance(default, str):
        return text.strip() == default
    documented = _literal(text)
    if documented is None or not isinstance(default, (bool, int, float, tuple)):
        return None
    return _same_default(documented, _hashable(default))


def test_the_sensor_tables_in_docs_sensors_give_the_specs_defaults():
    """docs/sensors.md's camera, sonar and light keys: each is a field of its spec, and each
    default said as a value is the field's default."""
    from dataclasses import MISSING, fields

    from uvms_pin.perception.camera import CameraSpec
    from uvms_pin.perception.optics import Light
    from uvms_pin.perception.sonar import SonarSpec

    defaults = {
        spec: {f.name: f.default for f in fields(spec) if f.default is not MISSING}
        for spec in (CameraSpec, SonarSpec, Light)
    }
    rows = _table_rows((DOCS / "sensors.md").read_text())
    checked, wrong = 0, []

    def compare(spec, key: str, text: str) -> None:
        nonlocal checked
        if key not in {f.name for f in fields(spec)}:
            wrong.append(f"{spec.__name__}: documented key {key} is not a field")
            return
        verdict = _agrees(defaults[spec].get(key), text)
        checked += verdict is not None
        if verdict is False:
            wrong.append(f"{spec.__name__}.{key}: documented {text}, {defaults[spec][key]!r}")

    for section, spec in (("Camera", CameraSpec), ("Sonar", SonarSpec)):
        table = [row[1:] for row in rows if row[0] == section]
        assert table, f"no key table under '## {section}'"
        for key, default, meaning in table:
            compare(spec, key, default)
            if key == "lights":  # the lights' keys, their defaults in parentheses
                for light_key, text in re.findall(r"`(\w+)` \(([-\d.]+)\)", meaning):
                    compare(Light, light_key, text)
    assert checked >= 25, f"only {checked} documented defaults compared"
    assert not wrong, "docs/sensors.md and the specs disagree:\n" + "\n".join(wrong)


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
