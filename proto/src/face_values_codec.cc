#include "vc/wire/face_values_codec.h"

#include <bit>
#include <cstring>
#include <string>

namespace vc::wire {

static_assert(std::endian::native == std::endian::little, "the packed arrays are copied as they lie in memory");

namespace {

template <typename T>
std::string Packed(const std::vector<T>& v) {
  if (v.empty()) return {};  // no pointer into an empty vector
  return std::string(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

template <typename T>
void Unpack(const std::string& bytes, std::vector<T>& out) {
  out.resize(bytes.size() / sizeof(T));
  if (!bytes.empty()) std::memcpy(out.data(), bytes.data(), bytes.size());  // memcpy from null is undefined
}

// The join state of `out` (faces already decoded) from `message`: exact_values and perceptions,
// one per face, values empty; `out.values` becomes the float of each double.
Status DecodeJoinState(const v1::FaceValues& message, SparseFaceValues& out) {
  const size_t n = out.faces.size();
  if (message.exact_values().size() != n * sizeof(double) || message.perceptions().size() != n ||
      !message.values().empty()) {
    return DataLossError("face values: " + std::to_string(message.exact_values().size()) + " bytes of V and " +
                         std::to_string(message.perceptions().size()) + " of perceptions for " + std::to_string(n) +
                         " faces (and " + std::to_string(message.values().size()) +
                         " bytes of float V), not one float64 and one byte per face alone");
  }
  Unpack(message.exact_values(), out.exact_values);
  Unpack(message.perceptions(), out.perceptions);
  out.values.resize(n);
  for (size_t k = 0; k < n; ++k) {
    out.values[k] = float(out.exact_values[k]);
    const uint8_t p = out.perceptions[k];
    if (p != uint8_t(Perception::kPartial) && p != uint8_t(Perception::kFull)) {
      return DataLossError("face values: perception " + std::to_string(p) + " of face " + std::to_string(out.faces[k]) +
                           " is neither partial (1) nor full (2)");
    }
    if (!(out.exact_values[k] > 0.0 && out.exact_values[k] <= 1.0)) {
      return DataLossError("face values: V " + std::to_string(out.exact_values[k]) + " of face " +
                           std::to_string(out.faces[k]) + " is not in (0, 1]");
    }
  }
  return Status::Ok();
}

}  // namespace

v1::FaceValues EncodeFaceValues(const SparseFaceValues& values) {
  v1::FaceValues m;
  m.set_faces(Packed(values.faces));
  if (values.HasJoinState() && !values.faces.empty()) {
    m.set_exact_values(Packed(values.exact_values));
    m.set_perceptions(Packed(values.perceptions));
  } else {
    m.set_values(Packed(values.values));
  }
  return m;
}

Result<SparseFaceValues> DecodeFaceValues(const v1::FaceValues& message, uint64_t faces_total) {
  const std::string& faces = message.faces();
  const std::string& values = message.values();
  const bool join_state = !message.exact_values().empty() || !message.perceptions().empty();
  if (faces.size() % sizeof(uint32_t) != 0 || (!join_state && values.size() != faces.size())) {
    return DataLossError("face values: " + std::to_string(faces.size()) + " bytes of faces and " +
                         std::to_string(values.size()) + " of values, not one uint32 and one float per face");
  }
  SparseFaceValues out;
  Unpack(faces, out.faces);
  if (join_state) {
    VC_RETURN_IF_ERROR(DecodeJoinState(message, out));
  } else {
    Unpack(values, out.values);
  }
  for (size_t k = 0; k < out.faces.size(); ++k) {
    if (out.faces[k] >= faces_total || (k > 0 && out.faces[k - 1] >= out.faces[k])) {
      return DataLossError("face values: face " + std::to_string(out.faces[k]) + " at position " + std::to_string(k) +
                           " is not ascending below " + std::to_string(faces_total));
    }
    if (!(out.values[k] > 0.f && out.values[k] <= 1.f)) {  // V of a face seen is in (0, 1]; NaN fails too
      return DataLossError("face values: V " + std::to_string(out.values[k]) + " of face " +
                           std::to_string(out.faces[k]) + " is not in (0, 1]");
    }
  }
  return out;
}

}  // namespace vc::wire
