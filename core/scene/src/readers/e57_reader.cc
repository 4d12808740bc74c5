// ASTM E57 (E2807) 1.0: the points of every /data3D scan, in the world frame, and the scans' poses.
//
// The physical file is 1024-byte pages: 1020 bytes of data, then the CRC-32C of those bytes stored
// big-endian (libE57Format's CheckedFile byte-swaps the checksum before storing it on a
// little-endian host). "Logical" offsets count data bytes only. The 48-byte header gives the XML
// section's place; the XML (parsed with expat into a small tree) describes each scan: its pose and a
// compressedVector of points whose prototype lists the fields, each field one bytestream. A
// compressedVector's binary section is a 32-byte section header, then data packets (type 1) that
// hold one buffer per bytestream, with index (type 0) and empty (type 2) packets skipped. Values are
// bit-packed little-endian, least significant bit first, continuing across packets: Integer and
// ScaledInteger as (value - minimum) in ceil(log2(maximum - minimum + 1)) bits, Float as IEEE
// single or double. Every page read is CRC-checked; every offset, length and count is checked
// against the bytes present before anything is allocated or read.
#include <expat.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "readers/readers.h"
#include "vc/base/crc32c.h"

namespace vc::readers {
namespace {

constexpr uint64_t kPageSize = 1024;
constexpr uint64_t kPageData = 1020;  // Bytes of a page before its checksum.
constexpr uint64_t kHeaderSize = 48;
constexpr uint64_t kSectionHeaderSize = 32;
constexpr int kMaxXmlDepth = 64;
// A tree node costs ~40x the 4 bytes of "<a/>"; real files have a few dozen elements per scan.
constexpr size_t kMaxXmlElements = size_t{1} << 20;

std::string Str(uint64_t v) { return std::to_string(v); }

// Physical offset of logical offset `logical`.
uint64_t ToPhysical(uint64_t logical) { return logical / kPageData * kPageSize + logical % kPageData; }

// The file as pages: logical reads that verify each page's checksum once.
class PagedFile {
 public:
  PagedFile(std::string_view bytes, std::string_view source)
      : bytes_(bytes), source_(source), verified_(bytes.size() / kPageSize, false) {}

  // Logical bytes in the file.
  uint64_t logical_size() const { return verified_.size() * kPageData; }

  // Logical offset of physical offset `physical`, or an error naming `what` if it points into a
  // checksum or past the end.
  Result<uint64_t> ToLogical(uint64_t physical, std::string_view what) const {
    if (physical % kPageSize >= kPageData || physical / kPageSize >= verified_.size()) {
      return InvalidInput(source_, "E57 " + std::string(what) + " at physical byte " + Str(physical) +
                                       (physical / kPageSize >= verified_.size()
                                            ? " is past the end of the file (" + Str(bytes_.size()) + " bytes)"
                                            : " points into a page checksum (bytes 1020-1023 of a page)"));
    }
    return physical / kPageSize * kPageData + physical % kPageSize;
  }

  // Appends `length` logical bytes from logical offset `logical` to *out.
  Status Read(uint64_t logical, uint64_t length, std::string_view what, std::string* out) {
    if (logical > logical_size() || length > logical_size() - logical) {
      return InvalidInput(source_, "E57 " + std::string(what) + " (" + Str(length) + " bytes at physical byte " +
                                       Str(ToPhysical(logical)) + ") runs past the end of the file (" +
                                       Str(bytes_.size()) + " bytes); file truncated?");
    }
    while (length > 0) {
      const uint64_t page = logical / kPageData;
      const uint64_t in_page = logical % kPageData;
      VC_RETURN_IF_ERROR(Verify(page));
      const uint64_t n = std::min(length, kPageData - in_page);
      out->append(bytes_.substr(page * kPageSize + in_page, n));
      logical += n;
      length -= n;
    }
    return Status::Ok();
  }

 private:
  Status Verify(uint64_t page) {
    if (verified_[page]) return Status::Ok();
    const std::string_view data = bytes_.substr(page * kPageSize, kPageData);
    const auto* c = reinterpret_cast<const unsigned char*>(bytes_.data() + page * kPageSize + kPageData);
    const uint32_t stored = uint32_t{c[0]} << 24 | uint32_t{c[1]} << 16 | uint32_t{c[2]} << 8 | uint32_t{c[3]};
    const uint32_t computed = ComputeCrc32c(data);
    if (stored != computed) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "stored CRC-32C 0x%08x does not match the computed 0x%08x", stored, computed);
      return InvalidInput(source_, "E57 page " + Str(page) + " (physical bytes " + Str(page * kPageSize) + " to " +
                                       Str(page * kPageSize + kPageSize - 1) + "): " + buf + "; file corrupt");
    }
    verified_[page] = true;
    return Status::Ok();
  }

