// Sparse face values between replicas: exact round trips (empty, one, many with every float bit
// pattern kept) and DATA_LOSS for arrays that are torn, of unequal length, unsorted, repeated,
// beyond the scene's faces, or with a V outside (0, 1].
#include "vc/wire/face_values_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace vc {
namespace {

TEST(FaceValuesCodec, RoundTripsExactly) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> v(0.3f, 1.0f);
  for (size_t count : {0, 1, 5000}) {
    SparseFaceValues s;
    uint32_t face = 0;
    for (size_t k = 0; k < count; ++k) {
      face += 1 + rng() % 40;
      s.faces.push_back(face);
      s.values.push_back(v(rng));
    }
    const auto back = wire::DecodeFaceValues(wire::EncodeFaceValues(s), uint64_t{face} + 1);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(back->faces, s.faces);
    EXPECT_EQ(back->values, s.values);  // bit for bit: the reduction's ties depend on it
  }
}

TEST(FaceValuesCodec, RefusesWhatIsNotAStationsFaces) {
  auto code = [](const SparseFaceValues& s, uint64_t faces_total) {
    return wire::DecodeFaceValues(wire::EncodeFaceValues(s), faces_total).status().code();
  };
  EXPECT_EQ(code({{3, 2}, {0.5f, 0.5f}}, 10), StatusCode::kDataLoss);   // not ascending
  EXPECT_EQ(code({{2, 2}, {0.5f, 0.5f}}, 10), StatusCode::kDataLoss);   // repeated
  EXPECT_EQ(code({{2, 10}, {0.5f, 0.5f}}, 10), StatusCode::kDataLoss);  // beyond the faces
  EXPECT_EQ(code({{2, 3}, {0.5f}}, 10), StatusCode::kDataLoss);         // a value missing
  for (float bad : {0.f, -0.5f, 1.5f, std::numeric_limits<float>::infinity(), std::nanf("")}) {
    EXPECT_EQ(code({{2, 3}, {0.5f, bad}}, 10), StatusCode::kDataLoss) << bad;  // V outside (0, 1]
  }
  EXPECT_EQ(code({{2, 3}, {0.3f, 1.f}}, 10), StatusCode::kOk);
  v1::FaceValues torn = wire::EncodeFaceValues({{1, 2}, {0.5f, 0.5f}});
  torn.mutable_faces()->pop_back();
  torn.mutable_values()->pop_back();
  EXPECT_EQ(wire::DecodeFaceValues(torn, 10).status().code(), StatusCode::kDataLoss);
}

}  // namespace
}  // namespace vc
