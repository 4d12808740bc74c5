// vc/scene/octomap_adapter.h, against OctoMap itself: the leaves we build are the cubes we report,
// streams OctoMap writes come back leaf for leaf, the tree-size limit is exact, lies in a header are
// refused naming them, and castRay and the known-free test give their three outcomes.
#include "vc/scene/octomap_adapter.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include <cmath>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace vc {
namespace {

using ::testing::HasSubstr;
using Cube = std::tuple<long, long, long, long>;  // min corner and edge, in 1/1000 m

// Every occupied leaf's cube, rounded to millimetres.
std::set<Cube> Leaves(const octomap::OcTree& tree) {
  std::set<Cube> out;
  ForEachOccupiedLeaf(tree, [&](const WorldPoint& lo, double edge) {
    out.insert(
        {std::lround(lo.x() * 1000), std::lround(lo.y() * 1000), std::lround(lo.z() * 1000), std::lround(edge * 1000)});
  });
  return out;
}

VoxelKey Key(int x, int y, int z) {
  return {uint16_t(kKeyOffset + x), uint16_t(kKeyOffset + y), uint16_t(kKeyOffset + z)};
}

// An aligned 2x2x2 block at the origin (pruned into one leaf of 0.2 m) and two single voxels.
std::shared_ptr<octomap::OcTree> SmallTree() {
  std::vector<VoxelKey> keys = {Key(5, -3, 0), Key(-4, 2, 7)};
  for (int d = 0; d < 8; ++d) keys.push_back(Key(d & 1, d >> 1 & 1, d >> 2));
  return BuildOctree(0.1, keys);
}

TEST(BuildOctreeTest, TheLeavesAreTheKeysCubesAndTheBoundingBoxTheirsToo) {
  const auto tree = SmallTree();
  EXPECT_EQ(OctreeResolution(*tree), 0.1);
  EXPECT_EQ(CountOccupiedLeaves(*tree), 3u);
  EXPECT_EQ(Leaves(*tree), (std::set<Cube>{{0, 0, 0, 200}, {500, -300, 0, 100}, {-400, 200, 700, 100}}));
  WorldPoint lo, hi;
  OccupiedBoundingBox(*tree, &lo, &hi);
  EXPECT_NEAR(lo.x(), -0.4, 1e-9);
  EXPECT_NEAR(lo.y(), -0.3, 1e-9);
  EXPECT_NEAR(lo.z(), 0.0, 1e-9);
  EXPECT_NEAR(hi.x(), 0.6, 1e-9);
  EXPECT_NEAR(hi.y(), 0.3, 1e-9);
  EXPECT_NEAR(hi.z(), 0.8, 1e-9);

  const auto empty = BuildOctree(0.1, {});
  EXPECT_EQ(CountOccupiedLeaves(*empty), 0u);
  OccupiedBoundingBox(*empty, &lo, &hi);
  EXPECT_GT(lo.x(), hi.x());
}

TEST(ReadOctreeTest, WhatOctoMapWritesComesBackLeafForLeaf) {
  const auto tree = SmallTree();
  std::stringstream bt, ot;
  ASSERT_TRUE(tree->writeBinary(bt));
  ASSERT_TRUE(tree->write(ot));
  Result<std::shared_ptr<octomap::OcTree>> binary = ReadOctreeBinary(bt.str(), "t.bt");
  ASSERT_TRUE(binary.ok()) << binary.status().ToString();
  EXPECT_EQ(Leaves(**binary), Leaves(*tree));
  Result<std::shared_ptr<octomap::OcTree>> text = ReadOctreeText(ot.str(), "t.ot");
  ASSERT_TRUE(text.ok()) << text.status().ToString();
  EXPECT_EQ(Leaves(**text), Leaves(*tree));
  EXPECT_EQ(OctreeResolution(**text), 0.1);
}

TEST(ReadOctreeTest, AColorOcTreeIsReadAsItsOccupancy) {
  octomap::ColorOcTree colour(0.1);
  colour.updateNode(octomap::point3d(0.05f, 0.05f, 0.05f), true)->setColor(255, 0, 0);
  colour.updateNode(octomap::point3d(0.55f, 0.05f, 0.05f), true);
  std::stringstream ot;
  ASSERT_TRUE(colour.write(ot));
  Result<std::shared_ptr<octomap::OcTree>> tree = ReadOctreeText(ot.str(), "colour.ot");
  ASSERT_TRUE(tree.ok()) << tree.status().ToString();
  EXPECT_EQ(Leaves(**tree), (std::set<Cube>{{0, 0, 0, 100}, {500, 0, 0, 100}}));
}

TEST(ReadOctreeTest, TheTreeSizeLimitIsExactAndCheckedBeforeReading) {
  const auto tree = SmallTree();
  std::stringstream bt, ot;
  ASSERT_TRUE(tree->writeBinary(bt));
  ASSERT_TRUE(tree->write(ot));
  const uint64_t nodes = tree->size();
  EXPECT_TRUE(ReadOctreeBinary(bt.str(), "t.bt", nodes * kOctreeNodeBytes).ok());
  EXPECT_TRUE(ReadOctreeText(ot.str(), "t.ot", nodes * kOctreeNodeBytes).ok());
  for (const Status& s : {ReadOctreeBinary(bt.str(), "t.bt", nodes * kOctreeNodeBytes - 1).status(),
                          ReadOctreeText(ot.str(), "t.ot", nodes * kOctreeNodeBytes - 1).status()}) {
    EXPECT_EQ(s.code(), StatusCode::kResourceExhausted);
    EXPECT_THAT(s.message(), HasSubstr("the OctoMap tree has " + std::to_string(nodes) + " nodes"));
  }
}

TEST(ReadOctreeTest, LiesAndDamageAreRefusedNamingTheSourceAndWhat) {
  std::stringstream bt_stream, ot_stream;
  ASSERT_TRUE(SmallTree()->writeBinary(bt_stream));
  ASSERT_TRUE(SmallTree()->write(ot_stream));
  const std::string bt = bt_stream.str(), ot = ot_stream.str();
  auto refused = [](const Result<std::shared_ptr<octomap::OcTree>>& r, const std::string& part) {
    EXPECT_FALSE(r.ok()) << part;
    EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument) << r.status().ToString();
    EXPECT_THAT(r.status().message(), HasSubstr(part));
  };
  refused(ReadOctreeBinary("not a tree", "x.bt"), "x.bt: not an OctoMap stream");
  refused(ReadOctreeBinary(bt.substr(0, bt.size() - 1), "cut.bt"), "(file truncated?)");
  const size_t size_at = bt.find("\nsize ") + 6;
  const std::string more = bt.substr(0, size_at) + "1" + bt.substr(size_at);  // ten times as many nodes and more
  refused(ReadOctreeBinary(more, "lie.bt"), "header and data do not match");
  std::string other = bt;
  other.replace(other.find("id OcTree"), 9, "id CountingOcTree");
  refused(ReadOctreeBinary(other, "count.bt"), "unsupported OctoMap tree type \"CountingOcTree\"");
  refused(ReadOctreeText(ot.substr(0, ot.size() - 2), "cut.ot"), "(file truncated?)");
  std::string no_data = ot.substr(0, ot.find("data\n"));
  refused(ReadOctreeText(no_data, "head.ot"), "header has no \"data\" line");
}

