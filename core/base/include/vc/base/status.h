// Status and Result<T>: how every predictable failure in vc_core is reported.
//
// Shaped like absl::Status / std::expected. Core functions never throw for bad input, never log
// an error they also return, and never crash on a predictable failure (bad file, scene too large,
// cancellation): they return one of these. StatusCode and grpc::StatusCode map to each other in
// one place (proto/src/status_mapping.cc). Exceptions are reserved for bugs.
#pragma once

#include <cassert>
#include <new>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace vc {

// Canonical codes: google.rpc.Code's, with the same meanings. The core returns the first eleven;
// the last six also describe failures of a remote call (vc::client).
enum class StatusCode {
  kOk = 0,
  kCancelled,
  kInvalidArgument,
  kDeadlineExceeded,
  kNotFound,
  kResourceExhausted,
  kFailedPrecondition,
  kOutOfRange,
  kUnimplemented,
  kInternal,
  kDataLoss,
  kUnknown,
  kAlreadyExists,
  kPermissionDenied,
  kAborted,
  kUnavailable,
  kUnauthenticated,
};

// Human-readable name of a code ("INVALID_ARGUMENT").
std::string_view StatusCodeName(StatusCode code);

class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(StatusCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return Status(); }

  bool ok() const { return code_ == StatusCode::kOk; }
  StatusCode code() const { return code_; }
  const std::string& message() const { return message_; }
  // "INVALID_ARGUMENT: message".
  std::string ToString() const;

  // Returns a copy whose message is prefixed with `context` and ": ".
  Status WithContext(std::string_view context) const;

  friend bool operator==(const Status& a, const Status& b) { return a.code_ == b.code_ && a.message_ == b.message_; }

 private:
  StatusCode code_ = StatusCode::kOk;
  std::string message_;
};

inline Status CancelledError(std::string m) { return {StatusCode::kCancelled, std::move(m)}; }
inline Status InvalidArgumentError(std::string m) { return {StatusCode::kInvalidArgument, std::move(m)}; }
inline Status DeadlineExceededError(std::string m) { return {StatusCode::kDeadlineExceeded, std::move(m)}; }
inline Status NotFoundError(std::string m) { return {StatusCode::kNotFound, std::move(m)}; }
inline Status ResourceExhaustedError(std::string m) { return {StatusCode::kResourceExhausted, std::move(m)}; }
inline Status FailedPreconditionError(std::string m) { return {StatusCode::kFailedPrecondition, std::move(m)}; }
inline Status OutOfRangeError(std::string m) { return {StatusCode::kOutOfRange, std::move(m)}; }
inline Status UnimplementedError(std::string m) { return {StatusCode::kUnimplemented, std::move(m)}; }
inline Status InternalError(std::string m) { return {StatusCode::kInternal, std::move(m)}; }
inline Status DataLossError(std::string m) { return {StatusCode::kDataLoss, std::move(m)}; }
inline Status UnavailableError(std::string m) { return {StatusCode::kUnavailable, std::move(m)}; }
inline Status UnauthenticatedError(std::string m) { return {StatusCode::kUnauthenticated, std::move(m)}; }
inline Status PermissionDeniedError(std::string m) { return {StatusCode::kPermissionDenied, std::move(m)}; }
inline Status AbortedError(std::string m) { return {StatusCode::kAborted, std::move(m)}; }

// A value of type T or a non-OK Status.
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}        // NOLINT(google-explicit-constructor)
  Result(Status status) : v_(std::move(status)) {  // NOLINT(google-explicit-constructor)
    assert(!std::get<Status>(v_).ok() && "Result constructed from an OK status");
  }

  bool ok() const { return std::holds_alternative<T>(v_); }
  // The error; OK if this holds a value.
  Status status() const { return ok() ? Status::Ok() : std::get<Status>(v_); }

  T& value() & { return std::get<T>(v_); }
  const T& value() const& { return std::get<T>(v_); }
  T&& value() && { return std::get<T>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T&& operator*() && { return std::move(*this).value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

 private:
  std::variant<T, Status> v_;
};

// Calls fn() (returning a Status or Result) and turns a std::bad_alloc thrown inside into
// RESOURCE_EXHAUSTED "<what> ran out of memory ...; <advice>". For the boundaries where a job
// allocates in proportion to its input (reading, voxelising): the limits there are checked before
// allocating, and this backstop covers a machine with less free memory than the limits allow.
template <typename F>
auto CatchOutOfMemory(std::string_view what, F&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (const std::bad_alloc&) {
    return Status(StatusCode::kResourceExhausted,
                  std::string(what) +
                      " ran out of memory, within the limits but beyond the memory free now; "
                      "retry later, send a smaller scene or use a coarser resolution, or lower "
                      "--memory-budget-bytes to what the machine can hold");
  }
}

}  // namespace vc

#define VC_INTERNAL_CONCAT2(a, b) a##b
#define VC_INTERNAL_CONCAT(a, b) VC_INTERNAL_CONCAT2(a, b)

// Returns the status from the enclosing function if `expr` (a Status) is not OK.
#define VC_RETURN_IF_ERROR(expr)             \
  do {                                       \
    ::vc::Status vc_status_ = (expr);        \
    if (!vc_status_.ok()) return vc_status_; \
  } while (false)

// `lhs = *expr` if `expr` (a Result<T>) holds a value, else returns its status.
#define VC_ASSIGN_OR_RETURN(lhs, expr) VC_INTERNAL_ASSIGN_OR_RETURN(VC_INTERNAL_CONCAT(vc_result_, __LINE__), lhs, expr)
#define VC_INTERNAL_ASSIGN_OR_RETURN(tmp, lhs, expr) \
  auto tmp = (expr);                                 \
  if (!tmp.ok()) return tmp.status();                \
  lhs = std::move(tmp).value()
