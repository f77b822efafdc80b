"""Gymnasium environments on a scenario: the sampled closed loop of ``uvms-pin run`` with
the controller replaced by the policy (docs/gym.md).

Observation (float64), what a controller may measure, in this order (``observation_layout``):
    q_measured (nq): vehicle position [m] (3), quaternion xyzw (4), arm joints [rad];
    v_measured (nv): body linear [m/s] (3), body angular [rad/s] (3), joint rates [rad/s];
    wrench_measured (6): F/T force [N] (3), torque [N m] (3), world axes, with noise;
    goal: the task's goal (force tracking: f_d(t) [N] (3); station keeping: p_d [m] (3),
    quaternion xyzw (4)).
Action (n,) in [-1, 1]: tau_commanded[action_index] = action_scale * action
(`uvms_pin.apps.gym.actions`), then the plant's actuation (thruster allocation and
saturation, joint torque limits). The action drives the vehicle and the arm joints: all nv
entries, or, on a model whose jaw a ``[gripper]`` servo drives, all but the jaw's, which the
servo commands from the measurement as it does beside a controller (`jaw_servo`).
One step = one control period (the scenario's control.period_s); the episode is truncated
at the scenario's duration_s.
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
import pinocchio as pin

from uvms_pin.apps.gym.actions import action_scale as make_action_scale
from uvms_pin.control.measurement import Measurement
from uvms_pin.errors import ParameterError, ScenarioError, SimulationError
from uvms_pin.model.resources import shipped_path
from uvms_pin.results.rollout import Rollout
from uvms_pin.results.status import OK, RunStatus
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.closed_loop import ClosedLoop
from uvms_pin.sim.log import RolloutLog, run_metadata
from uvms_pin.sim.run import Scenario
from uvms_pin.sim.sensors import SensorSuite

# spawn key of the initial-perturbation stream: apart from the sensors' children 0..5
_PERTURBATION_STREAM = 1 << 16


def _continuous_control_message(scenario: Scenario, action_scale: Any) -> str:
    """Why a continuous-control scenario is refused, and the options that make it run: a
    control period that divides the log period (the log period itself does), and
    ``action_scale`` when the scenario has no actuation limits to normalize by."""
    log_period_s = scenario.settings.log_period_s
    fix = f'overrides={{"control.period_s": {log_period_s:g}}}'
    driven = _driven(scenario)
    try:
        make_action_scale(scenario.plant.actuation, scenario.uvms.nv, action_scale, driven)
    except ParameterError:
        fix += f", action_scale=<{len(driven)} numbers [N, N m]> (no [actuation] limits)"
    return (
        f"{scenario.path}: the environment steps one control period at a time, and the "
        "scenario's control is continuous: give it a control period that divides "
        f"output.log_period_s = {log_period_s:g} s, e.g. {fix}"
    )


def _driven(scenario: Scenario) -> np.ndarray:
    """The entries of tau the action drives: every one but a servoed jaw's."""
    servo = scenario.jaw_servo
    return np.arange(scenario.uvms.nv) if servo is None else servo.jaw.arm_v_index.copy()


def _shortened_record(scenario: Scenario) -> dict[str, Any]:
    """``{"shortened_from_s": T}`` for a scenario UVMS_PIN_MAX_DURATION_S shortened."""
    if scenario.shortened_from_s is None:
        return {}
    return {"shortened_from_s": scenario.shortened_from_s}


def _load_with_model(path: Path, overrides: dict[str, Any], model: str | None) -> Scenario:
    """The scenario at ``path`` with ``overrides``; when ``model`` replaced its model and
    the rest of the file does not fit the new one, the error says how to make it fit."""
    try:
        return load_scenario(path, overrides)
    except ScenarioError as exc:
        if model is None:
            raise
        raise ScenarioError(
            f"{exc}. model={model!r} replaces only the scenario's model; its other tables "
            "were written for the model it names: give the keys that do not fit as "
            "overrides (e.g. overrides={'initial.joint_positions_rad': [...]}, one number per "
            "joint of the new model, within its limits), or pass a scenario written for it"
        ) from None


def _episode_seed(np_random: np.random.Generator) -> int:
    return int(np_random.integers(0, 2**31 - 1))


