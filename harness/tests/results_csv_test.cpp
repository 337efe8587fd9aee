// Specification of the results CSV (harness/src/results/results_csv.h): the schema
// docs/formats.md documents and later tools (compare, gate) read.
#include "results/results_csv.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include "io/error.h"
#include "results/metadata.h"
#include "test_util.h"

namespace raybench {
namespace {

using testing::TempDir;

TEST(ResultsCsv, HasTheDocumentedColumnsInOrder) {
  const std::vector<std::string> required = {
      "scene", "triangles", "rayset", "rays", "backend", "threads", "build_ms", "memory_bytes", "mrays_s",
      "mrays_s_min", "mrays_s_max", "reps", "hit_rate", "agree_hit", "agree_prim", "t_relerr_max", "t_relerr_p999",
      "disagreements"};
  const auto& columns = result_columns();
  std::size_t last = 0;
  for (const std::string& c : required) {
    const auto it = std::find(columns.begin(), columns.end(), c);
    ASSERT_NE(it, columns.end()) << "missing column " << c;
    const auto index = static_cast<std::size_t>(it - columns.begin());
    EXPECT_GE(index, last) << c << " out of the documented order";
    last = index;
  }
}

TEST(ResultsCsv, RowsRoundTripAndNotApplicableIsEmpty) {
  TempDir dir;
  ResultRow row;
  row.scene = "bunny, scanned";  // a comma forces quoting
  row.triangles = 69451;
  row.rayset = "shadow";
  row.query = "occluded";
  row.rays = 1000;
  row.backend = "embree:high";
  row.threads = 2;
  row.mrays_s = 12.5;
  row.mrays_s_samples = {12.0, 12.5, 13.0};
  row.reps = 3;
  row.agree_prim = std::nan("");
  row.t_relerr_max = std::nan("");
  row.disagreements = 4;
  ResultRow must_hit = row;
  must_hit.rayset = "vertex-aimed";
  must_hit.leaks = 0;
  write_results_csv(dir.file("r.csv"), {row, must_hit});
  const auto rows = read_results_csv(dir.file("r.csv"));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("leaks"), "");  // not a must-hit ray set
  EXPECT_EQ(rows[1].at("leaks"), "0");
  EXPECT_EQ(rows[0].at("scene"), "bunny, scanned");
  EXPECT_EQ(rows[0].at("backend"), "embree:high");
  EXPECT_EQ(rows[0].at("threads"), "2");
  EXPECT_EQ(rows[0].at("mrays_s"), "12.5");
  EXPECT_EQ(rows[0].at("mrays_s_samples"), "12;12.5;13");
  EXPECT_EQ(rows[0].at("agree_prim"), "");
  EXPECT_EQ(rows[0].at("t_relerr_max"), "");
  EXPECT_EQ(rows[0].at("disagreements"), "4");
}

TEST(ResultsCsv, ColumnsAreAppendedAfterThoseOfOlderFiles) {
  // Appended last, so the columns of older files keep their positions.
  const std::vector<std::string>& c = result_columns();
  ASSERT_GE(c.size(), 29u);
  EXPECT_EQ(c[24], "leaks");
  EXPECT_EQ(c[25], "sah_cost");
  EXPECT_EQ(c[26], "reference");
  EXPECT_EQ(c[27], "ratio_to_reference");
  EXPECT_EQ(c[28], "plugin");
  ASSERT_GE(c.size(), 30u);
  EXPECT_EQ(c[29], "representation");
}

TEST(ResultsCsv, TheRepresentationRoundTripsAndIsEmptyInOlderFiles) {
  TempDir dir;
  ResultRow analytic, stand_in;
  analytic.scene = "balls";
  analytic.representation = "analytic";
  stand_in.scene = "balls@uv16x8";
  stand_in.representation = "uv16x8";
  write_results_csv(dir.file("r.csv"), {analytic, stand_in});
  const auto rows = read_results_csv(dir.file("r.csv"));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("representation"), "analytic");
  EXPECT_EQ(rows[1].at("representation"), "uv16x8");
  EXPECT_EQ(rows[1].at("scene"), "balls@uv16x8");
  // A file of the schema before it (up to plugin) reads, the column empty.
  std::string header, line;
  for (std::size_t i = 0; i + 1 < result_columns().size(); ++i) {
    header += (i ? "," : "") + result_columns()[i];
    line += (i ? "," : "") + std::string(i == 0 ? "old" : i == 2 ? "primary" : i == 5 ? "embree" : i == 6 ? "1" : "");
  }
  const auto old = read_results_csv(dir.write("old.csv", header + "\n" + line + "\n"));
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].at("representation"), "");
  EXPECT_EQ(old[0].at("scene"), "old");
}

