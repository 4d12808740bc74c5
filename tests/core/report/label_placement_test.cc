// Label placement on its own: labels stay put where there is room, never overlap each other, an
// anchor or an obstacle on a dense set, stay inside their bounds, and every leader line runs from
// its label's border to its anchor's square; the same input gives the same places.
#include "vc/report/label_placement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace vc {
namespace {

// True when p lies on the border of `box` (within 1e-9).
bool OnBorder(const LabelBox& box, const LabelPoint& p) {
  const double e = 1e-9;
  const bool inside = p.x >= box.x0 - e && p.x <= box.x1 + e && p.y >= box.y0 - e && p.y <= box.y1 + e;
  const bool edge = std::fabs(p.x - box.x0) < e || std::fabs(p.x - box.x1) < e || std::fabs(p.y - box.y0) < e ||
                    std::fabs(p.y - box.y1) < e;
  return inside && edge;
}

LabelBox AnchorSquare(const LabelRequest& l) {
  return {l.anchor.x - l.anchor_radius, l.anchor.y - l.anchor_radius, l.anchor.x + l.anchor_radius,
          l.anchor.y + l.anchor_radius};
}

// 60 stations 6 units apart on a 10 x 6 grid, each with a 23 x 23 numbered disc: centred, every
// disc would cover its neighbours.
std::vector<LabelRequest> DenseDiscs() {
  std::vector<LabelRequest> labels;
  for (int i = 0; i < 60; ++i) labels.push_back({{200.0 + 6 * (i % 10), 200.0 + 6 * (i / 10)}, 4, 23, 23});
  return labels;
}

TEST(LabelPlacementTest, LabelsWithRoomStayCentredOnTheirAnchorsWithoutLeaders) {
  const std::vector<LabelRequest> labels = {{{10, 10}, 4, 23, 23}, {{60, 10}, 4, 23, 23}};
  LabelPlacementOptions options;
  options.centred_first = true;
  const std::vector<PlacedLabel> placed = PlaceLabels(labels, {}, options);
  ASSERT_EQ(placed.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_TRUE(placed[k].centred);
    EXPECT_FALSE(placed[k].leader);
    EXPECT_FALSE(placed[k].overlaps);
    EXPECT_DOUBLE_EQ(placed[k].box.x0, labels[k].anchor.x - 11.5);
    EXPECT_DOUBLE_EQ(placed[k].box.y1, labels[k].anchor.y + 11.5);
  }
}

TEST(LabelPlacementTest, NoTwoLabelsOverlapOnADenseSetAndEveryLeaderEndsAtItsAnchor) {
  const std::vector<LabelRequest> labels = DenseDiscs();
  LabelPlacementOptions options;
  options.centred_first = true;
  options.bounds = {0, 0, 460, 460};
  const std::vector<PlacedLabel> placed = PlaceLabels(labels, {}, options);
  ASSERT_EQ(placed.size(), labels.size());
  int moved = 0;
  for (size_t i = 0; i < placed.size(); ++i) {
    EXPECT_FALSE(placed[i].overlaps) << "label " << i;
    EXPECT_TRUE(options.bounds.Contains(placed[i].box)) << "label " << i;
    for (size_t j = 0; j < placed.size(); ++j) {
      if (j == i) continue;
      EXPECT_FALSE(placed[i].box.Overlaps(placed[j].box)) << i << " and " << j;
      EXPECT_FALSE(placed[i].box.Overlaps(AnchorSquare(labels[j]))) << i << " over anchor " << j;
    }
    EXPECT_EQ(placed[i].leader, !placed[i].centred) << "label " << i;
    if (!placed[i].leader) continue;
    ++moved;
    EXPECT_TRUE(OnBorder(placed[i].box, placed[i].leader_start)) << "label " << i;
    EXPECT_TRUE(OnBorder(AnchorSquare(labels[i]), placed[i].leader_end)) << "label " << i;
    EXPECT_FALSE(placed[i].box.Overlaps(AnchorSquare(labels[i]))) << "label " << i << " clear of its own anchor";
  }
  EXPECT_GT(moved, 50) << "centred, nearly every disc would cover a neighbour";
}

TEST(LabelPlacementTest, TheSameLabelsGetTheSamePlaces) {
  LabelPlacementOptions options;
  options.centred_first = true;
  const std::vector<PlacedLabel> a = PlaceLabels(DenseDiscs(), {}, options);
  const std::vector<PlacedLabel> b = PlaceLabels(DenseDiscs(), {}, options);
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].box.x0, b[k].box.x0);
    EXPECT_EQ(a[k].box.y0, b[k].box.y0);
  }
}

// A name beside its marker: right of it first, then left, below and above, all without a leader;
// further out only with one.
TEST(LabelPlacementTest, ANameGoesBesideItsMarkerAndLeavesOnlyWithALeader) {
  const LabelRequest name{{100, 100}, 9, 40, 9};
  const std::vector<PlacedLabel> free = PlaceLabels({name}, {});
  EXPECT_DOUBLE_EQ(free[0].box.x0, 110);  // anchor + radius + gap
  EXPECT_DOUBLE_EQ(free[0].box.y0, 95.5);
  EXPECT_FALSE(free[0].leader);
  EXPECT_FALSE(free[0].centred);

  const std::vector<PlacedLabel> left = PlaceLabels({name}, {{110, 90, 160, 110}});
  EXPECT_DOUBLE_EQ(left[0].box.x1, 90);
  EXPECT_FALSE(left[0].leader);

  // Everything within 20 of the marker taken: the label moves out and a leader joins it back.
  const std::vector<LabelBox> crowd = {{80, 40, 200, 90}, {20, 90, 91, 120}, {109, 91, 200, 120}, {40, 109, 200, 160}};
  const std::vector<PlacedLabel> out = PlaceLabels({name}, crowd);
  EXPECT_FALSE(out[0].overlaps);
  EXPECT_TRUE(out[0].leader);
  for (const LabelBox& b : crowd) EXPECT_FALSE(out[0].box.Overlaps(b));
  EXPECT_TRUE(OnBorder(out[0].box, out[0].leader_start));
  EXPECT_TRUE(OnBorder(AnchorSquare(name), out[0].leader_end));
}

// With nowhere free, a label takes the candidate that covers least and says so.
TEST(LabelPlacementTest, WithNoRoomALabelOverlapsAsLittleAsItCanAndSaysSo) {
  const LabelRequest a{{10, 10}, 2, 10, 10}, b{{12, 10}, 2, 10, 10};
  LabelPlacementOptions options;
  options.centred_first = true;
  options.bounds = {0, 0, 20, 20};
  const std::vector<PlacedLabel> placed = PlaceLabels({a, b}, {}, options);
  ASSERT_EQ(placed.size(), 2u);
  EXPECT_TRUE(placed[0].overlaps) << "centred over the other anchor, or beside it off the page";
  EXPECT_TRUE(placed[1].overlaps);
  for (const PlacedLabel& p : placed) EXPECT_TRUE(options.bounds.Contains(p.box));
}

}  // namespace
}  // namespace vc