class UvmsEnv(gym.Env):
    """Base of the uvms-pin environments: a scenario stepped one control period at a time.

    Args:
        scenario: scenario file (path, or the name of a shipped scenario).
        model: replaces the scenario's model (a shipped model name or a URDF path).
        overrides: dotted scenario overrides, as ``uvms-pin run --set`` (e.g.
            ``{"control.period_s": 0.01}``).
        action_scale: scale of the normalized action (one per entry of ``action_index``)
            [N, N m]; default: the actuation limits (required when the scenario's
            actuation is unlimited).
        clip_actions: clip the action to [-1, 1] (False: pass it on; the actuation still
            saturates).
        initial_position_noise_m, initial_joint_noise_rad: bound of the uniform
            perturbation of the vehicle position [m] and of the arm joints [rad] at reset;
            None: the environment's ``initial_noise`` (force tracking 0.02, 0.02; station
            keeping 0.1, 0.05).
        effort_weight: w_effort of the reward. failure_penalty: reward of a diverged step.
        render_mode: None or "rgb_array".
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"], "render_fps": 30}
    #: bounds of the initial perturbation when not given: position [m], arm joints [rad]
    initial_noise: ClassVar[tuple[float, float]] = (0.0, 0.0)

    def __init__(
        self,
        scenario: str | Path,
        *,
        model: str | None = None,
        overrides: dict[str, Any] | None = None,
        action_scale: Any = None,
        clip_actions: bool = True,
        initial_position_noise_m: float | None = None,
        initial_joint_noise_rad: float | None = None,
        effort_weight: float = 0.01,
        failure_penalty: float = 100.0,
        render_mode: str | None = None,
    ):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ParameterError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        if initial_position_noise_m is None:
            initial_position_noise_m = self.initial_noise[0]
        if initial_joint_noise_rad is None:
            initial_joint_noise_rad = self.initial_noise[1]
        for label, value in (
            ("initial_position_noise_m", initial_position_noise_m),
            ("initial_joint_noise_rad", initial_joint_noise_rad),
            ("effort_weight", effort_weight),
            ("failure_penalty", failure_penalty),
        ):
            if not (isinstance(value, numbers.Real) and np.isfinite(value) and value >= 0.0):
                raise ParameterError(f"{label} must be a finite number >= 0, got {value!r}")
        self.render_mode = render_mode
        self.scenario_path = scenario_path(scenario)
        if overrides is not None and not isinstance(overrides, Mapping):
            raise ParameterError(
                "overrides must be a mapping of dotted scenario keys to values (e.g. "
                f"{{'control.period_s': 0.01}}), got {type(overrides).__name__}"
            )
        self.overrides = dict(overrides or {})
        if model is not None:
            self.overrides["scenario.model"] = model
        self.scenario = _load_with_model(self.scenario_path, self.overrides, model)
        if self.scenario.settings.control_period_s is None:
            raise ParameterError(_continuous_control_message(self.scenario, action_scale))
        self._loop = ClosedLoop(self.scenario.plant, self.scenario.settings)
        uvms = self.scenario.uvms
        #: the entries of tau the action drives (all but a servoed jaw's, `jaw_servo`)
        self.action_index = _driven(self.scenario)
        #: the scenario's jaw servo, which commands the jaw joints (None: no servoed jaw)
        self.jaw_servo = self.scenario.jaw_servo
        self.action_scale = make_action_scale(
            self.scenario.plant.actuation, uvms.nv, action_scale, self.action_index
        )
        self.clip_actions = bool(clip_actions)
        self.initial_position_noise_m = float(initial_position_noise_m)
        self.initial_joint_noise_rad = float(initial_joint_noise_rad)
        self.effort_weight = float(effort_weight)
        self.failure_penalty = float(failure_penalty)
        settings = self.scenario.settings
        self.max_steps = round(settings.duration_s / settings.control_period_s)
        self.task = self._make_task(self.scenario)
        self.observation_layout = _layout(uvms.nq, uvms.nv, self.task.goal_size)
        size = self.observation_layout["goal"].stop
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (size,), np.float64)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (self.action_index.size,), np.float64)
        self.episode_seed: int | None = None
        self._steps = 0
        self._log: RolloutLog | None = None
        self._failure: SimulationError | None = None
        self._measurement = None
        self._contact = np.zeros(6)
        self._anchor: np.ndarray | None = None
        self._render_data = uvms.model.createData()
        self._vehicle_box = None  # (centre, size) [m], found on the first render
        self._flow_seed = self.scenario.settings.seed

    @property
    def loop(self) -> ClosedLoop:
        """The closed loop the environment steps (``loop.state``: the system's true state)."""
        return self._loop

    # -- to be given by a task environment ---------------------------------------------
    def _make_task(self, scenario: Scenario):
        raise NotImplementedError

    # -- gymnasium API -------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict[str, Any] | None = None):
        """Start an episode. Every random draw (sensor noise, initial perturbation, sea
        state) comes from the episode seed: ``seed`` when given, else drawn from the
        environment's generator (itself seeded by the last given seed); ``info['seed']``."""
        super().reset(seed=seed)
        if options:
            raise ParameterError(f"reset takes no options, got {sorted(options)}")
        episode_seed = int(seed) if seed is not None else _episode_seed(self.np_random)
        self._reseed_flow(episode_seed)
        self.episode_seed = episode_seed
        q0, v0 = self._initial_state(episode_seed)
        scenario, loop = self.scenario, self._loop
        settings = scenario.settings
        sensors = SensorSuite(
            scenario.uvms.model, scenario.sensor_config, settings.duration_s, episode_seed
        )
        loop.start(q0, v0, sensors)
        self._steps = 0
        self._log = RolloutLog(
            scenario.uvms,
            self.max_steps + 1,
            self._episode_metadata(),
            scenario.plant.backend,
            system=loop.system,
        )
        self._failure = None
        self._anchor = None
        if scenario.plant.contact is not None:
            self._anchor = scenario.plant.ee_state(loop.q, loop.v)[0]
        self._measurement, self._contact = loop.observe()
        return self._observation(), {"seed": episode_seed, "time_s": 0.0}

    def step(self, action):
        try:
            a = np.asarray(action, dtype=float)
        except (TypeError, ValueError):  # strings, ragged lists: refused below by name
            a = np.full(0, np.nan)
        if a.shape != self.action_space.shape or not np.all(np.isfinite(a)):
            raise ParameterError(
                f"action must be {self.action_space.shape[0]} finite numbers, got {action!r}"
            )
        if self._measurement is None:
            raise ParameterError("call reset() before step()")
        if self.clip_actions:
            a = np.clip(a, -1.0, 1.0)
        loop = self._loop
        t, measured = loop.time_s, self._measurement
        tau = self.commanded_tau(a, t, measured)
        tau_applied = loop.actuate(tau)
        self._log.on_sample(loop.sample(measured, self._contact, tau, tau_applied))
        info: dict[str, Any] = {"seed": self.episode_seed}
        try:
            loop.step(tau_applied)
            self._measurement, self._contact = loop.observe()
        except SimulationError as exc:
            self._measurement = None  # the episode is over: reset() before stepping again
            self._failure = exc
            info.update(time_s=t, error=str(exc))
            obs = _observation_of(measured, self.task.goal(t))
            return obs, -self.failure_penalty, True, False, info
        self._steps += 1
        outcome = self.task.outcome(loop.time_s, loop.q, self._contact, a)
        truncated = self._steps >= self.max_steps and not outcome.terminated
        info.update(time_s=loop.time_s, **outcome.terms)
        return self._observation(), outcome.reward, outcome.terminated, truncated, info

    def commanded_tau(self, action: np.ndarray, time_s: float, measured: Measurement) -> np.ndarray:
        """tau_commanded (nv,) [N, N m] of a (clipped) normalized ``action`` at ``time_s``:
        ``action_scale * action`` on `action_index`, the jaw servo's torques from the
        ``measured`` jaw joints on the jaw's entries."""
        servo = self.jaw_servo
        if servo is None:  # the action drives every entry
            return self.action_scale * action
        tau = np.zeros(self.scenario.uvms.nv)
        tau[self.action_index] = self.action_scale * action
        jaw = servo.jaw
        tau[jaw.v_index] = servo.torque(time_s, measured.q[jaw.q_index], measured.v[jaw.v_index])
        return tau

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        from uvms_pin.apps.gym.render import side_view_rgb, vehicle_box

        if self._vehicle_box is None:
            self._vehicle_box = vehicle_box(self.scenario.uvms)
        loop = self._loop
        return side_view_rgb(
            self.scenario.uvms, self._render_data, loop.q, loop.time_s, self._anchor,
            box=self._vehicle_box,
        )  # fmt: skip

    # -- replay export -------------------------------------------------------------------
    def episode_rollout(self) -> Rollout:
        """The episode so far as a Rollout (``save`` it, then ``uvms-pin replay`` it):
        one sample per control tick up to the current state (where the last input is shown
        held), its status saying whether the plant diverged."""
        if self.episode_seed is None:
            raise ParameterError("no episode yet: call reset() first")
        loop, log = self._loop, self._log.copy()
        rollout = log.rollout
        if log.count == 0 or rollout.time_s[log.count - 1] != loop.time_s:  # the state reached
            k = log.count - 1
            held = (rollout.signals["tau_commanded"][k], rollout.tau[k]) if k >= 0 else None
            tau, tau_applied = held if held else (np.zeros(loop.v.size),) * 2
            measured = self._measurement
            if measured is None:  # diverged: the true contact stands in for the reading
                measured = Measurement(loop.time_s, loop.q, loop.v, self._contact)
            log.on_sample(loop.sample(measured, self._contact, tau, tau_applied))
        rollout = log.finish()
        failure = self._failure
        rollout.set_status(
            RunStatus(OK)
            if failure is None
            else RunStatus(type(failure).__name__, str(failure), float(rollout.time_s[-1]))
        )
        return rollout

    def _episode_metadata(self) -> dict[str, Any]:
        scenario = self.scenario
        settings = scenario.settings
        env_id = self.spec.id if self.spec else type(self).__name__
        return {
            "scenario": scenario.name,
            "scenario_path": str(scenario.path),
            "description": f"{scenario.description} (gymnasium {env_id})",
            "parameters": scenario.raw,
            **run_metadata(scenario.plant, settings),
            "seed": self.episode_seed,
            "log_period_s": settings.control_period_s,
            "world": self._loop.system.log.record(),
        } | _shortened_record(scenario)

    # -- helpers -------------------------------------------------------------------------
    def _observation(self) -> np.ndarray:
        return _observation_of(self._measurement, self.task.goal(self._loop.time_s))

    def _initial_state(self, episode_seed: int) -> tuple[np.ndarray, np.ndarray]:
        rng = np.random.default_rng(
            np.random.SeedSequence(episode_seed, spawn_key=(_PERTURBATION_STREAM,))
        )
        uvms = self.scenario.uvms
        q0 = self.scenario.q0.copy()
        q0[:3] += rng.uniform(-1.0, 1.0, 3) * self.initial_position_noise_m
        # each arm joint moved by its own angle (a continuous joint's q is (cos, sin))
        dq = np.zeros(uvms.nv)
        dq[6:] = rng.uniform(-1.0, 1.0, uvms.nv - 6) * self.initial_joint_noise_rad
        q0[7:] = pin.integrate(uvms.model, q0, dq)[7:]
        return q0, self.scenario.v0.copy()

    def _reseed_flow(self, episode_seed: int) -> None:
        """A seeded flow (waves, sea state, varying current) is drawn again from the episode
        seed: the scenario is rebuilt with scenario.seed = the episode seed."""
        if self.scenario.plant.flow is None or episode_seed == self._flow_seed:
            return
        self.scenario = load_scenario(
            self.scenario_path, {**self.overrides, "scenario.seed": episode_seed}
        )
        self._loop = ClosedLoop(self.scenario.plant, self.scenario.settings)
        self._flow_seed = episode_seed


def _observation_of(measurement, goal: np.ndarray) -> np.ndarray:
    return np.concatenate([measurement.q, measurement.v, measurement.wrench_world, goal])


def _layout(nq: int, nv: int, goal_size: int) -> dict[str, slice]:
    """Slices of the observation vector by name (module docstring)."""
    out, start = {}, 0
    for name, size in (("q", nq), ("v", nv), ("wrench", 6), ("goal", goal_size)):
        out[name] = slice(start, start + size)
        start += size
    return out


def scenario_path(scenario: str | Path) -> Path:
    """A scenario file, or the name of a shipped one (``realistic_force_tracking``)."""
    if not isinstance(scenario, str | os.PathLike):
        raise ParameterError(
            f"scenario must be a file or a shipped scenario's name, got {scenario!r}"
        )
    path = Path(scenario)
    if path.is_file():
        return path
    name = path.name if path.suffix == ".toml" else f"{path.name}.toml"
    if str(scenario) == path.name:
        try:
            return shipped_path(Path("scenarios") / name)
        except FileNotFoundError:
            pass
    raise ParameterError(f"scenario {str(scenario)!r}: no such file nor shipped scenario")


class PoseEnv(UvmsEnv):
    """A `UvmsEnv` whose task is a pose: the episode ends when the position error exceeds
    ``max_position_error_m`` [m] (None: the environment's ``default_max_position_error_m``);
    ``scenario`` None: its ``default_scenario``."""

    default_scenario: ClassVar[str]
    default_max_position_error_m: ClassVar[float]

    def __init__(
        self,
        scenario: str | Path | None = None,
        *,
        max_position_error_m: float | None = None,
        **kwargs: Any,
    ):
        bound = max_position_error_m
        self._max_position_error_m = self.default_max_position_error_m if bound is None else bound
        super().__init__(self.default_scenario if scenario is None else scenario, **kwargs)
