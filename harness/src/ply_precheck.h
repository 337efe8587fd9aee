// A check of a PLY file's header before assimp reads it: assimp 5.2's PLY
// reader loops forever on a header without "end_header" (a file cut short
// inside its header), so such a file is refused here first.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace raybench {

// How many bytes of a file's head ply_header_problem needs to see.
inline constexpr std::size_t kPlyPrecheckBytes = 1 << 20;

// Given the first bytes of a file (at most kPlyPrecheckBytes), the reason
// assimp must not read it as PLY, or "" when it is not a PLY file or its
// header is complete. Pure: no I/O, any bytes (the fuzz target's entry).
std::string ply_header_problem(std::string_view head);

}  // namespace raybench