TEST(ResultsCsv, SahCostReferenceAndPluginRoundTrip) {
  TempDir dir;
  ResultRow ours;
  ours.backend = "bvh8:sweep";
  ours.sah_cost = 41.8125;
  ours.reference = "embree";
  ours.ratio_to_reference = 1.5;
  ours.plugin = "my_bvh";
  ResultRow embree;
  embree.backend = "embree";  // sah_cost left NaN: not applicable
  write_results_csv(dir.file("r.csv"), {ours, embree});
  const auto rows = read_results_csv(dir.file("r.csv"));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].at("sah_cost"), "41.8125");
  EXPECT_EQ(rows[1].at("sah_cost"), "");
  EXPECT_EQ(rows[0].at("reference"), "embree");
  EXPECT_EQ(rows[0].at("ratio_to_reference"), "1.5");
  EXPECT_EQ(rows[0].at("plugin"), "my_bvh");
  EXPECT_EQ(rows[1].at("ratio_to_reference"), "");  // 0: no reference measured
  EXPECT_EQ(rows[1].at("plugin"), "");
}

TEST(ResultsCsv, AFileFromBeforeTheSahCostColumnStillReads) {
  // The header and first row of results/default-suite.csv, written before
  // sah_cost existed.
  TempDir dir;
  const auto path = dir.write(
      "old.csv",
      "scene,triangles,rayset,query,rays,backend,threads,build_ms,build_ms_min,build_ms_max,memory_bytes,mrays_s,"
      "mrays_s_min,mrays_s_max,reps,mrays_s_samples,ratio_to_embree,hit_rate,agree_hit,agree_prim,prim_ties,"
      "t_relerr_max,t_relerr_p999,disagreements,leaks\n"
      "sponza,262205,primary,intersect,262144,embree,1,109.478,101.859,139.236,17518080,2.92204,2.52573,3.24777,5,"
      "2.92204;2.52573;3.24777;2.93679;2.76549,1,0.983913,1,1,0,0,0,0,\n");
  const auto rows = read_results_csv(path);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].at("backend"), "embree");
  EXPECT_EQ(rows[0].at("mrays_s"), "2.92204");
  EXPECT_EQ(rows[0].at("sah_cost"), "");  // not in the file: not applicable
  // An older column is still required.
  const auto broken = dir.write("broken.csv", "scene,triangles\nbunny,1\n");
  EXPECT_NE(testing::input_error_of([&] { read_results_csv(broken); }).find("missing column"), std::string::npos);
}

TEST(ResultsCsv, AFileSavedByASpreadsheetReads) {
  // Excel's "CSV UTF-8" starts with a byte order mark and ends lines with
  // CRLF: the header's first column read as "\xEF\xBB\xBFscene" ("missing
  // column 'scene'") and its last as "leaks\r" before both were handled.
  TempDir dir;
  const auto path = dir.write(
      "excel.csv",
      "\xEF\xBB\xBFscene,triangles,rayset,query,rays,backend,threads,build_ms,build_ms_min,build_ms_max,memory_bytes,mrays_s,"
      "mrays_s_min,mrays_s_max,reps,mrays_s_samples,ratio_to_embree,hit_rate,agree_hit,agree_prim,prim_ties,"
      "t_relerr_max,t_relerr_p999,disagreements,leaks\r\n"
      "sponza,262205,primary,intersect,262144,embree,1,109.478,101.859,139.236,17518080,2.92204,2.52573,3.24777,5,"
      "2.92204;2.52573;3.24777;2.93679;2.76549,1,0.983913,1,1,0,0,0,0,7\r\n");
  std::vector<std::size_t> lines;
  const auto rows = read_results_csv(path, &lines);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].at("scene"), "sponza");
  EXPECT_EQ(rows[0].at("leaks"), "7");
  EXPECT_EQ(lines, std::vector<std::size_t>{2});
}

