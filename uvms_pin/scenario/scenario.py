"""Scenario files (TOML) -> the objects of one run; ``simulate(scenario)`` runs it.

A scenario is read in two stages: the TOML becomes a plain dict (on which dotted
``overrides`` such as ``{"environment.stiffness_N_m": [20, 20, 20]}`` or
``{"initial.joint_positions_rad[3]": 0.5}`` are applied, see `uvms_pin.scenario.overrides`; that is
how ``uvms-pin run --set``, sweeps and robustness tables vary it), then every table is
checked and turned into objects. Unknown keys, wrong types and bad values raise
`ScenarioError` naming the file and the key, or the override when an override set it, with
the closest known key. ``model`` is a path relative to the scenario file or the name of a
shipped model (``"uvms_lbv150"``, ``"lbv150"``). See ``scenarios/*.toml`` for documented
examples.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.control.base import Controller, ZeroController
from uvms_pin.control.ppc import PPCParams, PrescribedPerformanceController
from uvms_pin.errors import ParameterError, ScenarioError, UvmsPinError
from uvms_pin.flow import (
    AiryWave,
    DepthProfileCurrent,
    FlowField,
    GaussMarkovCurrent,
    IrregularSea,
    SumFlow,
    UniformCurrent,
)
from uvms_pin.model.resources import find_model, shipped_models
from uvms_pin.model.thruster import Thruster
from uvms_pin.model.urdf.load import load_uvms
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled import BACKENDS
from uvms_pin.physics.environment import (
    CompliantPlane,
    ContactModel,
    LinearSpring,
    SinusoidalDisturbance,
)
from uvms_pin.results.progress import ProgressBar, callback_or_none
from uvms_pin.results.rollout import Rollout
from uvms_pin.scenario.custom_controller import ControllerSpec, class_path, custom_controller
from uvms_pin.scenario.overrides import apply_overrides, closest, parse_key_path
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.actuation import Actuation, ThrustersAndJointLimits, Unlimited
from uvms_pin.sim.closed_loop import (
    DIVERGED_SPEED,
    Progress,
    SimulationSettings,
    check_log_fits,
    simulate_closed_loop,
)
from uvms_pin.sim.integrators import RK4, Adaptive, Integrator, SemiImplicitEuler
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sensors import NoiseSpec, SensorConfig, SensorSuite

ControllerFactory = Callable[[UVMS], Controller]

__all__ = ["Scenario", "apply_overrides", "load_scenario", "simulate"]


class _Table:
    """One TOML table, read key by key; leftovers are reported as unknown keys.

    ``overridden`` maps each overridden dotted key (without index) to the override's text,
    so an error about a value an override set names the override instead of the file.
    """

    def __init__(
        self, data: Any, where: str, source: str, overridden: dict[str, str] | None = None
    ):
        if not isinstance(data, dict):
            raise ScenarioError(f"{source}: [{where}] must be a table, got {type(data).__name__}")
        self._data = dict(data)
        self._where = where
        self._source = source
        self._overridden = overridden or {}
        self._asked: set[str] = set()  # every key the reader knows, for suggestions

    def _full(self, key: str) -> str:
        return f"{self._where}.{key}" if self._where else key

    def _err(self, key: str, msg: str) -> ScenarioError:
        where = self._full(key)
        if where in self._overridden:
            return ScenarioError(f"override '{self._overridden[where]}': {msg}")
        return ScenarioError(f"{self._source}: {where}: {msg}")

    def has(self, key: str) -> bool:
        self._asked.add(key)
        return key in self._data

    def number(
        self,
        key: str,
        default: float | None = None,
        *,
        positive: bool = False,
        nonneg: bool = False,
    ) -> float:
        self._asked.add(key)
        if key not in self._data:
            if default is None:
                raise self._err(key, "is required")
            return float(default)
        value = self._data.pop(key)
        if (
            isinstance(value, bool)
            or not isinstance(value, int | float)
            or not math.isfinite(value)
        ):
            raise self._err(key, f"must be a finite number, got {value!r}")
        if positive and value <= 0:
            raise self._err(key, f"must be positive, got {value}")
        if nonneg and value < 0:
            raise self._err(key, f"must be >= 0, got {value}")
        return float(value)

    def optional_number(self, key: str, **kw) -> float | None:
        return self.number(key, **kw) if key in self._data else None

    def integer(self, key: str, default: int) -> int:
        self._asked.add(key)
        value = self._data.pop(key, default)
        if isinstance(value, bool) or not isinstance(value, int):
            raise self._err(key, f"must be an integer, got {value!r}")
        return value

    def string(
        self, key: str, default: str | None = None, choices: tuple[str, ...] | None = None
    ) -> str:
        self._asked.add(key)
        if key not in self._data:
            if default is None:
                raise self._err(key, "is required")
            return default
        value = self._data.pop(key)
        if not isinstance(value, str):
            raise self._err(key, f"must be a string, got {value!r}")
        if choices is not None and value not in choices:
            raise self._err(key, f"must be one of {', '.join(choices)}, got '{value}'")
        return value

    def vector(
        self, key: str, size: int | None, default=None, *, nonneg: bool = False
    ) -> np.ndarray:
        self._asked.add(key)
        if key not in self._data:
            if default is None:
                raise self._err(key, "is required")
            return np.array(default, dtype=float)
        value = self._data.pop(key)
        if isinstance(value, int | float) and not isinstance(value, bool) and size is not None:
            value = [value] * size
        if not isinstance(value, list) or not all(
            isinstance(x, int | float) and not isinstance(x, bool) for x in value
        ):
            raise self._err(key, f"must be a list of numbers, got {value!r}")
        arr = np.array(value, dtype=float)
        if size is not None and arr.size != size:
            raise self._err(key, f"needs {size} numbers, got {arr.size}")
        if not np.all(np.isfinite(arr)):
            raise self._err(key, "has a non-finite value")
        if nonneg and np.any(arr < 0):
            raise self._err(key, f"must be >= 0, got {arr.tolist()}")
        return arr

    def table(self, key: str) -> _Table | None:
        self._asked.add(key)
        if key not in self._data:
            return None
        return _Table(self._data.pop(key), self._full(key), self._source, self._overridden)

    def pop_raw(self, key: str, default: Any = None) -> Any:
        self._asked.add(key)
        return self._data.pop(key, default)

    def rest(self) -> dict[str, Any]:
        """Every key not read yet (and the table is then finished)."""
        out, self._data = self._data, {}
        return out

    def finish(self) -> None:
        """ScenarioError for keys nobody read, naming the override that set one if any,
        with the closest known key."""
        if not self._data:
            return
        unknown = sorted(self._data)
        known = self._asked - set(unknown)
        for key in unknown:
            full = self._full(key)
            for dotted, text in self._overridden.items():
                if dotted == full or dotted.startswith(full + "."):
                    hint = closest(key, known)
                    fixed = (self._full(hint) + text[len(full) :]) if hint else None
                    raise ScenarioError(
                        f"override '{text}': unknown key '{full}'"
                        + (f"; did you mean '{fixed}'?" if fixed else "")
                    )
        hints = [f"'{k}' -> '{closest(k, known)}'" for k in unknown if closest(k, known)]
        raise ScenarioError(
            f"{self._source}: [{self._where}] has unknown key(s): {', '.join(unknown)}"
            + (f" (did you mean {', '.join(hints)}?)" if hints else "")
        )


@dataclass
class Scenario:
    """Everything one run needs, built from a scenario file.

    Attributes:
        name, description: from [scenario].
        path: the file it came from. raw: the dict after overrides (recorded in rollouts).
        plant: UVMS + water + environment + disturbance.
        controller_factory: builds a fresh controller for the plant's UVMS (a
            `ControllerSpec` for the [controller] table: its type and parameters are
            recorded in the rollout with the class that actually ran).
        sensor_config: noise of the measurements.
        q0, v0: initial state. settings: integrator, periods, duration, seed.
    """

    name: str
    description: str
    path: Path
    raw: dict[str, Any]
    plant: Plant
    controller_factory: ControllerFactory
    sensor_config: SensorConfig
    q0: np.ndarray
    v0: np.ndarray
    settings: SimulationSettings

    @property
    def uvms(self) -> UVMS:
        return self.plant.uvms


def load_scenario(path: str | Path, overrides: dict[str, Any] | None = None) -> Scenario:
    """Read a scenario TOML file, apply dotted overrides and build the objects.

    Args:
        path: the scenario file.
        overrides: dotted key (optionally ``[i]``-indexed) -> value, e.g.
            ``{"environment.stiffness_N_m": [20, 20, 20], "initial.joint_positions_rad[3]":
            0.5}`` (`uvms_pin.scenario.overrides`).

    Raises:
        ScenarioError: naming the file and the key, or the override that set a bad value.
    """
    path = Path(path)
    return scenario_from_raw(read_toml(path, ScenarioError), path, overrides)


def scenario_from_raw(
    raw: dict[str, Any], path: str | Path, overrides: dict[str, Any] | None = None
) -> Scenario:
    """`load_scenario` of an already-read document ``raw`` (as if read from ``path``:
    relative model paths and custom controllers resolve next to it)."""
    path = Path(path)
    source = str(path)
    raw = apply_overrides(raw, overrides)
    overridden = {parse_key_path(text).key: text for text in overrides or {}}
    try:
        return _build(raw, path, source, overridden)
    except ScenarioError:
        raise
    except UvmsPinError as exc:
        raise ScenarioError(f"{source}: {exc}") from exc


def _build(raw: dict[str, Any], path: Path, source: str, overridden: dict[str, str]) -> Scenario:
    top = _Table(raw, "", source, overridden)
    head = top.table("scenario") or _Table({}, "scenario", source)
    name = head.string("name", path.stem)
    description = head.string("description", "")
    model_entry = head.string("model")
    duration = head.number("duration_s", positive=True)
    seed = head.integer("seed", 0)
    head.finish()

    water = top.table("water") or _Table({}, "water", source)
    density = water.number("density_kg_m3", 1025.0, positive=True)
    current = water.vector("current_world_m_s", 3, [0.0, 0.0, 0.0])
    flow = _water_flow(water, seed)
    water.finish()

    model_path = find_model(model_entry, path.parent)
    if model_path is None:
        raise head._err(
            "model",
            f"'{model_entry}' is neither a file relative to the scenario "
            f"({path.parent.resolve() / model_entry}) nor a shipped model "
            f"({', '.join(shipped_models())})",
        )
    uvms = load_uvms(model_path, water_density_kg_m3=density)

    q0, v0 = _initial_state(top.table("initial") or _Table({}, "initial", source), uvms)
    contact = _environment(top.table("environment"), uvms)
    disturbance = _disturbance(top.table("disturbance"))
    actuation = _actuation(top.table("actuation"), uvms)
    sensor_config = _sensors(top.table("sensors") or _Table({}, "sensors", source))
    integrator, backend = _integrator(top.table("integrator") or _Table({}, "integrator", source))
    plant = Plant(uvms, current, contact, disturbance, actuation, flow=flow, backend=backend)

    control = top.table("control") or _Table({}, "control", source)
    control_period = control.optional_number("period_s", positive=True)
    control.finish()
    output = top.table("output") or _Table({}, "output", source)
    log_period = output.number("log_period_s", 0.01, positive=True)
    output.finish()

    controller_table = top.table("controller")
    controller_factory = _controller(controller_table, uvms, path.parent)
    # [baselines.<kind>]: tunings for `compare-controllers`, which builds (and so checks)
    # each one before any run; here only their names (a model with another arm, e.g. in
    # compare-arms, must not be refused for a comparison it is not running)
    baselines = top.table("baselines")
    for kind in baselines.rest() if baselines is not None else {}:
        if kind not in BASELINE_KINDS or (raw.get("controller") or {}).get("type") == kind:
            raise ScenarioError(
                f"{source}: [baselines.{kind}]: a baseline is one of "
                f"{', '.join(BASELINE_KINDS)} other than the scenario's [controller] type"
            )
    top.finish()
    try:
        settings = SimulationSettings(duration, integrator, log_period, control_period, seed)
        check_log_fits(settings, uvms.nq, uvms.nv)
    except ParameterError as exc:
        raise ScenarioError(f"{source}: {exc}") from exc
    return Scenario(
        name, description, path, raw, plant, controller_factory, sensor_config, q0, v0, settings
    )


def _initial_state(t: _Table, uvms: UVMS) -> tuple[np.ndarray, np.ndarray]:
    n_arm = uvms.n_arm_joints
    position = t.vector("position_world_m", 3, [0.0, 0.0, 0.0])
    rpy = t.vector("rpy_rad", 3, [0.0, 0.0, 0.0])
    joints = t.vector("joint_positions_rad", n_arm, uvms.neutral_configuration()[7:])
    velocity = t.vector("velocity", uvms.nv, np.zeros(uvms.nv))
    t.finish()
    if np.max(np.abs(velocity)) >= DIVERGED_SPEED:
        raise t._err(
            "velocity",
            f"{np.max(np.abs(velocity)):g} is not a physical speed (the simulator treats "
            f"|v| >= {DIVERGED_SPEED:g} m/s or rad/s as diverged)",
        )
    lo, hi = uvms.model.lowerPositionLimit[7:], uvms.model.upperPositionLimit[7:]
    outside = (joints < lo) | (joints > hi)
    if np.any(outside):
        names = [n for n, o in zip(uvms.arm_joint_names, outside, strict=True) if o]
        raise t._err("joint_positions_rad", f"outside the joint limits for {', '.join(names)}")
    q0 = np.empty(uvms.nq)
    q0[:3] = position
    q0[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
    q0[7:] = joints
    return q0, velocity


def water_flow_of(parameters: dict[str, Any], source: str = "<parameters>") -> FlowField | None:
    """The whole flow of a scenario's raw parameters (e.g. a rollout's
    ``metadata['parameters']``): the uniform current plus [water.current/waves/sea]."""
    water = _Table(copy.deepcopy(parameters.get("water", {})), "water", source)
    water.pop_raw("density_kg_m3")
    current = water.vector("current_world_m_s", 3, [0.0, 0.0, 0.0])
    seed = (parameters.get("scenario") or {}).get("seed", 0)
    flow = _water_flow(water, seed)
    water.finish()
    fields = [UniformCurrent(current)] if np.any(current) else []
    fields += [flow] if flow is not None else []
    if not fields:
        return None
    return fields[0] if len(fields) == 1 else SumFlow(tuple(fields))


def _water_flow(water: _Table, seed: int) -> FlowField | None:
    """[water.current], [water.waves] and [water.sea]: the flow beyond the uniform
    ``current_world_m_s``, summed. Seeds default to the scenario's seed."""
    fields: list[FlowField] = []
    current = water.table("current")
    if current is not None:
        fields.append(_current_field(current, seed))
    waves = water.table("waves")
    if waves is not None:
        fields.append(
            _flow_field(
                waves,
                lambda: AiryWave(
                    amplitude_m=waves.number("amplitude_m", nonneg=True),
                    period_s=waves.number("period_s", positive=True),
                    heading_rad=waves.number("heading_rad", 0.0),
                    water_depth_m=waves.number("water_depth_m", math.inf, positive=True),
                    phase_rad=waves.number("phase_rad", 0.0),
                ),
            )
        )
    sea = water.table("sea")
    if sea is not None:
        fields.append(
            _flow_field(
                sea,
                lambda: IrregularSea(
                    significant_height_m=sea.number("significant_height_m", nonneg=True),
                    peak_period_s=sea.number("peak_period_s", positive=True),
                    peak_enhancement=sea.number("peak_enhancement", 3.3, positive=True),
                    heading_rad=sea.number("heading_rad", 0.0),
                    spreading_exponent=sea.optional_number("spreading_exponent", positive=True),
                    n_components=sea.integer("n_components", 100),
                    seed=sea.integer("seed", seed),
                    water_depth_m=sea.number("water_depth_m", math.inf, positive=True),
                ),
            )
        )
    if not fields:
        return None
    return fields[0] if len(fields) == 1 else SumFlow(tuple(fields))


