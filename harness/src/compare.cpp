#include "compare.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "error.h"
#include "gbench.h"
#include "mann_whitney.h"
#include "metadata.h"
#include "results_csv.h"

namespace raybench {
namespace {

std::string row_key(const std::map<std::string, std::string>& r) {
  return r.at("scene") + "/" + r.at("rayset") + "/" + r.at("backend") + "/threads:" + r.at("threads");
}

std::vector<double> parse_samples(const std::string& text) {
  std::vector<double> out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    try {
      out.push_back(std::stod(text.substr(start, end - start)));
    } catch (const std::exception&) {
      throw InputError("", "malformed mrays_s_samples field '" + text + "'");
    }
    start = end + 1;
  }
  return out;
}

// The columns that are a pure function of the rays, the scene and the code.
const std::vector<std::string>& deterministic_columns() {
  static const std::vector<std::string> c = {"triangles",     "hit_rate",     "agree_hit",      "agree_prim",
                                             "prim_ties",     "t_relerr_max", "t_relerr_p999", "disagreements",
                                             "leaks",         "memory_bytes"};
  return c;
}

Verdict decide(double change, double p, const CompareOptions& o) {
  if (std::fabs(change) < o.min_effect) return Verdict::kSame;
  if (p >= o.alpha) return Verdict::kUnsure;
  return change > 0 ? Verdict::kFaster : Verdict::kSlower;
}

SampleComparison compare_samples(const std::vector<double>& base, const std::vector<double>& current,
                                 const CompareOptions& o) {
  SampleComparison c;
  if (base.empty() || current.empty()) return c;
  c.base = median(base);
  c.current = median(current);
  c.change = c.base > 0 ? c.current / c.base - 1.0 : 0.0;
  c.p_value = mann_whitney_u(current, base).p_value;
  c.verdict = decide(c.change, c.p_value, o);
  return c;
}

// The Embree row measured beside `row` in the same run, if any.
const std::map<std::string, std::string>* embree_row_beside(const ResultsFile& f,
                                                            const std::map<std::string, std::string>& row) {
  for (const auto& r : f.rows)
    if (r.at("backend") == "embree" && r.at("scene") == row.at("scene") && r.at("rayset") == row.at("rayset") &&
        r.at("threads") == row.at("threads"))
      return &r;
  return nullptr;
}

// Each repetition of a row divided by the median of the Embree row measured
// in the same run (same scene, ray set, threads); empty without one.
std::vector<double> ratio_samples(const ResultsFile& f, const std::map<std::string, std::string>& row) {
  if (row.at("backend") == "embree") return {};
  const auto* e = embree_row_beside(f, row);
  if (!e) return {};
  const double reference = median(parse_samples(e->at("mrays_s_samples")));
  if (!(reference > 0)) return {};
  std::vector<double> out = parse_samples(row.at("mrays_s_samples"));
  for (double& v : out) v /= reference;
  return out;
}

const std::map<std::string, std::string>* find_row(const ResultsFile& f, const std::string& key) {
  for (const auto& r : f.rows)
    if (row_key(r) == key) return &r;
  return nullptr;
}

std::string percent(double change) { return fmt::format("{:+.1f}%", 100.0 * change); }

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string json_number(double v) { return std::isfinite(v) ? fmt::format("{:.6g}", v) : "null"; }

}  // namespace

ResultsFile read_results_file(const std::string& path) {
  ResultsFile f;
  f.path = path;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "no such results file");
  f.rows = read_results_csv(path);
  for (const auto& r : f.rows) {
    try {
      parse_samples(r.at("mrays_s_samples"));
    } catch (const InputError& e) {
      throw InputError(path, std::string(e.what()) + " in row " + row_key(r));
    }
  }
  const std::string meta = metadata_path_for(path);
  if (std::filesystem::is_regular_file(meta, ec)) {
    try {
      const toml::table t = toml::parse_file(meta);
      for (const auto& [key, value] : t)
        if (auto s = value.value<std::string>()) f.metadata[std::string(key.str())] = *s;
    } catch (const toml::parse_error& e) {
      throw InputError(meta, fmt::format("line {}: {}", e.source().begin.line, e.description()));
    }
  }
  return f;
}

