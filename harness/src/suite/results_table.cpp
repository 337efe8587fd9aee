#include "suite/results_table.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace raybench {

bool spreads_widely(const ResultRow& row) {
  return row.mrays_s_min > 0 && row.mrays_s_max / row.mrays_s_min > kMaxRepetitionSpread;
}

bool sees_little(const CameraCoverage& c) { return c.hit_fraction < kMinCameraCoverage; }

std::string camera_warning(const CameraCoverage& c) {
  return fmt::format("camera sees little of the scene: {:.1f} % of primary rays hit; check it with {}",
                     100.0 * c.hit_fraction, c.preview);
}

std::string format_results_table(const std::vector<ResultRow>& rows, const std::vector<CameraCoverage>& cameras) {
  // Column widths follow the longest ray-set and backend names in the run;
  // with the default suite's names a line stays within 120 columns.
  // A plugin shows the name it reports, then the name it was given.
  const auto shown = [](const ResultRow& r) { return r.plugin.empty() ? r.backend : r.plugin + " (" + r.backend + ")"; };
  std::size_t rayset_width = 6, backend_width = 7;
  for (const ResultRow& r : rows) {
    rayset_width = std::max(rayset_width, r.rayset.size());
    backend_width = std::max(backend_width, shown(r).size());
  }
  const auto percent = [](double v) { return std::isnan(v) ? std::string("-") : fmt::format("{:.3f}%", 100.0 * v); };
  std::string out, scene;
  bool any_spread = false;
  for (const ResultRow& r : rows) {
    if (r.scene != scene) {
      scene = r.scene;
      out += fmt::format("\n{} ({} triangles)\n", r.scene, r.triangles);
      for (const CameraCoverage& c : cameras)
        if (c.scene == scene && sees_little(c)) out += "  warning: " + camera_warning(c) + "\n";
      out += fmt::format("  {:<{}} {:<{}} {:>3} {:>8} {:>18} {:>8} {:>7} {:>8} {:>8} {:>8} {:>7} {:>6}\n", "rayset",
                         rayset_width, "backend", backend_width, "thr", "Mrays/s", "[min - max] ", "x embree", "hit",
                         "agree", "same tri", "build ms", "MiB", "leaks");
    }
    const bool spread = spreads_widely(r);
    any_spread = any_spread || spread;
    out += fmt::format("  {:<{}} {:<{}} {:>3} {:>8.2f} {:>18} {:>8} {:>7} {:>8} {:>8} {:>8.1f} {:>7.1f} {:>6}\n", r.rayset,
                       rayset_width, shown(r), backend_width, r.threads, r.mrays_s,
                       fmt::format("[{:.2f} - {:.2f}]{}", r.mrays_s_min, r.mrays_s_max, spread ? "!" : " "),
                       r.ratio_to_embree > 0 ? fmt::format("{:.2f}", r.ratio_to_embree) : "-",
                       fmt::format("{:.1f}%", 100.0 * r.hit_rate), percent(r.agree_hit), percent(r.agree_prim), r.build_ms,
                       r.memory_bytes / 1048576.0, r.leaks ? std::to_string(*r.leaks) : "-");
  }
  if (any_spread)
    out += fmt::format("\n! repetitions spread widely (fastest / slowest > {}): that median and its x embree are not to be "
                       "trusted;\n  rerun on a quiet machine, with more --reps or a longer --min-time\n",
                       kMaxRepetitionSpread);
  return out;
}

std::string format_accuracy_table(const std::vector<AccuracyRow>& rows) {
  std::size_t rayset_width = 6, backend_width = 7, class_width = 5;
  for (const AccuracyRow& r : rows) {
    rayset_width = std::max(rayset_width, r.rayset.size());
    backend_width = std::max(backend_width, r.backend.size());
    class_width = std::max(class_width, r.accuracy_class.size());
  }
  // Rates are fractions of the row's rays: as counts they read as "3 of 3000".
  const auto count = [](const AccuracyRow& r, double rate) {
    return std::isnan(rate) ? std::string("-") : fmt::format("{}", std::llround(rate * static_cast<double>(r.rays)));
  };
  const auto ulps = [](double v) {
    return std::isnan(v) ? std::string("-") : v < 100 ? fmt::format("{:.3g}", v) : v < 1e7 ? fmt::format("{:.0f}", v)
                                                                                         : fmt::format("{:.1e}", v);
  };
  std::string out, scene;
  for (const AccuracyRow& r : rows) {
    if (r.scene != scene) {
      scene = r.scene;
      out += fmt::format("\n{}: the exact referee's verdicts (rays)\n", r.scene);
      out += fmt::format("  {:<{}} {:<{}} {:<{}} {:>7} {:>7} {:>6} {:>7} {:>6} {:>6} {:>6} {:>8} {:>8}\n", "rayset",
                         rayset_width, "backend", backend_width, "class", class_width, "rays", "hits", "ambig",
                         "f_miss", "f_hit", "wrong", "self", "ulp p50", "ulp max");
    }
    const bool intersect = r.query != "occluded";
    out += fmt::format("  {:<{}} {:<{}} {:<{}} {:>7} {:>7} {:>6} {:>7} {:>6} {:>6} {:>6} {:>8} {:>8}\n", r.rayset,
                       rayset_width, r.backend, backend_width, r.accuracy_class, class_width, r.rays,
                       count(r, r.truth_hits), count(r, r.ambiguous), count(r, r.false_miss), count(r, r.false_hit),
                       intersect ? count(r, r.wrong_prim) : "-", count(r, r.self_hits), ulps(r.ulp_p50), ulps(r.ulp_max));
  }
  if (!rows.empty())
    out += "\n  hits: rays the referee says hit; ambig: near an edge or vertex, or tied (another triangle is not wrong there);\n"
           "  f_miss/f_hit: the backend misses a hit / hits a miss; wrong: another triangle than the referee accepts;\n"
           "  self: secondary rays hitting the triangle they start from; ulp: |t - exact t| over rays both hit\n";
  return out;
}

}  // namespace raybench
