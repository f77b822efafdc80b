"""The rollout of a run, written sample by sample: the observer every run has.

Rows are preallocated (the run's number of logged samples, or a first guess that doubles when
full, for an episode of unknown length); the energies are computed once, for the rows
written, when the log is finished (they are functions of the state alone), and so, under a
free surface, is each hull's wet fraction (the signal ``wet_fraction``, one column per hull
named in the metadata's ``hull_names``: 1 deep, 0 out of the water); the potential energy
includes the joint stops' springs (`JointStops.energy_J`). With a world, each
sample also logs (the system of bodies' `SystemLog.signals`, among the sample's signals) the contact of every (body, object) pair (the signal ``world_contact``,
9 columns per pair named in the metadata's ``world_contact_pairs``: the force on the body
[N] (3), its point [m] (3) and the moment about that point [N m] (3), world axes; the
UVMS against free objects and its own vehicle included). With free objects, the signal
``free_objects`` holds each object's pose and body velocity (names and units in
``signal_units``) and ``free_object_contact`` their own pairs' wrenches (the same 9
columns, pairs named in ``free_object_contact_pairs``).
"""

from __future__ import annotations

import copy
from typing import Any

import pinocchio as pin

from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.dynamics import kinetic_energy, potential_energy_placed
from uvms_pin.physics.surface import wet_state
from uvms_pin.results.rollout import Rollout
from uvms_pin.results.signal import Signal, described
from uvms_pin.sim.plant import Plant
from uvms_pin.sim.sample import Sample
from uvms_pin.sim.settings import SimulationSettings
from uvms_pin.sim.system import System


class RolloutLog:
    """Writes the loop's samples into a `Rollout` (an `Observer`).

    Args:
        uvms: the model (sizes, energies). backend: the dynamics' backend for the energies.
        capacity: rows to allocate first. metadata: the rollout's metadata.
        system: the system of bodies run (`uvms_pin.sim.system.System`): its robot's free
            surface (energies and wet fractions under it), joint stops (their springs'
            energy) and world (the contact pairs' and free objects' names and units); None:
            water without a top, no stops, no world.
    """

    def __init__(
        self,
        uvms: UVMS,
        capacity: int,
        metadata: dict[str, Any],
        backend: str = "core",
        system: System | None = None,
    ):
        self.uvms = uvms
        self.backend = backend
        plant = None if system is None else system.plant
        self.plant = plant if plant is not None and plant.free_surface else None
        if self.plant is not None:
            metadata = {**metadata, "hull_names": hull_names(uvms)}
        # the joint stops' springs hold energy: a part of the potential energy logged
        self.stops = None if plant is None else plant.joint_stops
        if plant is not None and plant.world is not None:
            metadata = {**metadata, "world_contact_pairs": system.log.contact_pair_names}
        if system is not None and system.objects:
            names, units = system.moving.state_columns()
            units_meta = {
                **metadata.get("signal_units", {}),
                "free_objects": described(names, units),
            }
            metadata = {
                **metadata,
                "free_object_contact_pairs": system.moving.moving.object_pair_names,
                "signal_units": units_meta,
            }
        self.rollout = Rollout.allocate(max(int(capacity), 1), uvms.nq, uvms.nv, metadata)
        self.count = 0
        self.described: set[str] = set()  # the named signals (`Signal`) already described

    def on_sample(self, sample: Sample) -> None:
        if self.count == len(self.rollout):
            self.grow()
        k, rollout = self.count, self.rollout
        rollout.time_s[k] = sample.time_s
        rollout.q[k] = sample.q
        rollout.v[k] = sample.v
        rollout.tau[k] = sample.tau_applied
        rollout.signal("tau_commanded", self.uvms.nv)[k] = sample.tau_commanded
        rollout.wrench_contact_world[k] = sample.contact_world
        rollout.wrench_measured_world[k] = sample.measurement.wrench_world
        rollout.wrench_disturbance_body[k] = sample.disturbance_body
        for name, values in sample.signals.items():
            if isinstance(values, Signal):
                if name not in self.described:
                    self.describe(name, values)
                values = values.values
            rollout.signal(name, values.size)[k] = values
        self.count += 1

    def describe(self, name: str, signal: Signal) -> None:
        """Keep a named signal's component names and units in the metadata
        (``signal_units``: name -> {"components": [...], "units": [...]})."""
        described = self.rollout.metadata.setdefault("signal_units", {})
        described[name] = signal.describe()
        self.described.add(name)

    def grow(self) -> None:
        """Twice the rows (the samples written kept): for a log whose length is not known."""
        old, n = self.rollout, len(self.rollout)
        grown = Rollout.allocate(2 * n, self.uvms.nq, self.uvms.nv, old.metadata)
        for name in Rollout._BASE:
            getattr(grown, name)[:n] = getattr(old, name)
        for name, values in old.signals.items():
            grown.signal(name, values.shape[1])[:n] = values
        self.rollout = grown

    def copy(self) -> RolloutLog:
        """An independent log holding the same samples (the model is shared)."""
        out = RolloutLog.__new__(RolloutLog)
        out.uvms, out.backend, out.count = self.uvms, self.backend, self.count
        out.plant, out.stops = self.plant, self.stops
        out.described = set(self.described)
        out.rollout = copy.deepcopy(self.rollout)
        return out

    def finish(self) -> Rollout:
        """The rollout of the samples written so far, with their energies."""
        rollout = self.rollout
        rollout.truncate(self.count)
        plant, uvms = self.plant, self.uvms
        surface = {} if plant is None else {"free_surface": True, "flow": plant.water}
        fractions = None
        if plant is not None:
            fractions = rollout.signal("wet_fraction", len(uvms.surface_bodies))
            fractions[:] = 1.0  # deep: the rows the wet state leaves None
        model, data = uvms.model, uvms.data
        for k in range(self.count):
            q = rollout.q[k]
            if plant is not None:
                surface["time_s"] = float(rollout.time_s[k])
            rollout.kinetic_energy_J[k] = kinetic_energy(
                uvms, q, rollout.v[k], backend=self.backend, **surface
            )
            # the placements and the wet state once, for the wet fractions and U
            pin.forwardKinematics(model, data, q)
            wet = None if plant is None else wet_state(uvms, data, plant.water, surface["time_s"])
            if wet is not None:
                fractions[k] = wet.fraction
            rollout.potential_energy_J[k] = potential_energy_placed(uvms, data, q, wet)
            if self.stops is not None:
                rollout.potential_energy_J[k] += self.stops.energy_J(q)
        return rollout


