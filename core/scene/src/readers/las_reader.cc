// ASPRS LAS 1.0-1.4, uncompressed, point data record formats 0-10.
//
// Every format stores X, Y, Z as int32 at record offsets 0, 4 and 8; the coordinate is
// X * scale + offset from the public header block. LAS 1.4 adds a 64-bit point count at byte 247;
// the legacy 32-bit count at byte 107 is used for earlier versions. LAZ (LASzip) files are
// recognised by the compressed bit in the point format id or by the "laszip encoded" VLR and
// refused with instructions, since decoding them is out of scope.
#include <string>

#include "readers/readers.h"

namespace vc::readers {
namespace {

constexpr size_t kMinHeaderSize = 227;  // LAS 1.0-1.2.
constexpr size_t kVlrHeaderSize = 54;
// Smallest record length of point formats 0-10.
constexpr uint16_t kMinRecordLength[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

constexpr const char* kLazMessage =
    "compressed LAZ is not supported; decompress it first, e.g. `laszip -i in.laz -o out.las` or "
    "`pdal translate in.laz out.las`";

template <typename T>
T At(std::string_view b, size_t offset) {
  return LoadScalar<T>(b.data() + offset, false);
}

}  // namespace

bool LooksLikeLas(std::string_view bytes) { return bytes.substr(0, 4) == "LASF"; }

Result<PointCloud> ReadLas(std::string_view bytes, std::string_view source, const ReadOptions& options) {
  if (bytes.size() < kMinHeaderSize) {
    return InvalidInput(source, "LAS file has " + std::to_string(bytes.size()) +
                                    " bytes; the public header block alone needs " + std::to_string(kMinHeaderSize) +
                                    "; file truncated?");
  }
  const int major = At<uint8_t>(bytes, 24);
  const int minor = At<uint8_t>(bytes, 25);
  const std::string version = std::to_string(major) + "." + std::to_string(minor);
  if (major != 1 || minor > 4) {
    return InvalidInput(source, "unsupported LAS version " + version + " at byte 24 (expected 1.0 to 1.4)");
  }
  const uint16_t header_size = At<uint16_t>(bytes, 94);
  const uint32_t point_offset = At<uint32_t>(bytes, 96);
  const uint32_t vlr_count = At<uint32_t>(bytes, 100);
  const uint8_t format_id = At<uint8_t>(bytes, 104);
  const uint16_t record_length = At<uint16_t>(bytes, 105);
  const uint32_t legacy_count = At<uint32_t>(bytes, 107);
  const size_t required_header = minor >= 4 ? 375 : minor == 3 ? 235 : kMinHeaderSize;
  if (header_size < required_header) {
    return InvalidInput(source, "LAS " + version + " header size at byte 94 is " + std::to_string(header_size) +
                                    ", expected at least " + std::to_string(required_header));
  }
  if (header_size > bytes.size()) {
    return InvalidInput(source, "LAS header size at byte 94 is " + std::to_string(header_size) + " but the file has " +
                                    std::to_string(bytes.size()) + " bytes; file truncated?");
  }
  // LASzip sets bit 7 (and in some versions bit 6) of the point format id.
  if (format_id & 0xC0) return InvalidInput(source, kLazMessage);
  // Variable length records: look for the LASzip VLR (user "laszip encoded", record 22204).
  size_t pos = header_size;
  for (uint32_t i = 0; i < vlr_count; ++i) {
    // pos can pass the end: the previous record's length is not checked against the file.
    if (pos > bytes.size() || bytes.size() - pos < kVlrHeaderSize || pos + kVlrHeaderSize > point_offset) {
      return InvalidInput(source, "LAS header declares " + std::to_string(vlr_count) +
                                      " variable length records but record " + std::to_string(i) + " at byte " +
                                      std::to_string(pos) + " runs past the start of the point data (byte " +
                                      std::to_string(point_offset) + ")");
    }
    const std::string_view user = bytes.substr(pos + 2, 16);
    const uint16_t record_id = At<uint16_t>(bytes, pos + 18);
    const uint16_t length = At<uint16_t>(bytes, pos + 20);
    if (user.substr(0, 14) == "laszip encoded" || record_id == 22204) {
      return InvalidInput(source, kLazMessage);
    }
    pos += kVlrHeaderSize + length;
  }
  if (point_offset < pos || point_offset > bytes.size()) {
    return InvalidInput(source, "LAS offset to point data at byte 96 is " + std::to_string(point_offset) +
                                    ", expected " + std::to_string(pos) + " to " + std::to_string(bytes.size()) +
                                    " (after the header and VLRs, inside the file)");
  }
  if (format_id > 10) {
    return InvalidInput(source, "unknown LAS point data record format " + std::to_string(format_id) +
                                    " at byte 104 (expected 0 to 10)");
  }
  if (record_length < kMinRecordLength[format_id]) {
    return InvalidInput(source, "LAS point record length at byte 105 is " + std::to_string(record_length) +
                                    " but point format " + std::to_string(format_id) + " needs at least " +
                                    std::to_string(kMinRecordLength[format_id]));
  }
  uint64_t count = legacy_count;
  if (minor >= 4) {
    const uint64_t count64 = At<uint64_t>(bytes, 247);
    if (count64 != 0) {
      if (legacy_count != 0 && legacy_count != count64) {
        return InvalidInput(source, "LAS 1.4 header declares " + std::to_string(count64) +
                                        " points at byte 247 but a legacy count of " + std::to_string(legacy_count) +
                                        " at byte 107; header inconsistent");
      }
      count = count64;
    }
  }
  if (count == 0) return InvalidInput(source, "LAS header declares 0 points; the cloud is empty");
  VC_RETURN_IF_ERROR(CheckPointLimit(count, "LAS header", source, options));
  const uint64_t left = bytes.size() - point_offset;
  if (count > left / record_length) {
    return InvalidInput(source, "LAS header declares " + std::to_string(count) + " points but the body ends after " +
                                    std::to_string(left / record_length) + "; file truncated?");
  }
  double scale[3], offset[3];
  for (int a = 0; a < 3; ++a) {
    scale[a] = At<double>(bytes, 131 + 8 * a);
    offset[a] = At<double>(bytes, 155 + 8 * a);
    if (!std::isfinite(scale[a]) || scale[a] == 0 || !std::isfinite(offset[a])) {
      return InvalidInput(source, std::string("LAS ") + "xyz"[a] + " scale/offset at bytes " +
                                      std::to_string(131 + 8 * a) + "/" + std::to_string(155 + 8 * a) + " are " +
                                      std::to_string(scale[a]) + "/" + std::to_string(offset[a]) +
                                      "; expected a finite non-zero scale and a finite offset");
    }
  }
  PointCloud cloud(options);
  cloud.points.reserve(count);
  for (uint64_t i = 0; i < count; ++i) {
    const size_t p = point_offset + i * record_length;
    cloud.Add(At<int32_t>(bytes, p) * scale[0] + offset[0], At<int32_t>(bytes, p + 4) * scale[1] + offset[1],
              At<int32_t>(bytes, p + 8) * scale[2] + offset[2]);
  }
  cloud.detail = "LAS " + version + " PDRF " + std::to_string(format_id);
  return cloud;
}

}  // namespace vc::readers
