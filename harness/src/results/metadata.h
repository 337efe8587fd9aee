// What a result depends on, written beside every results CSV as
// <name>.meta.toml: CPU, compiler and flags, library versions, git commit,
// threads, date, and the command line.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace raybench {

using Metadata = std::vector<std::pair<std::string, std::string>>;

// Collects the machine and build description; `extra` is appended (suite,
// rays, repetitions, ...). Its git_commit is the checkout's state when the
// process started (record_source_state), not when a long run ends.
Metadata collect_metadata(const Metadata& extra);

// The commit checked out in the git work tree `dir` ("unknown" outside one),
// with "-dirty" when a tracked file differs from it; files under results/
// (a run's own outputs, rewritten by the run that records this) do not count.
std::string source_state(const std::string& dir);

// Reads the source tree's state (source_state of the tree this binary was
// configured from) once, now: main() calls it first, so a commit made while
// a run goes on (a 20-minute accuracy run) is not mistaken for the one the
// binary was built from. Later calls keep the first answer. A binary that
// does not run from its build tree (installed: io/default_paths.h) never
// reads the source tree: it answers the state recorded when it was built.
const std::string& record_source_state();

// "results/latest.csv" -> "results/latest.meta.toml".
std::string metadata_path_for(const std::string& csv_path);

// Keys are written as given: a dotted key (provenance.<backend>.<field>)
// names each part with toml_key.
void write_metadata(const std::string& path, const Metadata& metadata);

// A TOML key for `name`: bare when made of A-Za-z0-9_-, quoted otherwise
// ("plugin:build/x.so").
std::string toml_key(const std::string& name);

}  // namespace raybench
