// vc::Status -> grpc::Status: the one place core codes become gRPC codes (a single switch).
#pragma once

#include <grpcpp/support/status.h>

#include "vc/base/status.h"

namespace vc::server {

// The gRPC code with the same meaning as `code` (google.rpc.Code numbering).
grpc::StatusCode ToGrpcCode(StatusCode code);

// Same code, same message.
grpc::Status ToGrpcStatus(const Status& status);

}  // namespace vc::server
