// PLY (Stanford polygon format) in ascii, binary_little_endian and binary_big_endian.
//
// Only the "vertex" element's x, y and z are kept (any scalar type); every other property, element
// (faces, edges, ...) and list is parsed only to be skipped, so the offsets stay right. Ascii
// bodies are read one element item per line, so errors can name the line.
#include <algorithm>
#include <string>
#include <vector>

#include "readers/readers.h"

namespace vc::readers {
namespace {

enum class Type { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool ParseType(std::string_view name, Type* type) {
  struct Entry {
    std::string_view name;
    Type type;
  };
  static constexpr Entry kTypes[] = {
      {"char", Type::kInt8},     {"int8", Type::kInt8},       {"uchar", Type::kUint8},    {"uint8", Type::kUint8},
      {"short", Type::kInt16},   {"int16", Type::kInt16},     {"ushort", Type::kUint16},  {"uint16", Type::kUint16},
      {"int", Type::kInt32},     {"int32", Type::kInt32},     {"uint", Type::kUint32},    {"uint32", Type::kUint32},
      {"float", Type::kFloat32}, {"float32", Type::kFloat32}, {"double", Type::kFloat64}, {"float64", Type::kFloat64},
  };
  for (const Entry& e : kTypes) {
    if (e.name == name) {
      *type = e.type;
      return true;
    }
  }
  return false;
}

size_t SizeOf(Type t) {
  switch (t) {
    case Type::kInt8:
    case Type::kUint8:
      return 1;
    case Type::kInt16:
    case Type::kUint16:
      return 2;
    case Type::kInt32:
    case Type::kUint32:
    case Type::kFloat32:
      return 4;
    case Type::kFloat64:
      return 8;
  }
  return 1;
}

bool IsInteger(Type t) { return t != Type::kFloat32 && t != Type::kFloat64; }

// Value of type `t` at p (caller checked bounds).
double Load(const char* p, Type t, bool big_endian) {
  switch (t) {
    case Type::kInt8:
      return LoadScalar<int8_t>(p, big_endian);
    case Type::kUint8:
      return LoadScalar<uint8_t>(p, big_endian);
    case Type::kInt16:
      return LoadScalar<int16_t>(p, big_endian);
    case Type::kUint16:
      return LoadScalar<uint16_t>(p, big_endian);
    case Type::kInt32:
      return LoadScalar<int32_t>(p, big_endian);
    case Type::kUint32:
      return LoadScalar<uint32_t>(p, big_endian);
    case Type::kFloat32:
      return LoadScalar<float>(p, big_endian);
    case Type::kFloat64:
      return LoadScalar<double>(p, big_endian);
  }
  return 0;
}

struct Property {
  std::string name;
  Type type = Type::kFloat32;  // Item type for lists.
  bool is_list = false;
  Type count_type = Type::kUint8;  // Lists only.
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;

