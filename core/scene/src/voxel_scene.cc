#include "vc/scene/voxel_scene.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "vc/scene/octomap_adapter.h"

namespace vc {
namespace {

// "0.1 m", "0.025 m": a resolution for people (up to 6 significant digits).
std::string FormatMetres(double m) {
  std::ostringstream out;
  out << m << " m";
  return out.str();
}

// Packs a key into 48 bits in VoxelKey's order (z, then y, then x), so sorting packed values
// sorts keys.
uint64_t Pack(const VoxelKey& k) { return (uint64_t(k.z) << 32) | (uint64_t(k.y) << 16) | uint64_t(k.x); }
VoxelKey Unpack(uint64_t p) { return {uint16_t(p & 0xffff), uint16_t((p >> 16) & 0xffff), uint16_t(p >> 32)}; }

Status CheckResolution(double r) {
  if (!std::isfinite(r) || r <= 0) {
    return InvalidArgumentError("resolution must be a positive, finite number of metres; got " + std::to_string(r));
  }
  if (r < 0.001 || r > 100) {
    return InvalidArgumentError("resolution " + std::to_string(r) + " m is outside the supported range 0.001-100 m");
  }
  return Status::Ok();
}

// A length for people: "27,240" (whole metres, thousands grouped) from 1000 m, "12.35" below.
std::string FormatLength(double m) {
  std::ostringstream out;
  if (!(std::fabs(m) >= 1000 && std::fabs(m) < 1e15)) {
    out.precision(4);
    out << m;
    return out.str();
  }
  const std::string digits = std::to_string(std::llabs(std::llround(m)));
  std::string grouped = m < 0 ? "-" : "";
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) grouped += ',';
    grouped += digits[i];
  }
  return grouped;
}

std::string FormatPoint(const Eigen::Vector3d& p_m) {
  std::ostringstream out;
  out << '(' << FormatLength(p_m.x()) << ", " << FormatLength(p_m.y()) << ", " << FormatLength(p_m.z()) << ')';
  return out.str();
}

std::string FormatExtent(const Eigen::Vector3d& extent_m) {
  return FormatLength(extent_m.x()) + " x " + FormatLength(extent_m.y()) + " x " + FormatLength(extent_m.z()) + " m";
}

// No terrestrial scan site is larger than this in any axis, in metres.
constexpr double kLargestSiteM = 5000;

// How a scene of this extent begins its message: when it is implausible for metres, what the file
// probably is (docs/PLANNING.md "Coordinates": units).
std::string DescribeExtent(const Eigen::Vector3d& extent_m) {
  const double largest = extent_m.maxCoeff();
  if (!(largest > kLargestSiteM)) return "the scene spans " + FormatExtent(extent_m) + " and";
  std::string m = "the scene spans " + FormatExtent(extent_m) + " as metres, more than any terrestrial scan site: ";
  if (largest / 1000 <= kLargestSiteM) {
    m += "is the file in millimetres (it would span " + FormatExtent(extent_m / 1000) +
         ")? Give its units (vc-client --units mm, or --units cm for centimetres). As metres it";
  } else {
    m += "check the file for stray points far from the rest, or scans in different frames. As metres it";
  }
  return m;
}

// Refuses a box of voxel indices [lo, hi] that cannot be represented or would not fit.
Status CheckExtent(const Eigen::Vector3d& lo_m, const Eigen::Vector3d& hi_m, double r, uint64_t budget) {
  const Eigen::Vector3d lo = (lo_m / r).array().floor(), hi = (hi_m / r).array().floor();
  const std::string scene = DescribeExtent(hi_m - lo_m);
  if ((lo.array() < -kKeyOffset).any() || (hi.array() >= kKeyOffset).any()) {
    const double needed = std::max(lo_m.cwiseAbs().maxCoeff(), hi_m.cwiseAbs().maxCoeff()) / (kKeyOffset - 1);
    std::ostringstream os;
    os << scene << " does not fit OctoMap's 65536-voxel key range at resolution " << r << " m (coordinates within +-"
       << kKeyOffset * r << " m of the local frame's origin; the scene's bounding box "
       << "there is " << FormatPoint(lo_m) << " .. " << FormatPoint(hi_m) << " m); a resolution of at least "
       << std::ceil(needed * 1000) / 1000 << " m fits";
    return InvalidArgumentError(os.str());
  }
  const VoxelIndex a{int(lo.x()), int(lo.y()), int(lo.z())}, b{int(hi.x()), int(hi.y()), int(hi.z())};
  const uint64_t need = OccupancyGrid::BytesNeeded(a, b, 0);
  if (need > budget) {
    const double factor = std::cbrt(double(need) / double(budget) * 1.25);
    std::ostringstream os;
    os << scene << " needs " << double(need) / double(1 << 20) << " MiB for its traversal grid alone at resolution "
       << r << " m, over the memory budget of " << double(budget) / double(1 << 20)
       << " MiB; use a resolution of at least " << std::ceil(r * factor * 1000) / 1000
       << " m, raise the budget, or crop the scene";
    return ResourceExhaustedError(os.str());
  }
  return Status::Ok();
}