ResultsFile pool_runs(const std::vector<ResultsFile>& runs) {
  if (runs.empty()) throw InputError("", "no results to pool");
  ResultsFile pooled = runs.front();
  if (runs.size() == 1) return pooled;
  for (std::size_t i = 1; i < runs.size(); ++i) pooled.path += " + " + runs[i].path;
  for (auto& row : pooled.rows) {
    const std::string key = row_key(row);
    // Every run's own Embree median for this row, and the pooled one.
    std::vector<double> reference_per_run, all_reference;
    for (const ResultsFile& run : runs) {
      const auto* e = embree_row_beside(run, row);
      const std::vector<double> s = e ? parse_samples(e->at("mrays_s_samples")) : std::vector<double>{};
      reference_per_run.push_back(s.empty() ? 0.0 : median(s));
      all_reference.insert(all_reference.end(), s.begin(), s.end());
    }
    const double pooled_reference = all_reference.empty() ? 0.0 : median(all_reference);
    std::string samples;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const auto* r = find_row(runs[i], key);
      if (!r) continue;
      const bool rescale = row.at("backend") != "embree" && reference_per_run[i] > 0 && pooled_reference > 0;
      for (double v : parse_samples(r->at("mrays_s_samples")))
        samples += fmt::format("{}{:.9g}", samples.empty() ? "" : ";",
                               rescale ? v * pooled_reference / reference_per_run[i] : v);
    }
    row["mrays_s_samples"] = samples;
  }
  return pooled;
}

const std::vector<std::string>& machine_keys() {
  static const std::vector<std::string> keys = {"cpu", "hardware_threads", "compiler", "flags", "build_type", "embree"};
  return keys;
}

std::vector<std::string> machine_differences(const ResultsFile& base, const ResultsFile& current) {
  std::vector<std::string> out;
  if (base.metadata.empty()) out.push_back("no metadata beside " + base.path);
  if (current.metadata.empty()) out.push_back("no metadata beside " + current.path);
  if (!out.empty()) return out;
  for (const std::string& k : machine_keys()) {
    const auto b = base.metadata.find(k), c = current.metadata.find(k);
    const std::string bv = b == base.metadata.end() ? "(missing)" : b->second;
    const std::string cv = c == current.metadata.end() ? "(missing)" : c->second;
    if (bv != cv) out.push_back(fmt::format("{}: '{}' vs '{}'", k, bv, cv));
  }
  return out;
}

std::string to_string(Verdict v) {
  switch (v) {
    case Verdict::kSame: return "same";
    case Verdict::kFaster: return "faster";
    case Verdict::kSlower: return "slower";
    case Verdict::kUnsure: return "unsure";
    case Verdict::kNotApplicable: return "-";
  }
  return "?";
}

Comparison compare_results(const ResultsFile& base, const ResultsFile& current, const CompareOptions& options) {
  Comparison c;
  std::set<std::string> current_keys;
  for (const auto& r : current.rows) current_keys.insert(row_key(r));
  for (const auto& b : base.rows) {
    const std::string key = row_key(b);
    const auto* n = find_row(current, key);
    if (!n) {
      c.only_in_base.push_back(key);
      continue;
    }
    RowComparison rc;
    rc.scene = b.at("scene");
    rc.rayset = b.at("rayset");
    rc.backend = b.at("backend");
    rc.threads = b.at("threads");
    rc.base_row = b;
    rc.current_row = *n;
    rc.same_rays = b.at("rays") == n->at("rays");
    if (rc.same_rays) {
      rc.throughput = compare_samples(parse_samples(b.at("mrays_s_samples")), parse_samples(n->at("mrays_s_samples")), options);
      rc.ratio = compare_samples(ratio_samples(base, b), ratio_samples(current, *n), options);
      for (const std::string& col : deterministic_columns())
        if (b.at(col) != n->at(col)) rc.changes.push_back({col, b.at(col), n->at(col)});
    }
    c.rows.push_back(std::move(rc));
  }
  for (const auto& r : current.rows)
    if (!find_row(base, row_key(r))) c.only_in_current.push_back(row_key(r));
  return c;
}

