// The world's contacts in the nanobind module (world_bindings.cpp).
#pragma once

#include <nanobind/nanobind.h>

#include "plant.hpp"

void bind_world(nanobind::module_& m);
// The plant's operations with a world: its `world`, advance_in_world, acceleration_in_world,
// world_forces.
void bind_plant_world(nanobind::class_<uvms::Plant>& plant);