def _current_field(t: _Table, seed: int) -> FlowField:
    kind = t.string("type", "uniform", ("uniform", "gauss_markov", "profile"))
    if kind == "uniform":
        return _flow_field(t, lambda: UniformCurrent(t.vector("velocity_world_m_s", 3)))
    if kind == "profile":
        return _flow_field(
            t,
            lambda: DepthProfileCurrent(
                t.vector("velocity_world_m_s", 3),
                t.vector("depths_m", None),
                t.vector("factors", None),
            ),
        )
    return _flow_field(
        t,
        lambda: GaussMarkovCurrent(
            mean_velocity_world_m_s=t.vector("mean_velocity_world_m_s", 3),
            std_m_s=t.number("std_m_s", nonneg=True),
            time_constant_s=t.number("time_constant_s", positive=True),
            bound_m_s=t.number("bound_m_s", positive=True),
            seed=t.integer("seed", seed),
            sample_period_s=t.number("sample_period_s", 0.5, positive=True),
        ),
    )


def _flow_field(t: _Table, build: Callable[[], FlowField]) -> FlowField:
    """Build a flow field from a table; its own ParameterErrors name the table."""
    try:
        field = build()
    except ParameterError as exc:
        raise ScenarioError(f"{t._source}: [{t._where}]: {exc}") from exc
    t.finish()
    return field


