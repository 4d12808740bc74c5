#include "vc/server/upload_assembler.h"

#include <fmt/format.h>

#include "vc/scene/scene_input.h"
#include "vc/wire/convert.h"
#include "vc/wire/sha256.h"

namespace vc::server {

std::string HumanBytes(uint64_t bytes) {
  if (bytes < 1024) return std::to_string(bytes) + " B";
  if (bytes < (uint64_t{1} << 20)) return fmt::format("{:.1f} KiB", bytes / 1024.0);
  if (bytes < (uint64_t{1} << 30)) return fmt::format("{:.1f} MiB", bytes / 1048576.0);
  return fmt::format("{:.2f} GiB", bytes / 1073741824.0);
}

Result<double> SpecMetresPerUnit(std::string_view units, std::string_view field) {
  if (units.empty()) return 1.0;
  Result<double> metres = MetresPerUnit(units);
  if (!metres.ok()) return InvalidArgumentError(std::string(field) + ": " + metres.status().message());
  return metres;
}

Status UploadAssembler::StartSpec() {
  if (has_spec_) return InvalidArgumentError("a second spec arrived; send exactly one spec, first");
  has_spec_ = true;
  return Status::Ok();
}

Status UploadAssembler::AcceptSpec(const v1::UploadSpec& upload) {
  if (accepted_) return InvalidArgumentError("a second spec arrived; send exactly one spec, first");
  upload_ = upload;
  if (upload.format() != v1::INPUT_FORMAT_UNSPECIFIED) {
    VC_RETURN_IF_ERROR(wire::FromProto(upload.format()).status());
  }
  VC_RETURN_IF_ERROR(SpecMetresPerUnit(upload.units(), "the spec's units").status());
  if (!upload.scene_sha256().empty() && !wire::IsSha256Hex(upload.scene_sha256())) {
    return InvalidArgumentError("the spec's scene_sha256 is not 64 lower-case hex digits");
  }
  if (upload.from_cache() && upload.scene_sha256().empty()) {
    return InvalidArgumentError("the spec asks for a cached scene (from_cache) but names none (scene_sha256)");
  }
  if (upload.total_size_bytes() == 0) {
    return InvalidArgumentError("the spec declares an empty upload (total_size_bytes = 0); send the file's size");
  }
  if (upload.total_size_bytes() > max_upload_bytes_) {
    return ResourceExhaustedError("the upload of " + HumanBytes(upload.total_size_bytes()) +
                                  " exceeds this server's limit of " + HumanBytes(max_upload_bytes_) +
                                  " (--max-upload-bytes); send a smaller or downsampled scene");
  }
  ticket_ = pool_->TryAdmit();
  if (!ticket_) {
    busy_ = true;
    return ResourceExhaustedError("the server is busy: all " + std::to_string(pool_->workers()) +
                                  " workers are running and the " + std::to_string(pool_->queue_capacity()) +
                                  "-job queue is full; retry in a few seconds");
  }
  if (!upload.from_cache()) data_.reserve(upload_.total_size_bytes());
  accepted_ = true;
  return Status::Ok();
}

Status UploadAssembler::AddChunk(std::string_view data) {
  if (!has_spec_) {
    return InvalidArgumentError("a data chunk arrived before the spec; the first message must be the spec");
  }
  if (!accepted_) return InvalidArgumentError("a data chunk arrived for a refused spec; start a new upload");
  if (upload_.from_cache()) {
    return InvalidArgumentError("a data chunk arrived for a scene to take from the cache (from_cache); send none");
  }
  if (data.size() > upload_.total_size_bytes() - data_.size()) {
    return InvalidArgumentError("the upload carries more than the " + std::to_string(upload_.total_size_bytes()) +
                                " bytes its spec declares; fix total_size_bytes");
  }
  data_.append(data);
  crc_.Update(data);
  return Status::Ok();
}

Status UploadAssembler::Finish() const {
  if (!has_spec_) {
    return InvalidArgumentError("the stream ended before any spec; send a spec message first, then the data");
  }
  if (!accepted_) return InvalidArgumentError("the upload's spec was refused; start a new upload");
  if (upload_.from_cache()) return Status::Ok();  // the bytes come from the cache (the reactor)
  if (data_.size() != upload_.total_size_bytes()) {
    return InvalidArgumentError("the upload ended after " + std::to_string(data_.size()) + " of the " +
                                std::to_string(upload_.total_size_bytes()) +
                                " bytes its spec declares; send all the data or fix total_size_bytes");
  }
  if (crc_.value() != upload_.crc32c()) {
    return DataLossError(
        fmt::format("the upload's CRC32C is {:08x} but its spec declares {:08x}; the data was corrupted or the spec is "
                    "wrong: retry the upload",
                    crc_.value(), upload_.crc32c()));
  }
  return Status::Ok();
}

}  // namespace vc::server
