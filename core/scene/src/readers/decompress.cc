// gzip (zlib), bzip2 (libbz2) and LZF decompression with size limits, for the input readers.
//
// Output grows in chunks and the running total is checked against the limit before every chunk,
// so a decompression bomb stops at the limit instead of exhausting memory. LZF follows liblzf's
// lzf_decompress (Marc Lehmann), with every read and back-reference checked.
#include <bzlib.h>
#include <zlib.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <string>

#include "readers/readers.h"

namespace vc::readers {
namespace {

constexpr size_t kChunk = size_t{1} << 18;

bool StartsWith(std::string_view s, std::string_view prefix) {
  return s.size() >= prefix.size() && s.substr(0, prefix.size()) == prefix;
}

bool IsGzipMagic(std::string_view s) {
  return s.size() >= 2 && static_cast<unsigned char>(s[0]) == 0x1f &&
         static_cast<unsigned char>(s[1]) == 0x8b;
}

bool IsBzip2Magic(std::string_view s) {
  // "BZh" + block size '1'..'9' + block magic (pi) or end-of-stream magic (sqrt pi).
  if (s.size() < 10 || !StartsWith(s, "BZh") || s[3] < '1' || s[3] > '9') return false;
  const std::string_view m = s.substr(4, 6);
  return m == std::string_view("\x31\x41\x59\x26\x53\x59", 6) ||
         m == std::string_view("\x17\x72\x45\x38\x50\x90", 6);
}

bool AllZero(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c == 0; });
}

// Grows `out` by a chunk, or by up to one byte past the limit, so that exceeding the limit is
// detected without growing far beyond it; returns the bytes added. The capacity doubles (so
// appends stay amortised O(1)) but never past the limit plus one byte: std::string's own growth
// would reserve up to twice the limit.
size_t Grow(std::string* out, uint64_t max_bytes) {
  const size_t size = out->size();
  const uint64_t left = max_bytes - std::min<uint64_t>(size, max_bytes);
  const size_t grow = left >= kChunk ? kChunk : static_cast<size_t>(left + 1);
  if (out->capacity() < size + grow) {
    const uint64_t cap = std::max<uint64_t>(uint64_t{2} * out->capacity(), size + grow);
    // libstdc++'s reserve on a non-empty string doubles anyway; a fresh one reserves exactly.
    std::string bigger;
    bigger.reserve(static_cast<size_t>(std::min<uint64_t>(cap, max_bytes + 1)));
    bigger.append(*out);
    out->swap(bigger);
  }
  out->resize(size + grow);
  return grow;
}

Status TooLarge(std::string_view source, std::string_view kind, uint64_t max_bytes) {
  return ResourceExhaustedError(std::string(source) + ": " + std::string(kind) +
                                " input decompresses to more than the limit of " +
                                std::to_string(max_bytes) + " bytes" + std::string(kRaiseInputLimit));
}

Result<std::string> Gunzip(std::string_view in, std::string_view source, uint64_t max_bytes) {
  z_stream zs{};
  // 15 + 32: accept gzip or zlib headers.
  if (inflateInit2(&zs, 15 + 32) != Z_OK) return InternalError("zlib inflateInit2 failed");
  std::string out;
  size_t in_pos = 0;
  Status status = Status::Ok();
  while (true) {
    const size_t old = out.size();
    const size_t grow = Grow(&out, max_bytes);
    const size_t in_avail = std::min<size_t>(in.size() - in_pos, UINT_MAX);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data() + in_pos));
    zs.avail_in = static_cast<uInt>(in_avail);
    zs.next_out = reinterpret_cast<Bytef*>(out.data() + old);
    zs.avail_out = static_cast<uInt>(grow);
    const int rc = inflate(&zs, Z_NO_FLUSH);
    in_pos += in_avail - zs.avail_in;
    out.resize(old + (grow - zs.avail_out));
    if (out.size() > max_bytes) {
      status = TooLarge(source, "gzip", max_bytes);
      break;
    }
    if (rc == Z_STREAM_END) {
      const std::string_view rest = in.substr(in_pos);
      if (rest.empty() || AllZero(rest)) break;
      if (!IsGzipMagic(rest)) {
        status =
            InvalidInput(source, "gzip stream ends at compressed byte " + std::to_string(in_pos) +
                                     " but " + std::to_string(rest.size()) +
                                     " bytes of non-gzip data follow; corrupt file?");
        break;
      }
      inflateReset(&zs);  // Another gzip member (e.g. from `cat a.gz b.gz`).
      continue;
    }
    if (rc == Z_OK) continue;
    if (rc == Z_BUF_ERROR) {  // No progress possible: all input consumed mid-stream.
      status = InvalidInput(source, "gzip stream truncated: input ends after " +
                                        std::to_string(in.size()) + " compressed bytes (" +
                                        std::to_string(out.size()) +
                                        " decompressed) before the end-of-stream marker");
      break;
    }
    status =
        InvalidInput(source, "corrupt gzip stream near compressed byte " + std::to_string(in_pos) +
                                 ": " + (zs.msg ? zs.msg : "inflate error " + std::to_string(rc)));
    break;
  }
  inflateEnd(&zs);
  if (!status.ok()) return status;
  return out;
}

std::string Bzip2ErrorName(int rc) {
  switch (rc) {
    case BZ_DATA_ERROR:
      return "data integrity error (CRC mismatch or bad block)";
    case BZ_DATA_ERROR_MAGIC:
      return "bad stream magic";
    case BZ_MEM_ERROR:
      return "out of memory";
    default:
      return "libbz2 error " + std::to_string(rc);
  }
}