std::string format_comparison(const Comparison& c, const ResultsFile& base, const ResultsFile& current,
                              OutputFormat format, bool colour) {
  const auto paint = [&](Verdict v, const std::string& text) {
    if (!colour) return text;
    if (v == Verdict::kSlower) return "\033[31m" + text + "\033[0m";
    if (v == Verdict::kFaster) return "\033[32m" + text + "\033[0m";
    if (v == Verdict::kUnsure) return "\033[33m" + text + "\033[0m";
    return text;
  };
  const auto changes_text = [](const RowComparison& r) {
    if (!r.same_rays) return std::string("different ray counts: not compared");
    std::string s;
    for (const auto& ch : r.changes)
      s += (s.empty() ? "" : "; ") + ch.column + " " + (ch.base.empty() ? "-" : ch.base) + " -> " + (ch.current.empty() ? "-" : ch.current);
    return s;
  };
  std::string out;
  if (format == OutputFormat::kJson) {
    out += "{\n  \"base\": " + json_string(base.path) + ",\n  \"current\": " + json_string(current.path) + ",\n  \"rows\": [\n";
    for (std::size_t i = 0; i < c.rows.size(); ++i) {
      const RowComparison& r = c.rows[i];
      std::string changes;
      for (const auto& ch : r.changes)
        changes += (changes.empty() ? "" : ", ") + fmt::format("{{\"column\": {}, \"base\": {}, \"current\": {}}}",
                                                               json_string(ch.column), json_string(ch.base), json_string(ch.current));
      const auto sample = [&](const SampleComparison& s) {
        return fmt::format("{{\"base\": {}, \"current\": {}, \"change\": {}, \"p_value\": {}, \"verdict\": {}}}",
                           json_number(s.base), json_number(s.current), json_number(s.change), json_number(s.p_value),
                           json_string(to_string(s.verdict)));
      };
      out += fmt::format(
          "    {{\"scene\": {}, \"rayset\": {}, \"backend\": {}, \"threads\": {}, \"same_rays\": {}, \"mrays_s\": {}, "
          "\"ratio_to_embree\": {}, \"changes\": [{}]}}{}\n",
          json_string(r.scene), json_string(r.rayset), json_string(r.backend), r.threads, r.same_rays ? "true" : "false",
          sample(r.throughput), sample(r.ratio), changes, i + 1 < c.rows.size() ? "," : "");
    }
    const auto list = [&](const std::vector<std::string>& v) {
      std::string s;
      for (const auto& e : v) s += (s.empty() ? "" : ", ") + json_string(e);
      return "[" + s + "]";
    };
    out += "  ],\n  \"only_in_base\": " + list(c.only_in_base) + ",\n  \"only_in_current\": " + list(c.only_in_current) + "\n}\n";
    return out;
  }
  const bool md = format == OutputFormat::kMarkdown;
  std::vector<std::vector<std::string>> table;
  table.push_back({"scene", "rayset", "backend", "thr", "Mrays/s base", "current", "change", "p", "verdict", "x embree",
                   "change", "p", "verdict", "deterministic changes"});
  std::vector<std::vector<Verdict>> verdicts;
  for (const RowComparison& r : c.rows) {
    const auto& t = r.throughput;
    const auto& q = r.ratio;
    const bool has_ratio = q.verdict != Verdict::kNotApplicable;
    table.push_back({r.scene, r.rayset, r.backend, r.threads, fmt::format("{:.2f}", t.base), fmt::format("{:.2f}", t.current),
                     percent(t.change), fmt::format("{:.3g}", t.p_value), to_string(t.verdict),
                     has_ratio ? fmt::format("{:.3f} -> {:.3f}", q.base, q.current) : "-",
                     has_ratio ? percent(q.change) : "-", has_ratio ? fmt::format("{:.3g}", q.p_value) : "-",
                     to_string(q.verdict), changes_text(r)});
  }
  std::vector<std::size_t> width(table[0].size(), 0);
  for (const auto& row : table)
    for (std::size_t i = 0; i < row.size(); ++i) width[i] = std::max(width[i], row[i].size());
  for (std::size_t ri = 0; ri < table.size(); ++ri) {
    const auto& row = table[ri];
    const Verdict tv = ri ? c.rows[ri - 1].throughput.verdict : Verdict::kSame;
    const Verdict qv = ri ? c.rows[ri - 1].ratio.verdict : Verdict::kSame;
    std::string line = md ? "|" : "";
    for (std::size_t i = 0; i < row.size(); ++i) {
      std::string cell = md ? " " + row[i] + " |" : fmt::format("{:<{}}", row[i], width[i]) + (i + 1 < row.size() ? "  " : "");
      if (!md && (i == 8)) cell = paint(tv, cell);
      if (!md && (i == 12)) cell = paint(qv, cell);
      line += cell;
    }
    while (!md && !line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
    if (md && ri == 0) {
      out += "|";
      for (std::size_t i = 0; i < row.size(); ++i) out += "---|";
      out += "\n";
    }
  }
  if (!c.only_in_base.empty()) out += (md ? "\n**Only in " : "\nonly in ") + base.path + (md ? "**: " : ": ") + fmt::format("{}", fmt::join(c.only_in_base, ", ")) + "\n";
  if (!c.only_in_current.empty()) out += (md ? "\n**Only in " : "\nonly in ") + current.path + (md ? "**: " : ": ") + fmt::format("{}", fmt::join(c.only_in_current, ", ")) + "\n";
  return out;
}

GateConfig load_gate_config(const std::string& path) {
  GateConfig g;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "no such gate config");
  toml::table t;
  try {
    t = toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw InputError(path, fmt::format("line {}: {}", e.source().begin.line, e.description()));
  }
  const std::set<std::string> known = {"max_ratio_drop", "alpha", "max_agree_hit_drop", "max_agree_prim_drop",
                                       "min_agree_hit", "no_new_leaks", "fail_on_missing_rows"};
  for (const auto& [key, value] : t)
    if (!known.count(std::string(key.str()))) throw InputError(path, fmt::format("'{}': unknown key", key.str()));
  const auto number = [&](const char* key, double& out, double lo, double hi) {
    if (const toml::node* n = t.get(key)) {
      const auto v = n->value<double>();
      if (!v || !(*v >= lo && *v <= hi)) throw InputError(path, fmt::format("'{}': expected a number in [{}, {}]", key, lo, hi));
      out = *v;
    }
  };
  number("max_ratio_drop", g.max_ratio_drop, 0.0, 1.0);
  number("alpha", g.alpha, 0.0, 1.0);
  number("max_agree_hit_drop", g.max_agree_hit_drop, 0.0, 1.0);
  number("max_agree_prim_drop", g.max_agree_prim_drop, 0.0, 1.0);
  number("min_agree_hit", g.min_agree_hit, 0.0, 1.0);
  if (const toml::node* n = t.get("no_new_leaks")) {
    const toml::array* a = n->as_array();
    if (!a) throw InputError(path, "'no_new_leaks': expected an array of backend-name substrings");
    g.no_new_leaks.clear();
    for (const toml::node& e : *a) {
      auto s = e.value<std::string>();
      if (!s) throw InputError(path, "'no_new_leaks': expected an array of backend-name substrings");
      g.no_new_leaks.push_back(*s);
    }
  }
  if (const toml::node* n = t.get("fail_on_missing_rows")) {
    const auto v = n->value<bool>();
    if (!v) throw InputError(path, "'fail_on_missing_rows': expected true or false");
    g.fail_on_missing_rows = *v;
  }
  return g;
}

