#include "results/compare.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>
#include <string_view>
#include <unordered_map>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <toml++/toml.h>

#include "io/error.h"
#include "measure/gbench.h"
#include "io/input_file.h"
#include "results/mann_whitney.h"
#include "results/signed_rank.h"
#include "results/metadata.h"
#include "results/results_csv.h"

namespace raybench {
namespace {

using Row = std::map<std::string, std::string>;

// How messages name a row: "scene/rayset/backend/threads:T".
std::string row_key(const Row& r) {
  return r.at("scene") + "/" + r.at("rayset") + "/" + r.at("backend") + "/threads:" + r.at("threads");
}

// A row's identity in the hash maps below: its fields joined by '\n', which
// no field read from a CSV line holds, so two rows share a key only when all
// four fields are equal (a '/' in a scene name could make row_key collide).
std::string match_key(const Row& r) {
  return r.at("scene") + '\n' + r.at("rayset") + '\n' + r.at("backend") + '\n' + r.at("threads");
}
// The key of the row of backend `backend` measured beside `r`: same scene, rayset, threads.
std::string key_beside(const Row& r, const std::string& backend) {
  return r.at("scene") + '\n' + r.at("rayset") + '\n' + backend + '\n' + r.at("threads");
}
// Whether `r` is a row of the file's reference backend, whose ratio is 1 by definition.
bool is_reference(const Row& r, const ResultsFile& f) { return r.at("backend") == f.reference; }

// Each row of a file by its match_key.
class RowIndex {
 public:
  explicit RowIndex(const ResultsFile& f) : file_(f) {
    index_.reserve(f.rows.size());
    for (std::size_t i = 0; i < f.rows.size(); ++i) index_.emplace(match_key(f.rows[i]), i);
  }
  // The row with the same key as `like`, if any.
  const Row* find(const Row& like) const { return at(match_key(like)); }
  // The row of `backend` measured beside `row` in the same run, if any.
  const Row* beside(const Row& row, const std::string& backend) const { return at(key_beside(row, backend)); }
  // The reference backend's row measured beside `row` in the same run, if any.
  const Row* reference_beside(const Row& row) const { return beside(row, file_.reference); }
  // The position of `row` in the file (for its line).
  std::size_t position(const Row& row) const { return static_cast<std::size_t>(&row - file_.rows.data()); }

 private:
  const Row* at(const std::string& key) const {
    const auto it = index_.find(key);
    return it == index_.end() ? nullptr : &file_.rows[it->second];
  }
  const ResultsFile& file_;
  std::unordered_map<std::string, std::size_t> index_;
};

// The whole of `text` as a number, or nullopt ("12abc", "" and " 1" are not).
std::optional<double> parse_number(std::string_view text) {
  double v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return v;
}

// The ';'-separated samples of a row that read_results_file checked.
std::vector<double> parse_samples(const std::string& text) {
  std::vector<double> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    out.push_back(parse_number(std::string_view(text).substr(start, end - start)).value_or(std::nan("")));
    start = end + 1;
  }
  return out;
}

// "line 7 (scene/rayset/backend/threads:T)": a row as a user finds it in the file.
std::string row_where(const ResultsFile& f, std::size_t i) {
  return i < f.lines.size() ? fmt::format("line {} ({})", f.lines[i], row_key(f.rows[i])) : row_key(f.rows[i]);
}

// The rules of compare.h for one row; throws InputError naming the file,
// the row and the column.
void check_row(const ResultsFile& f, std::size_t i) {
  const Row& r = f.rows[i];
  const auto bad = [&](const std::string& column, const std::string& problem) {
    return InputError(f.path, fmt::format("{}, column '{}': {}", row_where(f, i), column, problem));
  };
  const std::string& samples = r.at("mrays_s_samples");
  if (samples.empty()) throw bad("mrays_s_samples", "empty: no throughput samples");
  const std::vector<double> values = parse_samples(samples);
  std::size_t start = 0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    const std::size_t end = std::min(samples.find(';', start), samples.size());
    if (!(std::isfinite(values[k]) && values[k] > 0))
      throw bad("mrays_s_samples", fmt::format("sample {} of {} is '{}', not a finite number > 0", k + 1, values.size(),
                                               samples.substr(start, end - start)));
    start = end + 1;
  }
  for (const char* column : {"agree_hit", "agree_prim"}) {
    const std::string& text = r.at(column);
    if (text.empty() && std::string_view(column) == "agree_prim" && r.at("query") == "occluded") continue;
    const std::optional<double> v = parse_number(text);
    if (!v || !(*v >= 0.0 && *v <= 1.0))
      throw bad(column, text.empty() ? std::string("empty, expected a number in [0, 1]")
                                     : fmt::format("'{}' is not a number in [0, 1]", text));
  }
  const std::string& leaks = r.at("leaks");
  unsigned long long count = 0;
  const auto [end, ec] = std::from_chars(leaks.data(), leaks.data() + leaks.size(), count);
  if (!leaks.empty() && (ec != std::errc() || end != leaks.data() + leaks.size()))
    throw bad("leaks", fmt::format("'{}' is not a count of rays (empty, or a whole number >= 0)", leaks));
}

