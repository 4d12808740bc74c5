#include "vc/wire/face_values_codec.h"

#include <bit>
#include <cstring>
#include <string>

namespace vc::wire {

static_assert(std::endian::native == std::endian::little, "the packed arrays are copied as they lie in memory");

v1::FaceValues EncodeFaceValues(const SparseFaceValues& values) {
  v1::FaceValues m;
  if (values.faces.empty()) return m;  // no pointer into an empty vector
  m.set_faces(std::string(reinterpret_cast<const char*>(values.faces.data()), values.faces.size() * sizeof(uint32_t)));
  m.set_values(std::string(reinterpret_cast<const char*>(values.values.data()), values.values.size() * sizeof(float)));
  return m;
}

Result<SparseFaceValues> DecodeFaceValues(const v1::FaceValues& message, uint64_t faces_total) {
  const std::string& faces = message.faces();
  const std::string& values = message.values();
  if (faces.size() % sizeof(uint32_t) != 0 || values.size() != faces.size()) {
    return DataLossError("face values: " + std::to_string(faces.size()) + " bytes of faces and " +
                         std::to_string(values.size()) + " of values, not one uint32 and one float per face");
  }
  SparseFaceValues out;
  out.faces.resize(faces.size() / sizeof(uint32_t));
  out.values.resize(out.faces.size());
  if (!faces.empty()) {  // memcpy from an empty vector's null data() is undefined
    std::memcpy(out.faces.data(), faces.data(), faces.size());
    std::memcpy(out.values.data(), values.data(), values.size());
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
