"""``[controller] type = "ppc"``: the paper's prescribed-performance law; omitted keys keep
the paper's values (`uvms_pin.control.ppc_params.PPCParams`, which checks them all: the
values are taken from the table as they are and checked there, once)."""

from __future__ import annotations

import dataclasses

from uvms_pin.control.ppc import PrescribedPerformanceController
from uvms_pin.control.ppc_params import PPCParams
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.control.task_space import velocity_names
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.compiled.backend import BACKENDS
from uvms_pin.scenario.controller_parts import (
    CONTROLLERS,
    ControllerContext,
    desired_force_profile,
    ee_frame_name,
    plain,
)
from uvms_pin.scenario.schema import Table

#: the table's keys that are `PPCParams` fields (the rest: ee_frame, backend, desired_force)
PARAMS_KEYS = tuple(f.name for f in dataclasses.fields(PPCParams))


@CONTROLLERS.register("ppc")
def read_ppc(t: Table, context: ControllerContext) -> ControllerSpec:
    """[controller] type = "ppc"."""
    uvms = context.uvms
    ee_frame = ee_frame_name(t, uvms, "ppc")
    given = {key: t.pop_raw(key) for key in PARAMS_KEYS if t.has(key)}
    # "core": the compiled law (Python reference on the calls it declines); "python": the reference
    backend = t.string("backend", "core", BACKENDS)
    desired_force, force_raw = desired_force_profile(t)
    t.finish()
    try:
        params = PPCParams(**given).sized(uvms.nv, velocity_names(uvms.model))
    except ParameterError as exc:
        message = str(exc)
        key = next((k for k in given if message.startswith(f"{k} ")), None)
        raise (t.fail(message) if key is None else t.error(key, message)) from exc
    parameters = {k: plain(v) for k, v in dataclasses.asdict(params).items()}
    recorded = {"ee_frame": ee_frame, "desired_force": force_raw, "backend": backend, **parameters}

    def build(u: UVMS) -> PrescribedPerformanceController:
        return PrescribedPerformanceController(
            u.model, ee_frame, params, desired_force, backend=backend
        )

    return ControllerSpec("ppc", recorded, build)