// The scene of sorted, unique keys at resolution r: the voxel list and its traversal grid.
Result<VoxelScene> SceneFromKeys(double r, std::vector<VoxelKey> occupied, uint64_t budget, const JobContext& ctx) {
  VoxelScene scene;
  scene.resolution_m = r;
  scene.occupied = std::move(occupied);
  std::vector<VoxelIndex> idx(scene.occupied.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = KeyToIndex(scene.occupied[i]);
  const uint64_t list_bytes = scene.occupied.size() * sizeof(VoxelKey);
  if (list_bytes >= budget) {
    return ResourceExhaustedError("the scene has " + std::to_string(scene.occupied.size()) +
                                  " occupied voxels, over the memory budget; use a coarser resolution");
  }
  VC_ASSIGN_OR_RETURN(scene.grid, OccupancyGrid::Build(r, idx, budget - list_bytes));
  ctx.Report(Stage::kVoxelize, 1.0, std::to_string(scene.occupied.size()) + " occupied voxels");
  return scene;
}

// VoxelAccumulator's recent-key cache: 2^14 slots (128 KiB), and a value no 48-bit key takes.
constexpr size_t kRecentSlots = size_t{1} << 14;
constexpr uint64_t kNoKey = ~uint64_t{0};
size_t RecentSlot(uint64_t key) { return size_t((key * 0x9E3779B97F4A7C15ull) >> 50); }
// Least room the key buffer is given for new keys after a merge (512 KiB).
constexpr size_t kMinRoom = size_t{1} << 16;

}  // namespace

int64_t VoxelScene::IdOf(const VoxelKey& key) const {
  auto it = std::lower_bound(occupied.begin(), occupied.end(), key);
  if (it == occupied.end() || *it != key) return -1;
  return it - occupied.begin();
}

WorldPoint VoxelScene::BoundsMin() const {
  WorldPoint m = WorldPoint::Constant(std::numeric_limits<double>::infinity());
  for (const VoxelKey& k : occupied) m = m.cwiseMin(KeyToCoord(resolution_m, k));
  return m - WorldPoint::Constant(resolution_m / 2);
}

WorldPoint VoxelScene::BoundsMax() const {
  WorldPoint m = WorldPoint::Constant(-std::numeric_limits<double>::infinity());
  for (const VoxelKey& k : occupied) m = m.cwiseMax(KeyToCoord(resolution_m, k));
  return m + WorldPoint::Constant(resolution_m / 2);
}

double WorkingResolution(const SceneInput& input, const VoxelizeOptions& options) {
  if (options.resolution_m != 0) return options.resolution_m;
  if (input.octree) return OctreeResolution(*input.octree);
  if (input.voxel_resolution_m > 0) return input.voxel_resolution_m;
  return kDefaultResolutionM;
}

