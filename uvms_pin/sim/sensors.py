"""Sensors with bounded, seeded noise; they produce the controller's `Measurement`.

Noise is drawn on a fixed sample grid (lazily, in chunks) from a seeded generator, so a
measurement is a deterministic function of time: the same run gives the same numbers whatever the
integrator. Between grid points the noise is blended with a smoothstep, n(t) = n_k +
(n_k+1 - n_k)(3 s^2 - 2 s^3), s = t / T - k: it equals the drawn samples at the grid points
(where a sampled controller reads it), never leaves their bounds, and is continuously
differentiable, so a continuous-time closed loop stays smooth enough for stiff adaptive
integrators (a held, stepwise noise makes them restart at every sample).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field, fields

import numpy as np
import pinocchio as pin

from uvms_pin.checks import number_fields
from uvms_pin.control.measurement import Measurement, read_only
from uvms_pin.errors import ParameterError
from uvms_pin.perception.loop import LoopCameras
from uvms_pin.perception.scene import scene_of
from uvms_pin.perception.suite import PerceptionSpec
from uvms_pin.results.signal import Signal
from uvms_pin.sim.estimation.estimator import NavigationEstimator
from uvms_pin.sim.estimation.spec import EstimatorSpec
from uvms_pin.sim.navigation.suite import NavigationSpec, NavigationSuite


@dataclass(frozen=True)
class NoiseSpec:
    """Bounded noise: ``uniform`` in [-bound, bound] or ``gaussian`` clipped at +-bound.

    For ``gaussian`` the standard deviation is bound / 3.
    """

    bound: float = 0.0
    distribution: str = "uniform"

    def __post_init__(self) -> None:
        number_fields(self)
        if not (self.bound >= 0.0 and math.isfinite(self.bound)):
            raise ParameterError(f"noise bound must be >= 0, got {self.bound}")
        if self.distribution not in ("uniform", "gaussian"):
            raise ParameterError(
                f"noise distribution must be 'uniform' or 'gaussian', got '{self.distribution}'"
            )

    def draw(self, rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
        if self.bound == 0.0:
            return np.zeros(shape)
        if self.distribution == "uniform":
            return rng.uniform(-self.bound, self.bound, size=shape)
        return np.clip(rng.normal(0.0, self.bound / 3.0, size=shape), -self.bound, self.bound)


class SampledNoise:
    """A noise signal drawn every ``period_s`` and smoothstep-blended between draws.

    The samples are drawn lazily, ``chunk_rows`` at a time, as time advances: memory stays
    bounded whatever the duration. Drawing a stream in chunks gives exactly the numbers of
    one draw of the whole table (numpy's generators fill arrays value by value), so the
    signal does not depend on the chunk size. Only the current and the previous chunk are
    kept; an earlier time replays the stream from the seed (never needed by the closed loop,
    whose integrators go back at most one output interval).
    """

    def __init__(
        self,
        spec: NoiseSpec,
        width: int,
        period_s: float,
        duration_s: float,
        rng: np.random.Generator,
        *,
        chunk_rows: int = 4096,
    ):
        if not (period_s > 0.0 and math.isfinite(period_s)):
            raise ParameterError(f"noise sample period must be positive, got {period_s}")
        if chunk_rows < 2:
            raise ParameterError(f"chunk_rows must be >= 2, got {chunk_rows}")
        self.period_s = period_s
        self._spec = spec
        self._width = width
        self._rows = math.ceil(duration_s / period_s) + 2
        self._chunk_rows = chunk_rows
        self._start_state = rng.bit_generator.state
        self._rng = rng
        self._rewind()

    def _rewind(self) -> None:
        self._rng.bit_generator.state = self._start_state
        self._first = 0  # row index of self._window[0]
        self._window = np.empty((0, self._width))

    def _rows_from(self, k: int) -> np.ndarray:
        """Rows k and k + 1 of the (virtual) table."""
        if k < self._first:
            self._rewind()
        while k + 1 >= self._first + len(self._window):
            # keep the last chunk (rows k - 1, k may straddle two chunks), append the next
            keep = self._window[-self._chunk_rows :]
            self._first += len(self._window) - len(keep)
            fresh = self._spec.draw(self._rng, (self._chunk_rows, self._width))
            self._window = np.concatenate([keep, fresh])
        return self._window[k - self._first : k - self._first + 2]

    @property
    def silent(self) -> bool:
        """True when the noise is identically zero (bound 0)."""
        return self._spec.bound == 0.0

    def values(self, times_s: np.ndarray) -> np.ndarray:
        """The signal at each of ``times_s`` (n,) sorted ascending, (n, width): row i equal,
        bit for bit, to ``self(times_s[i])`` (the same operations, element by element)."""
        times_s = np.asarray(times_s, dtype=float)
        if self.silent or len(times_s) == 0:
            return np.zeros((len(times_s), self._width))
        position = np.maximum(times_s, 0.0) / self.period_s
        k = np.minimum((position + 1e-9).astype(np.int64), self._rows - 2)
        s = np.minimum(np.maximum(position - k, 0.0), 1.0)
        self._rows_from(int(k[0]))
        self._rows_from(int(k[-1]))
        if int(k[0]) < self._first:  # wider than the window kept: one time at a time
            return np.array([self(t) for t in times_s.tolist()])
        here = self._window[k - self._first]
        after = self._window[k + 1 - self._first]
        blend = (s * s * (3.0 - 2.0 * s))[:, None]
        return np.where((s < 1e-9)[:, None], here, here + blend * (after - here))

    def __call__(self, time_s: float) -> np.ndarray:
        position = max(time_s, 0.0) / self.period_s
        k = min(int(position + 1e-9), self._rows - 2)
        s = min(max(position - k, 0.0), 1.0)
        here, after = self._rows_from(k)
        if s < 1e-9:
            return here
        blend = s * s * (3.0 - 2.0 * s)
        return here + blend * (after - here)


@dataclass(frozen=True)
class SensorConfig:
    """Noise of the force/torque sensor and of the state estimate.

    Attributes:
        force_noise: on each force component [N]. torque_noise: [N m].
        position_noise: vehicle position [m]; orientation_noise: rotation vector [rad];
        joint_noise: [rad]; velocity_noise: every component of zeta [m/s, rad/s].
        sample_period_s: sensor rate: a new noise value is drawn every sample period.
        navigation: the vehicle's navigation sensors (IMU, depth, DVL, USBL), logged as
            signals; what a controller measures is unchanged by them.
        perception: the cameras and sonars (`uvms_pin.perception`), fired over the logged
            states after the run (their images beside the rollout).
        estimator: a navigation filter on them (`uvms_pin.sim.estimation`), or None; with
            ``controller_input = "estimate"`` the controller's measurement carries its
            estimate in place of the measured vehicle state.
        held_object_wrench: the force/torque sensor also measures the wrench the robot's
            pieces exert on the free objects (what its jaws hold), at its end-effector frame's
            origin, world axes (`uvms_pin.sim.system.robots.Robots.object_wrenches`; runs of
            several robots only).
    """

    force_noise: NoiseSpec = NoiseSpec()
    torque_noise: NoiseSpec = NoiseSpec()
    position_noise: NoiseSpec = NoiseSpec()
    orientation_noise: NoiseSpec = NoiseSpec()
    joint_noise: NoiseSpec = NoiseSpec()
    velocity_noise: NoiseSpec = NoiseSpec()
    sample_period_s: float = 1e-3
    navigation: NavigationSpec = field(default_factory=NavigationSpec)
    estimator: EstimatorSpec | None = None
    perception: PerceptionSpec = field(default_factory=PerceptionSpec)
    held_object_wrench: bool = False

    def __post_init__(self) -> None:
        number_fields(self)
        for name in (f.name for f in fields(self) if isinstance(f.default, NoiseSpec)):
            value = getattr(self, name)
            if not isinstance(value, NoiseSpec):
                hint = (
                    f" (NoiseSpec({value!r}): uniform within +-{value!r})"
                    if isinstance(value, int | float)
                    else ""
                )
                raise ParameterError(
                    f"SensorConfig {name} must be a NoiseSpec{hint}, got "
                    f"{type(value).__name__} {value!r}"
                )


class SensorSuite:
    """Turns the true state and contact wrench into a noisy `Measurement`."""

    def __init__(self, model: pin.Model, config: SensorConfig, duration_s: float, seed: int):
        self.model = model
        self.config = config
        # one independent stream per channel: a channel's draws do not depend on the
        # others' sizes, and a longer run extends a shorter one with the same seed
        rngs = [np.random.default_rng(child) for child in np.random.SeedSequence(seed).spawn(6)]
        nj = model.nv - 6
        period = config.sample_period_s
        self._force = SampledNoise(config.force_noise, 3, period, duration_s, rngs[0])
        self._torque = SampledNoise(config.torque_noise, 3, period, duration_s, rngs[1])
        self._position = SampledNoise(config.position_noise, 3, period, duration_s, rngs[2])
        self._orientation = SampledNoise(config.orientation_noise, 3, period, duration_s, rngs[3])
        self._joints = SampledNoise(config.joint_noise, nj, period, duration_s, rngs[4])
        self._velocity = SampledNoise(config.velocity_noise, model.nv, period, duration_s, rngs[5])
        nav = config.navigation
        self.navigation = NavigationSuite(nav, seed) if nav.fitted else None
        self.estimator = (
            None if config.estimator is None else NavigationEstimator(config.estimator, nav, seed)
        )
        self._estimator_started = False
        self.seed = seed
        self.seeing: LoopCameras | None = None  # the cameras in the loop, once started
        #: several robots: () -> what the loop's scene holds beyond this robot as it stands
        #: (free objects' poses, fixtures' positions, other robots' q), set by its loop
        self.scene_view: Callable[[], tuple] | None = None
        self._layout = None
        self._free = 0  # the free objects among the bodies the cameras see
        self._state_noisy = any(
            s.bound > 0.0
            for s in (
                config.position_noise,
                config.orientation_noise,
                config.joint_noise,
                config.velocity_noise,
            )
        )

    def start_navigation(self, period_s: float | None) -> None:
        """A run starts: the navigation sensors sample every control period ``period_s``;
        the estimator starts at the first tick's true state (`navigate`)."""
        if self.navigation is not None:
            self.navigation.start(period_s)
        self._estimator_started = False

    def start_seeing(self, plant, layout, period_s: float | None, *, world=None, others=()) -> None:
        """A run starts: the cameras in the loop (`uvms_pin.perception.loop`) see the
        plant's world afresh, the system's state split by ``layout``; they fire at control
        ticks (ParameterError without a control period ``period_s``). In a run of several
        robots: ``world`` the run's (the first robot's, with the free objects), ``others``
        the other robots, (name, UVMS) each, posed by `scene_view`."""
        cameras = self.config.perception.in_loop
        self.seeing, self.scene_view = None, None
        if not cameras:
            return
        if period_s is None:
            raise ParameterError(
                "cameras in the loop fire at the control ticks: set [control] period_s"
            )
        world = plant.world if world is None else world
        scene = scene_of(
            plant.uvms, world, surface=plant.free_surface, backend=plant.backend, others=others
        )
        self.seeing, self._layout = LoopCameras(cameras, scene, self.seed), layout
        self._free = 0 if world is None else len(world.free)  # fixtures follow

    def see(self, time_s: float, state, measurement: Measurement) -> Measurement:
        """Once per control tick: the cameras in the loop whose instant has come fire from
        the system's true ``state``; ``measurement`` with their latest images. In a run of
        several robots the world's bodies and the other robots are ``scene_view``'s. The
        state is split only at the ticks a camera fires."""
        if self.seeing is None:
            return measurement
        if self.seeing.due(time_s):
            self._fire_seeing(time_s, state)
        return dataclasses.replace(measurement, images=self.seeing.images)

    def _fire_seeing(self, time_s: float, state) -> None:
        robot, *objects = self._layout.split(state.q, state.v)
        if self.scene_view is not None:
            self.seeing.update(time_s, robot[0], *self.scene_view())
        else:
            free, fixtures = objects[: self._free], objects[self._free :]
            self.seeing.update(time_s, robot[0], [q for q, _ in free], [q for q, _ in fixtures])

    def navigate(
        self, time_s: float, q: np.ndarray, v: np.ndarray, measurement: Measurement
    ) -> Measurement:
        """Once per control tick: the navigation sensors read the true (q, v), the
        estimator filters their readings; the measurement the controller is given
        (``measurement``, or its vehicle part replaced by the estimate)."""
        if self.navigation is None:
            return measurement
        self.navigation.update(time_s, q, v)
        estimator = self.estimator
        if estimator is None:
            return measurement
        if not self._estimator_started:  # the prior is drawn around the initial truth
            estimator.start(self.navigation.period_s, q, v)
            self._estimator_started = True
        estimator.update(time_s, self.navigation.signals())
        return estimator.measurement(measurement) if estimator.feeds_controller else measurement

    def navigation_signals(self) -> dict[str, np.ndarray | Signal]:
        """The navigation sensors' readings and the estimate, as logged signals."""
        if self.navigation is None:
            return {}
        signals: dict[str, np.ndarray | Signal] = self.navigation.signals()
        if self.estimator is not None and self._estimator_started:
            signals.update(self.estimator.signals())
        return signals

    def force_noise(self, time_s: float) -> np.ndarray:
        """[force noise (3) N; torque noise (3) N m] at time_s."""
        out = np.zeros(6)
        # a silent channel is zero by construction: nothing to draw or blend
        if not self._force.silent:
            out[:3] = self._force(time_s)
        if not self._torque.silent:
            out[3:] = self._torque(time_s)
        return out

    @property
    def state_noisy(self) -> bool:
        """True when q or v is measured with noise (else as it is)."""
        return self._state_noisy

    def noise_table(self, times_s: np.ndarray) -> np.ndarray:
        """The noise `measure` adds at each of ``times_s`` (sorted), one row per time:
        [force (3) N, torque (3) N m, orientation (3) rad, position (3) m, joints (nv - 6)
        rad, velocity (nv)], bit for bit the values `measure` uses (the compiled loop's
        input, src/uvms_core/sampled_loop.hpp)."""
        channels = (self._force, self._torque, self._orientation, self._position,
                    self._joints, self._velocity)  # fmt: skip
        return np.ascontiguousarray(np.hstack([c.values(times_s) for c in channels]))

    def measure(
        self, time_s: float, q: np.ndarray, v: np.ndarray, wrench_world: np.ndarray
    ) -> Measurement:
        wrench = read_only(wrench_world + self.force_noise(time_s))
        if not self._state_noisy:
            return Measurement(time_s, q, v, wrench)
        # Fix: the position noise used to go through pin.integrate together with the
        # orientation noise; the SE(3) exponential then maps it by R V(w) R^T (V the left
        # Jacobian of SO(3)), so the world offset exceeded its bound by up to |w|/2. Now:
        # orientation and joints by integrate (zero linear part: the position is untouched),
        # then the position noise added as a plain world offset.
        dq = np.zeros(self.model.nv)
        dq[3:6] = self._orientation(time_s)
        dq[6:] = self._joints(time_s)
        q_meas = pin.integrate(self.model, q, dq)
        q_meas[:3] = q[:3] + self._position(time_s)
        return Measurement(time_s, read_only(q_meas), read_only(v + self._velocity(time_s)), wrench)
