// All contact with OctoMap lives here.
//
// OctoMap's stream readers trust their input: they recurse without a depth limit, reserve
// whatever a count says and print errors to stderr. So every stream is first walked here, with
// bounds and depth checks and without allocation, and only a stream that passes is handed to
// OctoMap. Scan graphs are parsed here entirely (OctoMap's reader wants an std::ifstream).
#include "vc/scene/octomap_adapter.h"

#include <octomap/AbstractOcTree.h>
#include <octomap/OcTree.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <iostream>
#include <mutex>
#include <sstream>

#include "readers/readers.h"
#include "vc/scene/occupancy_grid.h"

namespace vc {
namespace {

constexpr int kTreeDepth = 16;

struct Header {
  std::string id;
  uint64_t size = 0;
  double res = 0;
  size_t data_offset = 0;
};

// Parses the text header shared by .bt and .ot: a magic first line, comment lines, then
// "id X", "size N", "res R" in any order, up to the line "data".
Result<Header> ParseHeader(std::string_view bytes, std::string_view magic, std::string_view source) {
  auto err = [&](const std::string& m) { return InvalidArgumentError(std::string(source) + ": " + m); };
  if (bytes.substr(0, magic.size()) != magic) {
    return err("not an OctoMap stream: expected it to start with \"" + std::string(magic) + "\"");
  }
  Header h;
  bool have_id = false, have_size = false, have_res = false;
  size_t pos = 0;
  int line_no = 0;
  while (pos < bytes.size() && line_no < 1000) {
    const size_t nl = bytes.find('\n', pos);
    if (nl == std::string_view::npos) break;
    std::string line(bytes.substr(pos, nl - pos));
    pos = nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string token;
    ls >> token;
    if (token == "data") {
      if (!have_id || !have_size || !have_res)
        return err("header line " + std::to_string(line_no) + ": \"data\" before id, size and res");
      h.data_offset = pos;
      return h;
    }
    if (token == "id") {
      have_id = bool(ls >> h.id);
    } else if (token == "size") {
      have_size = bool(ls >> h.size);
    } else if (token == "res") {
      have_res = bool(ls >> h.res);
      if (have_res && (!std::isfinite(h.res) || h.res <= 0 || h.res > 1000)) {
        return err("header line " + std::to_string(line_no) +
                   ": resolution must be a positive number of metres, found " + line);
      }
    } else {
      return err("header line " + std::to_string(line_no) + ": unknown keyword \"" + token + "\"");
    }
  }
  return err("header has no \"data\" line (truncated file?)");
}

// Walks the binary (.bt) node stream: per node two bytes of 2-bit child states
// (01 occupied leaf, 10 free leaf, 11 inner, 00 none), then the inner children in order.
struct BinaryWalker {
  std::string_view data;
  size_t pos = 0;
  uint64_t nodes = 0;
  std::string error;

  bool Node(int depth) {
    if (pos + 2 > data.size()) {
      error =
          "node data ends at byte " + std::to_string(pos) + " of " + std::to_string(data.size()) + " (file truncated?)";
      return false;
    }
    const uint8_t c[2] = {uint8_t(data[pos]), uint8_t(data[pos + 1])};
    pos += 2;
    ++nodes;
    for (int half = 0; half < 2; ++half) {
      for (int i = 0; i < 4; ++i) {
        const int bits = (c[half] >> (2 * i)) & 3;
        if (bits != 0) ++nodes;
        if (bits == 3) {
          if (depth + 1 >= kTreeDepth) {
            error = "an inner node is deeper than OctoMap's 16 levels at byte " + std::to_string(pos);
            return false;
          }
          --nodes;  // counted again when its own record is read
          if (!Node(depth + 1)) return false;
        }
      }
    }
    return true;
  }
};

// Walks the full (.ot) node stream: per node `value_bytes` of payload, one byte of child flags,
// then the children in order.
struct FullWalker {
  std::string_view data;
  size_t value_bytes = 4;
  size_t pos = 0;
  uint64_t nodes = 0;
  std::string error;
  std::string* rewrite = nullptr;  // if set, re-emit as OcTree nodes (float value + flags)

