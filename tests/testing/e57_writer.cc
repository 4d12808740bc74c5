#include "testing/e57_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "vc/base/crc32c.h"

namespace vc::testing {
namespace {

constexpr uint64_t kPageSize = 1024;
constexpr uint64_t kPageData = 1020;

template <typename T>
void Append(std::string* s, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  s->append(b, sizeof(T));
}

template <typename T>
void PutAt(std::string* s, size_t offset, T v) {
  std::memcpy(s->data() + offset, &v, sizeof(T));
}

std::string Number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// Packs values least significant bit first, as E57's bitPackCodec does.
class BitWriter {
 public:
  void Put(uint64_t value, unsigned bits) {
    for (unsigned i = 0; i < bits; ++i) {
      if (used_ == 0) bytes_.push_back('\0');
      if ((value >> i) & 1u) bytes_.back() = static_cast<char>(bytes_.back() | (1u << used_));
      used_ = (used_ + 1) % 8;
    }
  }
  std::string bytes() const { return bytes_; }

 private:
  std::string bytes_;
  unsigned used_ = 0;
};

// One prototype field: its XML and its bytestream.
struct FieldOut {
  std::string xml;
  std::string stream;
};

unsigned Bits(int64_t minimum, int64_t maximum) {
  const uint64_t range = static_cast<uint64_t>(maximum) - static_cast<uint64_t>(minimum);
  unsigned bits = 0;
  while (bits < 64 && (range >> bits) != 0) ++bits;
  return bits;
}

FieldOut IntegerField(const std::string& name, const std::vector<int64_t>& values, int64_t minimum, int64_t maximum,
                      const std::string& scaled_attributes) {
  FieldOut f;
  f.xml = "<" + name + " type=\"" + (scaled_attributes.empty() ? "Integer" : "ScaledInteger") + "\" minimum=\"" +
          std::to_string(minimum) + "\" maximum=\"" + std::to_string(maximum) + "\"" + scaled_attributes + "/>";
  const unsigned bits = Bits(minimum, maximum);
  BitWriter w;
  for (int64_t v : values) w.Put(static_cast<uint64_t>(v) - static_cast<uint64_t>(minimum), bits);
  f.stream = w.bytes();
  return f;
}

FieldOut CoordinateField(const std::string& name, const E57ScanSpec& scan, int axis) {
  std::vector<double> values;
  for (const Eigen::Vector3d& p : scan.points) values.push_back(p[axis]);
  FieldOut f;
  switch (scan.type) {
    case E57ValueType::kFloatDouble:
      f.xml = "<" + name + " type=\"Float\"/>";
      for (double v : values) Append<double>(&f.stream, v);
      return f;
    case E57ValueType::kFloatSingle:
      f.xml = "<" + name + " type=\"Float\" precision=\"single\"/>";
      for (double v : values) Append<float>(&f.stream, static_cast<float>(v));
      return f;
    case E57ValueType::kInteger:
    case E57ValueType::kScaledInteger:
      break;
  }
  const bool scaled = scan.type == E57ValueType::kScaledInteger;
  std::vector<int64_t> raw;
  for (double v : values) raw.push_back(scaled ? std::llround((v - scan.offset) / scan.scale) : std::llround(v));
  int64_t lo = 0, hi = 0;
  if (!raw.empty()) {
    lo = *std::min_element(raw.begin(), raw.end()) - 3;
    hi = *std::max_element(raw.begin(), raw.end()) + 5;
  }
  return IntegerField(name, raw, lo, hi,
                      scaled ? " scale=\"" + Number(scan.scale) + "\" offset=\"" + Number(scan.offset) + "\"" : "");
}

// The binary section of `scan` at logical offset `start`; its prototype XML into *prototype.
std::string Section(const E57ScanSpec& scan, uint64_t start, std::string* prototype) {
  std::vector<FieldOut> fields;
  if (scan.intensity) {
    std::vector<int64_t> intensity;
    for (size_t i = 0; i < scan.points.size(); ++i) intensity.push_back(static_cast<int64_t>((i * 37) % 4096));
    fields.push_back(IntegerField("intensity", intensity, 0, 4095, ""));
  }
  const bool spherical = scan.coordinates == E57Coordinates::kSpherical;
  const char* names[3] = {"cartesianX", "cartesianY", "cartesianZ"};
  const char* spherical_names[3] = {"sphericalRange", "sphericalAzimuth", "sphericalElevation"};
  for (int a = 0; a < 3; ++a) fields.push_back(CoordinateField(spherical ? spherical_names[a] : names[a], scan, a));
  if (!scan.invalid_state.empty()) {
    std::vector<int64_t> states(scan.invalid_state.begin(), scan.invalid_state.end());
    fields.push_back(IntegerField(spherical ? "sphericalInvalidState" : "cartesianInvalidState", states, 0, 2, ""));
  }
  prototype->clear();
  for (const FieldOut& f : fields) *prototype += f.xml;

  std::string section(32, '\0');
  section[0] = 1;
  const int packets = std::max(scan.packets, 1);
  for (int k = 0; k < packets; ++k) {
    if (scan.extra_packets && k == 1) {
      std::string empty(8, '\0');
      empty[0] = 2;
      PutAt<uint16_t>(&empty, 2, static_cast<uint16_t>(empty.size() - 1));
      section += empty;
      std::string index(16, '\0');  // Type 0, no entries.
      PutAt<uint16_t>(&index, 2, static_cast<uint16_t>(index.size() - 1));
      section += index;
    }
    std::string packet(6 + 2 * fields.size(), '\0');
    packet[0] = 1;
    PutAt<uint16_t>(&packet, 4, static_cast<uint16_t>(fields.size()));
    for (size_t s = 0; s < fields.size(); ++s) {
      const std::string& stream = fields[s].stream;
      const size_t from = stream.size() * k / packets, to = stream.size() * (k + 1) / packets;
      PutAt<uint16_t>(&packet, 6 + 2 * s, static_cast<uint16_t>(to - from));
      packet += stream.substr(from, to - from);
    }
    while (packet.size() % 4 != 0) packet += '\0';
    PutAt<uint16_t>(&packet, 2, static_cast<uint16_t>(packet.size() - 1));
    section += packet;
  }
  PutAt<uint64_t>(&section, 8, section.size());
  PutAt<uint64_t>(&section, 16, E57PhysicalOffset(start + 32));
  return section;
}

std::string ScanXml(const E57ScanSpec& scan, uint64_t section_physical, const std::string& prototype) {
  std::string x = "<vectorChild type=\"Structure\">\n";
  x += "<guid type=\"String\"><![CDATA[" + scan.guid + "]]></guid>\n";
  x += "<name type=\"String\"><![CDATA[" + scan.name + "]]></name>\n";
  x += "<description type=\"String\"><![CDATA[written by the vc test writer]]></description>\n";
  if (scan.write_pose) {
    const Eigen::Quaterniond& q = scan.rotation;
    const Eigen::Vector3d& t = scan.translation_m;
    x += "<pose type=\"Structure\">\n<rotation type=\"Structure\">";
    x += "<w type=\"Float\">" + Number(q.w()) + "</w><x type=\"Float\">" + Number(q.x()) + "</x><y type=\"Float\">" +
         Number(q.y()) + "</y><z type=\"Float\">" + Number(q.z()) + "</z></rotation>\n";
    x += "<translation type=\"Structure\"><x type=\"Float\">" + Number(t.x()) + "</x><y type=\"Float\">" +
         Number(t.y()) + "</y><z type=\"Float\">" + Number(t.z()) + "</z></translation>\n</pose>\n";
  }
  const int64_t count = static_cast<int64_t>(scan.points.size()) + scan.record_count_delta;
  x += "<points type=\"CompressedVector\" fileOffset=\"" + std::to_string(section_physical) + "\" recordCount=\"" +
       std::to_string(count) + "\">\n<prototype type=\"Structure\">" + prototype +
       "</prototype>\n<codecs type=\"Vector\" allowHeterogeneousChildren=\"1\"></codecs>\n</points>\n";
  x += "</vectorChild>\n";
  return x;
}

}  // namespace

uint64_t E57PhysicalOffset(uint64_t logical) { return logical / kPageData * kPageSize + logical % kPageData; }

void FixE57Checksums(std::string* file) {
  for (size_t page = 0; (page + 1) * kPageSize <= file->size(); ++page) {
    const uint32_t crc = ComputeCrc32c(std::string_view(*file).substr(page * kPageSize, kPageData));
    char* c = file->data() + page * kPageSize + kPageData;
    c[0] = static_cast<char>(crc >> 24);
    c[1] = static_cast<char>(crc >> 16);
    c[2] = static_cast<char>(crc >> 8);
    c[3] = static_cast<char>(crc);
  }
}

std::string WriteE57(const E57Spec& spec) {
  std::string logical(48, '\0');
  std::string scans_xml;
  for (const E57ScanSpec& scan : spec.scans) {
    while (logical.size() % 4 != 0) logical += '\0';
    const uint64_t start = logical.size();
    std::string prototype;
    logical += Section(scan, start, &prototype);
    scans_xml += ScanXml(scan, E57PhysicalOffset(start), prototype);
  }
  std::string xml =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<e57Root type=\"Structure\" xmlns=\"http://www.astm.org/COMMIT/E57/2010-e57-v1.0\">\n"
      "<formatName type=\"String\"><![CDATA[ASTM E57 3D Imaging Data File]]></formatName>\n"
      "<guid type=\"String\"><![CDATA[{5C2F6E9A-0000-4000-8000-0000000000FF}]]></guid>\n"
      "<versionMajor type=\"Integer\">1</versionMajor>\n"
      "<versionMinor type=\"Integer\">0</versionMinor>\n"
      "<e57LibraryVersion type=\"String\"><![CDATA[vc-test-writer]]></e57LibraryVersion>\n"
      "<coordinateMetadata type=\"String\"></coordinateMetadata>\n"
      "<creationDateTime type=\"Structure\">\n<dateTimeValue type=\"Float\">1.3e9</dateTimeValue>\n"
      "<isAtomicClockReferenced type=\"Integer\">0</isAtomicClockReferenced>\n</creationDateTime>\n"
      "<data3D type=\"Vector\" allowHeterogeneousChildren=\"1\">\n" +
      scans_xml +
      "</data3D>\n"
      "<images2D type=\"Vector\" allowHeterogeneousChildren=\"1\"></images2D>\n"
      "</e57Root>\n";
  if (spec.edit_xml) spec.edit_xml(xml);
  const uint64_t xml_logical = logical.size();
  logical += xml;
  if (logical.size() % kPageData != 0) logical.append(kPageData - logical.size() % kPageData, '\0');
  const uint64_t pages = logical.size() / kPageData;
  std::memcpy(logical.data(), "ASTM-E57", 8);
  PutAt<uint32_t>(&logical, 8, 1);
  PutAt<uint32_t>(&logical, 12, 0);
  PutAt<uint64_t>(&logical, 16, pages * kPageSize);
  PutAt<uint64_t>(&logical, 24, E57PhysicalOffset(xml_logical));
  PutAt<uint64_t>(&logical, 32, xml.size());
  PutAt<uint64_t>(&logical, 40, kPageSize);
  std::string file;
  for (uint64_t p = 0; p < pages; ++p) {
    file += logical.substr(p * kPageData, kPageData);
    file.append(4, '\0');
  }
  FixE57Checksums(&file);
  return file;
}

}  // namespace vc::testing