Result<std::string> Bunzip2(std::string_view in, std::string_view source, uint64_t max_bytes) {
  bz_stream bz{};
  if (BZ2_bzDecompressInit(&bz, 0, 0) != BZ_OK) return InternalError("BZ2_bzDecompressInit failed");
  std::string out;
  size_t in_pos = 0;
  Status status = Status::Ok();
  while (true) {
    const size_t old = out.size();
    const size_t grow = Grow(&out, max_bytes);
    const size_t in_avail = std::min<size_t>(in.size() - in_pos, UINT_MAX);
    bz.next_in = const_cast<char*>(in.data() + in_pos);
    bz.avail_in = static_cast<unsigned>(in_avail);
    bz.next_out = out.data() + old;
    bz.avail_out = static_cast<unsigned>(grow);
    const int rc = BZ2_bzDecompress(&bz);
    in_pos += in_avail - bz.avail_in;
    const size_t produced = grow - bz.avail_out;
    out.resize(old + produced);
    if (out.size() > max_bytes) {
      status = TooLarge(source, "bzip2", max_bytes);
      break;
    }
    if (rc == BZ_STREAM_END) {
      const std::string_view rest = in.substr(in_pos);
      if (rest.empty() || AllZero(rest)) break;
      if (!IsBzip2Magic(rest)) {
        status =
            InvalidInput(source, "bzip2 stream ends at compressed byte " + std::to_string(in_pos) +
                                     " but " + std::to_string(rest.size()) +
                                     " bytes of non-bzip2 data follow; corrupt file?");
        break;
      }
      BZ2_bzDecompressEnd(&bz);  // Another stream (e.g. from pbzip2 or `cat a.bz2 b.bz2`).
      bz = bz_stream{};
      if (BZ2_bzDecompressInit(&bz, 0, 0) != BZ_OK) {
        return InternalError("BZ2_bzDecompressInit failed");
      }
      continue;
    }
    if (rc == BZ_OK) {
      if (in_pos >= in.size() && produced == 0) {
        status = InvalidInput(source, "bzip2 stream truncated: input ends after " +
                                          std::to_string(in.size()) + " compressed bytes (" +
                                          std::to_string(out.size()) +
                                          " decompressed) before the end-of-stream marker");
        break;
      }
      continue;
    }
    status = InvalidInput(source, "corrupt bzip2 stream near compressed byte " +
                                      std::to_string(in_pos) + ": " + Bzip2ErrorName(rc));
    break;
  }
  BZ2_bzDecompressEnd(&bz);
  if (!status.ok()) return status;
  return out;
}

}  // namespace

Compression DetectCompression(std::string_view bytes) {
  if (IsGzipMagic(bytes)) return Compression::kGzip;
  if (IsBzip2Magic(bytes)) return Compression::kBzip2;
  return Compression::kNone;
}

std::string_view DetectUnsupportedCompression(std::string_view bytes) {
  if (StartsWith(bytes, std::string_view("\xFD"
                                         "7zXZ\0",
                                         6)))
    return "xz";
  if (StartsWith(bytes, "\x28\xB5\x2F\xFD")) return "zstd";
  if (StartsWith(bytes, "PK\x03\x04")) return "zip";
  if (StartsWith(bytes, "7z\xBC\xAF\x27\x1C")) return "7z";
  return "";
}

Result<std::string> Decompress(std::string_view bytes, Compression compression,
                               std::string_view source, uint64_t max_bytes) {
  switch (compression) {
    case Compression::kGzip:
      return Gunzip(bytes, source, max_bytes);
    case Compression::kBzip2:
      return Bunzip2(bytes, source, max_bytes);
    case Compression::kNone:
      break;
  }
  return std::string(bytes);
}

Result<std::string> LzfDecompress(std::string_view compressed, size_t expected_size) {
  std::string out(expected_size, '\0');
  const auto* ip = reinterpret_cast<const unsigned char*>(compressed.data());
  const unsigned char* const in_end = ip + compressed.size();
  size_t op = 0;
  auto error = [&](std::string_view what) -> Status {
    return InvalidArgumentError(
        "corrupt LZF data at compressed byte " +
        std::to_string(ip - reinterpret_cast<const unsigned char*>(compressed.data())) + ": " +
        std::string(what));
  };
  while (ip < in_end) {
    unsigned ctrl = *ip++;
    if (ctrl < 32) {  // Literal run of ctrl + 1 bytes.
      const size_t len = ctrl + 1;
      if (static_cast<size_t>(in_end - ip) < len) return error("literal run past the end of input");
      if (expected_size - op < len) return error("output longer than the declared size");
      std::memcpy(out.data() + op, ip, len);
      op += len;
      ip += len;
    } else {  // Back-reference: length (ctrl >> 5) + 2, distance from 13 bits + 1.
      size_t len = ctrl >> 5;
      if (ip >= in_end) return error("back-reference past the end of input");
      if (len == 7) {
        len += *ip++;
        if (ip >= in_end) return error("back-reference past the end of input");
      }
      const size_t distance = ((static_cast<size_t>(ctrl & 0x1f) << 8) | *ip++) + 1;
      len += 2;
      if (distance > op) return error("back-reference before the start of output");
      if (expected_size - op < len) return error("output longer than the declared size");
      for (size_t i = 0; i < len; ++i, ++op) out[op] = out[op - distance];
    }
  }
  if (op != expected_size) {
    return InvalidArgumentError("LZF data decompresses to " + std::to_string(op) +
                                " bytes, expected " + std::to_string(expected_size));
  }
  return out;
}

}  // namespace vc::readers
