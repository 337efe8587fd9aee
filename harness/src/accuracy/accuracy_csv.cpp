#include "accuracy/accuracy_csv.h"

#include <fmt/format.h>

#include "atomic_file.h"
#include "csv.h"
#include "error.h"

namespace raybench {

const std::vector<std::string>& accuracy_columns() {
  static const std::vector<std::string> columns = {
      "scene",     "scale",      "offset_x",   "offset_y",   "offset_z", "rayset",  "query",   "backend",
      "accuracy_class", "rays",  "invalid",    "truth_hits", "ambiguous", "false_miss", "false_hit", "wrong_prim",
      "self_hits", "ulp_p50",    "ulp_p99",    "ulp_max",    "mrays_s",  "mrays_s_min", "mrays_s_max"};
  return columns;
}

void write_accuracy_csv(const std::string& path, const std::vector<AccuracyRow>& rows) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << fmt::format("{}\n", fmt::join(accuracy_columns(), ","));
    for (const AccuracyRow& r : rows) {
      const std::string fields[] = {
          csv_text(r.scene),  csv_number(r.scale),     csv_number(r.offset_x),   csv_number(r.offset_y),
          csv_number(r.offset_z), csv_text(r.rayset),  r.query,                  csv_text(r.backend),
          r.accuracy_class,   std::to_string(r.rays),  csv_number(r.invalid),    csv_number(r.truth_hits),
          csv_number(r.ambiguous), csv_number(r.false_miss), csv_number(r.false_hit), csv_number(r.wrong_prim),
          csv_number(r.self_hits), csv_number(r.ulp_p50), csv_number(r.ulp_p99), csv_number(r.ulp_max),
          csv_number(r.mrays_s), csv_number(r.mrays_s_min), csv_number(r.mrays_s_max)};
      out << fmt::format("{}\n", fmt::join(fields, ","));
    }
  });
}

std::vector<AccuracyRow> read_accuracy_csv(const std::string& path) {
  std::vector<AccuracyRow> rows;
  std::size_t line = 1;
  for (const auto& m : read_csv_rows(path, accuracy_columns())) {
    ++line;
    const auto num = [&](const char* column) {
      const std::string& f = m.at(column);
      if (f.empty()) return static_cast<double>(NAN);
      try {
        std::size_t used = 0;
        const double v = std::stod(f, &used);
        if (used == f.size()) return v;
      } catch (const std::exception&) {
      }
      throw InputError(path, fmt::format("line {}: column {} is not a number: '{}'", line, column, f));
    };
    AccuracyRow r;
    r.scene = m.at("scene");
    r.scale = num("scale");
    r.offset_x = num("offset_x");
    r.offset_y = num("offset_y");
    r.offset_z = num("offset_z");
    r.rayset = m.at("rayset");
    r.query = m.at("query");
    r.backend = m.at("backend");
    r.accuracy_class = m.at("accuracy_class");
    r.rays = static_cast<std::size_t>(num("rays"));
    r.invalid = num("invalid");
    r.truth_hits = num("truth_hits");
    r.ambiguous = num("ambiguous");
    r.false_miss = num("false_miss");
    r.false_hit = num("false_hit");
    r.wrong_prim = num("wrong_prim");
    r.self_hits = num("self_hits");
    r.ulp_p50 = num("ulp_p50");
    r.ulp_p99 = num("ulp_p99");
    r.ulp_max = num("ulp_max");
    r.mrays_s = num("mrays_s");
    r.mrays_s_min = num("mrays_s_min");
    r.mrays_s_max = num("mrays_s_max");
    rows.push_back(std::move(r));
  }
  return rows;
}

}  // namespace raybench
