// The compact upload (vc-voxels): a cloud's voxels round-trip exactly, a plan from the stream is the
// plan from the cloud, and every malformed stream is refused naming what is wrong.
#include "vc/scene/voxel_stream.h"

#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstring>

#include "testing/scenes.h"
#include "vc/plan/planner.h"
#include "vc/scene/voxel_scene.h"

namespace vc {
namespace {

using testing::Synthetic;

template <typename T>
void PutAt(std::string& s, size_t at, T v) {
  std::memcpy(s.data() + at, &v, sizeof(T));
}

// Where a version 2 stream's voxel count lies (after the resolution and the frame origin).
constexpr size_t kCountAt = 44;

// A stream of `version` (2: with `frame_origin_m`; 1: without) with the given header fields over
// `varints` (deflated).
std::string Stream(uint64_t count, const std::string& varints, double resolution_m = 0.1, uint32_t version = 2,
                   const Eigen::Vector3d& frame_origin_m = Eigen::Vector3d::Zero()) {
  uLongf size = compressBound(uLong(varints.size()));
  std::string deflated(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(deflated.data()), &size, reinterpret_cast<const Bytef*>(varints.data()),
                      uLong(varints.size()), 6),
            Z_OK);
  deflated.resize(size);
  const size_t count_at = version == 1 ? 20 : kCountAt;
  std::string s(count_at + 24, '\0');
  std::memcpy(s.data(), "VCVOXELS", 8);
  PutAt<uint32_t>(s, 8, version);
  PutAt<double>(s, 12, resolution_m);
  if (version != 1) {
    for (int a = 0; a < 3; ++a) PutAt<double>(s, 20 + 8 * a, frame_origin_m[a]);
  }
  PutAt<uint64_t>(s, count_at, count);
  PutAt<uint64_t>(s, count_at + 8, varints.size());
  PutAt<uint64_t>(s, count_at + 16, deflated.size());
  return s + deflated;
}

Status ReadError(const std::string& bytes) {
  Result<SceneInput> r = ReadScene(bytes, "upload");
  EXPECT_FALSE(r.ok());
  return r.ok() ? Status::Ok() : r.status();
}

TEST(VoxelStream, ACloudRoundTripsToTheSameVoxelsAndIsFarSmaller) {
  const SceneInput cloud = Synthetic("rooms:3", 0.02);
  for (const double r : {0.1, 0.05}) {
    Result<CompactScene> compact = CompactPointCloud(cloud, r, kDefaultMemoryBudgetBytes);
    ASSERT_TRUE(compact.ok()) << compact.status().ToString();
    Result<SceneInput> back = ReadScene(compact->bytes, "upload");
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    EXPECT_EQ(back->format, InputFormat::kVoxelStream);
    EXPECT_EQ(back->voxel_resolution_m, r);
    EXPECT_EQ(back->points.size(), compact->voxels);
    VoxelizeOptions at_r;
    at_r.resolution_m = r;
    Result<VoxelScene> a = Voxelize(cloud, at_r), b = Voxelize(*back, at_r);
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->occupied, b->occupied) << r;
    // The default resolution of a stream is its own.
    Result<VoxelScene> own = Voxelize(*back, {});
    ASSERT_TRUE(own.ok());
    EXPECT_EQ(own->resolution_m, r);
    // Under 1 byte per voxel; the cloud's points take 12 bytes each.
    EXPECT_LT(compact->bytes.size(), compact->voxels) << r;
    EXPECT_LT(compact->bytes.size() * 50, cloud.points.size() * 12) << r;
  }
}

TEST(VoxelStream, APlanFromTheStreamIsThePlanFromTheCloud) {
  const SceneInput cloud = Synthetic("rooms:3");
  PlanOptions o;
  o.resolution_m = 0.1;
  Result<CompactScene> compact = CompactPointCloud(cloud, 0.1, kDefaultMemoryBudgetBytes);
  ASSERT_TRUE(compact.ok());
  Result<SceneInput> stream = ReadScene(compact->bytes, "upload");
  ASSERT_TRUE(stream.ok());
  Result<PlanResult> a = Plan(cloud, o), b = Plan(*stream, o);
  ASSERT_TRUE(a.ok() && b.ok()) << a.status().ToString() << b.status().ToString();
  ASSERT_EQ(a->stations.size(), b->stations.size());
  for (size_t k = 0; k < a->stations.size(); ++k) EXPECT_EQ(a->stations[k].position, b->stations[k].position);
  EXPECT_EQ(a->evaluation.overall.global_visibility, b->evaluation.overall.global_visibility);
  EXPECT_EQ(a->covered_voxels, b->covered_voxels);
}

TEST(VoxelStream, TheStreamCarriesTheFrameOriginOfASurveyScene) {
  SceneInput cloud = Synthetic("rooms:3");
  const Eigen::Vector3d origin(512000, 5612000, -1000);
  cloud.frame_origin_m = origin;
  Result<CompactScene> compact = CompactPointCloud(cloud, 0.1, kDefaultMemoryBudgetBytes);
  ASSERT_TRUE(compact.ok()) << compact.status().ToString();
  Result<SceneInput> back = ReadScene(compact->bytes, "upload");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->frame_origin_m, origin);
  Result<VoxelScene> a = Voxelize(cloud, {}), b = Voxelize(*back, {});
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->occupied, b->occupied);
  EXPECT_EQ(b->frame_origin_m, origin);
  // The stream is in metres already: units given for the upload do not scale it again.
  ReadOptions in_mm;
  in_mm.metres_per_unit = 0.001;
  Result<SceneInput> with_units = ReadScene(compact->bytes, "upload", in_mm);
  ASSERT_TRUE(with_units.ok()) << with_units.status().ToString();
  EXPECT_EQ(with_units->points, back->points);
  EXPECT_EQ(with_units->frame_origin_m, origin);
  EXPECT_EQ(EncodeVoxelStream({{1, 0, 0}}, 0.1, {0, std::nan(""), 0}).status().code(), StatusCode::kInvalidArgument);
}

