// UploadAssembler: the client-streamed upload of one job, checked as it arrives.
//
// The spec comes first: its size is checked against the server's --max-upload-bytes and the job
// reserves a place in the WorkerPool (TryAdmit) before any byte is uploaded, so a busy server or a
// too-large scene is refused at once. Chunks are then appended with the declared size and the
// CRC32C checked incrementally, and Finish verifies both once the client half-closes. Every
// failure is a vc::Status whose message tells the client what to fix.
//
// Not thread-safe: one per call, fed by one gRPC reaction at a time.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "vc/base/crc32c.h"
#include "vc/base/status.h"
#include "vc/server/worker_pool.h"
#include "vc/v1/planner.pb.h"

namespace vc::server {

// "12.3 MiB" style.
std::string HumanBytes(uint64_t bytes);

// Metres per unit of a spec's `units` field named `field` ("" = metres; MetresPerUnit otherwise).
// INVALID_ARGUMENT naming the field and the accepted units.
Result<double> SpecMetresPerUnit(std::string_view units, std::string_view field);

class UploadAssembler {
 public:
  // `pool` admits the job and must outlive the assembler.
  UploadAssembler(uint64_t max_upload_bytes, WorkerPool* pool) : max_upload_bytes_(max_upload_bytes), pool_(pool) {}

  // Notes that a spec message arrived, before its parameters are read: INVALID_ARGUMENT for a
  // second one.
  Status StartSpec();
  // Checks the upload spec (format, units, non-empty, within --max-upload-bytes) and admits the job.
  // INVALID_ARGUMENT, or RESOURCE_EXHAUSTED for a too-large upload or a busy server (busy() true).
  // INVALID_ARGUMENT once a spec was accepted. Until one is (it was refused, or the RPC refused its
  // parameters and never called this), AddChunk and Finish are INVALID_ARGUMENT: no data is taken
  // and no upload completes without a place in the pool.
  Status AcceptSpec(const v1::UploadSpec& upload);
  // Appends a chunk. INVALID_ARGUMENT before the spec, for a refused spec or past the declared size.
  Status AddChunk(std::string_view data);
  // After the client half-closed: INVALID_ARGUMENT without an accepted spec or with bytes missing,
  // DATA_LOSS when the CRC32C differs from the spec's. A from_cache spec takes no chunk and is
  // complete at once (its bytes come from the scene cache). OK only while the assembler holds the job's
  // place (unless TakeTicket already took it).
  Status Finish() const;

  // A spec message arrived (StartSpec was called).
  bool has_spec() const { return has_spec_; }
  // The spec was refused because the pool was full (clients should retry later).
  bool busy() const { return busy_; }
  // The upload spec given to AcceptSpec (empty before).
  const v1::UploadSpec& spec() const { return upload_; }
  // Bytes the spec declares (0 before AcceptSpec).
  uint64_t declared_bytes() const { return upload_.total_size_bytes(); }
  const std::string& data() const { return data_; }
  // The verified bytes and the job's place in the pool, moved out (after Finish succeeded); the
  // assembler is left holding neither, so a second TakeTicket returns nullopt, not an empty ticket.
  std::string TakeData() { return std::exchange(data_, std::string()); }
  std::optional<WorkerPool::Ticket> TakeTicket() { return std::exchange(ticket_, std::nullopt); }

 private:
  const uint64_t max_upload_bytes_;
  WorkerPool* const pool_;
  bool has_spec_ = false;
  bool busy_ = false;
  bool accepted_ = false;  // AcceptSpec succeeded: the place is reserved and chunks are taken
  v1::UploadSpec upload_;
  std::string data_;
  Crc32c crc_;
  std::optional<WorkerPool::Ticket> ticket_;
};

}  // namespace vc::server
