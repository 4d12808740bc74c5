// Station labels on a dense plan (heatmap.png's numbered discs, fieldsheet.pdf's numbered markers
// and name labels; docs/PLANNING.md, "Labels on a dense plan"). Each label goes to the first of a
// fixed list of candidate places around its anchor (the station, or its marker) that covers no
// anchor, no obstacle and no label placed before it; labels are taken in the order given (greedy
// point-feature labelling, Christensen, Marks & Shieber 1995, without their search). A label moved
// away from its anchor gets a leader line back to it. Where no place is free the label takes the
// candidate that overlaps least, and says so. The same requests always give the same places.
// Coordinates are a page's (pixels or points), x to the right and y down.
// Pure function of its arguments: thread-safe.
#pragma once

#include <vector>

namespace vc {

// A point on the page.
struct LabelPoint {
  double x = 0;
  double y = 0;
};

// An axis-aligned box [x0, x1] x [y0, y1] on the page.
struct LabelBox {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  // True when the interiors meet (boxes that only touch do not overlap).
  bool Overlaps(const LabelBox& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
  // True when `o` lies inside this box.
  bool Contains(const LabelBox& o) const { return o.x0 >= x0 && o.x1 <= x1 && o.y0 >= y0 && o.y1 <= y1; }
};

// One label to place: its anchor, the disc around the anchor that no other label may cover, and
// the label's size, all in page units.
struct LabelRequest {
  LabelPoint anchor;
  double anchor_radius = 0;  // half the side of the square kept clear around the anchor
  double width = 0;
  double height = 0;
};

struct LabelPlacementOptions {
  // Try the label centred on its own anchor first (a numbered marker over its station); off, the
  // label sits beside its anchor (a name beside its marker).
  bool centred_first = false;
  double gap = 1;        // clearance between a label beside its anchor and the anchor's square
  double ring_step = 0;  // how much further out each ring of candidates lies; 0: the label's smaller side
  int rings = 12;        // rings of 8 candidates (right, left, below, above, then the diagonals)
  LabelBox bounds;       // every label stays inside; an empty box (x1 <= x0) sets no bounds
};

// Where a label went.
struct PlacedLabel {
  LabelBox box;
  bool centred = false;  // centred on its anchor
  // A leader line runs from `leader_start` (on the box's border, towards the label's centre) to
  // `leader_end` (on the border of the anchor's square, towards the label). A label centred on its
  // anchor, or beside it in the first ring when `centred_first` is off, has none.
  bool leader = false;
  LabelPoint leader_start;
  LabelPoint leader_end;
  bool overlaps = false;  // no free candidate: it covers something (the least of all candidates)
};

// The places of `labels`, one per request in their order, avoiding each other, every anchor's
// square (a centred label may cover its own) and `obstacles`.
std::vector<PlacedLabel> PlaceLabels(const std::vector<LabelRequest>& labels, const std::vector<LabelBox>& obstacles,
                                     const LabelPlacementOptions& options = {});

}  // namespace vc