def _environment(t: _Table | None, uvms: UVMS) -> ContactModel | None:
    if t is None:
        return None
    uvms.require_ee_frame("[environment] (a contact at the end-effector)")
    kind = t.string("type", choices=("spring", "plane"))
    anchor = t.vector("anchor_world_m", 3) if t.has("anchor_world_m") else None
    if kind == "spring":
        model: ContactModel = LinearSpring(t.vector("stiffness_N_m", 3, nonneg=True), anchor)
    else:
        model = CompliantPlane(
            normal_world=t.vector("normal_world", 3, [-1.0, 0.0, 0.0]),
            stiffness_N_m=t.number("stiffness_N_m", positive=True),
            damping_N_s_m=t.number("damping_N_s_m", 0.0, nonneg=True),
            point_world_m=anchor,
        )
    t.finish()
    return model


def _disturbance(t: _Table | None) -> SinusoidalDisturbance | None:
    if t is None:
        return None
    out = SinusoidalDisturbance(
        amplitude=t.vector("amplitude", 6),
        period_s=t.number("period_s", positive=True),
        phase_rad=t.number("phase_rad", 0.0),
    )
    t.finish()
    return out


def _sensors(t: _Table) -> SensorConfig:
    distribution = t.string("distribution", "uniform", ("uniform", "gaussian"))

    def spec(key: str) -> NoiseSpec:
        return NoiseSpec(t.number(key, 0.0, nonneg=True), distribution)

    config = SensorConfig(
        force_noise=spec("force_noise_N"),
        torque_noise=spec("torque_noise_Nm"),
        position_noise=spec("position_noise_m"),
        orientation_noise=spec("orientation_noise_rad"),
        joint_noise=spec("joint_noise_rad"),
        velocity_noise=spec("velocity_noise"),
        sample_period_s=t.number("sample_period_s", 1e-3, positive=True),
    )
    t.finish()
    return config


