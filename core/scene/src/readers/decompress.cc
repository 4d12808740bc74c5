// gzip (zlib), bzip2 (libbz2) and LZF decompression with size limits, for the input readers.
//
// Two passes: the first inflates into one 256 KiB scratch chunk, counting the output and checking
// the running total against the limit after every chunk, so a decompression bomb is refused at
// the limit having allocated nothing; the second inflates into a string reserved at exactly the
// size counted. Twice the decompression time buys a peak of exactly the output (growing a string
// would hold up to 1.5-3x it while copying). LZF follows liblzf's lzf_decompress (Marc Lehmann),
// with every read and back-reference checked.
#include <bzlib.h>
#include <zlib.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <string>
#include <vector>

#include "readers/readers.h"

namespace vc::readers {
namespace {

constexpr size_t kChunk = size_t{1} << 18;

bool StartsWith(std::string_view s, std::string_view prefix) {
  return s.size() >= prefix.size() && s.substr(0, prefix.size()) == prefix;
}

bool IsGzipMagic(std::string_view s) {
  return s.size() >= 2 && static_cast<unsigned char>(s[0]) == 0x1f && static_cast<unsigned char>(s[1]) == 0x8b;
}

bool IsBzip2Magic(std::string_view s) {
  // "BZh" + block size '1'..'9' + block magic (pi) or end-of-stream magic (sqrt pi).
  if (s.size() < 10 || !StartsWith(s, "BZh") || s[3] < '1' || s[3] > '9') return false;
  const std::string_view m = s.substr(4, 6);
  return m == std::string_view("\x31\x41\x59\x26\x53\x59", 6) || m == std::string_view("\x17\x72\x45\x38\x50\x90", 6);
}

bool AllZero(std::string_view s) {
  return std::all_of(s.begin(), s.end(), [](char c) { return c == 0; });
}

Status TooLarge(std::string_view source, std::string_view kind, uint64_t max_bytes) {
  return ResourceExhaustedError(std::string(source) + ": " + std::string(kind) +
                                " input decompresses to more than the limit of " + std::to_string(max_bytes) +
                                " bytes" + std::string(kRaiseInputLimit));
}

// Inflates `in`, handing each chunk of output to sink(data, size); see the file comment.
template <typename Sink>
Status Gunzip(std::string_view in, std::string_view source, uint64_t max_bytes, Sink&& sink) {
  z_stream zs{};
  // 15 + 32: accept gzip or zlib headers.
  if (inflateInit2(&zs, 15 + 32) != Z_OK) return InternalError("zlib inflateInit2 failed");
  std::vector<char> chunk(kChunk);
  uint64_t total = 0;
  size_t in_pos = 0;
  Status status = Status::Ok();
  while (true) {
    const size_t in_avail = std::min<size_t>(in.size() - in_pos, UINT_MAX);
    zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data() + in_pos));
    zs.avail_in = static_cast<uInt>(in_avail);
    zs.next_out = reinterpret_cast<Bytef*>(chunk.data());
    zs.avail_out = static_cast<uInt>(kChunk);
    const int rc = inflate(&zs, Z_NO_FLUSH);
    in_pos += in_avail - zs.avail_in;
    const size_t produced = kChunk - zs.avail_out;
    total += produced;
    if (total > max_bytes) {
      status = TooLarge(source, "gzip", max_bytes);
      break;
    }
    sink(chunk.data(), produced);
    if (rc == Z_STREAM_END) {
      const std::string_view rest = in.substr(in_pos);
      if (rest.empty() || AllZero(rest)) break;
      if (!IsGzipMagic(rest)) {
        status =
            InvalidInput(source, "gzip stream ends at compressed byte " + std::to_string(in_pos) + " but " +
                                     std::to_string(rest.size()) + " bytes of non-gzip data follow; corrupt file?");
        break;
      }
      inflateReset(&zs);  // Another gzip member (e.g. from `cat a.gz b.gz`).
      continue;
    }
    if (rc == Z_OK) continue;
    if (rc == Z_BUF_ERROR) {  // No progress possible: all input consumed mid-stream.
      status = InvalidInput(source, "gzip stream truncated: input ends after " + std::to_string(in.size()) +
                                        " compressed bytes (" + std::to_string(total) +
                                        " decompressed) before the end-of-stream marker");
      break;
    }
    status = InvalidInput(source, "corrupt gzip stream near compressed byte " + std::to_string(in_pos) + ": " +
                                      (zs.msg ? zs.msg : "inflate error " + std::to_string(rc)));
    break;
  }
  inflateEnd(&zs);
  return status;
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

template <typename Sink>
Status Bunzip2(std::string_view in, std::string_view source, uint64_t max_bytes, Sink&& sink) {
  bz_stream bz{};
  if (BZ2_bzDecompressInit(&bz, 0, 0) != BZ_OK) return InternalError("BZ2_bzDecompressInit failed");
  std::vector<char> chunk(kChunk);
  uint64_t total = 0;
  size_t in_pos = 0;
  Status status = Status::Ok();
  while (true) {
    const size_t in_avail = std::min<size_t>(in.size() - in_pos, UINT_MAX);
    bz.next_in = const_cast<char*>(in.data() + in_pos);
    bz.avail_in = static_cast<unsigned>(in_avail);
    bz.next_out = chunk.data();
    bz.avail_out = static_cast<unsigned>(kChunk);
    const int rc = BZ2_bzDecompress(&bz);
    in_pos += in_avail - bz.avail_in;
    const size_t produced = kChunk - bz.avail_out;
    total += produced;
    if (total > max_bytes) {
      status = TooLarge(source, "bzip2", max_bytes);
      break;
    }
    sink(chunk.data(), produced);
    if (rc == BZ_STREAM_END) {
      const std::string_view rest = in.substr(in_pos);
      if (rest.empty() || AllZero(rest)) break;
      if (!IsBzip2Magic(rest)) {
        status =
            InvalidInput(source, "bzip2 stream ends at compressed byte " + std::to_string(in_pos) + " but " +
                                     std::to_string(rest.size()) + " bytes of non-bzip2 data follow; corrupt file?");
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
        status = InvalidInput(source, "bzip2 stream truncated: input ends after " + std::to_string(in.size()) +
                                          " compressed bytes (" + std::to_string(total) +
                                          " decompressed) before the end-of-stream marker");
        break;
      }
      continue;
    }
    status = InvalidInput(
        source, "corrupt bzip2 stream near compressed byte " + std::to_string(in_pos) + ": " + Bzip2ErrorName(rc));
    break;
  }
  BZ2_bzDecompressEnd(&bz);
  return status;
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

Result<std::string> Decompress(std::string_view bytes, Compression compression, std::string_view source,
                               uint64_t max_bytes) {
  if (compression == Compression::kNone) return std::string(bytes);
  auto inflate_into = [&](auto&& sink) {
    return compression == Compression::kGzip ? Gunzip(bytes, source, max_bytes, sink)
                                             : Bunzip2(bytes, source, max_bytes, sink);
  };
  uint64_t size = 0;
  VC_RETURN_IF_ERROR(inflate_into([&](const char*, size_t n) { size += n; }));
  std::string out;
  out.reserve(static_cast<size_t>(size));
  VC_RETURN_IF_ERROR(inflate_into([&](const char* p, size_t n) { out.append(p, n); }));
  return out;
}

Result<std::string> LzfDecompress(std::string_view compressed, size_t expected_size) {
  std::string out(expected_size, '\0');
  const auto* ip = reinterpret_cast<const unsigned char*>(compressed.data());
  const unsigned char* const in_end = ip + compressed.size();
  size_t op = 0;
  auto error = [&](std::string_view what) -> Status {
    return InvalidArgumentError("corrupt LZF data at compressed byte " +
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
    return InvalidArgumentError("LZF data decompresses to " + std::to_string(op) + " bytes, expected " +
                                std::to_string(expected_size));
  }
  return out;
}

}  // namespace vc::readers
