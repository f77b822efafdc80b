"""``[estimator]`` (optional): a navigation filter in the loop (`uvms_pin.sim.estimation`),
on the vehicle's navigation sensors (``[sensors.imu]`` needed; DVL, depth and USBL used when
fitted). Its keys are in docs/scenarios.md ("Estimator")."""

from __future__ import annotations

import warnings

from uvms_pin.errors import ObservabilityWarning, ParameterError
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.estimation.eskf import ImuNoise
from uvms_pin.sim.estimation.spec import CONTROLLER_INPUTS, ESTIMATOR_TYPES, EstimatorSpec
from uvms_pin.sim.navigation.suite import NavigationSpec

_SIGMAS = (
    ("initial_position_sigma_m", 0.1),
    ("initial_velocity_sigma_m_s", 0.05),
    ("initial_attitude_sigma_rad", 0.02),
    ("initial_gyro_bias_sigma_rad_s", 1e-3),
    ("initial_accel_bias_sigma_m_s2", 0.01),
)
_IMU_NOISE = (
    "gyro_noise_rad_s_rthz",
    "gyro_bias_walk_rad_s2_rthz",
    "accel_noise_m_s2_rthz",
    "accel_bias_walk_m_s3_rthz",
)


def build_estimator(t: Table | None, navigation: NavigationSpec) -> EstimatorSpec | None:
    """The ``[estimator]`` table's `EstimatorSpec` (None without the table).

    Raises:
        ScenarioError: a bad key or value, or no ``[sensors.imu]`` to propagate with.
    """
    if t is None:
        return None
    kind = t.string("type", "eskf", ESTIMATOR_TYPES)
    controller_input = t.string("controller_input", "measurement", CONTROLLER_INPUTS)
    sigmas = tuple(t.number(key, default, positive=True) for key, default in _SIGMAS)
    draw = t.boolean("draw_initial_error", True)
    imu = _imu_noise(t, navigation)
    spec = EstimatorSpec(
        kind,
        controller_input,
        sigmas,
        draw,
        imu,
        _optional(t, "dvl_noise_m_s"),
        _optional(t, "depth_noise_m"),
        _optional(t, "usbl_noise_m"),
    )
    t.finish()
    try:
        spec.checked_against(navigation)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    unobservable = unobservable_states(navigation)
    if controller_input == "estimate" and unobservable:
        warnings.warn(
            f'{t.source}: [estimator] controller_input = "estimate": the controller is given '
            f"an estimate whose {'; '.join(unobservable)}: it drifts without bound",
            ObservabilityWarning,
            stacklevel=2,
        )
    return spec


def unobservable_states(navigation: NavigationSpec) -> list[str]:
    """What an IMU-propagated estimate cannot observe with the fitted sensors, each with the
    sensor that would make it observable (empty: all of position and velocity is)."""
    out = []
    if navigation.usbl is None:
        vertical = navigation.depth_noise_Pa is not None
        what = "horizontal position" if vertical else "position"
        out.append(f"{what} is unobservable (fit a USBL{'' if vertical else ' or a depth sensor'})")
    if navigation.dvl is None and navigation.usbl is None:
        out.append("velocity is unobservable (fit a DVL)")
    return out


def _imu_noise(t: Table, navigation: NavigationSpec) -> ImuNoise | None:
    """The IMU noise the filter assumes: each key given, or the IMU's own value."""
    given = {key: _optional(t, key) for key in _IMU_NOISE}
    if all(value is None for value in given.values()):
        return None
    imu = navigation.imu
    own = (0.0,) * 4 if imu is None else tuple(getattr(imu, key) for key in _IMU_NOISE)
    return ImuNoise(
        *(own[i] if given[key] is None else given[key] for i, key in enumerate(_IMU_NOISE))
    )


def _optional(t: Table, key: str) -> float | None:
    """A number >= 0 when given; None: the sensor's own value."""
    return t.number(key, nonneg=True) if t.has(key) else None