def _actuation(t: _Table | None, uvms: UVMS) -> Actuation:
    if t is None:
        return Unlimited()
    limit_joints = t.pop_raw("limit_joint_torques", True)
    if not isinstance(limit_joints, bool):
        raise ScenarioError(f"{t._source}: actuation.limit_joint_torques must be true or false")
    entries = t.pop_raw("thruster", [])
    if not isinstance(entries, list) or not entries:
        raise ScenarioError(f"{t._source}: [actuation] needs at least one [[actuation.thruster]]")
    thrusters = []
    for k, entry in enumerate(entries):
        e = _Table(entry, f"actuation.thruster[{k}]", t._source)
        thrusters.append(
            Thruster(
                name=e.string("name", f"thruster{k}"),
                position_body_m=e.vector("position_body_m", 3),
                direction_body=e.vector("direction_body", 3),
                max_forward_N=e.number("max_forward_N", nonneg=True),
                max_reverse_N=e.number("max_reverse_N", nonneg=True),
            )
        )
        e.finish()
    components = t.vector("allocated_components", None, [0, 1, 2, 3, 4, 5])
    t.finish()
    limits = uvms.model.effortLimit[6:].copy() if limit_joints else None
    try:
        return ThrustersAndJointLimits(thrusters, limits, components.astype(int).tolist())
    except ParameterError as exc:
        raise ScenarioError(f"{t._source}: [actuation]: {exc}") from exc


