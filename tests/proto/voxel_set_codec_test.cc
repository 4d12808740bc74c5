// The Roaring encoding of visibility sets between replicas: exact round trips (empty, full, runs,
// scattered ids, a size not a multiple of 64) and DATA_LOSS for bytes that are not a whole bitmap
// of the scene's ids.
#include "vc/wire/voxel_set_codec.h"

#include <gtest/gtest.h>

#include <random>

namespace vc {
namespace {

void ExpectRoundTrip(const VoxelSet& s) {
  const std::string bytes = wire::EncodeVoxelSet(s);
  const auto back = wire::DecodeVoxelSet(bytes, s.size());
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->size(), s.size());
  EXPECT_EQ(back->words(), s.words());
}

TEST(VoxelSetCodec, RoundTripsExactly) {
  ExpectRoundTrip(VoxelSet(0));
  ExpectRoundTrip(VoxelSet(1000));
  VoxelSet full(200003);
  for (size_t i = 0; i < full.size(); ++i) full.set(i);
  ExpectRoundTrip(full);
  std::mt19937_64 rng(7);
  for (double density : {0.0001, 0.01, 0.3, 0.9}) {
    VoxelSet s(300007);
    std::bernoulli_distribution bit(density);
    for (size_t i = 0; i < s.size(); ++i) {
      if (bit(rng)) s.set(i);
    }
    ExpectRoundTrip(s);
  }
  VoxelSet runs(500000);
  for (size_t i = 1000; i < 90000; ++i) runs.set(i);
  for (size_t i = 400000; i < 499999; ++i) runs.set(i);
  ExpectRoundTrip(runs);
  // Runs compress: far below the dense 62.5 KB.
  EXPECT_LT(wire::EncodeVoxelSet(runs).size(), 100u);
}

TEST(VoxelSetCodec, RefusesWhatIsNotABitmapOfTheScenesIds) {
  VoxelSet s(1000);
  s.set(999);
  const std::string bytes = wire::EncodeVoxelSet(s);
  EXPECT_EQ(wire::DecodeVoxelSet(bytes, 999).status().code(), StatusCode::kDataLoss);  // id 999 of 999 voxels
  EXPECT_EQ(wire::DecodeVoxelSet(bytes.substr(0, bytes.size() - 1), 1000).status().code(), StatusCode::kDataLoss);
  EXPECT_EQ(wire::DecodeVoxelSet(bytes + "x", 1000).status().code(), StatusCode::kDataLoss);
  EXPECT_EQ(wire::DecodeVoxelSet("not a bitmap", 1000).status().code(), StatusCode::kDataLoss);
  EXPECT_EQ(wire::DecodeVoxelSet("", 1000).status().code(), StatusCode::kDataLoss);
}

}  // namespace
}  // namespace vc
