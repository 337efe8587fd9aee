#include "ply_precheck.h"

namespace raybench {

std::string ply_header_problem(std::string_view head) {
  if (head.size() < 4 || (head.substr(0, 4) != "ply\n" && head.substr(0, 4) != "ply\r")) return "";
  std::size_t start = 0;
  while (start < head.size()) {
    std::size_t end = head.find('\n', start);
    if (end == std::string_view::npos) end = head.size();
    if (head.substr(start, end - start).rfind("end_header", 0) == 0) return "";
    start = end + 1;
  }
  return "malformed PLY: the header never ends (no end_header line)";
}

}  // namespace raybench
