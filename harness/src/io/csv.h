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
// Reads what spreadsheets write too: a leading UTF-8 byte order mark (Excel's
// "CSV UTF-8") is skipped and CRLF line ends read as LF. When `lines` is
// given, it receives each row's line number in the file (1 is the header).
std::vector<std::map<std::string, std::string>> read_csv_rows(const std::string& path,
                                                              const std::vector<std::string>& required,
                                                              std::vector<std::size_t>* lines = nullptr);

}  // namespace raybench