  std::string_view bytes_;
  std::string_view source_;
  std::vector<bool> verified_;
};

template <typename T>
T At(std::string_view b, size_t offset) {
  return LoadScalar<T>(b.data() + offset, false);
}

// --- The XML section as a tree (expat) ---

struct XmlNode {
  std::string name;  // As written, with any namespace prefix.
  std::vector<std::pair<std::string, std::string>> attributes;
  std::string text;
  std::vector<size_t> children;  // Indices into XmlTree::nodes.
  uint64_t line = 0;             // 1-based line of the start tag.
  uint64_t byte = 0;             // Byte of the start tag in the XML section.

  const std::string* Attribute(std::string_view key) const {
    for (const auto& [k, v] : attributes) {
      if (k == key) return &v;
    }
    return nullptr;
  }
};

struct XmlTree {
  std::vector<XmlNode> nodes;  // nodes[0] is the root element.
};

struct XmlBuilder {
  XML_Parser parser = nullptr;
  XmlTree tree;
  std::vector<size_t> open;  // Indices of the elements being read.
  std::string error;         // Set when a handler stops the parser.

  void Stop(std::string why) {
    if (error.empty()) error = std::move(why);
    XML_StopParser(parser, XML_FALSE);
  }

  static void OnStart(void* user, const XML_Char* name, const XML_Char** attributes) {
    auto* b = static_cast<XmlBuilder*>(user);
    try {
      if (b->open.size() >= kMaxXmlDepth) return b->Stop("elements nest deeper than " + Str(kMaxXmlDepth));
      if (b->open.empty() && !b->tree.nodes.empty()) return b->Stop("more than one root element");
      if (b->tree.nodes.size() >= kMaxXmlElements) return b->Stop("more than " + Str(kMaxXmlElements) + " elements");
      XmlNode node;
      node.name = name;
      for (size_t i = 0; attributes[i] != nullptr; i += 2)
        node.attributes.emplace_back(attributes[i], attributes[i + 1]);
      node.line = XML_GetCurrentLineNumber(b->parser);
      node.byte = static_cast<uint64_t>(std::max<XML_Index>(XML_GetCurrentByteIndex(b->parser), 0));
      const size_t index = b->tree.nodes.size();
      if (!b->open.empty()) b->tree.nodes[b->open.back()].children.push_back(index);
      b->tree.nodes.push_back(std::move(node));
      b->open.push_back(index);
    } catch (const std::bad_alloc&) {
      b->Stop("out of memory");
    }
  }

  static void OnEnd(void* user, const XML_Char*) {
    auto* b = static_cast<XmlBuilder*>(user);
    if (!b->open.empty()) b->open.pop_back();
  }

  static void OnText(void* user, const XML_Char* text, int length) {
    auto* b = static_cast<XmlBuilder*>(user);
    if (b->open.empty()) return;
    try {
      b->tree.nodes[b->open.back()].text.append(text, static_cast<size_t>(length));
    } catch (const std::bad_alloc&) {
      b->Stop("out of memory");
    }
  }

  // E57 XML has no document type; refusing one also refuses entity-expansion bombs.
  static void OnDoctype(void* user, const XML_Char*, const XML_Char*, const XML_Char*, int) {
    static_cast<XmlBuilder*>(user)->Stop("has a DOCTYPE declaration, which E57 XML never has");
  }
};

Result<XmlTree> ParseXml(std::string_view xml, std::string_view source, uint64_t xml_physical) {
  XmlBuilder b;
  b.parser = XML_ParserCreate(nullptr);
  if (b.parser == nullptr) return ResourceExhaustedError(std::string(source) + ": cannot create an XML parser");
  XML_SetUserData(b.parser, &b);
  XML_SetElementHandler(b.parser, &XmlBuilder::OnStart, &XmlBuilder::OnEnd);
  XML_SetCharacterDataHandler(b.parser, &XmlBuilder::OnText);
  XML_SetStartDoctypeDeclHandler(b.parser, &XmlBuilder::OnDoctype);
  bool ok = true;
  constexpr size_t kChunk = size_t{1} << 20;
  for (size_t pos = 0; ok;) {
    const size_t n = std::min(kChunk, xml.size() - pos);
    const bool last = pos + n == xml.size();
    ok = XML_Parse(b.parser, xml.data() + pos, static_cast<int>(n), last ? XML_TRUE : XML_FALSE) == XML_STATUS_OK;
    pos += n;
    if (last) break;
  }
  Status status = Status::Ok();
  if (!ok || !b.error.empty()) {
    const std::string why = b.error.empty() ? XML_ErrorString(XML_GetErrorCode(b.parser)) : b.error;
    status =
        InvalidInput(source, "E57 XML section (at physical byte " + Str(xml_physical) + ") does not parse: " + why +
                                 " at line " + Str(XML_GetCurrentLineNumber(b.parser)) + ", byte " +
                                 Str(static_cast<uint64_t>(std::max<XML_Index>(XML_GetCurrentByteIndex(b.parser), 0))) +
                                 " of the XML");
  }
  XML_ParserFree(b.parser);
  if (!status.ok()) return status;
  if (b.tree.nodes.empty()) return InvalidInput(source, "E57 XML section holds no element");
  return std::move(b.tree);
}

