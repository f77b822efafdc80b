// The world's contacts in the nanobind module (world_bindings.cpp).
#pragma once

#include <nanobind/nanobind.h>

#include "plant.hpp"

void bind_world(nanobind::module_& m);
// The friction's state from and to a Python FrictionMemory (anchors, slipping, material).
void read_memory(nanobind::handle memory, uvms::FrictionMemory& out);
void write_memory(const uvms::FrictionMemory& memory, nanobind::handle out);
// World.forces as plain arrays: the fields of ContactForces and its Touch, as a dict.
nanobind::dict forces_dict(const uvms::ContactForces& forces);
// The plant's operations with a world: its `world`, advance_in_world, acceleration_in_world,
// world_forces.
void bind_plant_world(nanobind::class_<uvms::Plant>& plant);
