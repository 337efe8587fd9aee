#include "io/command_output.h"

#include <cstdio>

namespace raybench {

std::string command_output(const std::string& command) {
  std::string out;
  if (FILE* p = ::popen(command.c_str(), "r")) {
    char buffer[512];
    while (std::fgets(buffer, sizeof buffer, p)) out += buffer;
    ::pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out;
}

std::string command_first_line(const std::string& command) {
  const std::string out = command_output(command);
  return out.substr(0, out.find('\n'));
}

}  // namespace raybench