TEST(ResultsCsv, AFileWithoutTheSchemaIsRejected) {
  TempDir dir;
  const auto path = dir.write("other.csv", "name,time\nx,1\n");
  EXPECT_THROW(read_results_csv(path), InputError);
}

TEST(Metadata, RecordsWhatAResultDependsOn) {
  const Metadata m = collect_metadata({{"threads", "2"}});
  std::map<std::string, std::string> keys(m.begin(), m.end());
  for (const char* k : {"cpu", "cpu_id", "compiler", "flags", "embree", "git_commit", "date", "threads"})
    EXPECT_FALSE(keys[k].empty()) << k;
  EXPECT_EQ(keys["embree"].rfind("3.", 0), 0u);
  // The processor itself, where its model name is a virtual machine's generic one.
  EXPECT_EQ(keys["cpu_id"].rfind("family ", 0), 0u) << keys["cpu_id"];
  EXPECT_EQ(keys["cpu_id"].find('?'), std::string::npos) << keys["cpu_id"];
  EXPECT_EQ(metadata_path_for("results/latest.csv"), "results/latest.meta.toml");
}

// A git work tree in a temporary folder: one commit of a source file and a
// results CSV.
struct GitTree {
  TempDir dir;
  GitTree() {
    std::filesystem::create_directories(dir.file("results"));
    dir.write("kernel.cpp", "int x;\n");
    dir.write("results/run.csv", "a\n1\n");
    EXPECT_EQ(git("init -q"), 0);
    EXPECT_EQ(git("add -A"), 0);
    EXPECT_EQ(git("-c user.name=t -c user.email=t@example.org commit -qm first"), 0);
  }
  int git(const std::string& args) const {
    return std::system(("git -C '" + dir.file("") + "' " + args + " >/dev/null 2>&1").c_str());
  }
};

TEST(Metadata, SourceStateIsTheCommitAndDirtyWhenASourceFileDiffers) {
  GitTree tree;
  const std::string clean = source_state(tree.dir.file(""));
  ASSERT_EQ(clean.size(), 40u) << clean;
  tree.dir.write("notes.txt", "untracked\n");
  EXPECT_EQ(source_state(tree.dir.file("")), clean);  // untracked files are not sources
  tree.dir.write("kernel.cpp", "int y;\n");
  EXPECT_EQ(source_state(tree.dir.file("")), clean + "-dirty");
}

TEST(Metadata, ARunsOwnOutputsUnderResultsDoNotMakeTheSourcesDirty) {
  GitTree tree;
  const std::string clean = source_state(tree.dir.file(""));
  tree.dir.write("results/run.csv", "a\n2\n");  // a run rewriting the committed results
  EXPECT_EQ(source_state(tree.dir.file("")), clean);
}

TEST(Metadata, OutsideAGitTreeTheSourceStateIsUnknown) {
  TempDir dir;
  EXPECT_EQ(source_state(dir.file("")), "unknown");
}

TEST(Metadata, TheGitCommitIsTheStateRecordedOnceWhenTheProcessStarted) {
  const std::string& first = record_source_state();
  EXPECT_EQ(&record_source_state(), &first);  // read once, kept
  const Metadata m = collect_metadata({});
  std::map<std::string, std::string> keys(m.begin(), m.end());
  EXPECT_EQ(keys["git_commit"], first);
}

}  // namespace
}  // namespace raybench
