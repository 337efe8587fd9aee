// The Embree version the harness was built against, for a run's metadata
// (results/metadata.cpp). The embree family itself registers from
// embree_backend.cpp (RAYBENCH_BACKEND_FAMILY) and needs no declaration.
#pragma once

#include <string>

namespace raybench {

std::string embree_version();

}  // namespace raybench
