#include "backends/embree_memory.h"

namespace raybench {

// Interim (issue 33, helper "memory"): Embree's defaults either way until
// the policy is implemented.
std::string embree_memory_config(bool) { return {}; }

}  // namespace raybench
