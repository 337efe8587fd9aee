// A check of a PLY file's header before assimp reads it: assimp 5.2's PLY
// reader loops forever on a header without "end_header" (a file cut short
// inside its header), so such a file is refused here first.
//
// What assimp 5.2.5 reads as a PLY header (code/AssetLib/Ply/PlyLoader.cpp
// and PlyParser.cpp, include/assimp/IOStreamBuffer.h): its importer claims
// any file with "ply", in any case, in its first 200 bytes (CanRead), and
// reads a header when the first line, as IOStreamBuffer::getNextLine splits
// lines, starts with [Pp][Ll][Yy] ("ply ", "ply\t", "PLY", "plyx" alike).
// getNextLine ends a line at '\n', '\r', '\f' or '\0'; a line that starts
// on such a character is first skipped to just past the next '\n' (so a
// leading empty line is skipped, and "\r\r" swallows up to the next '\n').
// ParseHeader stops at a line that, after spaces and tabs, starts with the
// token "end_header" followed by a space, tab or line end; at the end of the
// file getNextLine stops advancing and leaves the last line in its buffer,
// so without such a line the loop never ends. ply_header_problem splits
// lines the same way, and counts an "end_header" only when the character
// ending its token is in the file (assimp reads past the end otherwise).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace raybench {

// How many bytes of a file's head ply_header_problem needs to see.
inline constexpr std::size_t kPlyPrecheckBytes = 1 << 20;

// Given the first bytes of a file (at most kPlyPrecheckBytes), the reason
// assimp must not read it as PLY, or "" when assimp would not read it as a
// PLY header or its header ends. Pure: no I/O, any bytes (the fuzz
// target's entry). A header longer than the head counts as never ending.
std::string ply_header_problem(std::string_view head);

}  // namespace raybench