  bool has_lists() const {
    return std::any_of(properties.begin(), properties.end(), [](const Property& p) { return p.is_list; });
  }
  // Bytes of one item if it has no lists; with lists, the least (every list empty).
  uint64_t min_stride() const {
    uint64_t s = 0;
    for (const Property& p : properties) s += SizeOf(p.is_list ? p.count_type : p.type);
    return s;
  }
};

enum class Encoding { kAscii, kBinaryLittle, kBinaryBig };

struct Header {
  Encoding encoding = Encoding::kAscii;
  std::string format_line;
  std::vector<Element> elements;
  size_t vertex_index = 0;
  int xyz[3] = {-1, -1, -1};  // Property indices of x, y, z in the vertex element.
  size_t body_offset = 0;
  uint64_t body_first_line = 0;  // Line number of the first body line (ascii).
};

// "vertices" for the vertex element, else `element "face"` style.
std::string Items(const Element& e) {
  return e.name == "vertex" ? std::string("vertices") : "\"" + e.name + "\" elements";
}

Status Truncated(std::string_view source, const Element& e, uint64_t present) {
  return InvalidInput(source, "PLY header declares " + std::to_string(e.count) + " " + Items(e) +
                                  " but the body ends after " + std::to_string(present) + "; file truncated?");
}

Result<Header> ParseHeader(std::string_view bytes, std::string_view source) {
  Header h;
  LineCursor lines(bytes);
  std::string_view line;
  lines.Next(&line);  // "ply", checked by LooksLikePly.
  bool have_format = false;
  bool have_end = false;
  while (lines.Next(&line)) {
    const std::string where = "line " + std::to_string(lines.line_number());
    const std::vector<std::string_view> t = SplitWhitespace(line);
    if (t.empty()) continue;
    const std::string_view key = t[0];
    if (key == "end_header") {
      have_end = true;
      break;
    }
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (t.size() != 3) {
        return InvalidInput(source, where +
                                        ": expected \"format <ascii|binary_little_endian|"
                                        "binary_big_endian> 1.0\", found " +
                                        Quote(line));
      }
      if (t[1] == "ascii") {
        h.encoding = Encoding::kAscii;
      } else if (t[1] == "binary_little_endian") {
        h.encoding = Encoding::kBinaryLittle;
      } else if (t[1] == "binary_big_endian") {
        h.encoding = Encoding::kBinaryBig;
      } else {
        return InvalidInput(source, where + ": unknown PLY format " + Quote(t[1]) +
                                        " (expected ascii, binary_little_endian or "
                                        "binary_big_endian)");
      }
      if (t[2] != "1.0" && t[2] != "1") {
        return InvalidInput(source, where + ": unsupported PLY version " + Quote(t[2]) + " (expected 1.0)");
      }
      h.format_line = std::string(t[1]) + " " + std::string(t[2]);
      have_format = true;
      continue;
    }
    if (key == "element") {
      Element e;
      if (t.size() != 3 || !ParseUint64(t[2], &e.count)) {
        return InvalidInput(source, where + ": expected \"element <name> <count>\", found " + Quote(line));
      }
      e.name = std::string(t[1]);
      h.elements.push_back(std::move(e));
      continue;
    }
    if (key == "property") {
      if (h.elements.empty()) {
        return InvalidInput(source, where + ": property " + Quote(line) + " before any \"element\" line");
      }
      Property p;
      std::string_view type_name;
      if (t.size() >= 2 && t[1] == "list") {
        if (t.size() != 5) {
          return InvalidInput(source, where +
                                          ": expected \"property list <count type> <item "
                                          "type> <name>\", found " +
                                          Quote(line));
        }
        p.is_list = true;
        if (!ParseType(t[2], &p.count_type)) {
          return InvalidInput(source, where + ": unknown PLY property type " + Quote(t[2]) +
                                          " (expected char, uchar, short, ushort, int, uint, "
                                          "float, double or int8..uint32, float32, float64)");
        }
        if (!IsInteger(p.count_type)) {
          return InvalidInput(source, where + ": list count type must be an integer type, found " + Quote(t[2]));
        }
        type_name = t[3];
        p.name = std::string(t[4]);
      } else {
        if (t.size() != 3) {
          return InvalidInput(source, where + ": expected \"property <type> <name>\", found " + Quote(line));
        }
        type_name = t[1];
        p.name = std::string(t[2]);
      }
      if (!ParseType(type_name, &p.type)) {
        return InvalidInput(source, where + ": unknown PLY property type " + Quote(type_name) +
                                        " (expected char, uchar, short, ushort, int, uint, "
                                        "float, double or int8..uint32, float32, float64)");
      }
      h.elements.back().properties.push_back(std::move(p));
      continue;
    }
    return InvalidInput(source, where + ": unknown PLY header keyword " + Quote(key) +
                                    " (expected format, element, property, comment, obj_info or "
                                    "end_header)");
  }
  if (!have_end) {
    return InvalidInput(
        source, "PLY header has no \"end_header\" line (read " + std::to_string(lines.line_number()) + " lines)");
  }
  if (!have_format) return InvalidInput(source, "PLY header has no \"format\" line");
  h.body_offset = lines.position();
  h.body_first_line = lines.line_number() + 1;

