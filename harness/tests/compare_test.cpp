// Specification of what compare and gate read (harness/src/results/compare.h): a
// value that cannot be read as a number is bad input naming the file, row and
// column; a baseline without the reference backend is bad input, a current
// run without it a failure; partial files are named; rows are matched
// through hash maps, so 100,000 rows compare (ctest's TIMEOUT guards it).
#include "results/compare.h"

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "results/results_csv.h"
#include "test_util.h"

namespace raybench {
namespace {

using testing::input_error_of;
using testing::TempDir;
using Fields = std::map<std::string, std::string>;

// A plausible row of the results schema, `changes` overriding some columns.
Fields row(const Fields& changes = {}) {
  Fields r = {{"scene", "terrain"},   {"triangles", "100"},     {"rayset", "primary"},     {"query", "intersect"},
              {"rays", "1000"},       {"backend", "embree"},    {"threads", "1"},          {"build_ms", "1"},
              {"build_ms_min", "1"},  {"build_ms_max", "1"},    {"memory_bytes", "4096"},  {"mrays_s", "10"},
              {"mrays_s_min", "9"},   {"mrays_s_max", "11"},    {"reps", "5"},             {"mrays_s_samples", "9;9.5;10;10.5;11"},
              {"ratio_to_embree", "1"}, {"hit_rate", "0.5"},    {"agree_hit", "1"},        {"agree_prim", "1"},
              {"prim_ties", "0"},     {"t_relerr_max", "0"},    {"t_relerr_p999", "0"},    {"disagreements", "0"},
              {"leaks", ""},          {"sah_cost", ""},         {"reference", "embree"},   {"ratio_to_reference", "1"},
              {"plugin", ""},         {"representation", "triangles"}};
  for (const auto& [k, v] : changes) r[k] = v;
  return r;
}

// One CSV line: the schema's columns of `r` (or their names), and a newline.
std::string line_of(const Fields* r) {
  std::string line;
  for (const std::string& c : result_columns()) {
    if (!line.empty()) line += ',';
    line += r ? r->at(c) : c;
  }
  line += '\n';
  return line;
}

// The CSV text of `rows` under the schema's header.
std::string csv(const std::vector<Fields>& rows) {
  std::string out = line_of(nullptr);
  for (const Fields& r : rows) out += line_of(&r);
  return out;
}

// An Embree row and a bvh2 row beside it (lines 2 and 3), `bvh2` overriding the latter.
std::string embree_and_bvh2(const Fields& bvh2) {
  Fields ours = row({{"backend", "bvh2"}});
  for (const auto& [k, v] : bvh2) ours[k] = v;
  return csv({row(), ours});
}

TEST(ReadResultsFile, EveryThroughputSampleIsAFiniteNumberAboveZero) {
  TempDir dir;
  // The inputs: NaN, empty, zero, negative, infinite; and a gap or
  // trailing text, which a lenient number parser would accept.
  for (const char* samples : {"nan", "", "0", "-3", "inf", "-inf", "10;nan;10", "10;;10", "10;", "12abc", "0x"}) {
    const std::string path = dir.write("r.csv", embree_and_bvh2({{"mrays_s_samples", samples}}));
    const std::string error = input_error_of([&] { read_results_file(path); });
    EXPECT_NE(error.find(path), std::string::npos) << samples << ": " << error;
    EXPECT_NE(error.find("line 3 (terrain/primary/bvh2/threads:1)"), std::string::npos) << samples << ": " << error;
    EXPECT_NE(error.find("column 'mrays_s_samples'"), std::string::npos) << samples << ": " << error;
  }
  const std::string error = input_error_of(
      [&] { read_results_file(dir.write("r.csv", embree_and_bvh2({{"mrays_s_samples", "10;nan;10"}}))); });
  EXPECT_NE(error.find("sample 2 of 3 is 'nan', not a finite number > 0"), std::string::npos) << error;
  EXPECT_EQ(input_error_of([&] { read_results_file(dir.write("r.csv", embree_and_bvh2({{"mrays_s_samples", "1e-3;7"}}))); }),
            "");
}

TEST(ReadResultsFile, AgreementIsANumberInZeroToOne) {
  TempDir dir;
  for (const char* column : {"agree_hit", "agree_prim"})
    for (const char* value : {"1.5", "-0.1", "nan", "inf", "", "lots"}) {
      const std::string path = dir.write("r.csv", embree_and_bvh2({{column, value}}));
      const std::string error = input_error_of([&] { read_results_file(path); });
      EXPECT_NE(error.find(path + ": line 3 (terrain/primary/bvh2/threads:1), column '" + column + "'"), std::string::npos)
          << column << " = '" << value << "': " << error;
    }
  // Occlusion queries have no primitive to compare: agree_prim is empty there.
  const std::string occluded =
      dir.write("o.csv", csv({row({{"rayset", "shadow"}, {"query", "occluded"}, {"agree_prim", ""}})}));
  EXPECT_EQ(input_error_of([&] { read_results_file(occluded); }), "");
  for (const char* value : {"0", "1", "0.999"})
    EXPECT_EQ(input_error_of([&] { read_results_file(dir.write("r.csv", embree_and_bvh2({{"agree_hit", value}}))); }), "");
}

TEST(ReadResultsFile, LeaksAreEmptyOrACountOfRays) {
  TempDir dir;
  for (const char* value : {"-1", "nan", "1.5", "x"}) {
    const std::string error =
        input_error_of([&] { read_results_file(dir.write("r.csv", embree_and_bvh2({{"leaks", value}}))); });
    EXPECT_NE(error.find("column 'leaks'"), std::string::npos) << value << ": " << error;
  }
  EXPECT_EQ(input_error_of([&] { read_results_file(dir.write("r.csv", embree_and_bvh2({{"leaks", "3"}}))); }), "");
}

TEST(ReadResultsFile, EachRowKeyAppearsOnce) {
  TempDir dir;
  const std::string path = dir.write("r.csv", csv({row(), row({{"backend", "bvh2"}}), row({{"mrays_s_samples", "8"}})}));
  const std::string error = input_error_of([&] { read_results_file(path); });
  EXPECT_NE(error.find(path + ": line 4 (terrain/primary/embree/threads:1) repeats line 2"), std::string::npos) << error;
  // Another thread count is another row; and the key's fields are matched
  // one by one, so a '/' in a scene name cannot make two rows one.
  EXPECT_EQ(input_error_of([&] { read_results_file(dir.write("r.csv", csv({row(), row({{"threads", "2"}})}))); }), "");
  const std::string slashes =
      dir.write("s.csv", csv({row({{"scene", "a/b"}, {"rayset", "c"}}), row({{"scene", "a"}, {"rayset", "b/c"}})}));
  EXPECT_EQ(read_results_file(slashes).rows.size(), 2u);
}

TEST(ReadResultsFile, AFileWithoutRowsIsRefused) {
  TempDir dir;
  const std::string path = dir.write("header_only.csv", csv({}));
  const std::string error = input_error_of([&] { read_results_file(path); });
  EXPECT_NE(error.find(path + ": no result rows"), std::string::npos) << error;
}

TEST(ReadResultsFile, ASpreadsheetsByteOrderMarkAndCrlfLineEndsRead) {
  TempDir dir;
  std::string text = "\xEF\xBB\xBF" + embree_and_bvh2({});
  for (std::size_t at = text.find('\n'); at != std::string::npos; at = text.find('\n', at + 2)) text.insert(at, "\r");
  const ResultsFile f = read_results_file(dir.write("excel.csv", text));
  ASSERT_EQ(f.rows.size(), 2u);
  EXPECT_EQ(f.rows[0].at("scene"), "terrain");
  EXPECT_EQ(f.rows[1].at("representation"), "triangles");  // the last column, without the '\r'
  EXPECT_EQ(f.lines, (std::vector<std::size_t>{2, 3}));
}

TEST(ReadResultsFile, APartialFileIsReadAndNamedWithItsProgress) {
  TempDir dir;
  const std::string path = dir.write("run.csv", embree_and_bvh2({}));
  EXPECT_TRUE(read_results_file(path).partial.empty());  // no metadata: complete
  dir.write("run.meta.toml", "cpu = \"x\"\nstatus = \"complete\"\n");
  EXPECT_TRUE(read_results_file(path).partial.empty());
  dir.write("run.meta.toml", "cpu = \"x\"\nstatus = \"partial\"\nprogress = \"2 of 5 scenes\"\n");
  const ResultsFile f = read_results_file(path);
  ASSERT_EQ(f.partial.size(), 1u);
  EXPECT_EQ(f.partial[0].path, path);
  EXPECT_EQ(f.partial[0].progress, "2 of 5 scenes");
  ASSERT_EQ(partial_notes(f).size(), 1u);
  EXPECT_EQ(partial_notes(f)[0].rfind(path + " is partial (2 of 5 scenes)", 0), 0u) << partial_notes(f)[0];
  dir.write("run.meta.toml", "status = \"half\"\n");
  const std::string error = input_error_of([&] { read_results_file(path); });
  EXPECT_NE(error.find(dir.file("run.meta.toml") + ": 'status'"), std::string::npos) << error;
}

TEST(Compare, EveryFormatNotesAPartialFile) {
  TempDir dir;
  const std::string base = dir.write("base.csv", embree_and_bvh2({}));
  const std::string current = dir.write("current.csv", csv({row()}));
  dir.write("current.meta.toml", "status = \"partial\"\nprogress = \"1 of 2 scenes\"\n");
  const ResultsFile b = read_results_file(base), c = read_results_file(current);
  const Comparison comparison = compare_results(b, c, {});
  for (OutputFormat format : {OutputFormat::kTable, OutputFormat::kMarkdown, OutputFormat::kJson}) {
    const std::string text = format_comparison(comparison, b, c, format, false);
    EXPECT_NE(text.find(current + " is partial (1 of 2 scenes)"), std::string::npos) << text;
  }
}

TEST(Gate, ABaselineWithoutTheEmbreeRowsIsBadInput) {
  TempDir dir;
  const std::string no_embree = dir.write("base.csv", csv({row({{"backend", "bvh2"}}), row({{"backend", "bvh8"}})}));
  const std::string current = dir.write("current.csv", embree_and_bvh2({}));
  const ResultsFile b = read_results_file(no_embree);
  const std::string error = input_error_of([&] { run_gate(b, {read_results_file(current)}, GateConfig{}); });
  EXPECT_NE(error.find(no_embree + ": line 2 (terrain/primary/bvh2/threads:1): no embree row for terrain/primary/threads:1"),
            std::string::npos)
      << error;
  // Pooled, each run must have its own: the second one here lacks it.
  const std::string good = dir.write("good.csv", embree_and_bvh2({}));
  const std::string pooled_error = input_error_of([&] { pool_runs({read_results_file(good), b}); });
  EXPECT_NE(pooled_error.find(no_embree + ": line 2"), std::string::npos) << pooled_error;
}

TEST(Gate, ACurrentRunWithoutTheEmbreeRowFailsTheRowsBesideIt) {
  TempDir dir;
  const ResultsFile base = read_results_file(dir.write("base.csv", embree_and_bvh2({})));
  const std::string current = dir.write("current.csv", csv({row({{"backend", "bvh2"}})}));
  GateConfig config;
  config.fail_on_missing_rows = false;  // the rule holds even when missing rows are allowed
  const GateResult g = run_gate(base, {read_results_file(current)}, config);
  ASSERT_EQ(g.failures.size(), 1u);
  EXPECT_EQ(g.failures[0].message, "terrain/primary/bvh2/threads:1: no embree row for terrain/primary/threads:1 in " + current +
                               ": its ratio to embree cannot be checked");
  // The confirming run is held to it too: its verdict decides as much.
  const GateResult two = run_gate(base, {base, read_results_file(current)}, config);
  ASSERT_EQ(two.failures.size(), 1u);
  EXPECT_NE(two.failures[0].message.find(" in " + current + ":"), std::string::npos);
}

TEST(Gate, APartialRunIsNamedInANote) {
  TempDir dir;
  const ResultsFile base = read_results_file(dir.write("base.csv", embree_and_bvh2({})));
  const std::string current = dir.write("current.csv", embree_and_bvh2({}));
  dir.write("current.meta.toml", "status = \"partial\"\nprogress = \"3 of 4 scenes\"\n");
  const GateResult g = run_gate(base, {read_results_file(current)}, GateConfig{});
  EXPECT_TRUE(g.failures.empty());
  bool named = false;
  for (const std::string& n : g.notes) named = named || n.rfind(current + " is partial (3 of 4 scenes)", 0) == 0;
  EXPECT_TRUE(named);
}

// Issue 30: runs timed in rounds pair their samples; every ratio is to the file's own reference.
TEST(Compare, ARunTimedInRoundsPairsEachSampleWithTheReferencesOfTheSameRound) {
  TempDir dir;
  // The machine swings from round to round; the candidate is 0.8x the reference in each round.
  const std::string path = dir.write("run.csv", csv({row({{"backend", "base"}, {"reference", "base"}, {"mrays_s_samples", "10;5;20"}}),
                                                     row({{"backend", "cand"}, {"reference", "base"}, {"mrays_s_samples", "8;4;16"}})}));
  dir.write("run.meta.toml", "reference_backend = \"base\"\ntiming = \"rounds\"\n");
  const ResultsFile f = read_results_file(path);
  EXPECT_EQ(f.reference, "base");
  EXPECT_TRUE(f.paired);
  const Comparison c = compare_results(f, f, {});
  ASSERT_EQ(c.rows.size(), 2u);
  EXPECT_EQ(c.rows[0].ratio.verdict, Verdict::kNotApplicable);  // the reference's own row
  EXPECT_DOUBLE_EQ(c.rows[1].ratio.current, 0.8);
  // Pooled with another run, each sample keeps the ratio of its own round.
  const std::string other = dir.write("other.csv", csv({row({{"backend", "base"}, {"reference", "base"}, {"mrays_s_samples", "30;40;50"}}),
                                                        row({{"backend", "cand"}, {"reference", "base"}, {"mrays_s_samples", "27;36;45"}})}));
  dir.write("other.meta.toml", "reference_backend = \"base\"\ntiming = \"rounds\"\n");
  const ResultsFile pooled = pool_runs({f, read_results_file(other)});
  EXPECT_FALSE(pooled.paired);
  const Comparison p = compare_results(pooled, pooled, {});
  EXPECT_DOUBLE_EQ(p.rows[1].ratio.current, 0.85);  // the median of 0.8, 0.8, 0.8, 0.9, 0.9, 0.9
}

TEST(ReadResultsFile, TheReferenceComesFromTheMetadataTheRowsOrIsEmbree) {
  TempDir dir;
  const std::string path = dir.write("r.csv", csv({row({{"reference", ""}}), row({{"backend", "bvh2"}, {"reference", ""}})}));
  EXPECT_EQ(read_results_file(path).reference, "embree");  // older files
  EXPECT_FALSE(read_results_file(path).paired);
  const std::string named = dir.write("n.csv", csv({row({{"reference", "bvh2"}}), row({{"backend", "bvh2"}, {"reference", "bvh2"}})}));
  EXPECT_EQ(read_results_file(named).reference, "bvh2");
  const std::string mixed = dir.write("m.csv", csv({row({{"reference", "bvh2"}}), row({{"backend", "bvh2"}, {"reference", "embree"}})}));
  EXPECT_NE(input_error_of([&] { read_results_file(mixed); }).find(mixed + ": line 3 (terrain/primary/bvh2/threads:1), column 'reference'"),
            std::string::npos);
  // Two files with different references do not compare.
  const std::string error = input_error_of([&] { compare_results(read_results_file(path), read_results_file(named), {}); });
  EXPECT_NE(error.find(named), std::string::npos) << error;
  EXPECT_NE(error.find(path), std::string::npos) << error;
}

// 100,000 rows: 50,000 scenes, each an Embree row and a bvh2 row beside it.
std::string many_rows(double bvh2_scale) {
  std::string out = line_of(nullptr);
  Fields r = row();
  for (int scene = 0; scene < 50000; ++scene)
    for (const char* backend : {"embree", "bvh2"}) {
      r["scene"] = fmt::format("s{}", scene);
      r["backend"] = backend;
      const double m = backend == std::string_view("embree") ? 10.0 : 10.0 * bvh2_scale;
      r["mrays_s_samples"] = fmt::format("{};{};{}", m, m * 1.01, m * 0.99);
      out += line_of(&r);
    }
  return out;
}

TEST(Compare, HundredThousandRowsAreMatchedInLinearTime) {
  TempDir dir;
  const ResultsFile base = read_results_file(dir.write("base.csv", many_rows(1.0)));
  const ResultsFile current = read_results_file(dir.write("current.csv", many_rows(0.5)));
  const Comparison c = compare_results(base, current, {});
  ASSERT_EQ(c.rows.size(), 100000u);
  EXPECT_TRUE(c.only_in_base.empty());
  EXPECT_TRUE(c.only_in_current.empty());
  EXPECT_EQ(c.rows[1].backend, "bvh2");
  EXPECT_NEAR(c.rows[1].ratio.current, 0.5, 1e-9);
  // Three repetitions each cannot reach p < 0.01: every halved row is only "unsure".
  const GateResult g = run_gate(base, {current, current}, GateConfig{});
  EXPECT_TRUE(g.failures.empty());
  std::size_t unsure = 0;
  for (const std::string& n : g.notes) unsure += n.find("-50.0% but not significant") != std::string::npos;
  EXPECT_EQ(unsure, 50000u);
}

}  // namespace
}  // namespace raybench
