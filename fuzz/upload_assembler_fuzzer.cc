// Fuzzes vc::server::UploadAssembler, the server's check of each client-streamed upload, as a
// sequence of protocol actions over three concurrent calls sharing a small WorkerPool (1 worker,
// a queue of 0 or 1), checked against a model after every step. Any broken invariant traps.
//
// Input (read from the front, so seeds are easy to write; fuzz/make_seeds.py):
//   byte 0: --max-upload-bytes (0..255); byte 1: bit 0 picks the pool with a 1-job queue.
//   Then actions, one op byte each: slot = (op >> 4) % 3, kind = (op & 15) % 10:
//     0 new assembler in the slot (drops the old one)   1 drop the slot's assembler
//     2 a spec message: flags byte (bit 0: the RPC's own parameters are refused, so AcceptSpec is
//       not called; bit 1: crc32c of a payload taken from the input, sent later by kind 3;
//       bits 2-3: size = next byte / max / max + 1 / next 8 bytes), format (byte < 8, else the
//       next 4 bytes as any int32), [crc32c: 4 bytes], source_name (length byte, bytes)
//     3 a chunk: byte m; m & 0x80 and a payload: its next m & 0x7f bytes (0: the rest), else
//       m & 0x7f bytes of the input          4 Finish          5 TakeData (after Finish was OK)
//     6 TakeTicket, held by the harness      7 TakeTicket, dropped at once
//     8 Release() the slot's held ticket (twice: idempotent)   9 drop the slot's held ticket
//
// Invariants: no crash or UB; every non-OK Status has a message and the documented code; the pool
// admits exactly the places the live tickets hold, never more than workers + queue, and a refused
// spec reserves none; has_spec() follows StartSpec; an upload never holds more bytes than its spec
// declares, and holds exactly the bytes the model sent; Finish is OK only for an accepted spec whose
// bytes all arrived with the CRC32C declared (computed here by a bitwise reference); an OK Finish
// leaves the place in the assembler (the reactor submits *TakeTicket()); TakeData returns the bytes.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "vc/server/upload_assembler.h"
#include "vc/server/worker_pool.h"