  bool found = false;
  for (size_t i = 0; i < h.elements.size(); ++i) {
    if (h.elements[i].name != "vertex") continue;
    if (found) return InvalidInput(source, "PLY header declares two \"vertex\" elements");
    found = true;
    h.vertex_index = i;
  }
  if (!found) {
    return InvalidInput(source,
                        "PLY header declares no \"vertex\" element (expected \"element "
                        "vertex <count>\" with x, y, z properties)");
  }
  const Element& v = h.elements[h.vertex_index];
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    for (size_t i = 0; i < v.properties.size(); ++i) {
      if (v.properties[i].name == kAxis[a]) h.xyz[a] = static_cast<int>(i);
    }
    if (h.xyz[a] < 0) {
      return InvalidInput(
          source, std::string("PLY vertex element has no \"") + kAxis[a] + "\" property (expected scalar x, y and z)");
    }
    if (v.properties[h.xyz[a]].is_list) {
      return InvalidInput(source, std::string("PLY vertex property \"") + kAxis[a] + "\" is a list; expected a scalar");
    }
  }
  if (v.count == 0) return InvalidInput(source, "PLY header declares 0 vertices; the cloud is empty");
  return h;
}

Status ReadBinaryBody(std::string_view bytes, std::string_view source, const Header& h, PointCloud* cloud) {
  const bool big = h.encoding == Encoding::kBinaryBig;
  size_t pos = h.body_offset;
  for (size_t ei = 0; ei < h.elements.size(); ++ei) {
    const Element& e = h.elements[ei];
    const bool is_vertex = ei == h.vertex_index;
    const uint64_t min_stride = e.min_stride();
    const uint64_t left = bytes.size() - pos;
    if (min_stride > 0 && e.count > left / min_stride) {
      return Truncated(source, e, left / min_stride);
    }
    if (!e.has_lists()) {
      if (is_vertex) {
        cloud->points.reserve(e.count);
        size_t offset[3];
        for (int a = 0; a < 3; ++a) {
          offset[a] = 0;
          for (int i = 0; i < h.xyz[a]; ++i) offset[a] += SizeOf(e.properties[i].type);
        }
        const Type tx = e.properties[h.xyz[0]].type, ty = e.properties[h.xyz[1]].type, tz = e.properties[h.xyz[2]].type;
        for (uint64_t i = 0; i < e.count; ++i) {
          const char* p = bytes.data() + pos + i * min_stride;
          cloud->Add(Load(p + offset[0], tx, big), Load(p + offset[1], ty, big), Load(p + offset[2], tz, big));
        }
      }
      pos += e.count * min_stride;
      continue;
    }
    // Items with list properties: walk every item, checking each read.
    if (is_vertex) cloud->points.reserve(e.count);
    for (uint64_t i = 0; i < e.count; ++i) {
      double xyz[3] = {0, 0, 0};
      for (size_t pi = 0; pi < e.properties.size(); ++pi) {
        const Property& p = e.properties[pi];
        const size_t head = SizeOf(p.is_list ? p.count_type : p.type);
        if (bytes.size() - pos < head) {
          return InvalidInput(source, "PLY " + Items(e) + " item " + std::to_string(i) + " of " +
                                          std::to_string(e.count) +
                                          " runs past the end of the "
                                          "body at byte " +
                                          std::to_string(bytes.size()) + "; file truncated?");
        }
        if (!p.is_list) {
          for (int a = 0; a < 3; ++a) {
            if (is_vertex && static_cast<int>(pi) == h.xyz[a]) xyz[a] = Load(bytes.data() + pos, p.type, big);
          }
          pos += head;
          continue;
        }
        const double n = Load(bytes.data() + pos, p.count_type, big);
        if (n < 0) {
          return InvalidInput(source, "PLY " + Items(e) + " item " + std::to_string(i) + ": negative list length " +
                                          std::to_string(static_cast<int64_t>(n)) + " at byte " + std::to_string(pos));
        }
        pos += head;
        const uint64_t need = static_cast<uint64_t>(n) * SizeOf(p.type);
        if (bytes.size() - pos < need) {
          return InvalidInput(source, "PLY " + Items(e) + " item " + std::to_string(i) + " of " +
                                          std::to_string(e.count) + ": list \"" + p.name + "\" of " +
                                          std::to_string(static_cast<uint64_t>(n)) + " items at byte " +
                                          std::to_string(pos) + " runs past the end of the body; file truncated?");
        }
        pos += need;
      }
      if (is_vertex) cloud->Add(xyz[0], xyz[1], xyz[2]);
    }
  }
  if (pos < bytes.size()) {
    const std::string_view rest = bytes.substr(pos);
    const bool blank =
        std::all_of(rest.begin(), rest.end(), [](char c) { return c == '\n' || c == '\r' || c == ' ' || c == '\0'; });
    if (!blank) {
      return InvalidInput(source, "PLY body has " + std::to_string(rest.size()) +
                                      " bytes left after the last declared element (at byte " + std::to_string(pos) +
                                      "); header and body do not match (wrong counts or types?)");
    }
  }
  return Status::Ok();
}

Status ReadAsciiBody(std::string_view bytes, std::string_view source, const Header& h, PointCloud* cloud) {
  const std::string_view body = bytes.substr(h.body_offset);
  LineCursor lines(body);
  const uint64_t line_base = h.body_first_line - 1;
  std::string_view line;
  std::vector<std::string_view> t;
  auto next_item = [&](std::string_view* out) {
    while (lines.Next(out)) {
      if (out->find_first_not_of(" \t") != std::string_view::npos) return true;
    }
    return false;
  };
  for (size_t ei = 0; ei < h.elements.size(); ++ei) {
    const Element& e = h.elements[ei];
    const bool is_vertex = ei == h.vertex_index;
    if (is_vertex) {
      // At least "0 0 0\n": two bytes per property.
      const uint64_t cap = body.size() / std::max<uint64_t>(2, 2 * e.properties.size());
      cloud->points.reserve(std::min<uint64_t>(e.count, cap));
    }
    for (uint64_t i = 0; i < e.count; ++i) {
      if (!next_item(&line)) return Truncated(source, e, i);
      const std::string where = "line " + std::to_string(line_base + lines.line_number());
      t = SplitWhitespace(line);
      size_t k = 0;
      double xyz[3] = {0, 0, 0};
      for (size_t pi = 0; pi < e.properties.size(); ++pi) {
        const Property& p = e.properties[pi];
        if (k >= t.size()) {
          return InvalidInput(source, where + ": PLY " + Items(e) + " item " + std::to_string(i) + " has " +
                                          std::to_string(t.size()) + " values; expected a value for property \"" +
                                          p.name + "\"");
        }
        if (p.is_list) {
          uint64_t n = 0;
          if (!ParseUint64(t[k], &n)) {
            return InvalidInput(source,
                                where + ": expected a list length for \"" + p.name + "\", found " + Quote(t[k]));
          }
          ++k;
          if (n > t.size() - k) {
            return InvalidInput(source, where + ": list \"" + p.name + "\" declares " + std::to_string(n) +
                                            " items but the line has " + std::to_string(t.size() - k) + " values left");
          }
          k += n;
          continue;
        }
        for (int a = 0; a < 3; ++a) {
          if (is_vertex && static_cast<int>(pi) == h.xyz[a] && !ParseDouble(t[k], &xyz[a])) {
            return InvalidInput(
                source, where + ": expected a number for vertex property \"" + p.name + "\", found " + Quote(t[k]));
          }
        }
        ++k;
      }
      if (k != t.size()) {
        return InvalidInput(source, where + ": PLY " + Items(e) + " item " + std::to_string(i) + " has " +
                                        std::to_string(t.size()) + " values, expected " + std::to_string(k) +
                                        " (header and body do not match)");
      }
      if (is_vertex) cloud->Add(xyz[0], xyz[1], xyz[2]);
    }
  }
  if (next_item(&line)) {
    return InvalidInput(source, "line " + std::to_string(line_base + lines.line_number()) + ": unexpected data " +
                                    Quote(line) + " after the last element declared in the PLY header");
  }
  return Status::Ok();
}

}  // namespace

bool LooksLikePly(std::string_view bytes) { return bytes.substr(0, 4) == "ply\n" || bytes.substr(0, 5) == "ply\r\n"; }

Result<PointCloud> ReadPly(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  VC_ASSIGN_OR_RETURN(const Header h, ParseHeader(bytes, source));
  VC_RETURN_IF_ERROR(CheckPointLimit(h.elements[h.vertex_index].count, "PLY header", source, options));
  PointCloud cloud(options);
  if (h.encoding == Encoding::kAscii) {
    VC_RETURN_IF_ERROR(ReadAsciiBody(bytes, source, h, &cloud));
  } else {
    VC_RETURN_IF_ERROR(ReadBinaryBody(bytes, source, h, &cloud));
  }
  cloud.detail = h.format_line;
  return cloud;
}

}  // namespace vc::readers