  bool Node(int depth) {
    if (depth > kTreeDepth) {
      error = "the tree is deeper than OctoMap's 16 levels at byte " + std::to_string(pos);
      return false;
    }
    if (pos + value_bytes + 1 > data.size()) {
      error =
          "node data ends at byte " + std::to_string(pos) + " of " + std::to_string(data.size()) + " (file truncated?)";
      return false;
    }
    if (rewrite) rewrite->append(data.substr(pos, sizeof(float)));
    pos += value_bytes;
    const uint8_t children = uint8_t(data[pos++]);
    if (rewrite) rewrite->push_back(char(children));
    ++nodes;
    for (int i = 0; i < 8; ++i) {
      if ((children >> i) & 1) {
        if (!Node(depth + 1)) return false;
      }
    }
    return true;
  }
};

// OctoMap reports through std::cerr (and, for a few errors, fprintf). While OctoMap parses a
// stream we have already validated, its std::cerr chatter ("Reading binary octree type OcTree")
// is swallowed: our own Status carries anything that matters. std::cerr's buffer is
// process-wide, so the swap is serialised; vc itself logs through spdlog, never std::cerr.
class QuietCerr {
 public:
  QuietCerr() : lock_(Mutex()), saved_(std::cerr.rdbuf(sink_.rdbuf())) {}
  ~QuietCerr() { std::cerr.rdbuf(saved_); }
  QuietCerr(const QuietCerr&) = delete;
  QuietCerr& operator=(const QuietCerr&) = delete;