// A scan graph as OctoMap's ScanGraph::writeBinary lays it out: the node count, then per node its
// points (count, then per point an int32 3 and three doubles), its pose (3 + 4 doubles, each list
// after its int32 length: x y z, then w x y z) and its id.
std::string Graph(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& t, const double q[4]) {
  std::string b;
  auto put = [&](const auto& v) { b.append(reinterpret_cast<const char*>(&v), sizeof(v)); };
  put(uint32_t{1});
  put(uint32_t(points.size()));
  for (const Eigen::Vector3d& p : points) {
    put(int32_t{3});
    for (int i = 0; i < 3; ++i) put(p[i]);
  }
  put(int32_t{3});
  for (int i = 0; i < 3; ++i) put(t[i]);
  put(int32_t{4});
  for (int i = 0; i < 4; ++i) put(q[i]);
  put(uint32_t{0});
  put(uint32_t{0});  // no edges
  return b;
}

TEST(ReadScanGraphTest, PointsGoToTheWorldByTheirScansPose) {
  const double quarter_turn_about_z[4] = {std::sqrt(0.5), 0, 0, std::sqrt(0.5)};
  const std::string g = Graph({{1, 0, 0}, {0, 2, 0}}, {10, 0, 1}, quarter_turn_about_z);
  Result<ScanGraphData> r = ReadScanGraph(g, "g.graph");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->origins.size(), 1u);
  EXPECT_EQ(r->origins[0], Eigen::Vector3d(10, 0, 1));
  ASSERT_EQ(r->points.size(), 2u);
  EXPECT_NEAR(r->points[0].x(), 10, 1e-5);  // (1, 0, 0) turned to (0, 1, 0)
  EXPECT_NEAR(r->points[0].y(), 1, 1e-5);
  EXPECT_NEAR(r->points[1].x(), 8, 1e-5);  // (0, 2, 0) turned to (-2, 0, 0)
  EXPECT_NEAR(r->points[1].z(), 1, 1e-5);
}