// --- The scans described by the XML ---

// The local name of a possibly prefixed XML name ("nor:normalX" -> "normalX").
std::string_view LocalName(std::string_view name) {
  const size_t colon = name.rfind(':');
  return colon == std::string_view::npos ? name : name.substr(colon + 1);
}

std::string_view Trim(std::string_view s) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && space(s.front())) s.remove_prefix(1);
  while (!s.empty() && space(s.back())) s.remove_suffix(1);
  return s;
}

bool ParseInt64(std::string_view token, int64_t* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), *value);
  return ec == std::errc() && end == token.data() + token.size() && !token.empty();
}

enum class FieldKind { kInteger, kScaledInteger, kFloat32, kFloat64 };

// One bytestream of a compressedVector: a terminal element of its prototype.
struct Field {
  std::string name;  // Local name; nested fields as "parent/child".
  FieldKind kind = FieldKind::kFloat64;
  int64_t minimum = 0;
  uint64_t range = 0;  // maximum - minimum (integers).
  uint32_t bits = 64;  // Bits per record in the bytestream.
  double scale = 1;
  double offset = 0;
};

// A scan as the XML describes it, with what reading its points needs.
struct ScanLayout {
  E57Scan scan;
  uint64_t file_offset = 0;  // Physical offset of the binary section.
  std::vector<Field> fields;
  bool spherical = false;
  int coord[3] = {-1, -1, -1};  // Field indices of x/y/z or range/azimuth/elevation.
  int invalid_state = -1;       // Field index of the matching invalid-state field, or -1.
};

class XmlReader {
 public:
  XmlReader(const XmlTree& tree, std::string_view source) : tree_(tree), source_(source) {}

  Result<std::vector<ScanLayout>> Scans() {
    const XmlNode& root = tree_.nodes[0];
    if (LocalName(root.name) != "e57Root") return Error(root, "the root element is <" + root.name + ">, not <e57Root>");
    VC_RETURN_IF_ERROR(ExpectType(root, "Structure"));
    const XmlNode* data3d = Child(root, "data3D");
    if (data3d == nullptr) return Error(root, "<e57Root> has no <data3D>");
    VC_RETURN_IF_ERROR(ExpectType(*data3d, "Vector"));
    std::vector<ScanLayout> scans;
    for (size_t i = 0; i < data3d->children.size(); ++i) {
      VC_ASSIGN_OR_RETURN(ScanLayout scan, Scan(tree_.nodes[data3d->children[i]], i));
      scans.push_back(std::move(scan));
    }
    return scans;
  }

 private:
  Status Error(const XmlNode& at, std::string_view what) const {
    return InvalidInput(source_, "E57 XML section, line " + Str(at.line) + " (byte " + Str(at.byte) +
                                     " of the XML): " + std::string(what));
  }
  Status ScanError(const XmlNode& at, size_t scan, std::string_view what) const {
    return Error(at, "scan " + Str(scan) + ": " + std::string(what));
  }

  const XmlNode* Child(const XmlNode& parent, std::string_view name) const {
    for (size_t c : parent.children) {
      if (tree_.nodes[c].name == name) return &tree_.nodes[c];
    }
    return nullptr;
  }

  static std::string_view Type(const XmlNode& n) {
    const std::string* type = n.Attribute("type");
    return type == nullptr ? std::string_view() : std::string_view(*type);
  }

  Status ExpectType(const XmlNode& n, std::string_view type) const {
    if (Type(n) == type) return Status::Ok();
    return Error(n,
                 "<" + n.name + "> has type \"" + std::string(Type(n)) + "\", expected \"" + std::string(type) + "\"");
  }

