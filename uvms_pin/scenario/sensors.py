"""``[sensors]``: the bounded noise of each measured channel and the sensors' rate; the
vehicle's navigation sensors in ``[sensors.imu]``, ``[sensors.depth]``, ``[sensors.dvl]``
and ``[sensors.usbl]`` (each fitted when its table is present); the cameras and sonars in
``[[sensors.camera]]`` and ``[[sensors.sonar]]`` (`uvms_pin.perception`)."""

from __future__ import annotations

from uvms_pin.errors import ParameterError
from uvms_pin.perception.sensor import SENSORS as SEEING
from uvms_pin.perception.suite import PerceptionSpec
from uvms_pin.physics.world.world import World
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.navigation.seabed import world_seabed
from uvms_pin.sim.navigation.suite import NavigationSpec
from uvms_pin.sim.sensors import NoiseSpec, SensorConfig


def build_sensors(
    t: Table, water_density_kg_m3: float = 1025.0, world: World | None = None
) -> SensorConfig:
    """The ``[sensors]`` table's `SensorConfig`; a DVL's bottom is ``world``'s seafloor
    (its upward planes) when it has one, else ``sensors.dvl.seabed_depth_m`` (not both)."""
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
        navigation=_navigation(t, water_density_kg_m3, world),
        perception=_perception(t),
        held_object_wrench=t.boolean("held_object_wrench", False),
    )
    t.finish()
    return config


def _navigation(t: Table, water_density_kg_m3: float, world: World | None) -> NavigationSpec:
    """Each registered sensor kind (`uvms_pin.sim.navigation.sensor.SENSORS`) fitted when its
    table ``[sensors.<name>]`` is present; the DVL's bottom is the world's seafloor or its
    ``seabed_depth_m``."""
    floor = None if world is None else world_seabed(world.objects)
    specs, bottom = {}, None
    for kind, _ in NavigationSpec().sensors():
        table = t.table(kind.name)
        if table is None:
            continue
        if kind.field == "dvl":
            bottom = _dvl_bottom(table, floor is not None)
        try:
            specs[kind.field] = kind.spec(
                **{key: table.number(key, default) for key, default in kind.table_keys()}
            )
        except ParameterError as exc:
            raise table.fail(str(exc)) from exc
        table.finish()
    try:
        return NavigationSpec(
            **specs,
            seabed_depth_m=bottom,
            water_density_kg_m3=water_density_kg_m3,
            seabed=floor if "dvl" in specs else None,
        )
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc


def _perception(t: Table) -> PerceptionSpec:
    """Every ``[[sensors.<kind>]]`` of a registered perception kind
    (`uvms_pin.perception.sensor.SENSORS`), in the file's order; names distinct."""
    sensors = []
    for name, kind in SEEING.items():
        for table in t.tables(name):
            try:
                spec = kind.spec.from_dict(table.rest(), table.title)
            except ParameterError as exc:
                raise table.fail(str(exc).removeprefix(f"{table.title}: ")) from exc
            sensors.append((name, spec))
    names = [spec.name for _, spec in sensors]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise t.fail(f"cameras and sonars need distinct names, got {', '.join(repeated)} twice")
    return PerceptionSpec(tuple(sensors))


def _dvl_bottom(t: Table, world_floor: bool) -> float | None:
    """The flat bottom's depth, or None when the world has a seafloor (the DVL's)."""
    if world_floor and t.has("seabed_depth_m"):
        raise t.error(
            "seabed_depth_m",
            "the world has a seafloor ([[world.objects]] plane): the DVL looks at it; "
            "remove seabed_depth_m (or the plane)",
        )
    if not (world_floor or t.has("seabed_depth_m")):
        raise t.error(
            "seabed_depth_m",
            "is required: a DVL needs a sea bottom (this key, or a [[world.objects]] plane)",
        )
    return None if world_floor else t.number("seabed_depth_m", positive=True)