_FIXED_STEP = {"rk4": RK4, "semi_implicit_euler": SemiImplicitEuler}


def _integrator(t: _Table) -> tuple[Integrator, str]:
    """The integrator and the plant's backend ("core": compiled, "python": the reference)."""
    backend = t.string("backend", "core", BACKENDS)
    method = t.string("method", "rk4", (*_FIXED_STEP, *Adaptive._METHODS))
    if method in _FIXED_STEP:
        out = _FIXED_STEP[method](t.number("step_s", 1e-3, positive=True))
    else:
        out = Adaptive(
            method,
            rtol=t.number("rtol", 1e-6, positive=True),
            atol=t.number("atol", 1e-8, positive=True),
            max_step_s=t.number("max_step_s", math.inf, positive=True),
        )
    t.finish()
    return out, backend


def _controller(t: _Table | None, uvms: UVMS, scenario_dir: Path) -> ControllerSpec:
    """[controller]: "none", "ppc", a baseline ("pi_force", "impedance", "computed_torque")
    or "package.module:ClassName" (`uvms_pin.scenario.custom_controller`)."""
    if t is None:
        return ControllerSpec("none", {}, _zero)
    kind = t.string("type")
    if ":" in kind:
        params = t.rest()
        try:
            spec = custom_controller(kind, params, scenario_dir)
            spec(uvms)  # built once now, so a bad parameter is found before the run
        except ParameterError as exc:
            raise ScenarioError(f"{t._source}: [controller]: {exc}") from exc
        return spec
    if kind not in _CONTROLLER_BUILDERS:
        choices = ", ".join(_CONTROLLER_BUILDERS)
        raise t._err(
            "type", f"must be one of {choices} or 'package.module:ClassName', got '{kind}'"
        )
    return _CONTROLLER_BUILDERS[kind](t, uvms)


