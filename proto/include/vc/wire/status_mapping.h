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
// The vc code with the same meaning as the gRPC code numbered `code`; kUnknown for a number outside
// google.rpc.Code (an int, not a grpc::StatusCode: 99 is no value of that enum, and making one is
// undefined behaviour, which clang's UBSan reports).
StatusCode FromGrpcCode(int code);

// Same code, same message.
grpc::Status ToGrpcStatus(const Status& status);
Status FromGrpcStatus(const grpc::Status& status);

}  // namespace vc::wire
