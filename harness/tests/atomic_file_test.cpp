// Specification of atomic_file.h: a result is either whole at its path or
// not there, and no temporary file outlives the write, on any path.
#include "io/atomic_file.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "test_util.h"

namespace raybench {
namespace {

std::string contents(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t files_in(const std::string& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

TEST(WriteFileAtomically, AFailingWriterLeavesTheOldFileAndNoTemporaryFile) {
  const testing::TempDir dir;
  const std::string path = dir.write("out.csv", "old\n");
  EXPECT_THROW(write_file_atomically(path, [](std::ostream& out) {
                 out << "half";
                 throw std::runtime_error("failed while writing");
               }),
               std::runtime_error);
  EXPECT_EQ(contents(path), "old\n");
  EXPECT_EQ(files_in(dir.file("")), 1u);
  write_file_atomically(path, [](std::ostream& out) { out << "new\n"; });
  EXPECT_EQ(contents(path), "new\n");
  EXPECT_EQ(files_in(dir.file("")), 1u);
}

TEST(TemporaryFile, IsRemovedWhenItEndsUnlessKept) {
  const testing::TempDir dir;
  {
    const TemporaryFile temp(dir.file("k.json.tmp.gbench"));
    std::ofstream(temp.path()) << "{";  // another writer fills it, then an error ends the scope
  }
  EXPECT_EQ(files_in(dir.file("")), 0u);
  {
    TemporaryFile temp(dir.file("k.json.tmp.gbench"));
    std::ofstream(temp.path()) << "{}";
    temp.keep_as(dir.file("k.json"));
  }
  EXPECT_EQ(contents(dir.file("k.json")), "{}");
  EXPECT_EQ(files_in(dir.file("")), 1u);
}

TEST(TemporaryFile, KeepingItWhereADirectoryStandsIsAnInputErrorAndTheFileIsStillRemoved) {
  const testing::TempDir dir;
  std::filesystem::create_directories(dir.file("k.json/inside"));
  {
    TemporaryFile temp(dir.file("k.json.tmp.gbench"));
    std::ofstream(temp.path()) << "{}";
    EXPECT_NE(testing::input_error_of([&] { temp.keep_as(dir.file("k.json")); }).find("k.json: cannot be replaced"),
              std::string::npos);
  }
  EXPECT_FALSE(testing::exists(dir.file("k.json.tmp.gbench")));
}

}  // namespace
}  // namespace raybench
