// The referee's part of the gate within one run (`raybench gate --current
// RUN.csv --candidate NAME --accuracy RUN-accuracy.csv`): each candidate's
// rows of the accuracy CSV (accuracy_csv.h) against the reference backend's
// rows of the same scene, transform, ray set and query.
#pragma once

#include <string>
#include <vector>

#include "accuracy/accuracy_csv.h"
#include "results/compare.h"

namespace raybench {

// The error counts the referee records, by their column names: rays the
// backend wrongly misses, wrongly hits, hits on a primitive the referee does
// not accept, and hits on the primitive a secondary ray starts from. The
// CSV holds fractions of the row's rays; counts are fraction x rays.
const std::vector<std::string>& referee_error_columns();

// Appends to `g` a failure (check "referee", kind = the column) for every
// error count of a candidate above the reference's on the same row, and a
// failure "missing" (a note with fail_on_missing_rows = false) where the
// candidate's or the reference's row is absent for a row the file has.
// Throws InputError naming `path` when a candidate has no row at all there
// while the reference does not either (the file is of another run).
void gate_accuracy(const std::vector<AccuracyRow>& rows, const std::string& path, const std::string& reference,
                   const std::vector<std::string>& candidates, const GateConfig& config, GateResult& g);

}  // namespace raybench