Result<std::vector<VoxelKey>> OccupiedKeys(const SceneInput& input, double r, uint64_t budget, const JobContext& ctx) {
  VC_RETURN_IF_ERROR(CheckResolution(r));
  // A voxel stream's points are voxel centres: at its own resolution they give back its voxels;
  // at any other they would not be the scene the client voxelised.
  if (input.voxel_resolution_m > 0 && std::fabs(r - input.voxel_resolution_m) > 1e-9 * input.voxel_resolution_m) {
    return InvalidArgumentError("the scene was uploaded as voxels of " + FormatMetres(input.voxel_resolution_m) +
                                " (a compact upload) and can only be voxelised at that resolution, not " +
                                FormatMetres(r) +
                                ": upload the raw cloud (vc-client --raw-upload), or let the "
                                "client voxelise at " +
                                FormatMetres(r));
  }
  std::vector<uint64_t> packed;
  if (input.octree) {
    const octomap::OcTree& tree = *input.octree;
    WorldPoint lo, hi;
    OccupiedBoundingBox(tree, &lo, &hi);
    if (!(lo.array() <= hi.array()).all()) return InvalidArgumentError("the octree has no occupied voxels");
    VC_RETURN_IF_ERROR(CheckExtent(lo, hi, r, budget));
    // Count first: a coarse leaf at a fine resolution expands to many voxels.
    const double eps = 1e-9;
    uint64_t total = 0;
    auto range = [&](const WorldPoint& m, double s, int axis, int* a, int* b) {
      *a = int(std::floor(m[axis] / r + eps));
      *b = int(std::ceil((m[axis] + s) / r - eps)) - 1;
    };
    ForEachOccupiedLeaf(tree, [&](const WorldPoint& m, double s) {
      uint64_t n = 1;
      for (int i = 0; i < 3; ++i) {
        int a, b;
        range(m, s, i, &a, &b);
        n *= uint64_t(std::max(0, b - a + 1));
      }
      total += n;
    });
    if (total * sizeof(uint64_t) > budget) {
      return ResourceExhaustedError(
          "resampling the octree at " + std::to_string(r) + " m gives " + std::to_string(total) +
          " occupied voxels, over the memory budget; use a coarser resolution (the tree's own is " +
          std::to_string(tree.getResolution()) + " m)");
    }
    packed.reserve(total);
    ForEachOccupiedLeaf(tree, [&](const WorldPoint& m, double s) {
      int a[3], b[3];
      for (int i = 0; i < 3; ++i) range(m, s, i, &a[i], &b[i]);
      for (int z = a[2]; z <= b[2]; ++z)
        for (int y = a[1]; y <= b[1]; ++y)
          for (int x = a[0]; x <= b[0]; ++x) packed.push_back(Pack(IndexToKey({x, y, z})));
    });
  } else {
    if (input.points.empty()) return InvalidArgumentError("the point cloud is empty");
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Eigen::Vector3f& p : input.points) {
      lo = lo.cwiseMin(p.cast<double>());
      hi = hi.cwiseMax(p.cast<double>());
    }
    if (!lo.allFinite() || !hi.allFinite()) return InvalidArgumentError("the point cloud has non-finite coordinates");
    VC_RETURN_IF_ERROR(CheckExtent(lo, hi, r, budget));
    if (input.points.size() * sizeof(uint64_t) > budget) {
      return ResourceExhaustedError("voxelising " + std::to_string(input.points.size()) +
                                    " points needs more than the memory budget; raise it or thin the cloud");
    }
    packed.reserve(input.points.size());
    const double f = 1.0 / r;
    for (size_t i = 0; i < input.points.size(); ++i) {
      if ((i & 0xfffff) == 0) VC_RETURN_IF_ERROR(ctx.CheckCancelled("voxelisation"));
      const Eigen::Vector3f& p = input.points[i];
      const VoxelKey k{uint16_t(int(std::floor(f * double(p.x()))) + kKeyOffset),
                       uint16_t(int(std::floor(f * double(p.y()))) + kKeyOffset),
                       uint16_t(int(std::floor(f * double(p.z()))) + kKeyOffset)};
      packed.push_back(Pack(k));
    }
  }
  VC_RETURN_IF_ERROR(ctx.CheckCancelled("voxelisation"));
  std::sort(packed.begin(), packed.end());
  packed.erase(std::unique(packed.begin(), packed.end()), packed.end());
  std::vector<VoxelKey> keys(packed.size());
  for (size_t i = 0; i < packed.size(); ++i) keys[i] = Unpack(packed[i]);
  return keys;
}

