#include "scene/ply_precheck.h"

namespace raybench {
namespace {

// assimp's IsLineEnd (include/assimp/ParsingUtils.h).
bool is_line_end(char c) { return c == '\n' || c == '\r' || c == '\f' || c == '\0'; }

// The lines of `text` as assimp's IOStreamBuffer::getNextLine returns them.
class AssimpLines {
 public:
  explicit AssimpLines(std::string_view text) : text_(text) {}

  // The next line, without its line end; false at the end of the text.
  // `terminated` says whether a line-end character follows it in the text.
  bool next(std::string_view& line, bool& terminated) {
    if (pos_ >= text_.size()) return false;
    if (is_line_end(text_[pos_])) {
      const std::size_t newline = text_.find('\n', pos_);
      if (newline == std::string_view::npos) return false;
      pos_ = newline + 1;
      if (pos_ >= text_.size()) return false;
    }
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !is_line_end(text_[pos_])) ++pos_;
    line = text_.substr(start, pos_ - start);
    terminated = pos_ < text_.size();
    ++pos_;  // past the line end
    return true;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

bool is_ply_magic(std::string_view line) {
  return line.size() >= 3 && (line[0] == 'p' || line[0] == 'P') && (line[1] == 'l' || line[1] == 'L') &&
         (line[2] == 'y' || line[2] == 'Y');
}

// ParseHeader's end: after spaces and tabs, the token "end_header" followed
// by a space or tab, or by the line's end when that is in the text.
bool is_end_header(std::string_view line, bool terminated) {
  constexpr std::string_view kToken = "end_header";
  std::size_t i = 0;
  while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
  if (line.substr(i, kToken.size()) != kToken) return false;
  i += kToken.size();
  return i < line.size() ? (line[i] == ' ' || line[i] == '\t') : terminated;
}

}  // namespace

std::string ply_header_problem(std::string_view head) {
  AssimpLines lines(head);
  std::string_view line;
  bool terminated = false;
  if (!lines.next(line, terminated) || !is_ply_magic(line)) return "";
  while (lines.next(line, terminated))
    if (is_end_header(line, terminated)) return "";
  return "malformed PLY: the header never ends (no end_header line)";
}

}  // namespace raybench