TEST(VoxelStream, Version1IsStillReadWithTheOriginAtZero) {
  const std::string varints("\x05\x01", 2);
  Result<SceneInput> v1 = ReadScene(Stream(2, varints, 0.1, 1), "upload");
  Result<SceneInput> v2 = ReadScene(Stream(2, varints, 0.1, 2, {1000, 2000, 0}), "upload");
  ASSERT_TRUE(v1.ok()) << v1.status().ToString();
  ASSERT_TRUE(v2.ok()) << v2.status().ToString();
  EXPECT_EQ(v1->frame_origin_m, Eigen::Vector3d::Zero());
  EXPECT_EQ(v2->frame_origin_m, Eigen::Vector3d(1000, 2000, 0));
  EXPECT_EQ(v1->points, v2->points);
  EXPECT_EQ(v1->points.size(), 2u);
}

TEST(VoxelStream, AnotherResolutionIsRefusedNamingBoth) {
  Result<CompactScene> compact = CompactPointCloud(Synthetic("box"), 0.1, kDefaultMemoryBudgetBytes);
  ASSERT_TRUE(compact.ok());
  Result<SceneInput> stream = ReadScene(compact->bytes, "upload");
  ASSERT_TRUE(stream.ok());
  VoxelizeOptions finer;
  finer.resolution_m = 0.05;
  Result<VoxelScene> v = Voxelize(*stream, finer);
  ASSERT_FALSE(v.ok());
  EXPECT_EQ(v.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(v.status().message().find("voxels of 0.1 m"), std::string::npos) << v.status().message();
  EXPECT_NE(v.status().message().find("not 0.05 m"), std::string::npos);
  EXPECT_NE(v.status().message().find("--raw-upload"), std::string::npos);
}

TEST(VoxelStream, OctreesAndScanOriginsAreNotCompacted) {
  SceneInput with_origins = Synthetic("box");
  with_origins.scan_origins.push_back(Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(CompactPointCloud(with_origins, 0.1, kDefaultMemoryBudgetBytes).status().code(),
            StatusCode::kFailedPrecondition);
  EXPECT_EQ(EncodeVoxelStream({}, 0.1).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodeVoxelStream({{2, 0, 0}, {1, 0, 0}}, 0.1).status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(EncodeVoxelStream({{1, 0, 0}}, 0.0).status().code(), StatusCode::kInvalidArgument);
}

TEST(VoxelStream, MalformedStreamsAreRefusedNamingWhat) {
  const std::string two = Stream(2, std::string("\x05\x01", 2));  // keys 5 and 6
  ASSERT_TRUE(ReadScene(two, "upload").ok());
  struct Case {
    std::string bytes;
    std::string says;
  };
  std::string bad_version = two;
  PutAt<uint32_t>(bad_version, 8, 3);
  std::string nan_origin = two;
  PutAt<double>(nan_origin, 28, std::nan(""));
  std::string nan_resolution = two;
  PutAt<double>(nan_resolution, 12, std::nan(""));
  std::string flipped = two;
  flipped[kVoxelStreamHeaderBytes + 3] ^= 0x5A;
  const Case cases[] = {
      {two.substr(0, 20), "header truncated"},
      {two.substr(0, 50), "version 2 header truncated"},
      {bad_version, "version 3"},
      {nan_origin, "frame origin at byte 20"},
      {nan_resolution, "resolution"},
      {Stream(0, ""), "0 voxels"},
      {Stream(3, std::string("\x05\x01\x01", 3)).substr(0, two.size()), "compressed bytes"},  // cut short
      {two + "x", "compressed bytes"},                                                        // padded
      {Stream(2, std::string("\x05\x01\x01", 3)), "after its last voxel"},
      {Stream(3, std::string("\x05\x01\x80", 3)), "end inside voxel 2"},
      {Stream(2, std::string("\x05\x00", 2)), "repeats the previous one"},
      {Stream(2, std::string("\x05", 1)), "key bytes"},  // fewer bytes than voxels
      {Stream(1, std::string("\xff\xff\xff\xff\xff\xff\xff\x01", 8)), "key bytes"},
      {Stream(1, std::string("\xff\xff\xff\xff\xff\xff\x7f", 7)), "past the largest key"},
      {flipped, "inflate"},
  };
  for (const Case& c : cases) {
    const Status st = ReadError(c.bytes);
    EXPECT_EQ(st.code(), StatusCode::kInvalidArgument) << c.says << ": " << st.ToString();
    EXPECT_NE(st.message().find(c.says), std::string::npos) << st.message();
    EXPECT_EQ(st.message().rfind("upload: ", 0), 0u) << st.message();
  }
}

TEST(VoxelStream, ADeclaredCountOverTheLimitsIsResourceExhaustedBeforeAnyAllocation) {
  ReadOptions small;
  small.max_points = 1000;
  std::string huge = Stream(2, std::string("\x05\x01", 2));
  PutAt<uint64_t>(huge, kCountAt, uint64_t{1} << 40);
  Result<SceneInput> r = ReadScene(huge, "upload", small);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kResourceExhausted) << r.status().ToString();
}

}  // namespace
}  // namespace vc
