// Embree's memory policy: the device-config settings that give Embree's
// acceleration structures the same page policy as our BVHs'
// (raybench/bvh/huge_pages.h), so neither side is measured with an
// advantage the other is denied. BackendConfig::huge_pages selects it.
#pragma once

#include <string>

namespace raybench {

// Device-config fragment ("key=value,key=value", or "") that gives Embree's
// build memory huge pages when `huge_pages`, and keeps it off them otherwise.
std::string embree_memory_config(bool huge_pages);

}  // namespace raybench