GateResult run_gate(const ResultsFile& baseline, const std::vector<ResultsFile>& currents, const GateConfig& config) {
  GateResult g;
  CompareOptions o;
  o.alpha = config.alpha;
  o.min_effect = config.max_ratio_drop;
  const ResultsFile& current = currents.at(0);
  const Comparison c = compare_results(baseline, current, o);
  // Rows whose ratio to Embree fell significantly in every other run too.
  std::vector<Comparison> confirmations;
  for (std::size_t i = 1; i < currents.size(); ++i) confirmations.push_back(compare_results(baseline, currents[i], o));
  const auto confirmed = [&](const RowComparison& r, std::string& also) {
    for (const Comparison& other : confirmations) {
      const auto it = std::find_if(other.rows.begin(), other.rows.end(), [&](const RowComparison& x) {
        return x.scene == r.scene && x.rayset == r.rayset && x.backend == r.backend && x.threads == r.threads;
      });
      if (it == other.rows.end() || it->ratio.verdict != Verdict::kSlower) return false;
      also += fmt::format(", confirmed by another run: {:.3f}", it->ratio.current);
    }
    return true;
  };
  for (const std::string& d : machine_differences(baseline, current))
    g.notes.push_back("machine differs (" + d + "): gating on ratios to Embree and deterministic columns only");
  if (config.fail_on_missing_rows)
    for (const std::string& k : c.only_in_base) g.failures.push_back(k + ": in the baseline but not in the current run");
  // A numeric column of the baseline's (from_base) or the current run's row.
  const auto number_in = [&](const RowComparison& rc, bool from_base, const char* col) {
    const std::string& s = (from_base ? rc.base_row : rc.current_row).at(col);
    if (s.empty()) return std::nan("");
    try {
      return std::stod(s);
    } catch (const std::exception&) {
      throw InputError(from_base ? baseline.path : current.path,
                       fmt::format("column '{}' of row {} holds '{}', not a number", col, row_key(rc.base_row), s));
    }
  };
  for (const RowComparison& r : c.rows) {
    const std::string key = r.scene + "/" + r.rayset + "/" + r.backend + "/threads:" + r.threads;
    if (!r.same_rays) {
      g.failures.push_back(key + ": ray count differs from the baseline (" + r.base_row.at("rays") + " vs " +
                           r.current_row.at("rays") + "); regenerate the baseline");
      continue;
    }
    std::string also;
    if (r.ratio.verdict == Verdict::kSlower && confirmed(r, also))
      g.failures.push_back(fmt::format("{}: ratio to Embree fell {:.1f}% ({:.3f} -> {:.3f}, p = {:.2g}{}; limit {:.0f}%)", key,
                                       -100.0 * r.ratio.change, r.ratio.base, r.ratio.current, r.ratio.p_value, also,
                                       100.0 * config.max_ratio_drop));
    else if (r.ratio.verdict == Verdict::kSlower)
      g.notes.push_back(fmt::format("{}: ratio to Embree fell {:.1f}% in one run but not in the confirming run: noise",
                                    key, -100.0 * r.ratio.change));
    else if (r.ratio.verdict == Verdict::kUnsure && r.ratio.change < 0)
      g.notes.push_back(fmt::format("{}: ratio to Embree {:+.1f}% but not significant (p = {:.2g})", key,
                                    100.0 * r.ratio.change, r.ratio.p_value));
    const double hit_drop = number_in(r, true, "agree_hit") - number_in(r, false, "agree_hit");
    if (hit_drop > config.max_agree_hit_drop)
      g.failures.push_back(fmt::format("{}: agree_hit fell by {:.6f} ({} -> {}; limit {})", key, hit_drop,
                                       r.base_row.at("agree_hit"), r.current_row.at("agree_hit"), config.max_agree_hit_drop));
    const double prim_drop = number_in(r, true, "agree_prim") - number_in(r, false, "agree_prim");
    if (prim_drop > config.max_agree_prim_drop)
      g.failures.push_back(fmt::format("{}: agree_prim fell by {:.6f} ({} -> {}; limit {})", key, prim_drop,
                                       r.base_row.at("agree_prim"), r.current_row.at("agree_prim"), config.max_agree_prim_drop));
    const bool seed_faithful = r.backend.find("_seed") != std::string::npos;
    const double agree_hit = number_in(r, false, "agree_hit");
    const bool must_hit = !r.current_row.at("leaks").empty();
    if (!seed_faithful && !must_hit && agree_hit < config.min_agree_hit)
      g.failures.push_back(fmt::format("{}: agree_hit {} is below the floor {}", key, r.current_row.at("agree_hit"),
                                       config.min_agree_hit));
    for (const std::string& pattern : config.no_new_leaks) {
      if (r.backend.find(pattern) == std::string::npos || !must_hit) continue;
      const double before = number_in(r, true, "leaks"), after = number_in(r, false, "leaks");
      if (after > (std::isnan(before) ? 0.0 : before))
        g.failures.push_back(fmt::format("{}: new leaks: {} rays miss a closed mesh from inside (baseline {})", key,
                                         r.current_row.at("leaks"), r.base_row.at("leaks").empty() ? "-" : r.base_row.at("leaks")));
    }
  }
  return g;
}

}  // namespace raybench
