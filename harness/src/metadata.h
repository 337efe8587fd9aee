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
// rays, repetitions, ...).
Metadata collect_metadata(const Metadata& extra);

// "results/latest.csv" -> "results/latest.meta.toml".
std::string metadata_path_for(const std::string& csv_path);

void write_metadata(const std::string& path, const Metadata& metadata);

}  // namespace raybench