TEST(ReadScanGraphTest, SurveyCoordinatesGoToALocalFrameAndTheOriginsStayInTheWorld) {
  const double identity[4] = {1, 0, 0, 0};
  const Eigen::Vector3d station(512345.678, 5612330.123, 312.5);
  Result<ScanGraphData> r = ReadScanGraph(Graph({{0.001, -0.002, 0.5}, {-3, 4, -1}}, station, identity), "g.graph");
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, Eigen::Vector3d(512000, 5612000, 0));
  ASSERT_EQ(r->origins.size(), 1u);
  EXPECT_EQ(r->origins[0], station);
  ASSERT_EQ(r->points.size(), 2u);
  EXPECT_LE((r->points[0].cast<double>() + r->frame_origin_m - Eigen::Vector3d(512345.679, 5612330.121, 313)).norm(),
            1e-4);
  EXPECT_LE((r->points[1].cast<double>() + r->frame_origin_m - Eigen::Vector3d(512342.678, 5612334.123, 311.5)).norm(),
            1e-4);

  r = ReadScanGraph(Graph({{1000, 0, 0}}, {0, 0, 0}, identity), "mm.graph", 0.001);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->frame_origin_m, Eigen::Vector3d::Zero());
  EXPECT_EQ(r->points[0], Eigen::Vector3f(1, 0, 0));
}

TEST(ReadScanGraphTest, BadGraphsAreRefusedNamingTheByte) {
  const double identity[4] = {1, 0, 0, 0}, zero[4] = {0, 0, 0, 0};
  Result<ScanGraphData> r = ReadScanGraph(Graph({{1, 0, 0}}, {0, 0, 0}, zero), "g.graph");
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(r.status().message(), HasSubstr("scan 0: invalid rotation quaternion"));
  r = ReadScanGraph(std::string(4, '\0'), "empty.graph");
  EXPECT_THAT(r.status().message(), HasSubstr("empty.graph: scan graph, byte 0: the graph has no scans"));
  const std::string good = Graph({{1, 0, 0}, {2, 0, 0}}, {0, 0, 0}, identity);
  r = ReadScanGraph(good.substr(0, 4 + 4 + 28 + 10), "cut.graph");
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
}

TEST(IsKnownFreeTest, OnlyWhereTheRaysSawFreeSpace) {
  octomap::OcTree tree(0.1);
  tree.updateNode(octomap::point3d(0.05f, 0.05f, 0.05f), true);
  tree.updateNode(octomap::point3d(0.35f, 0.05f, 0.05f), false);
  EXPECT_FALSE(IsKnownFree(tree, {0.05, 0.05, 0.05}));  // occupied
  EXPECT_TRUE(IsKnownFree(tree, {0.35, 0.05, 0.05}));   // observed free
  EXPECT_FALSE(IsKnownFree(tree, {0.65, 0.05, 0.05}));  // never observed
}

TEST(OctomapCastRayTest, HitsTheFirstOccupiedVoxelWithinRangeAndPassesUnknownSpace) {
  const auto tree = BuildOctree(0.1, {Key(10, 0, 0), Key(20, 0, 0)});
  const WorldPoint origin(0.05, 0.05, 0.05);
  CastRayOutcome out = OctomapCastRay(*tree, origin, {1, 0, 0}, 5.0);
  ASSERT_EQ(out.kind, CastRayOutcome::Kind::kHitOccupied);
  EXPECT_EQ(out.hit, Key(10, 0, 0));
  EXPECT_EQ(OctomapCastRay(*tree, origin, {1, 0, 0}, 0.5).kind, CastRayOutcome::Kind::kNoHit);  // out of range
  EXPECT_EQ(OctomapCastRay(*tree, origin, {0, 1, 0}, 5.0).kind, CastRayOutcome::Kind::kNoHit);  // nothing there
}

}  // namespace
}  // namespace vc