 private:
  static std::mutex& Mutex() {
    static std::mutex mu;
    return mu;
  }
  std::lock_guard<std::mutex> lock_;
  std::ostringstream sink_;
  std::streambuf* saved_;
};

// RESOURCE_EXHAUSTED when a tree of `nodes` nodes would take more than `max_tree_bytes`.
Status CheckTreeSize(uint64_t nodes, uint64_t max_tree_bytes, std::string_view source) {
  if (nodes <= max_tree_bytes / kOctreeNodeBytes) return Status::Ok();
  return ResourceExhaustedError(std::string(source) + ": the OctoMap tree has " + std::to_string(nodes) +
                                " nodes, about " + std::to_string(nodes * kOctreeNodeBytes) +
                                " bytes in memory, more than the limit of " + std::to_string(max_tree_bytes) +
                                " bytes");
}

template <typename T>
bool ReadPod(std::string_view bytes, size_t* pos, T* out) {
  if (*pos + sizeof(T) > bytes.size()) return false;
  std::memcpy(out, bytes.data() + *pos, sizeof(T));
  *pos += sizeof(T);
  return true;
}

}  // namespace

Result<std::shared_ptr<octomap::OcTree>> ReadOctreeBinary(std::string_view bytes, std::string_view source,
                                                          uint64_t max_tree_bytes) {
  VC_ASSIGN_OR_RETURN(Header h, ParseHeader(bytes, "# Octomap OcTree binary file", source));
  if (h.id != "OcTree" && h.id != "ColorOcTree" && h.id != "OcTreeStamped") {
    return InvalidArgumentError(std::string(source) + ": unsupported OctoMap tree type \"" + h.id +
                                "\" (supported: OcTree and its ColorOcTree/OcTreeStamped variants)");
  }
  BinaryWalker walker;
  walker.data = bytes.substr(h.data_offset);
  if (h.size > 0 && !walker.Node(0)) {
    return InvalidArgumentError(std::string(source) + ": corrupt OctoMap binary data: " + walker.error);
  }
  if (walker.nodes != h.size) {  // OctoMap refuses this too, but only on stderr
    return InvalidArgumentError(std::string(source) + ": the header declares size " + std::to_string(h.size) +
                                " but the node data holds " + std::to_string(walker.nodes) +
                                " nodes; header and data do not match (corrupt file?)");
  }
  VC_RETURN_IF_ERROR(CheckTreeSize(walker.nodes, max_tree_bytes, source));
  // Re-emit a canonical header (the .bt node data is the same for every occupancy tree type).
  std::ostringstream header;
  header.precision(17);
  header << "# Octomap OcTree binary file\nid OcTree\nsize " << h.size << "\nres " << h.res << "\ndata\n";
  std::istringstream stream{header.str() + std::string(bytes.substr(h.data_offset))};
  auto tree = std::make_shared<octomap::OcTree>(h.res);
  QuietCerr quiet;
  if (!tree->readBinary(stream)) {
    return InvalidArgumentError(std::string(source) + ": OctoMap could not read the binary tree");
  }
  return tree;
}

Result<std::shared_ptr<octomap::OcTree>> ReadOctreeText(std::string_view bytes, std::string_view source,
                                                        uint64_t max_tree_bytes) {
  VC_ASSIGN_OR_RETURN(Header h, ParseHeader(bytes, "# Octomap OcTree file", source));
  size_t value_bytes = 0;
  if (h.id == "OcTree")
    value_bytes = 4;
  else if (h.id == "ColorOcTree")
    value_bytes = 4 + 3;
  else if (h.id == "OcTreeStamped")
    value_bytes = 4 + 4;
  else {
    return InvalidArgumentError(std::string(source) + ": unsupported OctoMap tree type \"" + h.id +
                                "\" (supported: OcTree, ColorOcTree, OcTreeStamped)");
  }
  std::string rewritten;
  FullWalker walker;
  walker.data = bytes.substr(h.data_offset);
  walker.value_bytes = value_bytes;
  if (h.id != "OcTree") walker.rewrite = &rewritten;
  if (h.size > 0 && !walker.Node(0)) {
    return InvalidArgumentError(std::string(source) + ": corrupt OctoMap tree data: " + walker.error);
  }
  VC_RETURN_IF_ERROR(CheckTreeSize(walker.nodes, max_tree_bytes, source));
  std::string stream_text;
  if (h.id == "OcTree") {
    stream_text = std::string(bytes);
  } else {
    // Re-emit as a plain OcTree stream: occupancy is all vc uses.
    std::ostringstream os;
    os.precision(17);
    os << "# Octomap OcTree file\nid OcTree\nsize " << walker.nodes << "\nres " << h.res << "\ndata\n";
    stream_text = os.str() + rewritten;
  }
  std::istringstream stream(stream_text);
  QuietCerr quiet;
  std::unique_ptr<octomap::AbstractOcTree> tree(octomap::AbstractOcTree::read(stream));
  auto* oc = dynamic_cast<octomap::OcTree*>(tree.get());
  if (oc == nullptr) {
    return InvalidArgumentError(std::string(source) + ": OctoMap could not read the tree");
  }
  tree.release();
  return std::shared_ptr<octomap::OcTree>(oc);
}

Result<ScanGraphData> ReadScanGraph(std::string_view bytes, std::string_view source, double metres_per_unit) {
  auto err = [&](size_t pos, const std::string& m) {
    return InvalidArgumentError(std::string(source) + ": scan graph, byte " + std::to_string(pos) + ": " + m);
  };
  size_t pos = 0;
  uint32_t nodes = 0;
  if (!ReadPod(bytes, &pos, &nodes)) return err(0, "too short for a scan graph");
  // Each node needs at least a point count, a pose (4+24 + 4+32 bytes) and an id.
  constexpr size_t kMinNode = 4 + 28 + 36 + 4;
  if (nodes == 0) return err(0, "the graph has no scans");
  if (uint64_t(nodes) * kMinNode > bytes.size()) {
    return err(0, "declares " + std::to_string(nodes) + " scans but holds only " + std::to_string(bytes.size()) +
                      " bytes (not a scan graph, or truncated)");
  }
  ScanGraphData out;
  readers::LocalFrame frame(metres_per_unit);
  auto read_vec = [&](int n, double* v) {
    int32_t count = 0;
    if (!ReadPod(bytes, &pos, &count)) return false;
    if (count != n) return false;
    for (int i = 0; i < n; ++i) {
      if (!ReadPod(bytes, &pos, &v[i])) return false;
    }
    return true;
  };
  // OctoMap's ScanNode::writeBinary: the scan's points (uint32 count, then per point an int32 3
  // and 3 doubles), then the pose (int32 3 + 3 doubles, int32 4 + 4 doubles: w x y z), then the id.
  for (uint32_t n = 0; n < nodes; ++n) {
    const size_t node_pos = pos;
    uint32_t count = 0;
    if (!ReadPod(bytes, &pos, &count))
      return err(pos, "scan " + std::to_string(n) + ": truncated before its point count");
    constexpr size_t kPoint = 4 + 3 * sizeof(double);
    if (uint64_t(count) * kPoint > bytes.size() - pos) {
      return err(pos, "scan " + std::to_string(n) + " declares " + std::to_string(count) + " points but only " +
                          std::to_string((bytes.size() - pos) / kPoint) + " fit in the rest of the file (truncated?)");
    }
    std::vector<Eigen::Vector3d> local(count);
    for (uint32_t i = 0; i < count; ++i) {
      double p[3];
      if (!read_vec(3, p))
        return err(pos, "scan " + std::to_string(n) + ", point " + std::to_string(i) + ": malformed");
      // In double, as written: OctoMap writes its float points as doubles, so this is exact for its
      // files and keeps the precision of a graph written in world (survey) coordinates.
      local[i] = Eigen::Vector3d{p[0], p[1], p[2]};
    }
    double t[3], q[4];
    uint32_t id = 0;
    if (!read_vec(3, t) || !read_vec(4, q)) {
      return err(pos, "scan " + std::to_string(n) + ": malformed pose (expected 3 + 4 doubles after its points)");
    }
    if (!ReadPod(bytes, &pos, &id)) return err(pos, "scan " + std::to_string(n) + ": truncated before its id");
    for (double v : t) {
      if (!std::isfinite(v)) return err(node_pos, "scan " + std::to_string(n) + ": non-finite origin");
    }
    Eigen::Quaterniond rot(q[0], q[1], q[2], q[3]);
    if (!std::isfinite(rot.norm()) || rot.norm() < 1e-9) {
      return err(node_pos, "scan " + std::to_string(n) + ": invalid rotation quaternion");
    }
    rot.normalize();
    const Eigen::Vector3d trans(t[0], t[1], t[2]);
    out.origins.push_back(trans * metres_per_unit);
    out.origin_rotations.push_back(rot);
    out.points.reserve(out.points.size() + count);
    for (const Eigen::Vector3d& l : local) {
      const Eigen::Vector3d w = rot * l + trans;
      if (const std::optional<Eigen::Vector3f> p = frame.ToLocal(w.x(), w.y(), w.z())) {
        out.points.push_back(*p);
      } else {
        ++out.dropped_nonfinite;
      }
    }
  }
  out.frame_origin_m = frame.origin_m();
  // Edges (uint32 count, then per edge two ids, a pose and a weight) follow; vc does not use them.
  return out;
}

double OctreeResolution(const octomap::OcTree& tree) { return tree.getResolution(); }

bool IsKnownFree(const octomap::OcTree& tree, const WorldPoint& p) {
  const octomap::OcTreeNode* node = tree.search(p.x(), p.y(), p.z());
  return node != nullptr && !tree.isNodeOccupied(node);
}

size_t CountOccupiedLeaves(const octomap::OcTree& tree) {
  size_t n = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (tree.isNodeOccupied(*it)) ++n;
  }
  return n;
}

