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

// With the join state (what a replica answers the coordinator that asked for it): the doubles and
// the perceptions bit for bit, no floats on the wire (the decoder gives the float of each double),
// 5 bytes a face more than the floats alone.
TEST(FaceValuesCodec, RoundTripsTheJoinStateExactly) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> v(0.3, 1.0);
  for (size_t count : {0, 1, 5000}) {
    SparseFaceValues s;
    uint32_t face = 0;
    for (size_t k = 0; k < count; ++k) {
      face += 1 + rng() % 40;
      s.faces.push_back(face);
      s.exact_values.push_back(v(rng));
      s.values.push_back(float(s.exact_values.back()));
      s.perceptions.push_back(uint8_t(1 + rng() % 2));
    }
    const v1::FaceValues m = wire::EncodeFaceValues(s);
    EXPECT_TRUE(m.values().empty());
    SparseFaceValues plain = s;
    plain.exact_values.clear();
    plain.perceptions.clear();
    const size_t more = m.ByteSizeLong() - wire::EncodeFaceValues(plain).ByteSizeLong();
    EXPECT_GE(more, 5 * count);
    EXPECT_LE(more, 5 * count + 3) << count;  // a field's tag and length more
    const auto back = wire::DecodeFaceValues(m, uint64_t{face} + 1);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(back->faces, s.faces);
    EXPECT_EQ(back->values, s.values);
    EXPECT_EQ(back->exact_values, s.exact_values);
    EXPECT_EQ(back->perceptions, s.perceptions);
    EXPECT_TRUE(back->HasJoinState());
  }
}

TEST(FaceValuesCodec, RefusesAJoinStateThatIsNotAStationsFaces) {
  const SparseFaceValues good{{2, 3}, {0.5f, 1.f}, {0.5, 1.0}, {1, 2}};
  ASSERT_TRUE(wire::DecodeFaceValues(wire::EncodeFaceValues(good), 10).ok());
  auto code = [](const v1::FaceValues& m) { return wire::DecodeFaceValues(m, 10).status().code(); };
  v1::FaceValues m = wire::EncodeFaceValues(good);
  m.mutable_perceptions()->pop_back();  // a perception missing
  EXPECT_EQ(code(m), StatusCode::kDataLoss);
  m = wire::EncodeFaceValues(good);
  m.mutable_exact_values()->pop_back();  // a torn double
  EXPECT_EQ(code(m), StatusCode::kDataLoss);
  m = wire::EncodeFaceValues(good);
  m.set_values(std::string(8, '\0'));  // floats beside the doubles
  EXPECT_EQ(code(m), StatusCode::kDataLoss);
  for (uint8_t p : {0, 3}) {  // neither partial nor full
    SparseFaceValues bad = good;
    bad.perceptions[1] = p;
    EXPECT_EQ(code(wire::EncodeFaceValues(bad)), StatusCode::kDataLoss) << int(p);
  }
  for (double bad_v : {0.0, 1.5, std::nan("")}) {
    SparseFaceValues bad = good;
    bad.exact_values[0] = bad_v;
    EXPECT_EQ(code(wire::EncodeFaceValues(bad)), StatusCode::kDataLoss) << bad_v;
  }
}

}  // namespace
}  // namespace vc