  Result<std::string> String(const XmlNode& n) const {
    VC_RETURN_IF_ERROR(ExpectType(n, "String"));
    return n.text;
  }

  // The value of a Float, Integer or ScaledInteger element (0 when empty, as E57 defaults).
  Result<double> Number(const XmlNode& n) const {
    const std::string_view type = Type(n);
    const std::string_view text = Trim(n.text);
    if (type == "Float") {
      double v = 0;
      if (!text.empty() && (!ParseDouble(text, &v) || !std::isfinite(v))) {
        return Error(n, "<" + n.name + "> holds " + Quote(text) + ", expected a finite number");
      }
      return v;
    }
    if (type == "Integer" || type == "ScaledInteger") {
      int64_t raw = 0;
      if (!text.empty() && !ParseInt64(text, &raw)) {
        return Error(n, "<" + n.name + "> holds " + Quote(text) + ", expected an integer");
      }
      double scale = 1, offset = 0;
      if (type == "ScaledInteger") VC_RETURN_IF_ERROR(ScaleOffset(n, &scale, &offset));
      return static_cast<double>(raw) * scale + offset;
    }
    return Error(n, "<" + n.name + "> has type \"" + std::string(type) + "\", expected a number");
  }

  Status ScaleOffset(const XmlNode& n, double* scale, double* offset) const {
    for (auto [key, out] : {std::pair{"scale", scale}, std::pair{"offset", offset}}) {
      const std::string* text = n.Attribute(key);
      if (text != nullptr && (!ParseDouble(Trim(*text), out) || !std::isfinite(*out))) {
        return Error(n, "<" + n.name + "> " + key + "=" + Quote(*text) + " is not a finite number");
      }
    }
    if (*scale == 0) return Error(n, "<" + n.name + "> has scale 0");
    return Status::Ok();
  }

  // The number in <parent><name>, required.
  Result<double> Required(const XmlNode& parent, std::string_view name, size_t scan) const {
    const XmlNode* n = Child(parent, name);
    if (n == nullptr) return ScanError(parent, scan, "<" + parent.name + "> has no <" + std::string(name) + ">");
    return Number(*n);
  }

  Status Pose(const XmlNode& pose, size_t index, E57Scan* scan) const {
    VC_RETURN_IF_ERROR(ExpectType(pose, "Structure"));
    if (const XmlNode* r = Child(pose, "rotation")) {
      VC_RETURN_IF_ERROR(ExpectType(*r, "Structure"));
      double q[4];
      for (int i = 0; i < 4; ++i) {
        VC_ASSIGN_OR_RETURN(q[i], Required(*r, std::string_view("wxyz").substr(i, 1), index));
      }
      Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
      const double norm = rotation.norm();
      // Writers store doubles of a unit quaternion; more than 1e-3 off is not a rotation.
      if (!(std::abs(norm - 1) <= 1e-3)) {
        return ScanError(
            *r, index,
            "the pose rotation (w, x, y, z) has norm " + std::to_string(norm) + ", expected a unit quaternion");
      }
      scan->rotation = rotation.normalized();
    }
    if (const XmlNode* t = Child(pose, "translation")) {
      VC_RETURN_IF_ERROR(ExpectType(*t, "Structure"));
      for (int i = 0; i < 3; ++i) {
        VC_ASSIGN_OR_RETURN(scan->translation_m[i], Required(*t, std::string_view("xyz").substr(i, 1), index));
      }
    }
    return Status::Ok();
  }

  Result<uint64_t> UintAttribute(const XmlNode& n, std::string_view key, size_t scan) const {
    const std::string* text = n.Attribute(key);
    uint64_t v = 0;
    if (text == nullptr) return ScanError(n, scan, "<" + n.name + "> has no " + std::string(key) + " attribute");
    if (!ParseUint64(Trim(*text), &v)) {
      return ScanError(n, scan,
                       "<" + n.name + "> " + std::string(key) + "=" + Quote(*text) + " is not a non-negative integer");
    }
    return v;
  }

