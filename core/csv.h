#pragma once
// Fields of the CSV files nadir writes (RFC 4180): a field that holds a comma, a
// double quote or a line break is quoted, its quotes doubled; any other as it is.
#include <string>
#include <string_view>

namespace nadir::core {

inline std::string csvField(std::string_view text) {
  if (text.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(text);
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

}  // namespace nadir::core
