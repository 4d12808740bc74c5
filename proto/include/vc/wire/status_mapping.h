// vc::Status <-> grpc::Status: the one place core codes and gRPC codes meet (one switch each way).
//
// The server maps what the core returns to the call's gRPC status; the client maps the call's
// gRPC status back, so both speak vc::Status. Codes share google.rpc.Code's meanings, so the
// mapping is one-to-one and keeps the message.
#pragma once

#include <grpcpp/support/status.h>

#include "vc/base/status.h"

namespace vc::wire {

// The gRPC code with the same meaning as `code` (google.rpc.Code numbering).
grpc::StatusCode ToGrpcCode(StatusCode code);
// The vc code with the same meaning as `code`; kUnknown for a number outside google.rpc.Code.
StatusCode FromGrpcCode(grpc::StatusCode code);

// Same code, same message.
grpc::Status ToGrpcStatus(const Status& status);
Status FromGrpcStatus(const grpc::Status& status);

}  // namespace vc::wire