Result<VoxelScene> Voxelize(const SceneInput& input, const VoxelizeOptions& options, const JobContext& ctx) {
  const double r = WorkingResolution(input, options);
  ctx.Report(Stage::kVoxelize, 0.0, "voxelising at " + std::to_string(r) + " m");
  return CatchOutOfMemory("voxelising at " + std::to_string(r) + " m", [&]() -> Result<VoxelScene> {
    VC_ASSIGN_OR_RETURN(std::vector<VoxelKey> occupied, OccupiedKeys(input, r, options.memory_budget_bytes, ctx));
    VC_ASSIGN_OR_RETURN(VoxelScene scene, SceneFromKeys(r, std::move(occupied), options.memory_budget_bytes, ctx));
    scene.scan_origins = input.scan_origins;
    scene.frame_origin_m = input.frame_origin_m;
    return scene;
  });
}

VoxelAccumulator::VoxelAccumulator(double resolution_m, uint64_t memory_budget_bytes)
    : resolution_m_(resolution_m),
      inv_resolution_(1.0 / resolution_m),
      memory_budget_bytes_(memory_budget_bytes),
      status_(CheckResolution(resolution_m)),
      recent_(kRecentSlots, kNoKey),
      lo_m_(Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity())),
      hi_m_(-lo_m_) {
  NotePeak(memory_bytes());
}

uint64_t VoxelAccumulator::memory_bytes() const { return (keys_.capacity() + recent_.capacity()) * sizeof(uint64_t); }

void VoxelAccumulator::Add(const Eigen::Vector3f& p) {
  if (!p.allFinite()) {
    ++dropped_nonfinite_;
    return;
  }
  if (!status_.ok()) return;
  ++points_added_;
  lo_m_ = lo_m_.cwiseMin(p);
  hi_m_ = hi_m_.cwiseMax(p);
  // OctoMap's coordToKey, as OccupiedKeys computes it: floor(u) for u = p * (1/r). In range,
  // floor(u) is int(u) (truncation) minus one where that rounded a negative u up.
  const double ux = inv_resolution_ * double(p.x()), uy = inv_resolution_ * double(p.y()),
               uz = inv_resolution_ * double(p.z());
  if (!(std::min({ux, uy, uz}) >= -kKeyOffset) || !(std::max({ux, uy, uz}) < kKeyOffset)) {
    status_ = CheckExtent(lo_m_.cast<double>(), hi_m_.cast<double>(), resolution_m_, memory_budget_bytes_);
    if (status_.ok()) {
      status_ = InvalidArgumentError("a point lies outside OctoMap's key range at resolution " +
                                     std::to_string(resolution_m_) + " m; use a coarser resolution");
    }
    return;
  }
  auto floor_key = [](double u) {
    const int i = int(u);
    return uint16_t(i - int(u < double(i)) + kKeyOffset);
  };
  const uint64_t key = Pack(VoxelKey{floor_key(ux), floor_key(uy), floor_key(uz)});
  if (key == last_key_) return;
  last_key_ = key;
  uint64_t& recent = recent_[RecentSlot(key)];
  if (recent == key) return;
  recent = key;
  if (keys_.size() == keys_.capacity()) {
    Merge();
    Grow();
    if (!status_.ok()) return;
  }
  keys_.push_back(key);
}

void VoxelAccumulator::Merge() {
  const size_t a = sorted_;
  const auto tail = keys_.begin() + ptrdiff_t(a);
  std::sort(tail, keys_.end());
  const size_t b = size_t(std::unique(tail, keys_.end()) - tail);
  if (a == 0 || b == 0) {
    keys_.resize(a + b);
    sorted_ = a + b;
    return;
  }
  // Merge from the back into [0, a + b): with w - i = j + (duplicates so far) >= j, a write never
  // lands on an unread prefix key. Duplicates leave a gap [i, w) that is closed afterwards.
  const std::vector<uint64_t> scratch(tail, tail + ptrdiff_t(b));
  NotePeak(memory_bytes() + scratch.capacity() * sizeof(uint64_t));
  size_t i = a, j = b, w = a + b;
  while (j > 0) {
    if (i > 0 && keys_[i - 1] >= scratch[j - 1]) {
      if (keys_[i - 1] == scratch[j - 1]) --j;
      keys_[--w] = keys_[--i];
    } else {
      keys_[--w] = scratch[--j];
    }
  }
  std::move(keys_.begin() + ptrdiff_t(w), keys_.begin() + ptrdiff_t(a + b), keys_.begin() + ptrdiff_t(i));
  keys_.resize(i + (a + b - w));
  sorted_ = keys_.size();
}