  Status Prototype(const XmlNode& node, const std::string& prefix, size_t scan, std::vector<Field>* fields) const {
    for (size_t c : node.children) {
      const XmlNode& n = tree_.nodes[c];
      Field f;
      f.name = prefix + std::string(LocalName(n.name));
      const std::string_view type = Type(n);
      if (type == "Structure") {
        VC_RETURN_IF_ERROR(Prototype(n, f.name + "/", scan, fields));
        continue;
      }
      if (type == "Integer" || type == "ScaledInteger") {
        int64_t minimum = std::numeric_limits<int64_t>::min(), maximum = std::numeric_limits<int64_t>::max();
        for (auto [key, out] : {std::pair{"minimum", &minimum}, std::pair{"maximum", &maximum}}) {
          const std::string* text = n.Attribute(key);
          if (text != nullptr && !ParseInt64(Trim(*text), out)) {
            return ScanError(
                n, scan, "prototype field <" + n.name + "> " + key + "=" + Quote(*text) + " is not a 64-bit integer");
          }
        }
        if (maximum < minimum) {
          return ScanError(n, scan,
                           "prototype field <" + n.name + "> has maximum " + std::to_string(maximum) +
                               " below its minimum " + std::to_string(minimum));
        }
        f.kind = type == "Integer" ? FieldKind::kInteger : FieldKind::kScaledInteger;
        f.minimum = minimum;
        f.range = static_cast<uint64_t>(maximum) - static_cast<uint64_t>(minimum);
        f.bits = static_cast<uint32_t>(std::bit_width(f.range));  // ceil(log2(range + 1)), at most 64.
        if (f.kind == FieldKind::kScaledInteger) VC_RETURN_IF_ERROR(ScaleOffset(n, &f.scale, &f.offset));
      } else if (type == "Float") {
        const std::string* precision = n.Attribute("precision");
        if (precision == nullptr || *precision == "double") {
          f.kind = FieldKind::kFloat64;
          f.bits = 64;
        } else if (*precision == "single") {
          f.kind = FieldKind::kFloat32;
          f.bits = 32;
        } else {
          return ScanError(n, scan,
                           "prototype field <" + n.name + "> has precision " + Quote(*precision) +
                               ", expected \"single\" or \"double\"");
        }
      } else {
        return ScanError(n, scan,
                         "prototype field <" + n.name + "> has type \"" + std::string(type) +
                             "\"; only Integer, ScaledInteger, Float and Structure are supported");
      }
      fields->push_back(std::move(f));
    }
    return Status::Ok();
  }

  Result<ScanLayout> Scan(const XmlNode& node, size_t index) const {
    VC_RETURN_IF_ERROR(ExpectType(node, "Structure"));
    ScanLayout layout;
    E57Scan& scan = layout.scan;
    if (const XmlNode* n = Child(node, "name")) {
      VC_ASSIGN_OR_RETURN(scan.name, String(*n));
    }
    if (const XmlNode* n = Child(node, "guid")) {
      VC_ASSIGN_OR_RETURN(scan.guid, String(*n));
    }
    if (const XmlNode* pose = Child(node, "pose")) VC_RETURN_IF_ERROR(Pose(*pose, index, &scan));
    const XmlNode* points = Child(node, "points");
    if (points == nullptr) return ScanError(node, index, "<" + node.name + "> has no <points>");
    VC_RETURN_IF_ERROR(ExpectType(*points, "CompressedVector"));
    VC_ASSIGN_OR_RETURN(layout.file_offset, UintAttribute(*points, "fileOffset", index));
    VC_ASSIGN_OR_RETURN(scan.point_count, UintAttribute(*points, "recordCount", index));
    const XmlNode* prototype = Child(*points, "prototype");
    if (prototype == nullptr) return ScanError(*points, index, "<points> has no <prototype>");
    VC_RETURN_IF_ERROR(ExpectType(*prototype, "Structure"));
    VC_RETURN_IF_ERROR(Prototype(*prototype, "", index, &layout.fields));
    if (layout.fields.empty()) return ScanError(*prototype, index, "the points' <prototype> has no fields");
    if (const XmlNode* codecs = Child(*points, "codecs")) {
      for (size_t c : codecs->children) {
        for (size_t k : tree_.nodes[c].children) {
          const XmlNode& codec = tree_.nodes[k];
          if (codec.name != "inputs" && codec.name != "bitPackCodec") {
            return ScanError(codec, index,
                             "codec <" + codec.name + "> is not supported (only bitPackCodec, E57 1.0's one)");
          }
        }
      }
    }
    const auto find = [&](std::string_view name) {
      for (size_t i = 0; i < layout.fields.size(); ++i) {
        if (layout.fields[i].name == name) return static_cast<int>(i);
      }
      return -1;
    };
    const int cartesian[3] = {find("cartesianX"), find("cartesianY"), find("cartesianZ")};
    const int spherical[3] = {find("sphericalRange"), find("sphericalAzimuth"), find("sphericalElevation")};
    if (cartesian[0] >= 0 && cartesian[1] >= 0 && cartesian[2] >= 0) {
      std::copy(cartesian, cartesian + 3, layout.coord);
      layout.invalid_state = find("cartesianInvalidState");
    } else if (spherical[0] >= 0 && spherical[1] >= 0 && spherical[2] >= 0) {
      layout.spherical = true;
      std::copy(spherical, spherical + 3, layout.coord);
      layout.invalid_state = find("sphericalInvalidState");
    } else {
      return ScanError(*prototype, index,
                       "the points' <prototype> has neither cartesianX/Y/Z nor "
                       "sphericalRange/Azimuth/Elevation");
    }
    return layout;
  }