def hull_names(uvms: UVMS) -> list[str]:
    """The name of each hull's body (the columns of the ``wet_fraction`` signal)."""
    return [uvms.hydro_bodies[int(k)].name for k in uvms.surface_bodies.body_index]


def run_metadata(plant: Plant, settings: SimulationSettings) -> dict[str, Any]:
    """What a rollout records of the run: settings, seed, versions, model and arm joints
    (their kinds and position limits, None where a joint has none)."""
    from uvms_pin.results.provenance import package_versions

    uvms = plant.uvms
    arm = uvms.arm_joints
    lower, upper = arm.limits_record()
    return {
        "seed": settings.seed,
        "duration_s": settings.duration_s,
        "log_period_s": settings.log_period_s,
        "control_period_s": settings.control_period_s,
        "integrator": type(settings.integrator).__name__,
        "integrator_settings": dict(vars(settings.integrator)),
        "versions": package_versions(),
        "model_source": uvms.source,
        "arm_joint_names": list(arm.names),
        "arm_joint_kinds": list(arm.kinds),
        "arm_position_lower_rad": lower,
        "arm_position_upper_rad": upper,
        "signal_units": described_columns(plant.actuation.signal_columns()),
    }


def described_columns(columns: dict[str, list[tuple[str, str]]]) -> dict[str, dict[str, list[str]]]:
    """Producers' (component, unit) columns per signal in the rollout's ``signal_units``
    record, the one a controller's `Signal` is described by (`uvms_pin.sim.log`)."""
    return {
        name: described([c for c, _ in cols], [u for _, u in cols])
        for name, cols in columns.items()
    }