#: Controllers whose tuning a scenario may carry in [baselines.<kind>] for comparisons.
BASELINE_KINDS = ("pi_force", "impedance", "computed_torque")
#: Keys of a PPC [controller] table a baseline of the same task inherits (the same task,
#: and for the J^# baselines the same pseudo-inverse and null-space pull).
_TASK_KEYS = ("ee_frame", "desired_rpy", "desired_force")
_PSEUDO_INVERSE_INHERITED = ("velocity_weights", "null_space_gain_per_s", "null_space_target")


def baseline_controller_table(raw: dict[str, Any], kind: str) -> dict[str, Any]:
    """The [controller] table that runs the scenario ``raw``'s task with controller ``kind``.

    The scenario's own [controller] when its type is ``kind``; else a baseline's table: the
    task (``ee_frame``, ``desired_rpy``, ``desired_force``; for "pi_force" and
    "computed_torque" also the PPC's ``velocity_weights`` and null-space keys) taken from
    [controller], then the gains of ``[baselines.<kind>]`` (defaults if absent).

    Raises:
        ScenarioError: ``kind`` is not the scenario's controller nor a baseline.
    """
    controller = raw.get("controller") or {}
    if controller.get("type") == kind:
        return copy.deepcopy(controller)
    if kind not in BASELINE_KINDS:
        choices = ", ".join((controller.get("type", "none"), *BASELINE_KINDS))
        raise ScenarioError(f"controller '{kind}': this scenario can run {choices}")
    inherited = _TASK_KEYS + (_PSEUDO_INVERSE_INHERITED if kind != "impedance" else ())
    table = {"type": kind, **{k: controller[k] for k in inherited if k in controller}}
    tuning = (raw.get("baselines") or {}).get(kind) or {}
    if not isinstance(tuning, dict):
        raise ScenarioError(f"[baselines.{kind}] must be a table, got {tuning!r}")
    return copy.deepcopy({**table, **tuning})


def _zero(uvms: UVMS) -> Controller:
    return ZeroController(uvms.nv)


def _zero_controller(t: _Table, uvms: UVMS) -> ControllerSpec:
    t.finish()
    return ControllerSpec("none", {}, _zero)


def _sine_profile(t: _Table | None, size: int) -> Callable[[float], np.ndarray]:
    """offset + amplitude sin(2 pi t / period + phase), component-wise."""
    if t is None:
        zero = np.zeros(size)
        return lambda time_s: zero
    offset = t.vector("offset", size, np.zeros(size))
    amplitude = t.vector("amplitude", size, np.zeros(size))
    period = t.number("period_s", 1.0, positive=True)
    phase = t.number("phase_rad", 0.0)
    t.finish()
    omega = 2.0 * math.pi / period
    return lambda time_s: offset + amplitude * math.sin(omega * time_s + phase)