// Throws InputError naming the first row of a backend other than the
// reference without the reference's row of its scene, ray set and threads
// in the same file.
void require_reference_rows(const ResultsFile& f) {
  const RowIndex index(f);
  for (std::size_t i = 0; i < f.rows.size(); ++i)
    if (!is_reference(f.rows[i], f) && !index.reference_beside(f.rows[i]))
      throw InputError(f.path, fmt::format("{}: no {} row for {}/{}/threads:{}: a baseline needs the {} "
                                           "backend's rows, the reference of every ratio the gate checks",
                                           row_where(f, i), f.reference, f.rows[i].at("scene"), f.rows[i].at("rayset"),
                                           f.rows[i].at("threads"), f.reference));
}

// The reference of `f` (see ResultsFile::reference), checked against every
// row's `reference` column; and, in a file timed in rounds, every row's
// sample count against its reference row's. Throws InputError.
void read_reference(ResultsFile& f) {
  const std::string meta = metadata_path_for(f.path);
  const auto declared = f.metadata.find("reference_backend");
  const bool from_metadata = declared != f.metadata.end() && !declared->second.empty();
  std::size_t first_column = f.rows.size();  // the first row that names a reference
  for (std::size_t i = 0; i < f.rows.size(); ++i) {
    const auto it = f.rows[i].find("reference");
    const std::string named = it == f.rows[i].end() ? "" : it->second;
    if (named.empty()) continue;
    if (from_metadata && named != declared->second)
      throw InputError(f.path, fmt::format("{}, column 'reference': '{}', but {} says reference_backend = '{}'",
                                           row_where(f, i), named, meta, declared->second));
    if (!from_metadata && first_column < f.rows.size() && named != f.rows[first_column].at("reference"))
      throw InputError(f.path, fmt::format("{}, column 'reference': '{}', but line {} says '{}': one run has one reference",
                                           row_where(f, i), named, f.lines.at(first_column),
                                           f.rows[first_column].at("reference")));
    if (first_column == f.rows.size()) first_column = i;
  }
  if (from_metadata) f.reference = declared->second;
  else if (first_column < f.rows.size()) f.reference = f.rows[first_column].at("reference");
  const auto timing = f.metadata.find("timing");
  f.paired = timing != f.metadata.end() && timing->second == "rounds";
  if (!f.paired) return;
  const RowIndex index(f);
  for (std::size_t i = 0; i < f.rows.size(); ++i) {
    const Row* ref = index.reference_beside(f.rows[i]);
    if (!ref || ref == &f.rows[i]) continue;
    const std::size_t mine = parse_samples(f.rows[i].at("mrays_s_samples")).size();
    const std::size_t theirs = parse_samples(ref->at("mrays_s_samples")).size();
    if (mine != theirs)
      throw InputError(f.path, fmt::format("{}, column 'mrays_s_samples': {} samples, but its {} row ({}) has {}: "
                                           "timed in rounds ({}), the samples pair round by round",
                                           row_where(f, i), mine, f.reference, row_where(f, index.position(*ref)), theirs,
                                           meta));
  }
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

// A row's ratio samples to the reference row measured beside it in the same
// run (same scene, ray set, threads): in a file timed in rounds, sample i over
// the reference's sample i (read_reference checked the counts); otherwise
// each sample over the reference's median. Empty without a reference row.
std::vector<double> ratio_samples(const ResultsFile& f, const RowIndex& index, const Row& row) {
  if (is_reference(row, f)) return {};
  const Row* e = index.reference_beside(row);
  if (!e) return {};
  const std::vector<double> reference = parse_samples(e->at("mrays_s_samples"));
  std::vector<double> out = parse_samples(row.at("mrays_s_samples"));
  if (f.paired && reference.size() == out.size()) {
    for (std::size_t i = 0; i < out.size(); ++i) out[i] /= reference[i];
    return out;
  }
  const double m = median(reference);
  if (!(m > 0)) return {};
  for (double& v : out) v /= m;
  return out;
}

std::string percent(double change) { return fmt::format("{:+.1f}%", 100.0 * change); }

}  // namespace

// A JSON string literal (RFC 8259: quote, backslash and control characters escaped).
std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\u{:04x}", static_cast<unsigned>(static_cast<unsigned char>(c)));
      continue;
    }
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// The shortest text that reads back as the same double.
std::string json_number(double v) { return std::isfinite(v) ? fmt::format("{}", v) : "null"; }