  const XmlTree& tree_;
  std::string_view source_;
};

// --- Header, XML, binary sections ---

struct E57File {
  std::string version;
  std::vector<ScanLayout> scans;
};

Result<E57File> ReadHeaderAndXml(std::string_view bytes, std::string_view source, PagedFile* file) {
  if (bytes.size() < kHeaderSize || !LooksLikeE57(bytes)) {
    return InvalidInput(source, "E57 header: the file has " + Str(bytes.size()) +
                                    " bytes without the 48-byte header that starts with \"ASTM-E57\"");
  }
  const uint32_t major = At<uint32_t>(bytes, 8), minor = At<uint32_t>(bytes, 12);
  const uint64_t file_length = At<uint64_t>(bytes, 16);
  const uint64_t xml_offset = At<uint64_t>(bytes, 24), xml_length = At<uint64_t>(bytes, 32);
  const uint64_t page_size = At<uint64_t>(bytes, 40);
  E57File out;
  out.version = Str(major) + "." + Str(minor);
  if (major != 1 || minor != 0) {
    return InvalidInput(source, "E57 header: version " + out.version + " at byte 8 is not supported (expected 1.0)");
  }
  if (page_size != kPageSize) {
    return InvalidInput(source, "E57 header: page size at byte 40 is " + Str(page_size) + ", expected 1024");
  }
  if (file_length != bytes.size()) {
    return InvalidInput(source, "E57 header: file length at byte 16 is " + Str(file_length) + " but the file has " +
                                    Str(bytes.size()) + " bytes; file truncated?");
  }
  if (bytes.size() % kPageSize != 0) {
    return InvalidInput(source, "E57 header: the file's " + Str(bytes.size()) +
                                    " bytes are not whole 1024-byte pages; the last page, at physical byte " +
                                    Str(bytes.size() / kPageSize * kPageSize) + ", is truncated");
  }
  std::string header;
  VC_RETURN_IF_ERROR(file->Read(0, kHeaderSize, "header", &header));  // Verifies page 0.
  VC_ASSIGN_OR_RETURN(const uint64_t xml_logical, file->ToLogical(xml_offset, "XML section (header byte 24)"));
  std::string xml;
  VC_RETURN_IF_ERROR(file->Read(xml_logical, xml_length, "XML section", &xml));
  VC_ASSIGN_OR_RETURN(const XmlTree tree, ParseXml(xml, source, xml_offset));
  VC_ASSIGN_OR_RETURN(out.scans, XmlReader(tree, source).Scans());
  return out;
}

// Reads bits [bit, bit + bits) of `s`, least significant first; `s` is padded with 16 bytes.
uint64_t ReadBits(const std::string& s, uint64_t bit, uint32_t bits) {
  if (bits == 0) return 0;
  const uint64_t byte = bit >> 3;
  const unsigned shift = bit & 7;
  uint64_t v = LoadScalar<uint64_t>(s.data() + byte, false) >> shift;
  if (shift + bits > 64) v |= uint64_t{static_cast<unsigned char>(s[byte + 8])} << (64 - shift);
  if (bits < 64) v &= (uint64_t{1} << bits) - 1;
  return v;
}

// Bits a writer may leave after the last record of a field: libE57Format flushes integers in whole
// words of 8, 16, 32 or 64 bits (the smallest that holds one record); floats are never padded.
uint64_t AllowedPaddingBits(const Field& f) {
  if (f.kind == FieldKind::kFloat32 || f.kind == FieldKind::kFloat64) return 0;
  return f.bits <= 8 ? 7 : f.bits <= 16 ? 15 : f.bits <= 32 ? 31 : 63;
}

