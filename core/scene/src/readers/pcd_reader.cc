// PCD v0.7 (Point Cloud Library) in ascii, binary and binary_compressed.
//
// Fields may come in any order and with any SIZE/TYPE/COUNT; only the first element of x, y and z
// is kept. binary_compressed is one LZF block (uint32 compressed size, uint32 uncompressed size,
// data) whose decompressed bytes hold the fields one after another: every point's x, then every
// point's y, and so on (PCL's "structure of arrays" layout). Binary data is little-endian.
#include <algorithm>
#include <string>
#include <vector>

#include "readers/readers.h"

namespace vc::readers {
namespace {

struct Field {
  std::string name;
  uint64_t size = 4;
  char type = 'F';
  uint64_t count = 1;
  uint64_t offset = 0;  // Within one point's record.
};

enum class Data { kAscii, kBinary, kBinaryCompressed };

struct Header {
  std::vector<Field> fields;
  uint64_t points = 0;
  Data data = Data::kAscii;
  std::string data_name;
  uint64_t step = 0;  // Bytes per point.
  int xyz[3] = {-1, -1, -1};
  size_t body_offset = 0;
  uint64_t body_first_line = 0;
};

// Largest expansion of LZF: a 3-byte back-reference yields 264 bytes.
constexpr uint64_t kMaxLzfRatio = 88;

double Load(const char* p, const Field& f) {
  switch (f.type) {
    case 'F':
      return f.size == 4 ? double{LoadScalar<float>(p, false)} : LoadScalar<double>(p, false);
    case 'I':
      switch (f.size) {
        case 1:
          return LoadScalar<int8_t>(p, false);
        case 2:
          return LoadScalar<int16_t>(p, false);
        case 4:
          return LoadScalar<int32_t>(p, false);
        default:
          return static_cast<double>(LoadScalar<int64_t>(p, false));
      }
    default:
      switch (f.size) {
        case 1:
          return LoadScalar<uint8_t>(p, false);
        case 2:
          return LoadScalar<uint16_t>(p, false);
        case 4:
          return LoadScalar<uint32_t>(p, false);
        default:
          return static_cast<double>(LoadScalar<uint64_t>(p, false));
      }
  }
}

Result<Header> ParseHeader(std::string_view bytes, std::string_view source) {
  Header h;
  LineCursor lines(bytes);
  std::string_view line;
  bool have[4] = {false, false, false, false};  // SIZE, TYPE, COUNT, POINTS
  bool have_width = false, have_height = false, have_data = false;
  uint64_t width = 0, height = 0;
  std::vector<std::string_view> sizes, types, counts;
  uint64_t size_line = 0, type_line = 0, count_line = 0;
  while (lines.Next(&line)) {
    const std::string where = "line " + std::to_string(lines.line_number());
    const std::vector<std::string_view> t = SplitWhitespace(line);
    if (t.empty() || t[0].front() == '#') continue;
    const std::string_view key = t[0];
    auto one_number = [&](uint64_t* v) -> Status {
      if (t.size() != 2 || !ParseUint64(t[1], v)) {
        return InvalidInput(
            source, where + ": expected \"" + std::string(key) + " <non-negative integer>\", found " + Quote(line));
      }
      return Status::Ok();
    };
    if (key == "VERSION") {
      if (t.size() != 2 || (t[1] != "0.7" && t[1] != ".7" && t[1] != "0.6" && t[1] != ".6")) {
        return InvalidInput(source, where + ": unsupported PCD version " + Quote(line) + " (expected VERSION 0.7)");
      }
    } else if (key == "FIELDS" || key == "COLUMNS") {
      if (t.size() < 2) return InvalidInput(source, where + ": FIELDS lists no fields");
      for (size_t i = 1; i < t.size(); ++i) h.fields.push_back(Field{std::string(t[i])});
    } else if (key == "SIZE") {
      sizes.assign(t.begin() + 1, t.end());
      have[0] = true;
      size_line = lines.line_number();
    } else if (key == "TYPE") {
      types.assign(t.begin() + 1, t.end());
      have[1] = true;
      type_line = lines.line_number();
    } else if (key == "COUNT") {
      counts.assign(t.begin() + 1, t.end());
      have[2] = true;
      count_line = lines.line_number();
    } else if (key == "WIDTH") {
      VC_RETURN_IF_ERROR(one_number(&width));
      have_width = true;
    } else if (key == "HEIGHT") {
      VC_RETURN_IF_ERROR(one_number(&height));
      have_height = true;
    } else if (key == "POINTS") {
      VC_RETURN_IF_ERROR(one_number(&h.points));
      have[3] = true;
    } else if (key == "VIEWPOINT") {
      continue;
    } else if (key == "DATA") {
      if (t.size() != 2) {
        return InvalidInput(source, where +
                                        ": expected \"DATA <ascii|binary|binary_compressed>\""
                                        ", found " +
                                        Quote(line));
      }
      if (t[1] == "ascii") {
        h.data = Data::kAscii;
      } else if (t[1] == "binary") {
        h.data = Data::kBinary;
      } else if (t[1] == "binary_compressed") {
        h.data = Data::kBinaryCompressed;
      } else {
        return InvalidInput(source, where + ": unknown PCD DATA type " + Quote(t[1]) +
                                        " (expected ascii, binary or binary_compressed)");
      }
      h.data_name = std::string(t[1]);
      have_data = true;
      break;
    } else {
      return InvalidInput(source, where + ": unknown PCD header keyword " + Quote(key) +
                                      " (expected VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, "
                                      "HEIGHT, VIEWPOINT, POINTS or DATA)");
    }
  }
  if (!have_data) {
    return InvalidInput(source,
                        "PCD header has no \"DATA\" line (read " + std::to_string(lines.line_number()) + " lines)");
  }
  h.body_offset = lines.position();
  h.body_first_line = lines.line_number() + 1;
  if (h.fields.empty()) return InvalidInput(source, "PCD header has no \"FIELDS\" line");
  const size_t n = h.fields.size();
  auto check_len = [&](const std::vector<std::string_view>& v, bool present, const char* key,
                       uint64_t line_no) -> Status {
    if (present && v.size() != n) {
      return InvalidInput(source, "line " + std::to_string(line_no) + ": " + key + " lists " +
                                      std::to_string(v.size()) + " entries but FIELDS lists " + std::to_string(n));
    }
    return Status::Ok();
  };
  if (!have[0] || !have[1]) {
    return InvalidInput(source, std::string("PCD header has no \"") + (have[0] ? "TYPE" : "SIZE") + "\" line");
  }
  VC_RETURN_IF_ERROR(check_len(sizes, true, "SIZE", size_line));
  VC_RETURN_IF_ERROR(check_len(types, true, "TYPE", type_line));
  VC_RETURN_IF_ERROR(check_len(counts, have[2], "COUNT", count_line));
  for (size_t i = 0; i < n; ++i) {
    Field& f = h.fields[i];
    if (types[i].size() != 1 || std::string_view("FIU").find(types[i][0]) == std::string_view::npos) {
      return InvalidInput(source, "line " + std::to_string(type_line) + ": unknown PCD TYPE " + Quote(types[i]) +
                                      " for field \"" + f.name + "\" (expected F, I or U)");
    }
    f.type = types[i][0];
    const bool size_ok =
        ParseUint64(sizes[i], &f.size) &&
        (f.type == 'F' ? (f.size == 4 || f.size == 8) : (f.size == 1 || f.size == 2 || f.size == 4 || f.size == 8));
    if (!size_ok) {
      return InvalidInput(source, "line " + std::to_string(size_line) + ": invalid SIZE " + Quote(sizes[i]) +
                                      " for field \"" + f.name + "\" of TYPE " + f.type + " (expected " +
                                      (f.type == 'F' ? "4 or 8" : "1, 2, 4 or 8") + ")");
    }
    if (have[2] && (!ParseUint64(counts[i], &f.count) || f.count == 0 || f.count > 1'000'000)) {
      return InvalidInput(source, "line " + std::to_string(count_line) + ": invalid COUNT " + Quote(counts[i]) +
                                      " for field \"" + f.name + "\" (expected a positive integer)");
    }
    f.offset = h.step;
    h.step += f.size * f.count;
  }
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    for (size_t i = 0; i < n; ++i) {
      if (h.fields[i].name == kAxis[a]) h.xyz[a] = static_cast<int>(i);
    }
    if (h.xyz[a] < 0) {
      return InvalidInput(source,
                          std::string("PCD header has no field \"") + kAxis[a] + "\" (expected fields x, y and z)");
    }
  }
  if (!have_width) return InvalidInput(source, "PCD header has no \"WIDTH\" line");
  if (!have_height) height = 1;
  if (height != 0 && width > UINT64_MAX / height) {
    return InvalidInput(
        source, "PCD WIDTH " + std::to_string(width) + " times HEIGHT " + std::to_string(height) + " overflows");
  }
  if (!have[3]) {
    h.points = width * height;
  } else if (h.points != width * height) {
    return InvalidInput(source, "PCD header declares POINTS " + std::to_string(h.points) +
                                    " but WIDTH * HEIGHT = " + std::to_string(width) + " * " + std::to_string(height) +
                                    " = " + std::to_string(width * height));
  }
  if (h.points == 0) return InvalidInput(source, "PCD header declares 0 points; the cloud is empty");
  return h;
}

Status Truncated(std::string_view source, uint64_t declared, uint64_t present) {
  return InvalidInput(source, "PCD header declares " + std::to_string(declared) + " points but the body ends after " +
                                  std::to_string(present) + "; file truncated?");
}

Status CheckTrailing(std::string_view source, std::string_view rest, size_t pos) {
  const bool blank =
      std::all_of(rest.begin(), rest.end(), [](char c) { return c == '\n' || c == '\r' || c == ' ' || c == '\0'; });
  if (blank) return Status::Ok();
  return InvalidInput(source, "PCD body has " + std::to_string(rest.size()) +
                                  " bytes left after the declared points (at byte " + std::to_string(pos) +
                                  "); header and body do not match (wrong POINTS or SIZE?)");
}

Status ReadAscii(std::string_view bytes, std::string_view source, const Header& h, PointCloud* cloud) {
  const std::string_view body = bytes.substr(h.body_offset);
  LineCursor lines(body);
  uint64_t values = 0;
  for (const Field& f : h.fields) values += f.count;
  cloud->points.reserve(std::min<uint64_t>(h.points, body.size() / (2 * values)));
  std::string_view line;
  auto next_point = [&](std::string_view* out) {
    while (lines.Next(out)) {
      if (out->find_first_not_of(" \t") != std::string_view::npos) return true;
    }
    return false;
  };
  const uint64_t line_base = h.body_first_line - 1;
  for (uint64_t i = 0; i < h.points; ++i) {
    if (!next_point(&line)) return Truncated(source, h.points, i);
    const std::vector<std::string_view> t = SplitWhitespace(line);
    const std::string where = "line " + std::to_string(line_base + lines.line_number());
    if (t.size() != values) {
      return InvalidInput(source, where + ": expected " + std::to_string(values) +
                                      " values per point (FIELDS times COUNT), found " + std::to_string(t.size()));
    }
    double xyz[3];
    for (int a = 0; a < 3; ++a) {
      const Field& f = h.fields[h.xyz[a]];
      uint64_t k = 0;
      for (int i2 = 0; i2 < h.xyz[a]; ++i2) k += h.fields[i2].count;
      if (!ParseDouble(t[k], &xyz[a])) {
        return InvalidInput(source, where + ": expected a number for field \"" + f.name + "\", found " + Quote(t[k]));
      }
    }
    cloud->Add(xyz[0], xyz[1], xyz[2]);
  }
  if (next_point(&line)) {
    return InvalidInput(source, "line " + std::to_string(line_base + lines.line_number()) + ": unexpected data " +
                                    Quote(line) + " after the " + std::to_string(h.points) +
                                    " points declared in the header");
  }
  return Status::Ok();
}

Status ReadBinary(std::string_view bytes, std::string_view source, const Header& h, PointCloud* cloud) {
  const uint64_t left = bytes.size() - h.body_offset;
  if (h.points > left / h.step) return Truncated(source, h.points, left / h.step);
  cloud->points.reserve(h.points);
  const char* base = bytes.data() + h.body_offset;
  const Field& fx = h.fields[h.xyz[0]];
  const Field& fy = h.fields[h.xyz[1]];
  const Field& fz = h.fields[h.xyz[2]];
  for (uint64_t i = 0; i < h.points; ++i) {
    const char* p = base + i * h.step;
    cloud->Add(Load(p + fx.offset, fx), Load(p + fy.offset, fy), Load(p + fz.offset, fz));
  }
  const size_t end = h.body_offset + h.points * h.step;
  return CheckTrailing(source, bytes.substr(end), end);
}

Status ReadCompressed(std::string_view bytes, std::string_view source, const Header& h, const ReadOptions& options,
                      PointCloud* cloud) {
  const size_t pos = h.body_offset;
  if (bytes.size() - pos < 8) {
    return InvalidInput(source, "PCD binary_compressed body at byte " + std::to_string(pos) + " has " +
                                    std::to_string(bytes.size() - pos) +
                                    " bytes; expected an 8-byte size header; file truncated?");
  }
  const uint64_t compressed = LoadScalar<uint32_t>(bytes.data() + pos, false);
  const uint64_t uncompressed = LoadScalar<uint32_t>(bytes.data() + pos + 4, false);
  if (h.points > UINT64_MAX / h.step || uncompressed != h.points * h.step) {
    return InvalidInput(source, "PCD header declares " + std::to_string(h.points) + " points of " +
                                    std::to_string(h.step) + " bytes but the compressed block at byte " +
                                    std::to_string(pos) + " decompresses to " + std::to_string(uncompressed) +
                                    " bytes; header and body do not match");
  }
  const uint64_t left = bytes.size() - pos - 8;
  if (compressed > left) {
    return InvalidInput(source, "PCD compressed block declares " + std::to_string(compressed) +
                                    " bytes but the body ends after " + std::to_string(left) + "; file truncated?");
  }
  if (uncompressed > compressed * kMaxLzfRatio + 64) {
    return InvalidInput(source, "PCD compressed block of " + std::to_string(compressed) +
                                    " bytes cannot decompress to the declared " + std::to_string(uncompressed) +
                                    " bytes; corrupt header?");
  }
  if (uncompressed > options.max_decompressed_bytes) {
    return ResourceExhaustedError(std::string(source) + ": PCD compressed block decompresses to " +
                                  std::to_string(uncompressed) + " bytes, more than the limit of " +
                                  std::to_string(options.max_decompressed_bytes) + std::string(kRaiseInputLimit));
  }
  Result<std::string> raw = LzfDecompress(bytes.substr(pos + 8, compressed), uncompressed);
  if (!raw.ok()) {
    return InvalidInput(
        source, "PCD binary_compressed block at byte " + std::to_string(pos + 8) + ": " + raw.status().message());
  }
  const std::string& data = *raw;
  cloud->points.reserve(h.points);
  const Field& fx = h.fields[h.xyz[0]];
  const Field& fy = h.fields[h.xyz[1]];
  const Field& fz = h.fields[h.xyz[2]];
  // Field f of point i lives at points * f.offset + i * f.size * f.count.
  const char* px = data.data() + h.points * fx.offset;
  const char* py = data.data() + h.points * fy.offset;
  const char* pz = data.data() + h.points * fz.offset;
  const uint64_t sx = fx.size * fx.count, sy = fy.size * fy.count, sz = fz.size * fz.count;
  for (uint64_t i = 0; i < h.points; ++i) {
    cloud->Add(Load(px + i * sx, fx), Load(py + i * sy, fy), Load(pz + i * sz, fz));
  }
  const size_t end = pos + 8 + compressed;
  return CheckTrailing(source, bytes.substr(end), end);
}

}  // namespace

bool LooksLikePcd(std::string_view bytes) {
  LineCursor lines(bytes.substr(0, 4096));
  std::string_view line;
  while (lines.Next(&line)) {
    const std::vector<std::string_view> t = SplitWhitespace(line);
    if (t.empty() || t[0].front() == '#') continue;
    return t[0] == "VERSION" || t[0] == "FIELDS";
  }
  return false;
}

Result<PointCloud> ReadPcd(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  VC_ASSIGN_OR_RETURN(const Header h, ParseHeader(bytes, source));
  VC_RETURN_IF_ERROR(CheckPointLimit(h.points, "PCD header", source, options));
  PointCloud cloud(options);
  switch (h.data) {
    case Data::kAscii:
      VC_RETURN_IF_ERROR(ReadAscii(bytes, source, h, &cloud));
      break;
    case Data::kBinary:
      VC_RETURN_IF_ERROR(ReadBinary(bytes, source, h, &cloud));
      break;
    case Data::kBinaryCompressed:
      VC_RETURN_IF_ERROR(ReadCompressed(bytes, source, h, options, &cloud));
      break;
  }
  cloud.detail = h.data_name;
  return cloud;
}

}  // namespace vc::readers
