// Text helpers shared by the input readers: exception-free number parsing and message quoting.
#include <charconv>
#include <cstdio>
#include <limits>
#include <string>
#include <system_error>

#include "readers/readers.h"

namespace vc::readers {

bool ParseDouble(std::string_view token, double* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty() || token.front() == '+') return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, *value);
  // ERANGE: beyond double range. Overflow becomes +-inf (then counted as non-finite), underflow
  // becomes 0, rather than rejecting the whole file.
  if (ec == std::errc::result_out_of_range && ptr == end) {
    const size_t e = token.find_first_of("eE");
    const bool underflow = e != std::string_view::npos && e + 1 < token.size() && token[e + 1] == '-';
    const double magnitude = underflow ? 0.0 : std::numeric_limits<double>::infinity();
    *value = token.front() == '-' ? -magnitude : magnitude;
    return true;
  }
  return ec == std::errc() && ptr == end;
}

bool ParseUint64(std::string_view token, uint64_t* value) {
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, *value);
  return ec == std::errc() && ptr == end;
}

std::string Quote(std::string_view text) {
  constexpr size_t kMax = 40;
  std::string out = "\"";
  for (size_t i = 0; i < text.size() && i < kMax; ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f && c != '"' && c != '\\') {
      out += static_cast<char>(c);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\x%02x", c);
      out += buf;
    }
  }
  if (text.size() > kMax) out += "...";
  out += '"';
  return out;
}

std::vector<std::string_view> SplitWhitespace(std::string_view text) {
  std::vector<std::string_view> tokens;
  size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
    const size_t start = i;
    while (i < text.size() && text[i] != ' ' && text[i] != '\t') ++i;
    if (i > start) tokens.push_back(text.substr(start, i - start));
  }
  return tokens;
}

}  // namespace vc::readers
