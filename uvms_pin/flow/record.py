"""A flow field back from its record (`FlowField.record`), e.g. the flow a rollout saved."""

from __future__ import annotations

from typing import Any

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.flow.base import FlowField, SumFlow
from uvms_pin.flow.components import WaveComponents, Waves
from uvms_pin.flow.gauss_markov import GaussMarkovCurrent
from uvms_pin.flow.profile import DepthProfileCurrent
from uvms_pin.flow.uniform import UniformCurrent


def _waves(record: dict[str, Any]) -> Waves:
    arrays = {
        name: np.asarray(record[name], dtype=float)
        for name in ("amplitude_m", "angular_frequency_rad_s", "wavenumber_rad_m",
                     "heading_rad", "phase_rad")
    }  # fmt: skip
    components = WaveComponents(**arrays, water_depth_m=float(record["water_depth_m"]))
    return Waves(components, record.get("repr", "Waves"))


def _fields(record: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in record.items() if k != "type"}


#: record type -> how the field is rebuilt from its record
_BUILDERS = {
    "uniform_current": lambda r: UniformCurrent(r["velocity_world_m_s"]),
    "waves": _waves,
    "gauss_markov_current": lambda r: GaussMarkovCurrent(**_fields(r)),
    "depth_profile_current": lambda r: DepthProfileCurrent(**_fields(r)),
    "sum": lambda r: SumFlow(tuple(flow_from_record(f) for f in r["fields"])),
}


def flow_from_record(record: dict[str, Any] | None) -> FlowField | None:
    """The field ``record`` describes; None for None (still water).

    Raises:
        ParameterError: a record of a field defined outside uvms-pin (only its type and
            repr were saved) or a malformed record.
    """
    if record is None:
        return None
    kind = record.get("type") if isinstance(record, dict) else None
    build = _BUILDERS.get(kind)
    if build is None:
        raise ParameterError(
            f"cannot rebuild the flow {record.get('repr', kind) if isinstance(record, dict) else record!r}"
            f" from its record (type {kind!r}: only uvms-pin's own fields can be)"
        )
    try:
        return build(record)
    except (KeyError, TypeError, ValueError) as exc:
        raise ParameterError(f"malformed flow record of type {kind!r}: {exc}") from exc
