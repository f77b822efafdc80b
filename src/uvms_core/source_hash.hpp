// The fingerprint of the core's sources (CMakeLists.txt's CORE_SOURCE_HASH, the SHA-256 of every
// src/uvms_core/*.cpp and *.hpp): the module's SOURCE_HASH, which
// uvms_pin/physics/compiled/extension.py compares with the tree it runs from.
#pragma once

namespace uvms {

const char* core_source_hash();

}  // namespace uvms
