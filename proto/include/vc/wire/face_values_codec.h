// A station's faces with V > 0 (vc::SparseFaceValues) on the wire between replicas, as the
// reduction's evaluation shards carry them (v1::FaceValues, docs/PROTOCOL.md "Between replicas"):
// the face indices and the values as packed little-endian arrays. Packed arrays, not Roaring: the
// values travel with the indices one for one, and a station's faces are a small share of the
// site's, so the array is already the compact form. Pure functions, thread-safe.
#pragma once

#include <cstdint>

#include "vc/base/status.h"
#include "vc/v1/planner.pb.h"
#include "vc/visibility/visibility.h"

namespace vc::wire {

// With the join state (SparseFaceValues::HasJoinState, a station that sees something): the faces,
// the doubles and the perceptions, no floats; else the faces and the floats. The figures are the
// caller's to set.
v1::FaceValues EncodeFaceValues(const SparseFaceValues& values);
// DATA_LOSS when the arrays are not whole, differ in length, list faces that are not ascending or
// not below faces_total, or a V that is not in (0, 1] (NaN and infinities included); with the join
// state, also a perception that is not partial or full, or floats beside the doubles. The floats
// of a message with the join state are those of its doubles.
Result<SparseFaceValues> DecodeFaceValues(const v1::FaceValues& message, uint64_t faces_total);

}  // namespace vc::wire