void ForEachOccupiedLeaf(const octomap::OcTree& tree,
                         const std::function<void(const WorldPoint& min_corner, double edge_m)>& fn) {
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const double size = it.getSize();
    // The leaf's cube from its key and depth, exactly (not from the float centre).
    const octomap::OcTreeKey key = it.getIndexKey();
    const double r = tree.getResolution();
    fn(WorldPoint((int(key[0]) - kKeyOffset) * r, (int(key[1]) - kKeyOffset) * r, (int(key[2]) - kKeyOffset) * r),
       size);
  }
}

void OccupiedBoundingBox(const octomap::OcTree& tree, WorldPoint* min, WorldPoint* max) {
  *min = WorldPoint::Constant(std::numeric_limits<double>::infinity());
  *max = WorldPoint::Constant(-std::numeric_limits<double>::infinity());
  ForEachOccupiedLeaf(tree, [&](const WorldPoint& lo, double edge) {
    *min = min->cwiseMin(lo);
    *max = max->cwiseMax(lo + WorldPoint::Constant(edge));
  });
}

std::shared_ptr<octomap::OcTree> BuildOctree(double resolution_m, const std::vector<VoxelKey>& occupied) {
  auto tree = std::make_shared<octomap::OcTree>(resolution_m);
  const float occ = tree->getClampingThresMaxLog();
  for (const VoxelKey& k : occupied) tree->setNodeValue(octomap::OcTreeKey(k.x, k.y, k.z), occ, true);
  tree->updateInnerOccupancy();
  tree->prune();
  return tree;
}

CastRayOutcome OctomapCastRay(const octomap::OcTree& tree, const WorldPoint& origin, const Eigen::Vector3d& direction,
                              double max_range_m) {
  octomap::point3d end;
  CastRayOutcome out;
  const bool hit = tree.castRay(octomap::point3d(float(origin.x()), float(origin.y()), float(origin.z())),
                                octomap::point3d(float(direction.x()), float(direction.y()), float(direction.z())), end,
                                /*ignoreUnknownCells=*/true, max_range_m);
  if (hit) {
    octomap::OcTreeKey k = tree.coordToKey(end);
    out.kind = CastRayOutcome::Kind::kHitOccupied;
    out.hit = {k[0], k[1], k[2]};
  }
  return out;
}

}  // namespace vc