// Collects each field's bytestream from the data packets of the scan's binary section.
Result<std::vector<std::string>> ReadStreams(PagedFile* file, const ScanLayout& layout, size_t index,
                                             std::string_view source) {
  const std::string where = "scan " + Str(index) + " binary section";
  VC_ASSIGN_OR_RETURN(const uint64_t start, file->ToLogical(layout.file_offset, where + " (XML fileOffset)"));
  std::string header;
  VC_RETURN_IF_ERROR(file->Read(start, kSectionHeaderSize, where + " header", &header));
  const auto error = [&](uint64_t logical, const std::string& what) {
    return InvalidInput(source, "E57 " + where + " at physical byte " + Str(ToPhysical(logical)) + ": " + what);
  };
  if (header[0] != 1) {
    return error(start,
                 "section id is " + Str(static_cast<unsigned char>(header[0])) + ", expected 1 (compressedVector)");
  }
  const uint64_t section_length = At<uint64_t>(header, 8);
  const uint64_t data_offset = At<uint64_t>(header, 16);
  if (section_length < kSectionHeaderSize || section_length > file->logical_size() - start) {
    return error(start, "section length " + Str(section_length) + " is less than its 32-byte header or runs past " +
                            "the end of the file");
  }
  const uint64_t end = start + section_length;
  std::vector<std::string> streams(layout.fields.size(), std::string(16, '\0'));
  // A writer that wrote no record may leave the data offset 0: nothing to read.
  if (data_offset == 0 && layout.scan.point_count == 0) return streams;
  for (std::string& s : streams) s.clear();
  VC_ASSIGN_OR_RETURN(uint64_t pos, file->ToLogical(data_offset, where + " data (section header byte 16)"));
  if (pos < start + kSectionHeaderSize || pos > end) {
    return error(start, "data offset " + Str(data_offset) + " is outside the section");
  }
  std::string packet;
  while (pos < end) {
    packet.clear();
    if (end - pos < 4) return error(pos, "a packet header would run past the end of the section");
    VC_RETURN_IF_ERROR(file->Read(pos, 4, where + " packet header", &packet));
    const unsigned type = static_cast<unsigned char>(packet[0]);
    const uint64_t length = uint64_t{At<uint16_t>(packet, 2)} + 1;
    if (length > end - pos) {
      return error(pos, "packet of " + Str(length) + " bytes runs past the end of the section (" + Str(end - pos) +
                            " bytes left)");
    }
    if (type == 0 || type == 2) {  // Index and empty packets: nothing to read.
      pos += length;
      continue;
    }
    if (type != 1) return error(pos, "unknown packet type " + Str(type) + " (expected 0, 1 or 2)");
    if (length < 6) return error(pos, "data packet of " + Str(length) + " bytes is shorter than its 6-byte header");
    VC_RETURN_IF_ERROR(file->Read(pos + 4, length - 4, where + " data packet", &packet));
    const uint64_t count = At<uint16_t>(packet, 4);
    if (count != streams.size()) {
      return error(pos, "data packet has " + Str(count) + " bytestreams but the prototype has " + Str(streams.size()) +
                            " fields");
    }
    uint64_t offset = 6 + 2 * count;
    if (offset > length) return error(pos, "data packet of " + Str(length) + " bytes cannot hold its buffer lengths");
    for (uint64_t s = 0; s < count; ++s) {
      const uint64_t n = At<uint16_t>(packet, 6 + 2 * s);
      if (n > length - offset) {
        return error(pos, "bytestream " + Str(s) + " buffer of " + Str(n) + " bytes runs past the end of its " +
                              Str(length) + "-byte packet");
      }
      streams[s].append(packet, offset, n);
      offset += n;
    }
    pos += length;
  }
  // Each field must hold exactly recordCount records, give or take a writer's padding.
  const uint64_t records = layout.scan.point_count;
  for (size_t s = 0; s < streams.size(); ++s) {
    const Field& f = layout.fields[s];
    const uint64_t have_bits = uint64_t{streams[s].size()} * 8;
    const uint64_t held = f.bits == 0 ? records : have_bits / f.bits;
    if (held < records || have_bits - records * f.bits > AllowedPaddingBits(f)) {
      const std::string held_text = held < records ? Str(held) : "more than " + Str(records);
      return error(start, "field " + f.name + " holds " + held_text + " records (" + Str(streams[s].size()) +
                              " bytes of " + Str(f.bits) + "-bit values) but the XML recordCount is " + Str(records));
    }
    streams[s].append(16, '\0');  // Padding for ReadBits.
  }
  return streams;
}

