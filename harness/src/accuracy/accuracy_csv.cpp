#include "accuracy/accuracy_csv.h"

#include <type_traits>
#include <variant>

#include <fmt/format.h>

#include "io/atomic_file.h"
#include "io/csv.h"
#include "io/error.h"

namespace raybench {
namespace {

// The schema in file order: each column's name and the field it holds. The
// header, the writer and the reader all come from this one list.
struct Column {
  const char* name;
  std::variant<std::string AccuracyRow::*, double AccuracyRow::*, std::size_t AccuracyRow::*> field;
};

const std::vector<Column>& schema() {
  using R = AccuracyRow;
  static const std::vector<Column> columns = {
      {"scene", &R::scene},           {"scale", &R::scale},         {"offset_x", &R::offset_x},
      {"offset_y", &R::offset_y},     {"offset_z", &R::offset_z},   {"rayset", &R::rayset},
      {"query", &R::query},           {"backend", &R::backend},     {"accuracy_class", &R::accuracy_class},
      {"rays", &R::rays},             {"invalid", &R::invalid},     {"truth_hits", &R::truth_hits},
      {"ambiguous", &R::ambiguous},   {"false_miss", &R::false_miss}, {"false_hit", &R::false_hit},
      {"wrong_prim", &R::wrong_prim}, {"self_hits", &R::self_hits}, {"ulp_p50", &R::ulp_p50},
      {"ulp_p99", &R::ulp_p99},       {"ulp_max", &R::ulp_max},     {"mrays_s", &R::mrays_s},
      {"mrays_s_min", &R::mrays_s_min}, {"mrays_s_max", &R::mrays_s_max}, {"t_relerr_p99", &R::t_relerr_p99},
      {"t_relerr_max", &R::t_relerr_max}, {"representation", &R::representation}};
  return columns;
}

// Appended after files were published; older files lack them.
bool is_optional_column(const std::string& c) {
  return c == "t_relerr_p99" || c == "t_relerr_max" || c == "representation";
}

}  // namespace

const std::vector<std::string>& accuracy_columns() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Column& c : schema()) out.push_back(c.name);
    return out;
  }();
  return names;
}

void write_accuracy_csv(const std::string& path, const std::vector<AccuracyRow>& rows) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << fmt::format("{}\n", fmt::join(accuracy_columns(), ","));
    std::vector<std::string> fields;
    for (const AccuracyRow& r : rows) {
      fields.clear();
      for (const Column& c : schema()) {
        fields.push_back(std::visit(
            [&](auto member) {
              const auto& value = r.*member;
              using T = std::decay_t<decltype(value)>;
              if constexpr (std::is_same_v<T, std::string>) return csv_text(value);
              else if constexpr (std::is_same_v<T, double>) return csv_number(value);
              else return std::to_string(value);
            },
            c.field));
      }
      out << fmt::format("{}\n", fmt::join(fields, ","));
    }
  });
}

std::vector<AccuracyRow> read_accuracy_csv(const std::string& path) {
  std::vector<AccuracyRow> rows;
  std::size_t line = 1;
  std::vector<std::string> required;
  for (const std::string& c : accuracy_columns())
    if (!is_optional_column(c)) required.push_back(c);
  for (auto m : read_csv_rows(path, required)) {
    ++line;
    for (const std::string& c : accuracy_columns())
      if (is_optional_column(c)) m.emplace(c, "");  // keeps the file's value when it has the column
    const auto number = [&](const char* column) {
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
    for (const Column& c : schema()) {
      std::visit(
          [&](auto member) {
            auto& value = r.*member;
            using T = std::decay_t<decltype(value)>;
            if constexpr (std::is_same_v<T, std::string>) value = m.at(c.name);
            else if constexpr (std::is_same_v<T, double>) value = number(c.name);
            else value = static_cast<T>(number(c.name));
          },
          c.field);
    }
    rows.push_back(std::move(r));
  }
  return rows;
}

}  // namespace raybench
