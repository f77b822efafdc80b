// The fingerprint (source_hash.hpp), alone in its unit: the only one compiled with it, so a
// changed source recompiles this small unit, not one that includes Pinocchio.
#include "source_hash.hpp"

namespace uvms {

const char* core_source_hash() { return UVMS_CORE_SOURCE_HASH; }

}  // namespace uvms