ResultsFile read_results_file(const std::string& path) {
  ResultsFile f;
  f.path = path;
  check_input_file(path, "results file");
  f.rows = read_results_csv(path, &f.lines);
  if (f.rows.empty()) throw InputError(path, "no result rows (only a header): nothing to compare");
  std::unordered_map<std::string, std::size_t> seen;
  seen.reserve(f.rows.size());
  for (std::size_t i = 0; i < f.rows.size(); ++i) {
    check_row(f, i);
    const auto [it, fresh] = seen.emplace(match_key(f.rows[i]), i);
    if (!fresh)
      throw InputError(path, fmt::format("{} repeats line {}: each (scene, rayset, backend, threads) may appear once",
                                         row_where(f, i), f.lines.at(it->second)));
  }
  const std::string meta = metadata_path_for(path);
  std::error_code ec;
  if (std::filesystem::exists(meta, ec)) {
    check_input_file(meta, "results metadata");
    try {
      const toml::table t = toml::parse_file(meta);
      for (const auto& [key, value] : t)
        if (auto s = value.value<std::string>()) f.metadata[std::string(key.str())] = *s;
    } catch (const toml::parse_error& e) {
      throw InputError(meta, fmt::format("line {}: {}", e.source().begin.line, e.description()));
    }
  }
  // A file without `status` is from a run older than partial files: complete.
  if (const auto status = f.metadata.find("status"); status != f.metadata.end()) {
    if (status->second == "partial") {
      const auto progress = f.metadata.find("progress");
      f.partial.push_back({path, progress == f.metadata.end() ? "" : progress->second});
    } else if (status->second != "complete") {
      throw InputError(meta, fmt::format("'status': '{}', expected \"partial\" or \"complete\"", status->second));
    }
  }
  read_reference(f);
  return f;
}

std::vector<std::string> partial_notes(const ResultsFile& f) {
  std::vector<std::string> out;
  for (const PartialFile& p : f.partial)
    out.push_back(fmt::format("{} is partial ({}): its run was interrupted or is still going, so the rows of its "
                              "unfinished scenes are missing",
                              p.path, p.progress.empty() ? "progress unknown" : p.progress));
  return out;
}