_PPC_FIRST_LEVEL_KEYS = ("k_x", "rho0_x", "rho_inf_x", "l_x_per_s")  # 6 components
_PPC_SECOND_LEVEL_KEYS = ("k_zeta", "rho0_zeta", "rho_inf_zeta", "l_zeta_per_s", "velocity_weights")


def _ppc_controller(t: _Table, uvms: UVMS) -> ControllerSpec:
    """[controller] type = "ppc": the paper's law; omitted keys keep the paper's values."""
    if t.has("ee_frame"):
        ee_frame = t.string("ee_frame")
    else:
        ee_id = uvms.require_ee_frame("[controller] type = 'ppc'")
        ee_frame = uvms.model.frames[ee_id].name
    fields: dict[str, Any] = {}
    for keys, size in ((_PPC_FIRST_LEVEL_KEYS, 6), (_PPC_SECOND_LEVEL_KEYS, uvms.nv)):
        for key in keys:
            if t.has(key):
                fields[key] = t.vector(key, size)
    for key in ("null_space_gain_per_s", "pinv_relative_cutoff"):
        if t.has(key):
            fields[key] = t.number(key, nonneg=True)
    if t.has("null_space_target"):
        fields["null_space_target"] = t.vector("null_space_target", uvms.n_arm_joints)
    desired_rpy = t.vector("desired_rpy", 3, [0.0, 0.0, 0.0])
    # "core": the compiled law (Python reference on the calls it declines); "python": the reference
    backend = t.string("backend", "core", BACKENDS)
    force_table = t.table("desired_force")
    force_raw = {} if force_table is None else dict(force_table._data)
    desired_force = _sine_profile(force_table, 3)
    t.finish()
    try:
        params = PPCParams(desired_rpy=desired_rpy, **fields).sized(uvms.nv)
        PrescribedPerformanceController(
            uvms.model, ee_frame, params, desired_force, backend=backend
        )
    except ParameterError as exc:
        raise ScenarioError(f"{t._source}: [controller]: {exc}") from exc
    recorded = {
        "ee_frame": ee_frame,
        "desired_force": force_raw,
        "backend": backend,
        **{k: _plain(v) for k, v in dataclasses.asdict(params).items()},
    }
    return ControllerSpec(
        "ppc",
        recorded,
        lambda u: PrescribedPerformanceController(
            u.model, ee_frame, params, desired_force, backend=backend
        ),
    )


