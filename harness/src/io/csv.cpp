#include "io/csv.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "io/error.h"

namespace raybench {
namespace {

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') field += '"', ++i;
      else if (c == '"') quoted = false;
      else field += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      out.push_back(field);
      field.clear();
    } else {
      field += c;
    }
  }
  out.push_back(field);
  return out;
}

}  // namespace

std::string csv_number(double v) { return std::isnan(v) ? std::string() : fmt::format("{:.6g}", v); }

// Scene and backend names never contain commas or quotes in practice, but
// a user's file name might: quote per RFC 4180 when needed.
std::string csv_text(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::vector<std::map<std::string, std::string>> read_csv_rows(const std::string& path,
                                                              const std::vector<std::string>& required,
                                                              std::vector<std::size_t>* lines) {
  if (lines) lines->clear();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot be opened for reading");
  std::string line;
  // One line without its end, LF or CRLF.
  const auto next_line = [&] {
    if (!std::getline(in, line)) return false;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  };
  if (!next_line()) throw InputError(path, "empty file, expected a CSV header");
  if (line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 byte order mark
  const std::vector<std::string> header = split_csv_line(line);
  for (const std::string& c : required)
    if (std::find(header.begin(), header.end(), c) == header.end()) throw InputError(path, "missing column '" + c + "'");
  std::vector<std::map<std::string, std::string>> rows;
  std::size_t line_number = 1;
  while (next_line()) {
    ++line_number;
    if (line.empty()) continue;
    const std::vector<std::string> fields = split_csv_line(line);
    if (fields.size() != header.size())
      throw InputError(path, fmt::format("line {}: {} fields, header has {}", line_number, fields.size(), header.size()));
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size(); ++i) row[header[i]] = fields[i];
    rows.push_back(std::move(row));
    if (lines) lines->push_back(line_number);
  }
  return rows;
}

}  // namespace raybench
