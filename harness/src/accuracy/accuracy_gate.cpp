#include "accuracy/accuracy_gate.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "io/error.h"

namespace raybench {
namespace {

// The row's scene as traced: its name, and its transform when it is not the identity.
std::string scene_label(const AccuracyRow& r) {
  if (r.scale == 1.0 && r.offset_x == 0.0 && r.offset_y == 0.0 && r.offset_z == 0.0) return r.scene;
  return fmt::format("{} (scale {:g}, offset [{:g}, {:g}, {:g}])", r.scene, r.scale, r.offset_x, r.offset_y, r.offset_z);
}

// A row's place: everything but the backend.
std::string place_of(const AccuracyRow& r) {
  return fmt::format("{}\n{:.17g}\n{:.17g}\n{:.17g}\n{:.17g}\n{}\n{}", r.scene, r.scale, r.offset_x, r.offset_y, r.offset_z,
                     r.rayset, r.query);
}

double AccuracyRow::*error_field(const std::string& column) {
  if (column == "false_miss") return &AccuracyRow::false_miss;
  if (column == "false_hit") return &AccuracyRow::false_hit;
  if (column == "wrong_prim") return &AccuracyRow::wrong_prim;
  return &AccuracyRow::self_hits;
}

// The number of rays a fraction of the row's rays is; NaN stays NaN (not applicable).
double count_of(const AccuracyRow& r, double fraction) {
  return std::isnan(fraction) ? fraction : std::round(fraction * static_cast<double>(r.rays));
}

GateFailure failure_at(const AccuracyRow& at, const std::string& backend, const std::string& check, const std::string& what) {
  GateFailure f;
  f.scene = scene_label(at);
  f.rayset = at.rayset;
  f.backend = backend;
  f.check = check;
  f.message = fmt::format("{}/{}/{} (accuracy, {}): {}", f.scene, f.rayset, backend, at.query, what);
  return f;
}

}  // namespace

const std::vector<std::string>& referee_error_columns() {
  static const std::vector<std::string> c = {"false_miss", "false_hit", "wrong_prim", "self_hits"};
  return c;
}

void gate_accuracy(const std::vector<AccuracyRow>& rows, const std::string& path, const std::string& reference,
                   const std::vector<std::string>& candidates, const GateConfig& config, GateResult& g) {
  std::map<std::pair<std::string, std::string>, const AccuracyRow*> by_place;  // (place, backend) -> row
  std::vector<const AccuracyRow*> places;                                     // each place once, in file order
  std::set<std::string> seen, backends;
  for (const AccuracyRow& r : rows) {
    by_place.emplace(std::make_pair(place_of(r), r.backend), &r);
    backends.insert(r.backend);
    if (seen.insert(place_of(r)).second) places.push_back(&r);
  }
  if (rows.empty()) throw InputError(path, "no accuracy rows: nothing to judge the candidates by");
  for (const std::string& c : candidates)
    if (!backends.count(c) && !backends.count(reference))
      throw InputError(path, fmt::format("has rows of neither the candidate '{}' nor the reference '{}' (it has {}): "
                                         "is it the accuracy CSV of this run?",
                                         c, reference, fmt::join(backends, ", ")));
  std::set<std::string> done;
  for (const std::string& candidate : candidates) {
    if (!done.insert(candidate).second) continue;
    for (const AccuracyRow* place : places) {
      const auto find = [&](const std::string& backend) -> const AccuracyRow* {
        const auto it = by_place.find({place_of(*place), backend});
        return it == by_place.end() ? nullptr : it->second;
      };
      const AccuracyRow* cand = find(candidate);
      const AccuracyRow* ref = find(reference);
      if (!cand || !ref) {
        const std::string what = fmt::format("no {} row in {}", !cand ? candidate : reference, path);
        GateFailure f = failure_at(*place, candidate, "missing", what);
        if (config.fail_on_missing_rows) g.failures.push_back(f);
        else g.notes.push_back(f.message);
        continue;
      }
      for (const std::string& column : referee_error_columns()) {
        const double mine = count_of(*cand, cand->*error_field(column));
        const double theirs = count_of(*ref, ref->*error_field(column));
        if (!(mine > (std::isnan(theirs) ? 0.0 : theirs))) continue;
        GateFailure f = failure_at(*cand, candidate, "referee",
                                   fmt::format("{} {:.0f} of {} rays, the reference {} {}", column, mine, cand->rays, reference,
                                               std::isnan(theirs) ? std::string("-") : fmt::format("{:.0f}", theirs)));
        f.kind = column;
        f.value = mine;
        f.against = std::isnan(theirs) ? 0.0 : theirs;
        g.failures.push_back(f);
      }
    }
  }
}

}  // namespace raybench
