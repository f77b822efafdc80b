"""Native vector environments: N episodes of a uvms-pin environment stepped in one call.

    envs = gym.make_vec("uvms_pin/StationKeeping-v0", num_envs=16,
                        vectorization_mode="vector_entry_point", num_threads=2)

The plant of every environment (actuation, one control period of dynamics, contact, sensor
noise) runs in the compiled batch (`uvms_pin.sim.batched_plant.BatchedPlant`, threads without the
interpreter lock); observations, rewards, terminations and truncations are numpy over the
batch. Environment i is the single environment (``gym.make``) with the same arguments:
reset with ``seed=s`` it runs the episodes of a single environment reset with ``seed=s+i``,
to rounding (tests/apps/gym/test_vector.py).

Autoreset follows Gymnasium 1.x (``metadata["autoreset_mode"]``): ``NEXT_STEP`` (default:
the step after an episode ends resets that environment, ignores its action and returns its
first observation with reward 0) or ``SAME_STEP`` (the ending step returns the new episode's
first observation; the last one and its info are in ``infos["final_obs"]`` and
``infos["final_info"]``). A new episode's seed is drawn from the environment's own
generator, as a single environment's is.
"""

from __future__ import annotations

from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv

from uvms_pin.apps.gym.env import UvmsEnv, _episode_seed
from uvms_pin.apps.gym.force_tracking import ForceTrackingEnv
from uvms_pin.apps.gym.station_keeping import StationKeepingEnv
from uvms_pin.errors import ParameterError
from uvms_pin.sim.batched_plant import DIVERGED, BatchedPlant, check_count
from uvms_pin.sim.run_start import checked_run_start
from uvms_pin.sim.system import System

_MODES = {mode.value: mode for mode in (AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP)}


def _autoreset_mode(mode: Any) -> AutoresetMode:
    if isinstance(mode, AutoresetMode) and mode.value in _MODES:
        return mode
    if isinstance(mode, str) and mode in _MODES:
        return _MODES[mode]
    raise ParameterError(
        f"autoreset_mode must be AutoresetMode.NEXT_STEP or SAME_STEP, got {mode!r}"
    )


