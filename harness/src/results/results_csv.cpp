#include "results/results_csv.h"

#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/atomic_file.h"
#include "io/csv.h"
#include "io/error.h"

namespace raybench {
namespace {

std::string number(double v) { return csv_number(v); }
std::string text(const std::string& s) { return csv_text(s); }

}  // namespace

const std::vector<std::string>& result_columns() {
  static const std::vector<std::string> columns = {
      "scene",        "triangles",    "rayset",          "query",         "rays",         "backend",
      "threads",      "build_ms",     "build_ms_min",    "build_ms_max",  "memory_bytes", "mrays_s",
      "mrays_s_min",  "mrays_s_max",  "reps",            "mrays_s_samples", "ratio_to_embree", "hit_rate",
      "agree_hit",    "agree_prim",   "prim_ties",       "t_relerr_max",  "t_relerr_p999", "disagreements",
      "leaks",        "sah_cost",     "reference",       "ratio_to_reference", "plugin",
      "representation"};
  return columns;
}

namespace {

// Appended after the first published schema; older files lack them.
bool is_optional_column(const std::string& c) {
  return c == "sah_cost" || c == "reference" || c == "ratio_to_reference" || c == "plugin" ||
         c == "representation";
}

}  // namespace

void write_results_csv(const std::string& path, const std::vector<ResultRow>& rows) {
  write_file_atomically(path, [&](std::ostream& out) {
    const auto& columns = result_columns();
    for (std::size_t i = 0; i < columns.size(); ++i) out << (i ? "," : "") << columns[i];
    out << '\n';
    for (const ResultRow& r : rows) {
      const std::string samples = fmt::format("{:.6g}", fmt::join(r.mrays_s_samples, ";"));
      out << fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", text(r.scene),
                         r.triangles, text(r.rayset), r.query, r.rays, text(r.backend), r.threads, number(r.build_ms),
                         number(r.build_ms_min), number(r.build_ms_max), r.memory_bytes, number(r.mrays_s),
                         number(r.mrays_s_min), number(r.mrays_s_max), r.reps, samples,
                         r.ratio_to_embree > 0 ? number(r.ratio_to_embree) : std::string(), number(r.hit_rate),
                         number(r.agree_hit), number(r.agree_prim), r.prim_ties, number(r.t_relerr_max),
                         number(r.t_relerr_p999), r.disagreements, r.leaks ? std::to_string(*r.leaks) : std::string(),
                         number(r.sah_cost), text(r.reference),
                         r.ratio_to_reference > 0 ? number(r.ratio_to_reference) : std::string(), text(r.plugin),
                         text(r.representation));
    }
  });
}

std::vector<std::map<std::string, std::string>> read_results_csv(const std::string& path,
                                                                 std::vector<std::size_t>* lines) {
  std::vector<std::string> required;
  for (const std::string& c : result_columns())
    if (!is_optional_column(c)) required.push_back(c);
  std::vector<std::map<std::string, std::string>> rows = read_csv_rows(path, required, lines);
  for (auto& row : rows)
    for (const std::string& c : result_columns())
      if (is_optional_column(c)) row.emplace(c, "");  // keeps the file's value when it has the column
  return rows;
}

}  // namespace raybench
