// CSV fields as every raybench CSV writes and reads them (RFC 4180 quoting,
// NaN written as an empty field meaning "not applicable").
#pragma once

#include <map>
#include <string>
#include <vector>

namespace raybench {

// A number with 6 significant digits; NaN becomes the empty field.
std::string csv_number(double v);
// A text field, quoted when it holds a comma, quote or newline.
std::string csv_text(const std::string& s);
// Rows of a CSV file as column -> field maps. Throws InputError when the file
// cannot be read, lacks one of `required` columns, or has a ragged line.
std::vector<std::map<std::string, std::string>> read_csv_rows(const std::string& path,
                                                              const std::vector<std::string>& required);

}  // namespace raybench