def _plain(value: Any) -> Any:
    """numpy arrays and scalars as lists and floats (for the rollout's JSON)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value.item() if isinstance(value, np.generic) else value


def _ee_frame(t: _Table, uvms: UVMS, kind: str) -> str:
    if t.has("ee_frame"):
        return t.string("ee_frame")
    ee_id = uvms.require_ee_frame(f"[controller] type = '{kind}'")
    return uvms.model.frames[ee_id].name


#: The keys of the baseline controllers' tables: name -> size ("nv", "arm" or a number).
_FORCE_LOOP_KEYS = {
    "kp_force_m_s_per_N": 3,
    "ki_force_m_s2_per_N": 3,
    "k_orientation_per_s": 3,
    "integral_limit_Ns": 3,
}
_PSEUDO_INVERSE_KEYS = {"velocity_weights": "nv", "null_space_target": "arm"}
_BASELINE_KEYS: dict[str, dict[str, int | str]] = {
    "pi_force": {**_FORCE_LOOP_KEYS, "damping": "nv", **_PSEUDO_INVERSE_KEYS},
    "impedance": {
        "stiffness_N_m": 3,
        "damping_N_s_m": 3,
        "stiffness_Nm_rad": 3,
        "damping_Nm_s_rad": 3,
        "velocity_damping": "nv",
        "posture_stiffness_Nm_rad": "arm",
    },
    "computed_torque": {**_FORCE_LOOP_KEYS, "velocity_gain_per_s": "nv", **_PSEUDO_INVERSE_KEYS},
}
_MODEL_ERROR_KEYS = ("mass_scale", "added_mass_scale", "damping_scale", "buoyancy_scale")


def _baseline_controller(t: _Table, uvms: UVMS, kind: str) -> ControllerSpec:
    """[controller] type = "pi_force" | "impedance" | "computed_torque" (docs/controllers.md)."""
    from uvms_pin.control.baselines.computed_torque import ComputedTorqueController
    from uvms_pin.control.baselines.impedance import ImpedanceController
    from uvms_pin.control.baselines.pi_force import PIForceController

    ee_frame = _ee_frame(t, uvms, kind)
    sizes = {"nv": uvms.nv, "arm": uvms.n_arm_joints}
    fields: dict[str, Any] = {}
    for key, size in _BASELINE_KEYS[kind].items():
        if t.has(key):
            fields[key] = t.vector(key, sizes.get(size, size))
    if kind != "impedance" and t.has("null_space_gain_per_s"):
        fields["null_space_gain_per_s"] = t.number("null_space_gain_per_s", nonneg=True)
    fields["desired_rpy"] = t.vector("desired_rpy", 3, [0.0, 0.0, 0.0])
    force_table = t.table("desired_force")
    force_raw = {} if force_table is None else dict(force_table._data)
    fields["desired_force_world_N"] = _sine_profile(force_table, 3)
    factors: dict[str, float] = {}
    error_table = t.table("model_error") if kind == "computed_torque" else None
    if error_table is not None:
        factors = {k: error_table.number(k, 1.0, positive=True) for k in _MODEL_ERROR_KEYS}
        error_table.finish()
    t.finish()

    def build(u: UVMS) -> Controller:
        if kind == "computed_torque":
            from uvms_pin.model.scaled import scaled_uvms

            return ComputedTorqueController(scaled_uvms(u, **factors), ee_frame, **fields)
        cls = PIForceController if kind == "pi_force" else ImpedanceController
        return cls(u.model, ee_frame, **fields)

    try:
        build(uvms)
    except ParameterError as exc:
        raise ScenarioError(f"{t._source}: [controller]: {exc}") from exc
    recorded = {
        "ee_frame": ee_frame,
        "desired_force": force_raw,
        "model_error": factors,
        **{k: _plain(v) for k, v in fields.items() if k != "desired_force_world_N"},
    }
    return ControllerSpec(kind, recorded, build)


_CONTROLLER_BUILDERS: dict[str, Callable[[_Table, UVMS], ControllerSpec]] = {
    "none": _zero_controller,
    "ppc": _ppc_controller,
    **{
        kind: functools.partial(_baseline_controller, kind=kind)
        for kind in ("pi_force", "impedance", "computed_torque")
    },
}


def simulate(scenario: Scenario, *, progress: bool | Progress | None = True) -> Rollout:
    """Run a scenario: fresh sensors (seeded) and controller, closed loop, rollout.

    ``progress``: True (default) shows a tqdm bar (notebook widget in Jupyter) once the
    run has lasted `uvms_pin.results.progress.BAR_DELAY_S` of wall time, so short runs print
    nothing; False or None: silent; a callable ``(t_s, duration_s)`` is called after
    every logged sample.

    Raises FunnelViolation / SimulationError with the partial rollout attached as
    ``exc.rollout`` (see `simulate_closed_loop`).
    """
    if progress is True:
        with ProgressBar(scenario.name, scenario.settings.duration_s) as bar:
            return _simulate(scenario, bar)
    return _simulate(scenario, callback_or_none(progress))


def _simulate(scenario: Scenario, progress: Progress | None) -> Rollout:
    settings = scenario.settings
    sensors = SensorSuite(
        scenario.uvms.model, scenario.sensor_config, settings.duration_s, settings.seed
    )
    controller = scenario.controller_factory(scenario.uvms)
    metadata = {
        "scenario": scenario.name,
        "scenario_path": str(scenario.path),
        "description": scenario.description,
        "parameters": scenario.raw,
        "controller": controller_record(scenario.controller_factory, controller),
    }
    return simulate_closed_loop(
        scenario.plant,
        controller,
        sensors,
        scenario.q0,
        scenario.v0,
        settings,
        metadata=metadata,
        progress=progress,
    )


def controller_record(factory: ControllerFactory, controller: Controller) -> dict[str, Any]:
    """What ran: the class of ``controller`` (``module:QualifiedName``) and, when the
    factory is a `ControllerSpec`, its type and parameters (else None: unknown)."""
    inner = getattr(controller, "wrapped_controller", controller)  # a viewer's tap
    spec = factory if isinstance(factory, ControllerSpec) else None
    return {
        "class": class_path(inner),
        "type": None if spec is None else spec.type,
        "params": None if spec is None else spec.params,
    }
