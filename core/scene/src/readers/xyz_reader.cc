// ASCII point lists: one "x y z [more columns]" line per point.
//
// Fields are separated by a comma (CSV, surrounding blanks trimmed) or by runs of spaces/tabs,
// decided per line. Blank lines and lines starting with '#' or "//" are skipped. The first data
// line may be a header (fewer than three fields, or not all numbers); any later non-numeric x/y/z
// field is an error naming the line and column.
#include <algorithm>
#include <string>

#include "readers/readers.h"

namespace vc::readers {
namespace {

// The first three fields of a line and how many fields it has.
struct Fields {
  std::string_view xyz[3];
  size_t count = 0;
};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

Fields SplitFields(std::string_view line, char* separator) {
  Fields f;
  if (line.find(',') != std::string_view::npos) {
    *separator = ',';
    size_t start = 0;
    while (true) {
      const size_t comma = line.find(',', start);
      const std::string_view field =
          Trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
      if (f.count < 3) f.xyz[f.count] = field;
      ++f.count;
      if (comma == std::string_view::npos) break;
      start = comma + 1;
    }
    return f;
  }
  size_t i = 0;
  bool saw_tab = false;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) {
      saw_tab |= line[i] == '\t';
      ++i;
    }
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
    if (i > start) {
      if (f.count < 3) f.xyz[f.count] = line.substr(start, i - start);
      ++f.count;
    }
  }
  *separator = saw_tab ? '\t' : ' ';
  return f;
}

std::string SeparatorName(char c) {
  switch (c) {
    case ',':
      return "comma-separated";
    case '\t':
      return "tab-separated";
    default:
      return "space-separated";
  }
}

}  // namespace

bool LooksLikeText(std::string_view bytes) {
  const std::string_view sample = bytes.substr(0, 64 * 1024);
  if (sample.empty()) return false;
  return std::all_of(sample.begin(), sample.end(),
                     [](char ch) {
                       const auto c = static_cast<unsigned char>(ch);
                       return c >= 0x20 || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
                     }) &&
         sample.find('\x7f') == std::string_view::npos;
}

Result<PointCloud> ReadXyz(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  if (bytes.substr(0, 3) == "\xEF\xBB\xBF") bytes.remove_prefix(3);  // UTF-8 byte-order mark.
  PointCloud cloud(options);
  LineCursor lines(bytes);
  std::string_view line;
  bool seen_data_line = false;
  bool has_header = false;
  char separator = ' ';
  uint64_t columns = 0;
  uint64_t total = 0;
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  while (lines.Next(&line)) {
    const std::string_view trimmed = Trim(line);
    if (trimmed.empty() || trimmed.front() == '#' || trimmed.substr(0, 2) == "//") continue;
    const Fields f = SplitFields(trimmed, &separator);
    double v[3] = {0, 0, 0};
    int bad = -1;
    for (int a = 0; a < 3 && a < static_cast<int>(f.count); ++a) {
      if (!ParseDouble(f.xyz[a], &v[a])) {
        bad = a;
        break;
      }
    }
    if (!seen_data_line) {
      seen_data_line = true;
      if (bad >= 0 || f.count < 3) {  // A header such as "x,y,z,intensity" or a point count.
        has_header = true;
        continue;
      }
      columns = f.count;
    }
    const std::string where = "line " + std::to_string(lines.line_number());
    if (f.count < 3) {
      return InvalidInput(source, where + ": expected at least 3 columns (x y z), found " + std::to_string(f.count) +
                                      " in " + Quote(trimmed));
    }
    if (bad >= 0) {
      return InvalidInput(source, where + ": expected a number for " + kAxis[bad] + " (column " +
                                      std::to_string(bad + 1) + "), found " + Quote(f.xyz[bad]));
    }
    if (columns == 0) columns = f.count;
    ++total;
    if (total > options.max_points) {
      return ResourceExhaustedError(std::string(source) + ": more than the limit of " +
                                    std::to_string(options.max_points) + " points" + std::string(kRaiseResultLimit));
    }
    cloud.Add(v[0], v[1], v[2]);
  }
  if (total == 0) {
    return InvalidInput(source, "no points: expected one \"x y z\" line per point, found " +
                                    std::string(has_header ? "only a header line" : "no data lines"));
  }
  cloud.detail =
      SeparatorName(separator) + ", " + std::to_string(columns) + " columns" + (has_header ? ", header line" : "");
  return cloud;
}

}  // namespace vc::readers
