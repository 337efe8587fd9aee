#include "results_csv.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "atomic_file.h"
#include "error.h"

namespace raybench {
namespace {

std::string number(double v) { return std::isnan(v) ? std::string() : fmt::format("{:.6g}", v); }

// Scene and backend names never contain commas or quotes in practice, but
// a user's file name might: quote per RFC 4180 when needed.
std::string text(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

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

const std::vector<std::string>& result_columns() {
  static const std::vector<std::string> columns = {
      "scene",        "triangles",    "rayset",          "query",         "rays",         "backend",
      "threads",      "build_ms",     "build_ms_min",    "build_ms_max",  "memory_bytes", "mrays_s",
      "mrays_s_min",  "mrays_s_max",  "reps",            "mrays_s_samples", "ratio_to_embree", "hit_rate",
      "agree_hit",    "agree_prim",   "prim_ties",       "t_relerr_max",  "t_relerr_p999", "disagreements",
      "leaks"};
  return columns;
}

void write_results_csv(const std::string& path, const std::vector<ResultRow>& rows) {
  write_file_atomically(path, [&](std::ostream& out) {
    const auto& columns = result_columns();
    for (std::size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
    out << '\n';
    for (const ResultRow& r : rows) {
      const std::string samples = fmt::format("{:.6g}", fmt::join(r.mrays_s_samples, ";"));
      out << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", text(r.scene),
                         r.triangles, text(r.rayset), r.query, r.rays, text(r.backend), r.threads, number(r.build_ms),
                         number(r.build_ms_min), number(r.build_ms_max), r.memory_bytes, number(r.mrays_s),
                         number(r.mrays_s_min), number(r.mrays_s_max), r.reps, samples,
                         r.ratio_to_embree > 0 ? number(r.ratio_to_embree) : std::string(), number(r.hit_rate),
                         number(r.agree_hit), number(r.agree_prim), r.prim_ties, number(r.t_relerr_max),
                         number(r.t_relerr_p999), r.disagreements, r.leaks ? std::to_string(*r.leaks) : std::string());
    }
  });
}

std::vector<std::map<std::string, std::string>> read_results_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "cannot be opened for reading");
  std::string line;
  if (!std::getline(in, line)) throw InputError(path, "empty file, expected a results CSV header");
  const std::vector<std::string> header = split_csv_line(line);
  for (const std::string& c : result_columns())
    if (std::find(header.begin(), header.end(), c) == header.end()) throw InputError(path, "missing column '" + c + "'");
  std::vector<std::map<std::string, std::string>> rows;
  std::size_t line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    const std::vector<std::string> fields = split_csv_line(line);
    if (fields.size() != header.size())
      throw InputError(path, fmt::format("line {}: {} fields, header has {}", line_number, fields.size(), header.size()));
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; i < header.size(); ++i) row[header[i]] = fields[i];
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace raybench
