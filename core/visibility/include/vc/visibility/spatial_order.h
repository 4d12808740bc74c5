// Internal to vc_core: the orders in which the visibility engine takes bricks of targets
// (surface_groups.cc) and the exact evaluation's corner rays take the lattice corners
// (evaluate.cc). Any order gives the same answers; these make consecutive work go to neighbouring
// places, which is what the occluder caches and the grid's memory reward.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "vc/base/geometry.h"
#include "vc/scene/occupancy_grid.h"

namespace vc::internal {

// The bits of x (< 2^32) spread to the even bit positions.
inline uint64_t SpreadBits2(uint64_t x) {
  x = (x | x << 16) & 0x0000ffff0000ffffull;
  x = (x | x << 8) & 0x00ff00ff00ff00ffull;
  x = (x | x << 4) & 0x0f0f0f0f0f0f0f0full;
  x = (x | x << 2) & 0x3333333333333333ull;
  return (x | x << 1) & 0x5555555555555555ull;
}

// The bits of x (< 2^21) spread to every third bit position, from bit 0.
inline uint64_t SpreadBits3(uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x001f00000000ffffull;
  x = (x | x << 16) & 0x001f0000ff0000ffull;
  x = (x | x << 8) & 0x100f00f00f00f00full;
  x = (x | x << 4) & 0x10c30c30c30c30c3ull;
  return (x | x << 2) & 0x1249249249249249ull;
}

// The place of (x, y) on the Z-order (Morton) curve: x's bits at even positions, y's at odd.
inline uint64_t ZOrder2(uint64_t x, uint64_t y) { return SpreadBits2(x) | SpreadBits2(y) << 1; }
// The place of (x, y, z) (each < 2^21) on the 3-D Z-order curve.
inline uint64_t ZOrder3(uint64_t x, uint64_t y, uint64_t z) {
  return SpreadBits3(x) | SpreadBits3(y) << 1 | SpreadBits3(z) << 2;
}

// The positions 0..n-1 of n corners (corner_at(i): a VoxelIndex, the corners sorted by (z, y, x))
// in brick order: slab by slab of bricks (8 layers of z, from the lowest corner's), in a slab
// brick by brick (8 x 8 x 8 lattice points) along the Z-order curve over the bricks' x and y,
// each brick's corners in their own order. Consecutive rays then go to neighbouring corners in all
// three axes, so the occluder cache (the last few occluders) proves more of them blocked without
// a walk, and the walks that remain read the grid where the last ones did, rather than along rows
// that cross the whole site (docs/BENCHMARKS.md, "Corner rays brick by brick"). A stable counting
// sort, a slab at a time: besides the result, three 4-byte words per column of bricks.
template <typename CornerAt>
std::vector<uint32_t> CornersByBrick(size_t n, const CornerAt& corner_at) {
  std::vector<uint32_t> order(n);
  if (n == 0) return order;
  constexpr int kMax = std::numeric_limits<int>::max(), kMin = std::numeric_limits<int>::min();
  int lo[3] = {kMax, kMax, kMax}, hi[3] = {kMin, kMin, kMin};
  for (size_t i = 0; i < n; ++i) {
    const VoxelIndex c = corner_at(i);
    const int v[3] = {c.x, c.y, c.z};
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], v[a]), hi[a] = std::max(hi[a], v[a]);
  }
  constexpr int kShift = OccupancyGrid::kBrickShift;
  const uint32_t columns_x = (uint32_t(hi[0] - lo[0]) >> kShift) + 1;
  const uint32_t columns_y = (uint32_t(hi[1] - lo[1]) >> kShift) + 1;
  const size_t columns = size_t(columns_x) * columns_y;
  // rank[column]: the column's place on the Z-order curve.
  std::vector<uint32_t> rank(columns);
  {
    std::vector<uint32_t> by_curve(columns);
    for (size_t i = 0; i < columns; ++i) by_curve[i] = uint32_t(i);
    auto curve = [&](uint32_t i) { return ZOrder2(i % columns_x, i / columns_x); };
    std::sort(by_curve.begin(), by_curve.end(), [&](uint32_t a, uint32_t b) { return curve(a) < curve(b); });
    for (size_t i = 0; i < columns; ++i) rank[by_curve[i]] = uint32_t(i);
  }
  auto place = [&](const VoxelIndex& c) {
    return size_t(rank[size_t(uint32_t(c.y - lo[1]) >> kShift) * columns_x + (uint32_t(c.x - lo[0]) >> kShift)]);
  };
  auto slab_of = [&](const VoxelIndex& c) { return uint32_t(c.z - lo[2]) >> kShift; };
  std::vector<uint32_t> start(columns + 1);
  // Sorted by z first, each slab's corners are one run.
  for (size_t begin = 0; begin < n;) {
    const uint32_t slab = slab_of(corner_at(begin));
    std::fill(start.begin(), start.end(), 0);
    size_t end = begin;
    for (; end < n; ++end) {
      const VoxelIndex c = corner_at(end);
      if (slab_of(c) != slab) break;
      ++start[place(c) + 1];
    }
    for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    for (size_t i = begin; i < end; ++i) order[begin + start[place(corner_at(i))]++] = uint32_t(i);
    begin = end;
  }
  return order;
}

}  // namespace vc::internal