ResultsFile pool_runs(const std::vector<ResultsFile>& runs) {
  if (runs.empty()) throw InputError("", "no results to pool");
  for (const ResultsFile& run : runs) {
    if (run.reference != runs.front().reference)
      throw InputError(run.path, fmt::format("its ratios are to '{}', those of {} to '{}': runs pooled as one baseline "
                                             "need one reference",
                                             run.reference, runs.front().path, runs.front().reference));
    require_reference_rows(run);
  }
  ResultsFile pooled = runs.front();
  if (runs.size() == 1) return pooled;
  pooled.paired = false;  // the pairs are kept in the rescaled samples (pool_runs in compare.h)
  std::vector<RowIndex> indexes;
  indexes.reserve(runs.size());
  for (const ResultsFile& run : runs) indexes.emplace_back(run);
  for (std::size_t i = 1; i < runs.size(); ++i) {
    pooled.path += " + " + runs[i].path;
    pooled.partial.insert(pooled.partial.end(), runs[i].partial.begin(), runs[i].partial.end());
  }
  for (auto& row : pooled.rows) {
    // Every run's own reference samples for this row, and the pooled median.
    std::vector<std::vector<double>> reference_per_run;
    std::vector<double> all_reference;
    for (const RowIndex& index : indexes) {
      const Row* e = index.reference_beside(row);
      reference_per_run.push_back(e ? parse_samples(e->at("mrays_s_samples")) : std::vector<double>{});
      all_reference.insert(all_reference.end(), reference_per_run.back().begin(), reference_per_run.back().end());
    }
    const double pooled_reference = all_reference.empty() ? 0.0 : median(all_reference);
    std::string samples;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const Row* r = indexes[i].find(row);
      if (!r) continue;
      const std::vector<double> own = parse_samples(r->at("mrays_s_samples"));
      const std::vector<double>& reference = reference_per_run[i];
      const bool rescale = !is_reference(row, pooled) && !reference.empty() && pooled_reference > 0;
      const bool pairs = runs[i].paired && reference.size() == own.size();
      const double run_median = reference.empty() ? 0.0 : median(reference);
      for (std::size_t k = 0; k < own.size(); ++k) {
        const double divisor = pairs ? reference[k] : run_median;
        samples += fmt::format("{}{:.9g}", samples.empty() ? "" : ";",
                               rescale && divisor > 0 ? own[k] * pooled_reference / divisor : own[k]);
      }
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
  if (base.reference != current.reference)
    throw InputError(current.path, fmt::format("its ratios are to '{}' (reference_backend), those of {} to '{}': runs "
                                               "measured against different references do not compare",
                                               current.reference, base.path, base.reference));
  Comparison c;
  const RowIndex base_index(base), current_index(current);
  for (const auto& b : base.rows) {
    const Row* n = current_index.find(b);
    if (!n) {
      c.only_in_base.push_back(row_key(b));
      continue;
    }
    RowComparison rc;
    rc.scene = b.at("scene");
    rc.rayset = b.at("rayset");
    rc.backend = b.at("backend");
    rc.threads = b.at("threads");
    rc.base_row = &b;
    rc.current_row = n;
    rc.same_rays = b.at("rays") == n->at("rays");
    if (rc.same_rays) {
      rc.throughput = compare_samples(parse_samples(b.at("mrays_s_samples")), parse_samples(n->at("mrays_s_samples")), options);
      rc.ratio = compare_samples(ratio_samples(base, base_index, b), ratio_samples(current, current_index, *n), options);
      for (const std::string& col : deterministic_columns())
        if (b.at(col) != n->at(col)) rc.changes.push_back({col, b.at(col), n->at(col)});
    }
    c.rows.push_back(std::move(rc));
  }
  for (const auto& r : current.rows)
    if (!base_index.find(r)) c.only_in_current.push_back(row_key(r));
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
  std::vector<std::string> notes = partial_notes(base);
  for (const std::string& n : partial_notes(current)) notes.push_back(n);
  const auto changes_text = [](const RowComparison& r) {
    if (!r.same_rays) return std::string("different ray counts: not compared");
    std::string s;
    for (const auto& ch : r.changes)
      s += (s.empty() ? "" : "; ") + ch.column + " " + (ch.base.empty() ? "-" : ch.base) + " -> " + (ch.current.empty() ? "-" : ch.current);
    return s;
  };
  std::string out;
  if (format == OutputFormat::kJson) {
    out += "{\n  \"base\": " + json_string(base.path) + ",\n  \"current\": " + json_string(current.path) +
           ",\n  \"reference_backend\": " + json_string(current.reference) + ",\n  \"rows\": [\n";
    for (std::size_t i = 0; i < c.rows.size(); ++i) {
      const RowComparison& r = c.rows[i];
      std::string changes;
      for (const auto& ch : r.changes)
        changes += (changes.empty() ? "" : ", ") + fmt::format("{{\"column\": {}, \"base\": {}, \"current\": {}}}",
                                                               json_string(ch.column), json_string(ch.base), json_string(ch.current));
      // A comparison that was not made (different ray counts) has null numbers.
      const auto sample = [&](const SampleComparison& s) {
        const bool made = s.verdict != Verdict::kNotApplicable;
        const auto number = [&](double v) { return made ? json_number(v) : std::string("null"); };
        return fmt::format("{{\"base\": {}, \"current\": {}, \"change\": {}, \"p_value\": {}, \"verdict\": {}}}",
                           number(s.base), number(s.current), number(s.change), number(s.p_value),
                           json_string(to_string(s.verdict)));
      };
      // The reference backend's own ratio is 1 by definition, as the CSV says (see compare.h).
      const bool reference = r.backend == current.reference;
      const std::string ratio =
          reference ? R"({"base": 1, "current": 1, "change": 0, "p_value": null, "verdict": "reference"})" : sample(r.ratio);
      // ratio_to_embree, as before --reference: the same comparison when Embree is the reference.
      const std::string to_embree = current.reference == "embree" ? ratio : sample(SampleComparison{});
      out += fmt::format(
          "    {{\"scene\": {}, \"rayset\": {}, \"backend\": {}, \"threads\": {}, \"reference\": {}, "
          "\"same_rays\": {}, \"mrays_s\": {}, \"ratio_to_reference\": {}, \"ratio_to_embree\": {}, \"changes\": [{}]}}{}\n",
          json_string(r.scene), json_string(r.rayset), json_string(r.backend), r.threads, reference ? "true" : "false",
          r.same_rays ? "true" : "false", sample(r.throughput), ratio, to_embree, changes, i + 1 < c.rows.size() ? "," : "");
    }
    const auto list = [&](const std::vector<std::string>& v) {
      std::string s;
      for (const auto& e : v) s += (s.empty() ? "" : ", ") + json_string(e);
      return "[" + s + "]";
    };
    out += "  ],\n  \"only_in_base\": " + list(c.only_in_base) + ",\n  \"only_in_current\": " + list(c.only_in_current) +
           ",\n  \"notes\": " + list(notes) + "\n}\n";
    return out;
  }
  const bool md = format == OutputFormat::kMarkdown;
  std::vector<std::vector<std::string>> table;
  table.push_back({"scene", "rayset", "backend", "thr", "Mrays/s base", "current", "change", "p", "verdict", "x " + current.reference,
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
  for (const std::string& n : notes) out += (md ? "\n**Note**: " : "\nnote: ") + n + "\n";
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

namespace {

// A failure of the row `r` (of the gated run), its message prefixed with the row.
GateFailure failure_of(const Row& r, std::string check, std::string message) {
  GateFailure f;
  f.scene = r.at("scene");
  f.rayset = r.at("rayset");
  f.backend = r.at("backend");
  f.threads = r.at("threads");
  f.check = std::move(check);
  f.message = row_key(r) + ": " + message;
  return f;
}

// A numeric column of a row; NaN when empty ("not applicable").
// read_results_file checked the values.
double number_of(const Row& r, const char* column) { return parse_number(r.at(column)).value_or(std::nan("")); }

}  // namespace

GateResult run_gate(const ResultsFile& baseline, const std::vector<ResultsFile>& currents, const GateConfig& config) {
  GateResult g;
  g.mode = "runs";
  g.reference = baseline.reference;
  require_reference_rows(baseline);
  const std::string& ref = baseline.reference;
  CompareOptions o;
  o.alpha = config.alpha;
  o.min_effect = config.max_ratio_drop;
  const ResultsFile& current = currents.at(0);
  const Comparison c = compare_results(baseline, current, o);
  // Rows whose ratio to the reference fell significantly in every other run too.
  struct Confirmation {
    Comparison comparison;
    std::unordered_map<std::string, std::size_t> by_key;  // match_key -> index in comparison.rows
  };
  std::vector<Confirmation> confirmations;
  for (std::size_t i = 1; i < currents.size(); ++i) {
    Confirmation& k = confirmations.emplace_back(Confirmation{compare_results(baseline, currents[i], o), {}});
    for (std::size_t j = 0; j < k.comparison.rows.size(); ++j) k.by_key.emplace(match_key(*k.comparison.rows[j].base_row), j);
  }
  const auto confirmed = [&](const RowComparison& r, std::string& also) {
    for (const Confirmation& other : confirmations) {
      const auto it = other.by_key.find(match_key(*r.base_row));
      if (it == other.by_key.end() || other.comparison.rows[it->second].ratio.verdict != Verdict::kSlower) return false;
      also += fmt::format(", confirmed by another run: {:.3f}", other.comparison.rows[it->second].ratio.current);
    }
    return true;
  };
  for (const std::string& n : partial_notes(baseline)) g.notes.push_back(n);
  for (const ResultsFile& run : currents)
    for (const std::string& n : partial_notes(run)) g.notes.push_back(n);
  for (const std::string& d : machine_differences(baseline, current))
    g.notes.push_back("machine differs (" + d + "): gating on ratios to " + ref + " and deterministic columns only");
  const RowIndex current_index(current);
  if (config.fail_on_missing_rows)
    for (const Row& b : baseline.rows)
      if (!current_index.find(b)) g.failures.push_back(failure_of(b, "missing", "in the baseline but not in the current run"));
  // A baseline row measured in a current run without its reference row: its
  // ratio, what the gate checks, cannot be computed there.
  for (const ResultsFile& run : currents) {
    const RowIndex index(run);
    for (const Row& b : baseline.rows)
      if (!is_reference(b, baseline) && index.find(b) && !index.reference_beside(b))
        g.failures.push_back(failure_of(b, "missing",
                                        fmt::format("no {} row for {}/{}/threads:{} in {}: its ratio to {} cannot be checked",
                                                    ref, b.at("scene"), b.at("rayset"), b.at("threads"), run.path, ref)));
  }
  for (const RowComparison& r : c.rows) {
    const Row& base = *r.base_row;
    const Row& now = *r.current_row;
    if (!r.same_rays) {
      GateFailure f = failure_of(base, "rays", "ray count differs from the baseline (" + base.at("rays") + " vs " +
                                                   now.at("rays") + "); regenerate the baseline");
      f.value = number_of(now, "rays");
      f.against = number_of(base, "rays");
      g.failures.push_back(f);
      continue;
    }
    std::string also;
    const std::string key = row_key(base);
    if (r.ratio.verdict == Verdict::kSlower && confirmed(r, also)) {
      GateFailure f = failure_of(base, "speed",
                                 fmt::format("ratio to {} fell {:.1f}% ({:.3f} -> {:.3f}, p = {:.2g}{}; limit {:.0f}%)", ref,
                                             -100.0 * r.ratio.change, r.ratio.base, r.ratio.current, r.ratio.p_value, also,
                                             100.0 * config.max_ratio_drop));
      f.value = r.ratio.current;
      f.against = r.ratio.base;
      f.change = r.ratio.change;
      f.p_value = r.ratio.p_value;
      f.limit = config.max_ratio_drop;
      g.failures.push_back(f);
    } else if (r.ratio.verdict == Verdict::kSlower) {
      g.notes.push_back(fmt::format("{}: ratio to {} fell {:.1f}% in one run but not in the confirming run: noise", key,
                                    ref, -100.0 * r.ratio.change));
    } else if (r.ratio.verdict == Verdict::kUnsure && r.ratio.change < 0) {
      g.notes.push_back(fmt::format("{}: ratio to {} {:+.1f}% but not significant (p = {:.2g})", key, ref,
                                    100.0 * r.ratio.change, r.ratio.p_value));
    }
    // A value the baseline recorded and the current run does not (only an
    // occluded row may leave agree_prim empty, so the query changed).
    for (const char* col : {"agree_hit", "agree_prim", "leaks"})
      if (!std::isnan(number_of(base, col)) && std::isnan(number_of(now, col))) {
        GateFailure f = failure_of(base, col, fmt::format("{} is empty in the current run (baseline {})", col, base.at(col)));
        f.against = number_of(base, col);
        g.failures.push_back(f);
      }
    for (const auto& [col, limit] : {std::pair<const char*, double>{"agree_hit", config.max_agree_hit_drop},
                                     std::pair<const char*, double>{"agree_prim", config.max_agree_prim_drop}}) {
      const double drop = number_of(base, col) - number_of(now, col);
      if (!(drop > limit)) continue;
      GateFailure f = failure_of(base, col, fmt::format("{} fell by {:.6f} ({} -> {}; limit {})", col, drop, base.at(col),
                                                        now.at(col), limit));
      f.value = number_of(now, col);
      f.against = number_of(base, col);
      f.change = -drop;
      f.limit = limit;
      g.failures.push_back(f);
    }
    const bool seed_faithful = r.backend.find("_seed") != std::string::npos;
    const double agree_hit = number_of(now, "agree_hit");
    const bool must_hit = !now.at("leaks").empty();
    if (!seed_faithful && !must_hit && agree_hit < config.min_agree_hit) {
      GateFailure f = failure_of(base, "agree_hit",
                                 fmt::format("agree_hit {} is below the floor {}", now.at("agree_hit"), config.min_agree_hit));
      f.value = agree_hit;
      f.limit = config.min_agree_hit;
      g.failures.push_back(f);
    }
    for (const std::string& pattern : config.no_new_leaks) {
      if (r.backend.find(pattern) == std::string::npos || !must_hit) continue;
      const double before = number_of(base, "leaks"), after = number_of(now, "leaks");
      if (after > (std::isnan(before) ? 0.0 : before)) {
        GateFailure f = failure_of(base, "leaks",
                                   fmt::format("new leaks: {} rays miss a closed mesh from inside (baseline {})",
                                               now.at("leaks"), base.at("leaks").empty() ? "-" : base.at("leaks")));
        f.value = after;
        f.against = std::isnan(before) ? 0.0 : before;
        g.failures.push_back(f);
        break;
      }
    }
  }
  return g;
}

GateResult run_within_run_gate(const ResultsFile& run, const std::vector<std::string>& candidates,
                               const GateConfig& config) {
  GateResult g;
  g.mode = "within-run";
  g.reference = run.reference;
  const std::string& ref = run.reference;
  if (!run.paired)
    throw InputError(run.path, fmt::format("its samples are not paired by round (no timing = \"rounds\" in {}): the "
                                           "gate within one run needs them; re-run with this raybench",
                                           metadata_path_for(run.path)));
  if (candidates.empty()) throw InputError("--candidate", "name at least one backend of the run to gate");
  std::vector<std::string> backends;  // in the run's order
  for (const Row& r : run.rows)
    if (std::find(backends.begin(), backends.end(), r.at("backend")) == backends.end()) backends.push_back(r.at("backend"));
  for (const std::string& c : candidates) {
    if (c == ref)
      throw InputError("--candidate", fmt::format("'{}' is the run's reference (reference_backend): name another of "
                                                  "its backends ({})", c, fmt::join(backends, ", ")));
    if (std::find(backends.begin(), backends.end(), c) == backends.end())
      throw InputError("--candidate", fmt::format("'{}' is not a backend of {}; it has {}", c, run.path,
                                                  fmt::join(backends, ", ")));
  }
  // A run that stopped early (a candidate that crashed the process, say)
  // lacks the rows of its unfinished scenes: nothing here can pass them.
  for (const std::string& n : partial_notes(run)) {
    GateFailure f;
    f.check = "missing";
    f.message = n;
    g.failures.push_back(f);
  }
  const RowIndex index(run);
  // Every (scene, rayset, threads) of the run, in its order, by a row there.
  std::vector<const Row*> places;
  std::set<std::string> seen;
  for (const Row& r : run.rows)
    if (seen.insert(key_beside(r, "")).second) places.push_back(&r);
  const std::size_t min_rounds = signed_rank_min_pairs(config.alpha);
  std::size_t untestable = 0, fewest_rounds = std::numeric_limits<std::size_t>::max();
  std::set<std::string> done;
  for (const std::string& candidate : candidates) {
    if (!done.insert(candidate).second) continue;  // named twice
    for (const Row* place : places) {
      const Row* cand = index.beside(*place, candidate);
      const Row* reference = index.reference_beside(*place);
      if (!cand || !reference) {
        Row named = *place;
        named["backend"] = candidate;
        const std::string what = !cand && !reference ? fmt::format("neither {} nor the reference {} has a row", candidate, ref)
                                 : !cand           ? fmt::format("no {} row in {}", candidate, run.path)
                                                   : fmt::format("no row of the reference {} in {}", ref, run.path);
        if (config.fail_on_missing_rows) g.failures.push_back(failure_of(named, "missing", what));
        else g.notes.push_back(row_key(named) + ": " + what);
        continue;
      }
      if (cand->at("rays") != reference->at("rays")) {
        GateFailure f = failure_of(*cand, "rays", fmt::format("traced {} rays, the reference {} {}", cand->at("rays"), ref,
                                                              reference->at("rays")));
        f.value = number_of(*cand, "rays");
        f.against = number_of(*reference, "rays");
        g.failures.push_back(f);
        continue;
      }
      // Speed: the rounds' paired ratios (read_reference checked the counts).
      const std::vector<double> ratios = ratio_samples(run, index, *cand);
      std::vector<double> logs;
      for (double v : ratios) logs.push_back(std::log(v));
      const double m = median(ratios);
      const SignedRank test = signed_rank_less(logs);
      g.speeds.push_back({cand->at("scene"), cand->at("rayset"), candidate, cand->at("threads"), ratios.size(), m,
                          *std::min_element(ratios.begin(), ratios.end()), *std::max_element(ratios.begin(), ratios.end()),
                          test.p_value});
      const bool testable = ratios.size() >= min_rounds;
      if (!testable) {
        ++untestable;
        fewest_rounds = std::min(fewest_rounds, ratios.size());
      }
      if (m < 1.0 - config.max_ratio_drop) {
        if (test.p_value < config.alpha) {
          GateFailure f = failure_of(*cand, "speed",
                                     fmt::format("{:.1f}% slower than the reference {} (paired ratio {:.3f} over {} rounds, "
                                                 "p = {:.2g}; limit {:.0f}%)",
                                                 100.0 * (1.0 - m), ref, m, ratios.size(), test.p_value,
                                                 100.0 * config.max_ratio_drop));
          f.value = m;
          f.against = 1.0;
          f.change = m - 1.0;
          f.p_value = test.p_value;
          f.limit = config.max_ratio_drop;
          g.failures.push_back(f);
        } else if (!testable) {
          g.notes.push_back(fmt::format("{}: {:.1f}% slower than the reference {} (paired ratio {:.3f}), but {} rounds can "
                                        "never give p < {}: re-run with --reps {} or more to gate its speed",
                                        row_key(*cand), 100.0 * (1.0 - m), ref, m, ratios.size(), config.alpha, min_rounds));
        } else {
          g.notes.push_back(fmt::format("{}: {:.1f}% slower than the reference {} but not significant (p = {:.2g})",
                                        row_key(*cand), 100.0 * (1.0 - m), ref, test.p_value));
        }
      }
      // Agreement with Embree and leaks: no worse than the reference's.
      for (const char* col : {"agree_hit", "agree_prim", "leaks"})
        if (!std::isnan(number_of(*reference, col)) && std::isnan(number_of(*cand, col))) {
          GateFailure f = failure_of(*cand, col, fmt::format("{} is empty, the reference {} has {}", col, ref,
                                                             reference->at(col)));
          f.against = number_of(*reference, col);
          g.failures.push_back(f);
        }
      for (const auto& [col, limit] : {std::pair<const char*, double>{"agree_hit", config.max_agree_hit_drop},
                                       std::pair<const char*, double>{"agree_prim", config.max_agree_prim_drop}}) {
        const double drop = number_of(*reference, col) - number_of(*cand, col);
        if (!(drop > limit)) continue;
        GateFailure f = failure_of(*cand, col, fmt::format("{} {} is {:.6f} below the reference {}'s {} (limit {})", col,
                                                           cand->at(col), drop, ref, reference->at(col), limit));
        f.value = number_of(*cand, col);
        f.against = number_of(*reference, col);
        f.change = -drop;
        f.limit = limit;
        g.failures.push_back(f);
      }
      const double leaks = number_of(*cand, "leaks"), reference_leaks = number_of(*reference, "leaks");
      if (leaks > reference_leaks) {
        GateFailure f = failure_of(*cand, "leaks",
                                   fmt::format("{} rays miss a closed mesh from inside, the reference {} {}",
                                               cand->at("leaks"), ref, reference->at("leaks")));
        f.value = leaks;
        f.against = reference_leaks;
        g.failures.push_back(f);
      }
    }
  }
  if (untestable > 0)
    g.notes.push_back(fmt::format("{} row{} had {} rounds or fewer: the signed-rank test needs {} to ever reach p < {}, so "
                                  "their speed is not gated (run with --reps {} or more)",
                                  untestable, untestable == 1 ? "" : "s", fewest_rounds, min_rounds, config.alpha, min_rounds));
  return g;
}

GateResult run_within_run_gate(const std::vector<ResultsFile>& runs, const std::vector<std::string>& candidates,
                               const GateConfig& config) {
  GateResult g = run_within_run_gate(runs.front(), candidates, config);
  for (std::size_t i = 1; i < runs.size(); ++i) {
    if (runs[i].reference != runs.front().reference)
      throw InputError(runs[i].path, fmt::format("its reference backend is '{}', {}'s is '{}': runs gated together "
                                                 "must share their reference",
                                                 runs[i].reference, runs.front().path, runs.front().reference));
    const GateResult other = run_within_run_gate(runs[i], candidates, config);
    std::erase_if(g.failures, [&](const GateFailure& f) {
      if (f.check != "speed") return false;
      const bool again = std::any_of(other.failures.begin(), other.failures.end(), [&](const GateFailure& o) {
        return o.check == "speed" && o.scene == f.scene && o.rayset == f.rayset && o.backend == f.backend &&
               o.threads == f.threads;
      });
      if (!again)
        g.notes.push_back(fmt::format("{}/{}/{}/threads:{}: slower in {} but not in {}: not counted (a regression "
                                      "reproduces in every run)",
                                      f.scene, f.rayset, f.backend, f.threads, runs.front().path, runs[i].path));
      return !again;
    });
  }
  return g;
}

std::string format_paired_speeds(const GateResult& g) {
  std::vector<std::vector<std::string>> table = {
      {"scene", "rayset", "backend", "thr", "rounds", "x " + g.reference, "[min - max]", "p (slower)"}};
  for (const PairedSpeed& s : g.speeds)
    table.push_back({s.scene, s.rayset, s.backend, s.threads, std::to_string(s.rounds), fmt::format("{:.3f}", s.ratio),
                     fmt::format("[{:.3f} - {:.3f}]", s.ratio_min, s.ratio_max), fmt::format("{:.2g}", s.p_value)});
  std::vector<std::size_t> width(table[0].size(), 0);
  for (const auto& row : table)
    for (std::size_t i = 0; i < row.size(); ++i) width[i] = std::max(width[i], row[i].size());
  std::string out;
  for (const auto& row : table) {
    std::string line;
    for (std::size_t i = 0; i < row.size(); ++i) line += fmt::format("{:<{}}", row[i], width[i]) + "  ";
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out += line + "\n";
  }
  return out;
}

std::string format_gate_json(const GateResult& g, const std::vector<std::string>& currents,
                             const std::vector<std::string>& baselines, const std::vector<std::string>& candidates) {
  const auto list = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& e : v) s += (s.empty() ? "" : ", ") + json_string(e);
    return "[" + s + "]";
  };
  std::string out = fmt::format("{{\n  \"verdict\": {},\n  \"mode\": {},\n  \"reference\": {},\n  \"current\": {},\n"
                                "  \"baseline\": {},\n  \"candidates\": {},\n  \"failures\": [",
                                json_string(g.failures.empty() ? "pass" : "fail"), json_string(g.mode),
                                json_string(g.reference), list(currents), list(baselines), list(candidates));
  for (std::size_t i = 0; i < g.failures.size(); ++i) {
    const GateFailure& f = g.failures[i];
    const std::optional<double> threads = parse_number(f.threads);
    out += fmt::format(
        "{}\n    {{\"scene\": {}, \"rayset\": {}, \"backend\": {}, \"threads\": {}, \"check\": {}, \"kind\": {}, "
        "\"message\": {}, \"value\": {}, \"against\": {}, \"change\": {}, \"p_value\": {}, \"limit\": {}}}",
        i ? "," : "", json_string(f.scene), json_string(f.rayset), json_string(f.backend),
        threads ? json_number(*threads) : "null", json_string(f.check), f.kind.empty() ? "null" : json_string(f.kind),
        json_string(f.message), json_number(f.value), json_number(f.against), json_number(f.change),
        json_number(f.p_value), json_number(f.limit));
  }
  out += std::string(g.failures.empty() ? "" : "\n  ") + "],\n  \"notes\": " + list(g.notes) + "\n}\n";
  return out;
}

}  // namespace raybench