namespace {

using vc::Status;
using vc::StatusCode;
using vc::server::UploadAssembler;
using vc::server::WorkerPool;

[[noreturn]] void Fail(const char* what, int line) {
  std::fprintf(stderr, "upload_assembler_fuzzer: invariant broken (line %d): %s\n", line, what);
  __builtin_trap();
}
#define CHECK(cond)                     \
  do {                                  \
    if (!(cond)) Fail(#cond, __LINE__); \
  } while (0)

// Bitwise CRC32C (reflected 0x82F63B78), independent of vc::wire's slice-by-8 tables.
uint32_t ReferenceCrc32c(std::string_view bytes) {
  uint32_t c = 0xFFFFFFFFu;
  for (const char ch : bytes) {
    c ^= uint8_t(ch);
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0x82F63B78u & (0u - (c & 1u)));
  }
  return ~c;
}

// Reads the input from the front; past the end every read is 0 / empty.
class Reader {
 public:
  Reader(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool empty() const { return pos_ >= size_; }
  uint8_t Byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  uint64_t Uint(int bytes) {
    uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) v |= uint64_t{Byte()} << (8 * i);
    return v;
  }
  std::string Bytes(size_t n) {
    n = std::min(n, size_ - std::min(pos_, size_));
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

constexpr int kSlots = 3;
constexpr int kWorkers = 1;

// What one call should look like, per the assembler's contract.
struct Model {
  bool started = false;   // StartSpec was OK
  bool accepted = false;  // AcceptSpec was OK (the place is reserved)
  bool ticket = false;    // the assembler still holds its place
  bool finished = false;  // Finish was OK
  bool data_taken = false;
  bool ticket_taken = false;  // TakeTicket ran (the reactor's Reject): the call is over
  uint64_t declared = 0;      // of the accepted spec
  uint32_t crc = 0;           // of the accepted spec
  std::string data;           // bytes the assembler accepted
  std::string payload;        // bytes matching the spec's CRC (flag bit 1), sent by chunks
  size_t payload_pos = 0;
};

struct Call {
  std::optional<UploadAssembler> assembler;
  Model model;
  std::optional<WorkerPool::Ticket> held;  // a ticket taken out by TakeTicket and kept
};

void CheckStatus(const Status& s) {
  if (!s.ok()) CHECK(!s.message().empty());
}

// Pools outlive the inputs (a pool per input would start a thread each time); every input must
// give all its places back, which the end of LLVMFuzzerTestOneInput checks.
WorkerPool& Pool(int queue) {
  static WorkerPool pool0(kWorkers, 0);
  static WorkerPool pool1(kWorkers, 1);
  return queue == 0 ? pool0 : pool1;
}

// One input's state: the limit, the pool and the three calls.
struct Session {
  uint64_t max_upload = 0;
  WorkerPool* pool = nullptr;
  int capacity = 0;  // workers + queue
  std::array<Call, kSlots> calls;

  // The places the live tickets hold: in an assembler, or held by the harness.
  int places() const {
    int n = 0;
    for (const Call& c : calls) n += int(c.model.ticket) + int(c.held.has_value());
    return n;
  }
};

// A spec message as the input describes it (action 2), and the flags that say how to send it.
struct SpecInput {
  uint8_t flags = 0;
  int32_t format = 0;
  uint64_t size = 0;
  vc::v1::UploadSpec spec;
  std::string payload;  // matching the spec's CRC (flag bit 1), sent later by chunks
};

SpecInput ReadSpec(Reader& in, uint64_t max_upload) {
  SpecInput s;
  s.flags = in.Byte();
  switch ((s.flags >> 2) & 3) {
    case 0:
      s.size = in.Byte();
      break;
    case 1:
      s.size = max_upload;
      break;
    case 2:
      s.size = max_upload + 1;
      break;
    default:
      s.size = in.Uint(8);
      break;
  }
  s.spec.set_total_size_bytes(s.size);
  const uint8_t f = in.Byte();
  s.format = f < 16 ? int32_t(f) : int32_t(uint32_t(in.Uint(4)));
  s.spec.set_format(vc::v1::InputFormat(s.format));
  if (s.flags & 2) {
    s.payload = in.Bytes(size_t(std::min<uint64_t>(s.size, 4096)));
    s.spec.set_crc32c(ReferenceCrc32c(s.payload));
  } else {
    s.spec.set_crc32c(uint32_t(in.Uint(4)));
  }
  s.spec.set_source_name(in.Bytes(in.Byte() % 64));
  return s;
}

// Action 2: StartSpec, then AcceptSpec unless the RPC refused its own parameters.
void SendSpec(Reader& in, Session& session, Call& call, int admitted_before) {
  if (!call.assembler) return;
  UploadAssembler& a = *call.assembler;
  Model& m = call.model;
  SpecInput input = ReadSpec(in, session.max_upload);

  const Status start = a.StartSpec();
  CheckStatus(start);
  CHECK(start.ok() == !m.started);
  if (!start.ok()) {
    CHECK(start.code() == StatusCode::kInvalidArgument);
    return;
  }
  m.started = true;
  CHECK(a.has_spec());
  if (input.flags & 1) return;  // the RPC refused its own parameters (TakeSpec): no AcceptSpec

  // Every value the enum names (E57 = 8 and vc-voxels = 9 came after this fuzzer).
  const bool format_ok = vc::v1::InputFormat_IsValid(input.format);
  const bool size_ok = input.size > 0 && input.size <= session.max_upload;
  const bool room = admitted_before < session.capacity;
  const Status s = a.AcceptSpec(input.spec);
  CheckStatus(s);
  CHECK(a.declared_bytes() == input.size);  // also after a refusal: the log line names it
  if (!format_ok || input.size == 0) {
    CHECK(s.code() == StatusCode::kInvalidArgument);
  } else if (!size_ok || !room) {
    CHECK(s.code() == StatusCode::kResourceExhausted);
  } else {
    CHECK(s.ok());
  }
  CHECK(a.busy() == (format_ok && size_ok && !room));
  if (s.ok()) {
    m.accepted = true;
    m.ticket = true;
    m.declared = input.size;
    m.crc = input.spec.crc32c();
    m.payload = std::move(input.payload);
    CHECK(session.pool->admitted() == admitted_before + 1);
  } else {
    CHECK(session.pool->admitted() == admitted_before);  // a refused spec reserves no place
  }
}

// Action 3: a chunk of the payload or of the input.
void SendChunk(Reader& in, Call& call) {
  if (!call.assembler) return;
  UploadAssembler& a = *call.assembler;
  Model& m = call.model;
  const uint8_t b = in.Byte();
  std::string chunk;
  if ((b & 0x80) && m.payload_pos < m.payload.size()) {
    const size_t left = m.payload.size() - m.payload_pos;
    const size_t n = (b & 0x7f) == 0 ? left : std::min<size_t>(b & 0x7f, left);
    chunk = m.payload.substr(m.payload_pos, n);
    m.payload_pos += n;
  } else {
    chunk = in.Bytes(b & 0x7f);
  }
  if (m.data_taken) return;  // the call was submitted: no more chunks reach it
  const Status s = a.AddChunk(chunk);
  CheckStatus(s);
  const bool fits = m.accepted && m.data.size() + chunk.size() <= m.declared;
  CHECK(s.ok() == fits);
  if (!s.ok()) CHECK(s.code() == StatusCode::kInvalidArgument);
  if (s.ok()) m.data += chunk;
  if (m.accepted) {
    CHECK(a.data().size() <= a.declared_bytes());
    CHECK(a.data() == m.data);
  }
}

// Action 4.
void FinishUpload(Call& call) {
  Model& m = call.model;
  if (!call.assembler || m.data_taken) return;
  const Status s = call.assembler->Finish();
  CheckStatus(s);
  const bool complete = m.accepted && m.data.size() == m.declared;
  const bool whole = complete && ReferenceCrc32c(m.data) == m.crc;
  CHECK(s.ok() == whole);
  if (s.ok()) {
    CHECK(m.ticket || m.ticket_taken);  // the reactor submits *TakeTicket() next
    m.finished = true;
  } else {
    CHECK(s.code() == (complete ? StatusCode::kDataLoss : StatusCode::kInvalidArgument));
  }
}

// Actions 6 (`hold`: the harness keeps the ticket) and 7.
void TakeTicket(Call& call, bool hold) {
  if (!call.assembler) return;
  std::optional<WorkerPool::Ticket> t = call.assembler->TakeTicket();
  CHECK(t.has_value() == call.model.ticket);
  CHECK(!call.assembler->TakeTicket().has_value());
  call.model.ticket = false;
  call.model.ticket_taken = true;
  if (hold && t) call.held = std::move(t);
}

// One action read from the input.
void Step(Reader& in, Session& session) {
  const uint8_t op = in.Byte();
  Call& call = session.calls[(op >> 4) % kSlots];
  Model& m = call.model;
  const int admitted_before = session.pool->admitted();
  switch ((op & 15) % 10) {
    case 0:
      call.assembler.reset();
      call.assembler.emplace(session.max_upload, session.pool);
      m = Model{};
      break;
    case 1:
      call.assembler.reset();
      m = Model{};
      break;
    case 2:
      SendSpec(in, session, call, admitted_before);
      break;
    case 3:
      SendChunk(in, call);
      break;
    case 4:
      FinishUpload(call);
      break;
    case 5:
      if (!call.assembler || !m.finished || m.data_taken) break;
      CHECK(call.assembler->TakeData() == m.data);
      m.data_taken = true;
      break;
    case 6:
    case 7:
      TakeTicket(call, (op & 15) % 10 == 6);
      break;
    case 8:
      if (call.held) {
        call.held->Release();
        call.held->Release();
        CHECK(session.pool->admitted() == admitted_before - 1);
        call.held.reset();
      }
      break;
    case 9:
      call.held.reset();
      break;
  }
}

// What holds after every action.
void CheckSession(const Session& session) {
  for (const Call& c : session.calls) {
    if (!c.assembler) continue;
    CHECK(c.assembler->has_spec() == c.model.started);
    if (c.model.accepted && !c.model.data_taken) CHECK(c.assembler->data().size() <= c.assembler->declared_bytes());
  }
  CHECK(session.pool->admitted() == session.places());
  CHECK(session.pool->admitted() <= session.capacity);
}

void Run(Reader& in) {
  Session session;
  session.max_upload = in.Byte();
  const int queue = in.Byte() & 1;
  session.pool = &Pool(queue);
  session.capacity = kWorkers + queue;
  CHECK(session.pool->admitted() == 0);
  while (!in.empty()) {
    Step(in, session);
    CheckSession(session);
  }
  for (Call& c : session.calls) {
    c.assembler.reset();
    c.held.reset();
  }
  CHECK(session.pool->admitted() == 0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Reader in(data, size);
  Run(in);
  return 0;
}