// The value of record `r` of field `f`; false if an integer lies outside [minimum, maximum].
bool Value(const Field& f, const std::string& stream, uint64_t r, double* value) {
  const uint64_t raw = ReadBits(stream, r * f.bits, f.bits);
  switch (f.kind) {
    case FieldKind::kFloat32: {
      const auto bits32 = static_cast<uint32_t>(raw);
      *value = std::bit_cast<float>(bits32);
      return true;
    }
    case FieldKind::kFloat64:
      *value = std::bit_cast<double>(raw);
      return true;
    case FieldKind::kInteger:
    case FieldKind::kScaledInteger: {
      if (raw > f.range) return false;
      const auto v = static_cast<int64_t>(static_cast<uint64_t>(f.minimum) + raw);
      *value = f.kind == FieldKind::kInteger ? static_cast<double>(v) : static_cast<double>(v) * f.scale + f.offset;
      return true;
    }
  }
  return false;
}

}  // namespace

Result<E57Cloud> ReadE57(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  PagedFile file(bytes, source);
  VC_ASSIGN_OR_RETURN(E57File e57, ReadHeaderAndXml(bytes, source, &file));
  uint64_t total = 0;
  for (const ScanLayout& s : e57.scans) {
    total = s.scan.point_count > UINT64_MAX - total ? UINT64_MAX : total + s.scan.point_count;
  }
  VC_RETURN_IF_ERROR(CheckPointLimit(total, "E57 XML section", source, options));
  if (total > options.max_result_bytes / kBytesPerPoint) {
    return ResourceExhaustedError(std::string(source) + ": E57 XML section declares " + Str(total) + " points (" +
                                  Str(total * kBytesPerPoint) + " bytes), more than the limit of " +
                                  Str(options.max_result_bytes) + " bytes" + std::string(kRaiseResultLimit));
  }
  E57Cloud out{PointCloud(options), {}};
  uint64_t invalid = 0;
  for (size_t i = 0; i < e57.scans.size(); ++i) {
    const ScanLayout& layout = e57.scans[i];
    VC_ASSIGN_OR_RETURN(const std::vector<std::string> streams, ReadStreams(&file, layout, i, source));
    const Eigen::Matrix3d rotation = layout.scan.rotation.toRotationMatrix();
    const Eigen::Vector3d& translation = layout.scan.translation_m;
    out.cloud.points.reserve(out.cloud.points.size() + layout.scan.point_count);
    for (uint64_t r = 0; r < layout.scan.point_count; ++r) {
      double c[3];
      for (int a = 0; a < 3; ++a) {
        const Field& f = layout.fields[layout.coord[a]];
        if (!Value(f, streams[layout.coord[a]], r, &c[a])) {
          return InvalidInput(source, "E57 scan " + Str(i) + " binary section: record " + Str(r) + " of field " +
                                          f.name + " is outside the field's minimum and maximum");
        }
      }
      if (layout.invalid_state >= 0) {
        double state = 0;
        // 0: valid; 1: direction only (no range); 2: invalid (ASTM E2807, 8.4.5). Only 0 is a point.
        if (!Value(layout.fields[layout.invalid_state], streams[layout.invalid_state], r, &state) || state != 0) {
          ++invalid;
          continue;
        }
      }
      Eigen::Vector3d p(c[0], c[1], c[2]);
      if (layout.spherical) {
        const double range = c[0], azimuth = c[1], elevation = c[2];
        p = range * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                                    std::sin(elevation));
      }
      const Eigen::Vector3d world = rotation * p + translation;
      out.cloud.Add(world.x(), world.y(), world.z());
    }
  }
  out.cloud.detail = "E57 " + e57.version + ", " + Str(e57.scans.size()) + (e57.scans.size() == 1 ? " scan" : " scans");
  if (invalid > 0) out.cloud.detail += ", " + Str(invalid) + " records marked invalid";
  out.scans.reserve(e57.scans.size());
  for (ScanLayout& s : e57.scans) out.scans.push_back(std::move(s.scan));
  return out;
}

}  // namespace vc::readers

namespace vc {

bool LooksLikeE57(std::string_view bytes) { return bytes.substr(0, 8) == "ASTM-E57"; }

Result<std::vector<E57Scan>> ReadE57Scans(std::string_view bytes, std::string_view source) {
  return CatchOutOfMemory(std::string(source) + ": reading the E57 scans", [&]() -> Result<std::vector<E57Scan>> {
    readers::PagedFile file(bytes, source);
    VC_ASSIGN_OR_RETURN(readers::E57File e57, readers::ReadHeaderAndXml(bytes, source, &file));
    std::vector<E57Scan> scans;
    scans.reserve(e57.scans.size());
    for (readers::ScanLayout& s : e57.scans) scans.push_back(std::move(s.scan));
    return scans;
  });
}

}  // namespace vc
