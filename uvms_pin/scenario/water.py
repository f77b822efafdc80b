"""``[water]``: the density, the uniform current and the flow fields of ``[water.current]``,
``[water.waves]`` and ``[water.sea]`` (their sum). Seeds default to the scenario's seed."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from uvms_pin.checks import Plausible
from uvms_pin.errors import ParameterError
from uvms_pin.flow import (
    AiryWave,
    DepthProfileCurrent,
    FlowField,
    GaussMarkovCurrent,
    IrregularSea,
    SumFlow,
    UniformCurrent,
)
from uvms_pin.flow.airy import WAVE_PERIOD
from uvms_pin.flow.irregular import MAX_COMPONENTS
from uvms_pin.model.uvms import WATER_DENSITY
from uvms_pin.scenario.schema import Table

#: The speed of the water [m/s]: the fastest tidal races run at ~5 m/s; faster than sound in
#: water, the incompressible model means nothing
CURRENT_SPEED = Plausible(
    "m/s", (0.0, 5.0), (0.0, 1480.0), "sea and tidal currents",
    "no water flows faster than sound in it (~1480 m/s)",
)  # fmt: skip
#: A regular wave's amplitude, half its height [m]
AMPLITUDE = Plausible(
    "m", (0.0, 10.0), (0.0, 50.0), "sea waves (the highest measured: ~30 m crest to trough)",
    "no sea wave is that high",
)  # fmt: skip
#: A sea state's significant wave height [m]
SIGNIFICANT_HEIGHT = Plausible(
    "m", (0.0, 15.0), (0.0, 40.0), "sea states (the highest measured: ~19 m)",
    "no sea state is that high",
)  # fmt: skip


@dataclass(frozen=True)
class Water:
    """What ``[water]`` gives: rho [kg/m^3], the uniform current [m/s] (world), the flow
    beyond it (None for none), whether the water has a free surface (z = 0, or the waves'
    elevation) that cuts the bodies, and whether a run stops when a body's centre of
    buoyancy reaches it."""

    density_kg_m3: float
    current_world_m_s: np.ndarray
    flow: FlowField | None
    free_surface: bool = True
    stop_at_surface: bool = False


def build_water(t: Table, seed: int) -> Water:
    density = t.plausible(
        "density_kg_m3", t.number("density_kg_m3", 1025.0, positive=True), WATER_DENSITY
    )
    current = t.vector("current_world_m_s", 3, [0.0, 0.0, 0.0])
    t.plausible("current_world_m_s", float(np.linalg.norm(current)), CURRENT_SPEED)
    stop_at_surface = t.boolean("stop_at_surface", False)
    # stopping at the surface is the model of submerged bodies: no surface in the dynamics
    # unless asked for as well
    free_surface = t.boolean("free_surface", not stop_at_surface)
    fields = []
    for key, kinds in FLOWS.items():
        table = t.table(key)
        if table is not None:
            fields.append(_flow_field(table, kinds, seed))
    t.finish()
    flow = None if not fields else fields[0] if len(fields) == 1 else SumFlow(tuple(fields))
    return Water(density, current, flow, free_surface, stop_at_surface)


def _waves(t: Table, seed: int) -> AiryWave:
    return AiryWave(
        amplitude_m=t.plausible("amplitude_m", t.number("amplitude_m", nonneg=True), AMPLITUDE),
        period_s=t.plausible("period_s", t.number("period_s", positive=True), WAVE_PERIOD),
        heading_rad=t.number("heading_rad", 0.0),
        water_depth_m=t.number("water_depth_m", math.inf, positive=True),
        phase_rad=t.number("phase_rad", 0.0),
    )


def _sea(t: Table, seed: int) -> IrregularSea:
    return IrregularSea(
        significant_height_m=t.plausible(
            "significant_height_m",
            t.number("significant_height_m", nonneg=True),
            SIGNIFICANT_HEIGHT,
        ),
        peak_period_s=t.plausible(
            "peak_period_s", t.number("peak_period_s", positive=True), WAVE_PERIOD
        ),
        peak_enhancement=t.number("peak_enhancement", 3.3, positive=True),
        heading_rad=t.number("heading_rad", 0.0),
        spreading_exponent=t.optional_number("spreading_exponent", positive=True),
        n_components=t.integer("n_components", 100, minimum=1, maximum=MAX_COMPONENTS),
        seed=t.seed("seed", seed),
        water_depth_m=t.number("water_depth_m", math.inf, positive=True),
    )


def _uniform_current(t: Table, seed: int) -> UniformCurrent:
    return UniformCurrent(t.vector("velocity_world_m_s", 3))


def _profile_current(t: Table, seed: int) -> DepthProfileCurrent:
    return DepthProfileCurrent(
        t.vector("velocity_world_m_s", 3), t.vector("depths_m", None), t.vector("factors", None)
    )


def _gauss_markov_current(t: Table, seed: int) -> GaussMarkovCurrent:
    return GaussMarkovCurrent(
        mean_velocity_world_m_s=t.vector("mean_velocity_world_m_s", 3),
        std_m_s=t.number("std_m_s", nonneg=True),
        time_constant_s=t.number("time_constant_s", positive=True),
        bound_m_s=t.number("bound_m_s", positive=True),
        seed=t.seed("seed", seed),
        sample_period_s=t.number("sample_period_s", 0.5, positive=True),
    )


#: the flows of [water]: its table -> its kinds (``type`` -> how the field is built from the
#: table; the first is the default, and a table of one kind has no ``type``), in the order
#: their fields are summed
FLOWS: dict[str, dict[str, Callable[[Table, int], FlowField]]] = {
    "current": {
        "uniform": _uniform_current,
        "gauss_markov": _gauss_markov_current,
        "profile": _profile_current,
    },
    "waves": {"airy": _waves},
    "sea": {"jonswap": _sea},
}


def _flow_field(
    t: Table, kinds: dict[str, Callable[[Table, int], FlowField]], seed: int
) -> FlowField:
    """Build a flow field of its table's kind; the field's own ParameterErrors name the
    table."""
    kind = (
        next(iter(kinds)) if len(kinds) == 1 else t.string("type", next(iter(kinds)), tuple(kinds))
    )
    try:
        field = kinds[kind](t, seed)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    t.finish()
    return field