class UvmsVectorEnv(VectorEnv):
    """``num_envs`` episodes of ``env_class(**kwargs)`` on ``num_threads`` threads.

    Args:
        env_class: a `UvmsEnv` whose task has batch outcomes (force tracking, station
            keeping).
        num_envs: N >= 1. num_threads: T >= 1.
        autoreset_mode: AutoresetMode.NEXT_STEP (default) or SAME_STEP.
        **kwargs: the single environment's arguments (scenario, action_scale, ...).

    Attributes:
        stiff_modes: the scenario's explicit stiff modes as checked before the batch is
            built (`uvms_pin.sim.run_start.checked_run_start`; StiffModeError if unstable).
    """

    metadata: ClassVar[dict[str, Any]] = {
        "render_modes": [],
        "autoreset_mode": AutoresetMode.NEXT_STEP,
    }

    def __init__(
        self,
        env_class: type[UvmsEnv],
        num_envs: int,
        num_threads: int = 1,
        autoreset_mode: Any = AutoresetMode.NEXT_STEP,
        **kwargs: Any,
    ):
        num_envs = check_count("num_envs", num_envs)
        num_threads = check_count("num_threads", num_threads)
        mode = _autoreset_mode(autoreset_mode)
        if kwargs.get("render_mode") is not None:
            raise ParameterError("the vector environment does not render: render_mode=None")
        self.single_env = env_class(**kwargs)  # the arguments parsed once, its task and spaces
        scenario = self.single_env.scenario
        # the batch steps the single environment's plant: its explicit stiff modes are checked
        # once, at the scenario's start, before the batch takes its memory (as a run does)
        system = System(scenario.plant)
        _, self.stiff_modes = checked_run_start(system, scenario.q0, scenario.v0, scenario.settings)
        self.batch = BatchedPlant(
            scenario.plant, scenario.settings, scenario.sensor_config, num_envs, num_threads
        )
        self.metadata = {**self.metadata, "autoreset_mode": mode}
        self.num_envs = num_envs
        self.num_threads = num_threads
        self.single_observation_space = self.single_env.observation_space
        self.single_action_space = self.single_env.action_space
        self.observation_space = gym.vector.utils.batch_space(
            self.single_observation_space, num_envs
        )
        self.action_space = gym.vector.utils.batch_space(self.single_action_space, num_envs)
        self._action_shape = self.action_space.shape
        self.render_mode = None
        self._tabulate()
        self._generators: list[np.random.Generator | None] = [None] * num_envs
        self.episode_seeds = np.zeros(num_envs, dtype=np.int64)
        self._autoreset = np.zeros(num_envs, dtype=bool)
        self._started = False

    def _tabulate(self) -> None:
        """The task's goal and bound at every tick of an episode (the single environment
        evaluates them at t = k period: the same numbers)."""
        env = self.single_env
        times = np.arange(env.max_steps + 1) * self.batch.period_s
        self._goals = np.array([env.task.goal(t) for t in times])
        self._bounds = np.array([env.task.bound(t) for t in times])

    # -- gymnasium API -------------------------------------------------------------------
    def reset(self, *, seed: int | list[int | None] | None = None, options: dict | None = None):
        """Start an episode in every environment (or in those of ``options["reset_mask"]``):
        environment i with seed ``seed + i`` (an int), ``seed[i]`` (a list) or one drawn
        from its generator (None)."""
        options = dict(options or {})
        mask = options.pop("reset_mask", None)
        if options:
            raise ParameterError(f"reset takes no options but reset_mask, got {sorted(options)}")
        seeds = self._seeds(seed)
        mask = np.ones(self.num_envs, dtype=bool) if mask is None else self._mask(mask)
        if not self._started and not mask.all():
            raise ParameterError("the first reset() resets every environment (no reset_mask)")
        for i in np.flatnonzero(mask):
            self._reset_env(int(i), seeds[i])
        self._autoreset[mask] = False
        self._started = True
        infos = {"seed": self.episode_seeds.copy(), "_seed": mask.copy()}
        return self._observations(), infos

    def step(self, actions):
        if not self._started:
            raise ParameterError("call reset() before step()")
        # the serial part of a step (this thread, between the threads' plant steps): numpy
        # over the batch, few calls (it bounds the speed-up of more threads)
        env = self.single_env
        try:
            a = np.asarray(actions, dtype=float)
        except (TypeError, ValueError):  # strings, ragged lists: refused below by name
            a = np.full(0, np.nan)
        if a.shape != self._action_shape or not np.isfinite(a).all():
            raise ParameterError(
                f"actions must be {self._action_shape} finite numbers, got shape {a.shape}"
            )
        if env.clip_actions:
            a = np.minimum(np.maximum(a, -1.0), 1.0)  # np.clip without its dispatch cost
        resetting = self._autoreset
        if resetting.any():
            for i in np.flatnonzero(resetting):  # NEXT_STEP: the ended episodes start again
                self._reset_env(int(i), None)
        stepping = ~resetting
        self.batch.step(self._commanded(a), stepping)
        reward, terminated, truncated, infos = self._outcomes(a, stepping)
        observations = self._observations()
        if self.metadata["autoreset_mode"] == AutoresetMode.SAME_STEP:
            observations, infos = self._reset_same_step(observations, terminated | truncated, infos)
            self._autoreset[:] = False
        else:
            self._autoreset = terminated | truncated
        return observations, reward, terminated, truncated, infos

    # -- helpers -------------------------------------------------------------------------
    def _commanded(self, a: np.ndarray) -> np.ndarray:
        """tau_commanded (N, nv) of the actions (N, n), as `UvmsEnv.commanded_tau` makes it
        for one environment: the scaled action on its entries, the jaw servo's torques from
        each environment's measured jaw at its own time."""
        env, batch = self.single_env, self.batch
        servo = env.jaw_servo
        if servo is None:
            return a * env.action_scale
        tau = np.zeros((self.num_envs, batch.v.shape[1]))
        tau[:, env.action_index] = a * env.action_scale
        jaw = servo.jaw
        tau[:, jaw.v_index] = servo.torques(
            batch.time_s(), batch.q_measured[:, jaw.q_index], batch.v_measured[:, jaw.v_index]
        )
        return tau

    def _outcomes(self, a: np.ndarray, stepping: np.ndarray):
        """Rewards, terminations, truncations and infos of the stepped environments (zero
        and False for those that were reset)."""
        env, batch = self.single_env, self.batch
        tick = batch.tick
        outcome = env.task.outcomes(
            self._goals[tick], self._bounds[tick], batch.q, batch.contact_world, a
        )
        diverged = stepping & (batch.status == DIVERGED)
        reward = np.where(diverged, -env.failure_penalty, outcome.reward)
        terminated = outcome.terminated | diverged
        truncated = (tick >= env.max_steps) & ~terminated
        reward[~stepping] = 0.0
        terminated &= stepping
        truncated &= stepping
        infos: dict[str, Any] = {"seed": self.episode_seeds.copy(), "time_s": tick * batch.period_s}
        infos["diverged"] = diverged
        kept = stepping & ~diverged
        for name, values in outcome.terms.items():
            infos[name] = np.where(kept, values, 0.0)
        for name in list(infos):
            infos[f"_{name}"] = np.ones(self.num_envs, dtype=bool)
        return reward, terminated, truncated, infos

    def _reset_same_step(self, observations: np.ndarray, ended: np.ndarray, infos: dict):
        if not ended.any():
            return observations, infos
        final_obs = np.full(self.num_envs, None, dtype=object)
        final_info: dict[str, Any] = {}
        for i in np.flatnonzero(ended):
            final_obs[i] = observations[i].copy()
        for name, values in infos.items():
            final_info[name] = values.copy() if not name.startswith("_") else ended.copy()
        for i in np.flatnonzero(ended):
            self._reset_env(int(i), None)
        infos = {**infos, "final_obs": final_obs, "_final_obs": ended.copy(),
                 "final_info": final_info, "_final_info": ended.copy()}  # fmt: skip
        infos["seed"] = self.episode_seeds.copy()
        return self._observations(), infos

    def _reset_env(self, i: int, seed: int | None) -> None:
        """Environment i's new episode, as `UvmsEnv.reset` starts one."""
        if seed is not None:
            self._generators[i], _ = seeding.np_random(seed)
        elif self._generators[i] is None:
            self._generators[i], _ = seeding.np_random()
        episode_seed = int(seed) if seed is not None else _episode_seed(self._generators[i])
        self.episode_seeds[i] = episode_seed
        q0, v0 = self.single_env._initial_state(episode_seed)
        self.batch.reset(i, q0, v0, episode_seed)

    def _observations(self) -> np.ndarray:
        batch = self.batch
        goals = self._goals[batch.tick]
        return np.concatenate(
            [batch.q_measured, batch.v_measured, batch.wrench_measured, goals], axis=1
        )

    def _seeds(self, seed) -> list[int | None]:
        if seed is None:
            return [None] * self.num_envs
        if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            return [int(seed) + i for i in range(self.num_envs)]
        seeds = list(seed)
        if len(seeds) != self.num_envs:
            raise ParameterError(f"{len(seeds)} seeds for {self.num_envs} environments")
        return seeds

    def _mask(self, mask) -> np.ndarray:
        mask = np.asarray(mask)
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_ or not mask.any():
            raise ParameterError(
                f"reset_mask must be {self.num_envs} booleans, at least one True, got {mask!r}"
            )
        return mask


def force_tracking_vector(num_envs: int, num_threads: int = 1, **kwargs: Any) -> UvmsVectorEnv:
    """The vector entry point of ``uvms_pin/ForceTracking-v0``."""
    return UvmsVectorEnv(ForceTrackingEnv, num_envs, num_threads, **kwargs)


def station_keeping_vector(num_envs: int, num_threads: int = 1, **kwargs: Any) -> UvmsVectorEnv:
    """The vector entry point of ``uvms_pin/StationKeeping-v0``."""
    return UvmsVectorEnv(StationKeepingEnv, num_envs, num_threads, **kwargs)