void VoxelAccumulator::Grow() {
  status_ = CheckExtent(lo_m_.cast<double>(), hi_m_.cast<double>(), resolution_m_, memory_budget_bytes_);
  if (!status_.ok()) return;
  const size_t n = keys_.size(), cap = keys_.capacity();
  // Growing holds the old and the new buffer at once, and a merge holds the buffer and a scratch
  // copy of its tail (no longer than the buffer), so a capacity of half the usable keys keeps
  // both within the budget.
  const uint64_t recent_bytes = recent_.capacity() * sizeof(uint64_t);
  const uint64_t max_cap = memory_budget_bytes_ > recent_bytes ? (memory_budget_bytes_ - recent_bytes) / 16 : 0;
  const size_t room = std::max<size_t>(n / 2, kMinRoom);
  if (cap - n < room && cap < max_cap) {
    const size_t new_cap = size_t(std::min<uint64_t>(std::max(2 * cap, n + room), max_cap));
    std::vector<uint64_t> grown;
    grown.reserve(new_cap);
    grown.assign(keys_.begin(), keys_.end());
    NotePeak(memory_bytes() + grown.capacity() * sizeof(uint64_t));
    keys_.swap(grown);
  }
  if (keys_.capacity() - n >= std::max<size_t>(keys_.capacity() / 16, 1)) return;
  // Full: occupied voxels of surfaces scale about with 1/r^2.
  const Eigen::Vector3f ext = hi_m_ - lo_m_;
  const double need = double(n + n / 16 + 1) * 16 + double(recent_bytes);
  const double factor = std::max(std::sqrt(need / double(std::max<uint64_t>(memory_budget_bytes_, 1)) * 1.25), 1.01);
  std::ostringstream os;
  os.precision(4);
  os << DescribeExtent(ext.cast<double>()) << " has more than " << n << " occupied voxels at resolution "
     << resolution_m_ << " m; streaming their keys needs more than the memory budget of "
     << double(memory_budget_bytes_) / double(1 << 20) << " MiB; use a resolution of at least "
     << std::ceil(resolution_m_ * factor * 1000) / 1000 << " m, raise the budget, or crop the scene";
  status_ = ResourceExhaustedError(os.str());
}

Result<VoxelScene> VoxelAccumulator::Finish(const JobContext& ctx) {
  if (finished_) return FailedPreconditionError("VoxelAccumulator::Finish was already called");
  finished_ = true;
  VC_RETURN_IF_ERROR(status_);
  if (points_added_ == 0) {
    return InvalidArgumentError(dropped_nonfinite_ == 0
                                    ? std::string("the point cloud is empty")
                                    : "the point cloud has no finite point (" + std::to_string(dropped_nonfinite_) +
                                          " non-finite points dropped)");
  }
  VC_RETURN_IF_ERROR(CheckExtent(lo_m_.cast<double>(), hi_m_.cast<double>(), resolution_m_, memory_budget_bytes_));
  ctx.Report(Stage::kVoxelize, 0.0, "voxelising at " + std::to_string(resolution_m_) + " m");
  VC_RETURN_IF_ERROR(ctx.CheckCancelled("voxelisation"));
  Merge();
  std::vector<VoxelKey> occupied(keys_.size());
  for (size_t i = 0; i < occupied.size(); ++i) occupied[i] = Unpack(keys_[i]);
  NotePeak(memory_bytes() + occupied.capacity() * sizeof(VoxelKey));
  std::vector<uint64_t>().swap(keys_);
  std::vector<uint64_t>().swap(recent_);
  sorted_ = 0;
  VC_ASSIGN_OR_RETURN(VoxelScene scene, SceneFromKeys(resolution_m_, std::move(occupied), memory_budget_bytes_, ctx));
  scene.frame_origin_m = frame_origin_m_;
  return scene;
}

}  // namespace vc
