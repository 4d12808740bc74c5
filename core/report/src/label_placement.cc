#include "vc/report/label_placement.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vc {

namespace {

// A candidate place of a label: its box and the ring it lies on (-1: centred on the anchor).
struct Candidate {
  LabelBox box;
  int ring = -1;
};

LabelBox Square(const LabelPoint& p, double half) { return {p.x - half, p.y - half, p.x + half, p.y + half}; }

// How much `a` covers `b`: the area of their intersection, and at least a token amount when the
// interiors meet (so a label over an anchor of no size counts too); 0 when they do not.
double Cover(const LabelBox& a, const LabelBox& b) {
  if (!a.Overlaps(b)) return 0.0;
  const double w = std::min(a.x1, b.x1) - std::max(a.x0, b.x0);
  const double h = std::min(a.y1, b.y1) - std::max(a.y0, b.y0);
  return std::max(w * h, 1e-9);
}

// The candidates in the order they are tried: centred (if asked), then per ring right, left,
// below, above, upper right, upper left, lower right, lower left. On a ring of clearance c the
// label's nearest side (or corner) lies c from the anchor in that direction.
std::vector<Candidate> Candidates(const LabelRequest& l, const LabelPlacementOptions& o) {
  std::vector<Candidate> out;
  const double w = l.width, h = l.height;
  if (o.centred_first)
    out.push_back({{l.anchor.x - w / 2, l.anchor.y - h / 2, l.anchor.x + w / 2, l.anchor.y + h / 2}});
  const double step = o.ring_step > 0 ? o.ring_step : std::max(std::min(w, h), 1e-6);
  const double d = std::sqrt(0.5);
  constexpr int kSide[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, -1}, {-1, -1}, {1, 1}, {-1, 1}};
  for (int ring = 0; ring < std::max(o.rings, 1); ++ring) {
    const double c = l.anchor_radius + o.gap + ring * step;
    for (const auto& s : kSide) {
      const double along = s[0] != 0 && s[1] != 0 ? c * d : c;  // the corner of a diagonal place
      const double cx = l.anchor.x + s[0] * (along + w / 2), cy = l.anchor.y + s[1] * (along + h / 2);
      out.push_back({{cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2}, ring});
    }
  }
  return out;
}

// Where the segment from `from` to the centre of `box` (with `from` outside the box) crosses the
// box's border.
LabelPoint BorderTowards(const LabelBox& box, const LabelPoint& from) {
  const double cx = 0.5 * (box.x0 + box.x1), cy = 0.5 * (box.y0 + box.y1);
  const double dx = from.x - cx, dy = from.y - cy;
  const double hw = 0.5 * (box.x1 - box.x0), hh = 0.5 * (box.y1 - box.y0);
  double t = 1;  // fraction of the way from the centre to `from`
  if (std::fabs(dx) > hw) t = std::min(t, hw / std::fabs(dx));
  if (std::fabs(dy) > hh) t = std::min(t, hh / std::fabs(dy));
  return {cx + t * dx, cy + t * dy};
}

PlacedLabel Place(const LabelRequest& l, const Candidate& c, const LabelPlacementOptions& o, bool overlaps) {
  PlacedLabel p;
  p.box = c.box;
  p.centred = c.ring < 0;
  p.overlaps = overlaps;
  p.leader = !p.centred && (o.centred_first || c.ring > 0);
  if (p.leader) {
    const LabelPoint centre{0.5 * (c.box.x0 + c.box.x1), 0.5 * (c.box.y0 + c.box.y1)};
    p.leader_start = BorderTowards(c.box, l.anchor);
    p.leader_end = BorderTowards(Square(l.anchor, l.anchor_radius), centre);
  }
  return p;
}

}  // namespace

std::vector<PlacedLabel> PlaceLabels(const std::vector<LabelRequest>& labels, const std::vector<LabelBox>& obstacles,
                                     const LabelPlacementOptions& options) {
  std::vector<LabelBox> anchors;
  for (const LabelRequest& l : labels) anchors.push_back(Square(l.anchor, l.anchor_radius));
  const bool bounded = options.bounds.x1 > options.bounds.x0 && options.bounds.y1 > options.bounds.y0;
  std::vector<PlacedLabel> placed;
  placed.reserve(labels.size());
  for (size_t k = 0; k < labels.size(); ++k) {
    const std::vector<Candidate> candidates = Candidates(labels[k], options);
    // What some candidate could cover (its own anchor apart): a filter, so that a plan of
    // thousands of stations compares each label with its neighbours only.
    LabelBox reach = candidates.front().box;
    for (const Candidate& c : candidates) {
      reach = {std::min(reach.x0, c.box.x0), std::min(reach.y0, c.box.y0), std::max(reach.x1, c.box.x1),
               std::max(reach.y1, c.box.y1)};
    }
    std::vector<LabelBox> near;
    for (size_t a = 0; a < anchors.size(); ++a) {
      if (a != k && reach.Overlaps(anchors[a])) near.push_back(anchors[a]);
    }
    for (const LabelBox& b : obstacles) {
      if (reach.Overlaps(b)) near.push_back(b);
    }
    for (const PlacedLabel& p : placed) {
      if (reach.Overlaps(p.box)) near.push_back(p.box);
    }
    // How much `box` covers the other anchors, the obstacles and the labels placed so far (0:
    // nothing), and its own anchor unless it is centred on it.
    auto covered = [&](const LabelBox& box, bool centred) {
      double area = centred ? 0.0 : Cover(box, anchors[k]);
      for (const LabelBox& b : near) area += Cover(box, b);
      return area;
    };
    const Candidate* best = nullptr;
    double best_area = std::numeric_limits<double>::infinity();
    for (const Candidate& c : candidates) {
      if (bounded && !options.bounds.Contains(c.box)) continue;
      const double area = covered(c.box, c.ring < 0);
      if (area <= 0) {
        best = &c, best_area = 0;
        break;
      }
      if (area < best_area) best = &c, best_area = area;
    }
    if (best == nullptr) best = &candidates.front(), best_area = covered(best->box, best->ring < 0);
    placed.push_back(Place(labels[k], *best, options, best_area > 0));
  }
  return placed;
}

}  // namespace vc
