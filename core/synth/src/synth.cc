// Synthetic scenes (see synth.h for the model and docs/SCENES.md for the scenes themselves).
//
// Sampling. Every face of every box is a candidate surface. Its rectangle is cut into cells by the
// edges of every box that touches its plane, so whether a point of the face lies on the boundary of
// the free space (free on exactly one side) is constant inside a cell and is decided once per cell,
// at the cell's midpoint. Each cell is sampled on its own grid (step <= spacing) that includes the
// cell's borders; a point on a border belongs to the surface if either neighbouring cell does. So
// every edge where a surface ends carries samples, which is what makes the voxelised surface
// watertight. Where two boxes have coplanar faces, the face with the lower index samples the shared
// part. Jitter moves interior grid points within their cell only, never border points.
#include "vc/synth/synth.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <tuple>
#include <utility>

namespace vc {
namespace {

constexpr double kEnvelopeM = 0.3;       // wall thickness around the free space, for the bounds
constexpr double kCorniceM = 0.2;        // cornice (crown moulding) section, m
constexpr double kJitterFraction = 0.1;  // in-plane jitter, fraction of the local grid step
constexpr int kMaxCount = 50;            // largest K of comb:K, hub:K, court:K and atrium:K and N of rooms:N

double Snap(double v) { return std::round(v * 1e6) / 1e6; }  // micrometres: equal edges compare equal

struct Box {
  std::array<double, 3> lo{};
  std::array<double, 3> hi{};
};

Box Cuboid(double x0, double y0, double z0, double x1, double y1, double z1) {
  return Box{{Snap(x0), Snap(y0), Snap(z0)}, {Snap(x1), Snap(y1), Snap(z1)}};
}

// A scene in design coordinates (floor of the ground storey at z = 0, before kSceneOffsetM).
struct Model {
  std::vector<Box> air;       // free space: rooms and openings
  std::vector<bool> is_room;  // air boxes that get a cornice along their walls
  std::vector<Box> solid;     // obstacles inside the free space
  SceneInfo info;             // rooms, floors and bounds still in design coordinates
  // An open site (outdoors): the faces on the air's bounding box (the sky and the site's edges)
  // are not sampled, so only the ground and what stands on it are.
  bool open_site = false;

  void Room(const Box& b) {
    air.push_back(b);
    is_room.push_back(true);
  }
  void Opening(const Box& b) {
    air.push_back(b);
    is_room.push_back(false);
  }
  void Solid(const Box& b) { solid.push_back(b); }
};

// Adds a cornice (kCorniceM x kCorniceM) under the ceiling of each room, along every stretch of
// its vertical sides that is a wall over the cornice's height band (not open to another air box).
// It makes each ceiling layer smaller than the floor below it, so the floor is the dominant
// horizontal layer, and it hides nothing from a station in the room.
void AddCornices(Model& m) {
  const size_t n = m.air.size();
  for (size_t r = 0; r < n; ++r) {
    if (!m.is_room[r]) continue;
    const Box& room = m.air[r];
    const double band_lo = Snap(room.hi[2] - kCorniceM), band_hi = room.hi[2];
    for (int a = 0; a < 2; ++a) {
      const int t = 1 - a;
      for (int side : {-1, 1}) {
        const double c = side > 0 ? room.hi[a] : room.lo[a];
        std::vector<std::pair<double, double>> open;
        for (size_t o = 0; o < n; ++o) {
          if (o == r) continue;
          const Box& b = m.air[o];
          const bool beyond = side > 0 ? (b.lo[a] <= c && c < b.hi[a]) : (b.lo[a] < c && c <= b.hi[a]);
          if (!beyond || b.lo[2] > band_lo || b.hi[2] < band_hi) continue;
          const double lo = std::max(b.lo[t], room.lo[t]), hi = std::min(b.hi[t], room.hi[t]);
          if (lo < hi) open.emplace_back(lo, hi);
        }
        std::sort(open.begin(), open.end());
        double at = room.lo[t];
        auto add_wall = [&](double lo, double hi) {
          if (hi <= lo) return;
          Box s;
          s.lo[a] = side > 0 ? Snap(c - kCorniceM) : c;
          s.hi[a] = side > 0 ? c : Snap(c + kCorniceM);
          s.lo[t] = lo;
          s.hi[t] = hi;
          s.lo[2] = band_lo;
          s.hi[2] = band_hi;
          m.Solid(s);
        };
        for (const auto& [lo, hi] : open) {
          add_wall(at, lo);
          at = std::max(at, hi);
        }
        add_wall(at, room.hi[t]);
      }
    }
  }
}

// ---- The scenes ----------------------------------------------------------------------------

constexpr double kRoomHeightM = 3.0;

Model MakeBox() {
  Model m;
  m.Room(Cuboid(0, 0, 0, 6, 5, kRoomHeightM));
  m.info.description = "one closed room 6 x 5 x 3 m";
  m.info.optimum_stations = 1;
  m.info.rooms = {{{0, 0, 0}, {6, 5, kRoomHeightM}}};
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeLRoom() {
  Model m;
  m.Room(Cuboid(0, 0, 0, 10, 4.5, kRoomHeightM));
  m.Room(Cuboid(0, 0, 0, 4.5, 9, kRoomHeightM));
  m.info.description =
      "L-shaped room, arms 10 x 4.5 and 4.5 x 9 m, 3 m high; one station in the 4.5 x 4.5 m square "
      "where the arms overlap sees everything";
  m.info.optimum_stations = 1;
  m.info.rooms = {{{0, 0, 0}, {4.5, 4.5, kRoomHeightM}}};
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeComb(int k) {
  // Bays of width wb and depth d on a corridor of width wc; a point in the corridor sees a bay's
  // back wall only within wb * wc / d of the bay's mouth, and bays are further apart than twice that.
  constexpr double wc = 2.0, wb = 2.0, d = 5.0, gap = 2.4, end = 1.0;
  constexpr double spread = wb * wc / d;
  Model m;
  const double length = 2 * end + k * wb + (k - 1) * gap;
  m.Room(Cuboid(0, 0, 0, length, wc, kRoomHeightM));
  for (int i = 0; i < k; ++i) {
    const double x = end + i * (wb + gap);
    m.Room(Cuboid(x, wc, 0, x + wb, wc + d, kRoomHeightM));
    m.info.rooms.push_back({{Snap(x - spread), 0, 0}, {Snap(x + wb + spread), wc + d, kRoomHeightM}});
  }
  m.info.description = "corridor 2 m wide with " + std::to_string(k) +
                       " dead-end bays 2 x 5 m, 2.4 m apart; no point sees into two bays";
  m.info.optimum_stations = k;
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeRooms(int n) {
  constexpr double wr = 4.0, dr = 4.0, wc = 2.0, wall = 0.25;
  Model m;
  const double length = n * wr + (n - 1) * wall;
  for (int i = 0; i < n; ++i) {
    const double x = i * (wr + wall);
    m.Room(Cuboid(x, wc + wall, 0, x + wr, wc + wall + dr, kRoomHeightM));
    m.Opening(Cuboid(x + 1.5, wc, 0, x + 2.5, wc + wall, 2.1));  // door 1 x 2.1 m
    m.info.rooms.push_back({{x, wc + wall, 0}, {x + wr, wc + wall + dr, kRoomHeightM}});
  }
  m.Room(Cuboid(0, 0, 0, length, wc, kRoomHeightM));
  m.info.rooms.push_back({{0, 0, 0}, {Snap(length), wc, kRoomHeightM}});
  m.info.description = std::to_string(n) +
                       " closed rooms 4 x 4 m off a 2 m corridor, one door each; every room and "
                       "the corridor need their own station";
  m.info.optimum_stations = n + 1;
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeHub(int k) {
  // A hub hall, 5k x 4.5 m, with k small rooms 4.5 x 3 m on each side (2k rooms), each joined to it
  // by a door 1 x 2.1 m in the 0.25 m wall, centred on the room; north door i at x = 5i + 2.5 faces
  // south door i. A station 0.125 m inside a room, on its door's centre line, sees through the door
  // the whole far half of the hub's 5 m segment in front of it (docs/SCENES.md has the proof).
  constexpr double seg = 5.0, d = 4.5, wall = 0.25, dr = 3.0, wr = 4.5, door = 1.0;
  Model m;
  m.Room(Cuboid(0, 0, 0, k * seg, d, kRoomHeightM));
  for (int i = 0; i < k; ++i) {
    const double x = i * seg + (seg - wr) / 2, xc = i * seg + seg / 2;
    m.Room(Cuboid(x, d + wall, 0, x + wr, d + wall + dr, kRoomHeightM));
    m.Opening(Cuboid(xc - door / 2, d, 0, xc + door / 2, d + wall, 2.1));
    m.Room(Cuboid(x, -wall - dr, 0, x + wr, -wall, kRoomHeightM));
    m.Opening(Cuboid(xc - door / 2, -wall, 0, xc + door / 2, 0, 2.1));
    m.info.rooms.push_back({{x, d + wall, 0}, {x + wr, d + wall + dr, kRoomHeightM}});
    m.info.rooms.push_back({{x, -wall - dr, 0}, {x + wr, -wall, kRoomHeightM}});
  }
  m.info.description = "hub hall " + std::to_string(5 * k) + " x 4.5 m with " + std::to_string(k) +
                       " small rooms 4.5 x 3 m on each side, one 1 m door each; every room needs a station, and one "
                       "just inside its door, on the door's centre line, also sees half the hall";
  m.info.optimum_stations = 2 * k;
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeCourt(int k) {
  // Hub-like, but not hub:K: the hub's 5k x 4.5 m hall and 2k rooms, with each door off its room's
  // centre (north doors 0.75 m west of it, south doors 0.75 m east, so no two face each other), and
  // a room 3 x 3 m at each end of the hall behind a door in the end wall (a door crossed along x,
  // the others along y). A station 0.125 m inside each side door, on its centre line, sees the far
  // half of the hall up to 3.25 m either side (docs/SCENES.md has the proof); the end rooms need
  // one station each, in line with their doors.
  constexpr double seg = 5.0, d = 4.5, wall = 0.25, dr = 3.0, wr = 4.5, door = 1.0, shift = 0.75;
  constexpr double end = 3.0, end_lo = (d - end) / 2;  // end rooms: 3 x 3 m, centred on the hall's width
  Model m;
  m.Room(Cuboid(0, 0, 0, k * seg, d, kRoomHeightM));
  for (int i = 0; i < k; ++i) {
    const double x = i * seg + (seg - wr) / 2, xc = i * seg + seg / 2;
    m.Room(Cuboid(x, d + wall, 0, x + wr, d + wall + dr, kRoomHeightM));
    m.Opening(Cuboid(xc - shift - door / 2, d, 0, xc - shift + door / 2, d + wall, 2.1));
    m.Room(Cuboid(x, -wall - dr, 0, x + wr, -wall, kRoomHeightM));
    m.Opening(Cuboid(xc + shift - door / 2, -wall, 0, xc + shift + door / 2, 0, 2.1));
    m.info.rooms.push_back({{x, d + wall, 0}, {x + wr, d + wall + dr, kRoomHeightM}});
    m.info.rooms.push_back({{x, -wall - dr, 0}, {x + wr, -wall, kRoomHeightM}});
  }
  const double east = k * seg;
  m.Room(Cuboid(-wall - end, end_lo, 0, -wall, end_lo + end, kRoomHeightM));
  m.Opening(Cuboid(-wall, d / 2 - door / 2, 0, 0, d / 2 + door / 2, 2.1));
  m.Room(Cuboid(east + wall, end_lo, 0, east + wall + end, end_lo + end, kRoomHeightM));
  m.Opening(Cuboid(east, d / 2 - door / 2, 0, east + wall, d / 2 + door / 2, 2.1));
  m.info.rooms.push_back({{-wall - end, end_lo, 0}, {-wall, end_lo + end, kRoomHeightM}});
  m.info.rooms.push_back({{east + wall, end_lo, 0}, {east + wall + end, end_lo + end, kRoomHeightM}});
  m.info.description = "court hall " + std::to_string(5 * k) + " x 4.5 m with " + std::to_string(k) +
                       " rooms on each side, doors off-centre and not facing each other, and a room behind "
                       "each end wall; every room needs a station, and one just inside each side door also "
                       "sees half the hall";
  m.info.optimum_stations = 2 * k + 2;
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeTee() {
  // A square hall 6 x 6 m with a room on three sides (north, east, west; none south), each behind
  // a door 1 x 2.1 m centred on its wall: doors crossed along both axes, none facing another. The
  // north room's station just inside its door sees the hall's southern 4.1 m, the east and west
  // ones the strip left along the north wall between them (docs/SCENES.md has the proof): optimum
  // 3, no station in the hall; the 1 m grid alone needs 4.
  constexpr double hall = 6.0, wall = 0.25, depth = 3.0, width = 4.0, door = 1.0;
  constexpr double lo = (hall - width) / 2, d0 = (hall - door) / 2;
  Model m;
  m.Room(Cuboid(0, 0, 0, hall, hall, kRoomHeightM));
  m.Room(Cuboid(lo, hall + wall, 0, lo + width, hall + wall + depth, kRoomHeightM));
  m.Opening(Cuboid(d0, hall, 0, d0 + door, hall + wall, 2.1));
  m.Room(Cuboid(hall + wall, lo, 0, hall + wall + depth, lo + width, kRoomHeightM));
  m.Opening(Cuboid(hall, d0, 0, hall + wall, d0 + door, 2.1));
  m.Room(Cuboid(-wall - depth, lo, 0, -wall, lo + width, kRoomHeightM));
  m.Opening(Cuboid(-wall, d0, 0, 0, d0 + door, 2.1));
  m.info.rooms = {{{lo, hall + wall, 0}, {lo + width, hall + wall + depth, kRoomHeightM}},
                  {{hall + wall, lo, 0}, {hall + wall + depth, lo + width, kRoomHeightM}},
                  {{-wall - depth, lo, 0}, {-wall, lo + width, kRoomHeightM}}};
  m.info.description =
      "square hall 6 x 6 m with a room 4 x 3 m behind a centred 1 m door on three sides (north, east, west); one "
      "station just inside each door sees its room and, together, the hall";
  m.info.optimum_stations = 3;
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeStar(int k) {
  // A square hub 6 x 6 m with k arms (2..4, in the order north, south, east, west), rooms and
  // corridors of different sizes, each behind a door 1 x 2.1 m in the 0.25 m wall at its own
  // position: north at x = 2 (a corridor 2.5 x 7 m), south at x = 3.5 (a room 3.5 x 4 m), east at
  // y = 1.5 (a corridor 6 x 2 m), west at y = 4 (a room 4 x 4 m). The stations just inside the north
  // and south doors see the whole hub between them (docs/SCENES.md has the proof): optimum k.
  constexpr double hub = 6.0, wall = 0.25, door = 1.0;
  struct Arm {
    Box room;
    Box opening;
  };
  const Arm arms[] = {
      {Cuboid(1.0, hub + wall, 0, 3.5, hub + wall + 7.0, kRoomHeightM), Cuboid(1.5, hub, 0, 2.5, hub + wall, 2.1)},
      {Cuboid(2.0, -wall - 4.0, 0, 5.5, -wall, kRoomHeightM), Cuboid(3.0, -wall, 0, 4.0, 0, 2.1)},
      {Cuboid(hub + wall, 0.75, 0, hub + wall + 6.0, 2.75, kRoomHeightM), Cuboid(hub, 1.0, 0, hub + wall, 2.0, 2.1)},
      {Cuboid(-wall - 4.0, 1.5, 0, -wall, 5.5, kRoomHeightM), Cuboid(-wall, 3.5, 0, 0, 4.5, 2.1)},
  };
  static_assert(door == 1.0, "the doors above are 1 m wide");
  Model m;
  m.Room(Cuboid(0, 0, 0, hub, hub, kRoomHeightM));
  for (int i = 0; i < k; ++i) {
    m.Room(arms[i].room);
    m.Opening(arms[i].opening);
    m.info.rooms.push_back({{arms[i].room.lo[0], arms[i].room.lo[1], arms[i].room.lo[2]},
                            {arms[i].room.hi[0], arms[i].room.hi[1], arms[i].room.hi[2]}});
  }
  m.info.description = "square hub 6 x 6 m with " + std::to_string(k) +
                       " arms (rooms and corridors, north, south, east, west) behind 1 m doors at different "
                       "positions; every arm needs a station, and the two just inside the north and south "
                       "doors see the hub";
  m.info.optimum_stations = k;
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeAtrium(int k) {
  // A square atrium 5k x 5k m, 4 m high, with a pier 1.2 x 1.2 m at its centre (floor to ceiling)
  // and k rooms 4.5 x 3 m (3 m high) on each of its four sides, 4k rooms, each behind a door
  // 1 x 2.1 m in the 0.25 m wall, 0.75 m off the room's centre: north doors at x = 5i + 1.75,
  // south doors at x = 5i + 3.25, west doors at y = 5i + 1.75, east doors at y = 5i + 3.25, so the
  // scene is the same turned by 90 degrees about the pier and no door faces another. The stations
  // just inside the doors see the whole atrium around the pier (docs/SCENES.md has the proof):
  // optimum 4k, none in the atrium.
  constexpr double seg = 5.0, wall = 0.25, depth = 3.0, width = 4.5, door = 1.0, shift = 0.75;
  constexpr double atrium_height = 4.0, pier = 1.2;
  const double a = k * seg, mid = a / 2;
  Model m;
  m.Room(Cuboid(0, 0, 0, a, a, atrium_height));
  m.Solid(Cuboid(mid - pier / 2, mid - pier / 2, 0, mid + pier / 2, mid + pier / 2, atrium_height));
  std::vector<AxisBox> north, south, west, east;
  auto add = [&m](std::vector<AxisBox>& rooms, const Box& room, const Box& opening) {
    m.Room(room);
    m.Opening(opening);
    rooms.push_back({{room.lo[0], room.lo[1], room.lo[2]}, {room.hi[0], room.hi[1], room.hi[2]}});
  };
  for (int i = 0; i < k; ++i) {
    const double lo = i * seg + (seg - width) / 2, hi = lo + width;
    const double c_lo = i * seg + seg / 2 - shift, c_hi = i * seg + seg / 2 + shift;  // 5i + 1.75, 5i + 3.25
    add(north, Cuboid(lo, a + wall, 0, hi, a + wall + depth, kRoomHeightM),
        Cuboid(c_lo - door / 2, a, 0, c_lo + door / 2, a + wall, 2.1));
    add(south, Cuboid(lo, -wall - depth, 0, hi, -wall, kRoomHeightM),
        Cuboid(c_hi - door / 2, -wall, 0, c_hi + door / 2, 0, 2.1));
    add(west, Cuboid(-wall - depth, lo, 0, -wall, hi, kRoomHeightM),
        Cuboid(-wall, c_lo - door / 2, 0, 0, c_lo + door / 2, 2.1));
    add(east, Cuboid(a + wall, lo, 0, a + wall + depth, hi, kRoomHeightM),
        Cuboid(a, c_hi - door / 2, 0, a + wall, c_hi + door / 2, 2.1));
  }
  for (const auto* side : {&north, &south, &west, &east}) {
    m.info.rooms.insert(m.info.rooms.end(), side->begin(), side->end());
  }
  m.info.description = "atrium " + std::to_string(5 * k) + " x " + std::to_string(5 * k) +
                       " x 4 m with a central pier and " + std::to_string(k) +
                       " rooms on each of its four sides behind off-centre 1 m doors; every room needs a station, "
                       "and those just inside the doors see the atrium";
  m.info.optimum_stations = 4 * k;
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeTwoFloor() {
  Model m;
  m.Room(Cuboid(0, 0, 0, 8, 6, 3.0));
  m.Room(Cuboid(0, 0, 3.3, 8, 6, 6.3));
  m.Opening(Cuboid(5.0, 0.5, 3.0, 7.5, 2.0, 3.3));  // stair opening 2.5 x 1.5 m in the 0.3 m slab
  m.info.description =
      "two storeys 8 x 6 x 3 m on a 0.3 m slab with a 2.5 x 1.5 m stair opening; one station per "
      "storey, the lower one under the opening";
  m.info.optimum_stations = 2;
  m.info.rooms = {{{0, 0, 0}, {8, 6, 3.0}}, {{0, 0, 3.3}, {8, 6, 6.3}}};
  m.info.floor_heights_m = {0, 3.3};
  return m;
}

Model MakeTwoRooms() {
  // Rooms A and B, 5 x 4 x 3 m, share a 0.25 m wall; the door through it is 0.9 x 2.1 m and 0.3 m
  // from the south wall, so each room sees the other only through a narrow off-centre gap.
  Model m;
  m.Room(Cuboid(0, 0, 0, 5, 4, kRoomHeightM));
  m.Room(Cuboid(5.25, 0, 0, 10.25, 4, kRoomHeightM));
  m.Opening(Cuboid(5, 0.3, 0, 5.25, 1.2, 2.1));  // door 0.9 x 2.1 m
  m.info.description =
      "two closed rooms 5 x 4 x 3 m side by side, joined by one off-centre door 0.9 x 2.1 m; one "
      "station per room, the one in A in line with the door";
  m.info.optimum_stations = 2;
  m.info.rooms = {{{0, 0, 0}, {5, 4, kRoomHeightM}}, {{5.25, 0, 0}, {10.25, 4, kRoomHeightM}}};
  m.info.floor_heights_m = {0};
  return m;
}

Model MakeStairs() {
  // Like twofloor, with a straight flight of 19 treads (20 risers of 0.165 m, going 0.3 m, 1 m
  // wide) along the south wall from the lower floor (z = 0) to the upper floor (z = 3.3), under a
  // slab opening over the whole flight. The lower storey is the main room (y in [1, 6]), a foot
  // bay in front of the flight (x in [0, 1.3], y in [0, 1]) and the stairwell over the flight
  // (x in [1.3, 8], y in [0, 1]; no cornice, so none runs over the steps). The upper storey is 1 m
  // shallower (y in [0, 5]) so that the lower floor stays the largest horizontal layer.
  constexpr double x0 = 1.3, going = 0.3, rise = 0.165;
  constexpr int treads = 19;
  constexpr double top = x0 + treads * going;  // 7.0: the last riser, up to the upper floor
  Model m;
  m.Room(Cuboid(0, 1, 0, 8, 6, 3.0));          // main room of the lower storey
  m.Room(Cuboid(0, 0, 0, x0, 1, 3.0));         // foot of the flight
  m.Opening(Cuboid(x0, 0, 0, 8, 1, 3.0));      // stairwell over the flight
  m.Room(Cuboid(0, 0, 3.3, 8, 5, 6.3));        // upper storey
  m.Opening(Cuboid(x0, 0, 3.0, top, 1, 3.3));  // slab opening 5.7 x 1 m
  for (int k = 1; k <= treads; ++k) {
    m.Solid(Cuboid(x0 + (k - 1) * going, 0, 0, x0 + k * going, 1, k * rise));  // step k, solid to the floor
  }
  m.Solid(Cuboid(top, 0, 0, 8, 1, 3.0));  // under the top landing, up to the slab
  m.info.description =
      "two storeys (8 x 6 and 8 x 5 m, 3 m high, 0.3 m slab) joined by a straight flight of 20 "
      "risers 0.165 m, going 0.3 m, 1 m wide";
  m.info.optimum_stations = 0;
  m.info.rooms = {{{0, 0, 0}, {8, 6, 3.0}}, {{0, 0, 3.3}, {8, 5, 6.3}}};
  m.info.floor_heights_m = {0, 3.3};
  return m;
}

Model MakeSlope() {
  // A site 40 x 30 m rising 4 m along x: 40 terraces 1 m deep, each 0.1 m above the one before
  // (a 1:10 slope, as a voxel staircase), open to the sky. On it two solid buildings with flat
  // roofs and a van, whose tops have free space above them but are not reachable on foot.
  constexpr double kDepth = 1.0, kRise = 0.1, kSky = 12.0;
  constexpr int kTerraces = 40;
  Model m;
  m.open_site = true;
  for (int i = 0; i < kTerraces; ++i) m.Opening(Cuboid(i * kDepth, 0, i * kRise, (i + 1) * kDepth, 30, kSky));
  m.Solid(Cuboid(8, 6, -1, 16, 14, 6.0));    // building A: 8 x 8 m, roof 4.5-5.2 m above the ground
  m.Solid(Cuboid(24, 16, -1, 32, 24, 8.0));  // building B: 8 x 8 m, roof 4.9-5.6 m above the ground
  m.Solid(Cuboid(34, 5, -1, 38.5, 7, 5.6));  // a van 4.5 x 2 m, top 1.8-2.2 m above the ground
  m.info.description =
      "an open site 40 x 30 m rising 4 m along x in 0.1 m terraces 1 m deep, with two 8 x 8 m buildings "
      "(flat roofs) and a van; terrain, optimum unknown";
  m.info.optimum_stations = 0;
  return m;
}

Model MakeHillside() {
  // A site 20 x 14 m rising 4 m along x: 40 terraces 0.5 m deep, each 0.1 m above the one before
  // (a 1:5 slope), open to the sky. A house is cut into it: walls 0.3 m thick round a room
  // 6 x 5.4 m whose floor is the ground outside its downhill wall, where a door 1 m wide and 2.1 m
  // high opens onto the slope; the ground rises beside and behind the house.
  constexpr double kDepth = 0.5, kRise = 0.1, kSky = 10.0, kFloor = 1.5, kCeiling = 4.2, kRoof = 4.5;
  constexpr int kTerraces = 40;
  Model m;
  m.open_site = true;
  for (int i = 0; i < kTerraces; ++i) m.Opening(Cuboid(i * kDepth, 0, i * kRise, (i + 1) * kDepth, 14, kSky));
  m.Opening(Cuboid(8.3, 4.3, kFloor, 14.3, 9.7, kCeiling));  // the room
  m.Opening(Cuboid(8, 6.5, kFloor, 8.3, 7.5, 3.6));          // the door, in the downhill wall
  m.Solid(Cuboid(8, 4, 0, 8.3, 6.5, kRoof));                 // downhill wall, either side of the door
  m.Solid(Cuboid(8, 7.5, 0, 8.3, 10, kRoof));
  m.Solid(Cuboid(8, 6.5, 3.6, 8.3, 7.5, kRoof));  // over the door
  m.Solid(Cuboid(14.3, 4, 0, 14.6, 10, kRoof));   // uphill wall
  m.Solid(Cuboid(8.3, 4, 0, 14.3, 4.3, kRoof));   // side walls
  m.Solid(Cuboid(8.3, 9.7, 0, 14.3, 10, kRoof));
  m.Solid(Cuboid(8.3, 4.3, kCeiling, 14.3, 9.7, kRoof));  // the roof slab
  m.info.description =
      "an open site 20 x 14 m rising 4 m along x in 0.1 m terraces 0.5 m deep, with a house cut into it "
      "whose door opens onto the slope; terrain, optimum unknown";
  m.info.optimum_stations = 0;
  return m;
}

Model MakeHall() {
  Model m;
  // Nave (south), aisle (north, ground level) and gallery above the aisle, split by an arcade
  // wall 0.6 m thick at y in [13.7, 14.3].
  m.Room(Cuboid(0, 0, 0, 40, 13.7, 10));
  m.Room(Cuboid(0, 14.3, 0, 40, 20, 5.0));
  m.Room(Cuboid(0, 14.3, 5.3, 40, 20, 10));
  m.Opening(Cuboid(0, 13.7, 6.3, 40, 14.3, 10));  // above the gallery's 1 m parapet
  // 20 pillars 0.6 x 0.6 m; 21 arches between them, stepped to 4.4 m.
  constexpr int kPillars = 20;
  for (int j = 0; j <= kPillars; ++j) {
    const double xa = j == 0 ? 0.0 : 1.95 + 1.9 * (j - 1) + 0.3;
    const double xb = j == kPillars ? 40.0 : 1.95 + 1.9 * j - 0.3;
    m.Opening(Cuboid(xa, 13.7, 0, xb, 14.3, 3.5));
    m.Opening(Cuboid(xa + 0.15, 13.7, 3.5, xb - 0.15, 14.3, 3.9));
    m.Opening(Cuboid(xa + 0.35, 13.7, 3.9, xb - 0.35, 14.3, 4.2));
    m.Opening(Cuboid(xa + 0.5, 13.7, 4.2, xb - 0.5, 14.3, 4.4));
  }
  // Windows through the 0.3 m outer walls, each opening into a closed well 0.35 m deep that
  // overlaps the window by 0.25 m on every side (so no ray leaves the building).
  auto window_y = [&m](double xc, double z0, double z1, bool north) {
    if (north) {
      m.Opening(Cuboid(xc - 0.6, 20, z0, xc + 0.6, 20.3, z1));
      m.Opening(Cuboid(xc - 0.85, 20.3, z0 - 0.25, xc + 0.85, 20.65, z1 + 0.25));
    } else {
      m.Opening(Cuboid(xc - 0.6, -0.3, z0, xc + 0.6, 0, z1));
      m.Opening(Cuboid(xc - 0.85, -0.65, z0 - 0.25, xc + 0.85, -0.3, z1 + 0.25));
    }
  };
  for (int k = 0; k < 8; ++k) {
    const double xc = 2.5 + 5.0 * k;
    window_y(xc, 3.5, 6.0, false);  // nave, south
    window_y(xc, 1.2, 3.2, true);   // aisle, north
    window_y(xc, 6.8, 8.8, true);   // gallery, north
  }
  m.Opening(Cuboid(-0.3, 5.85, 6.0, 0, 7.85, 8.0));  // west and east windows of the nave, 2 x 2 m
  m.Opening(Cuboid(-0.65, 5.6, 5.75, -0.3, 8.1, 8.25));
  m.Opening(Cuboid(40, 5.85, 6.0, 40.3, 7.85, 8.0));
  m.Opening(Cuboid(40.3, 5.6, 5.75, 40.65, 8.1, 8.25));
  // Nine roof cross-beams 0.4 x 0.5 m under the ceiling, spanning the whole width.
  for (int k = 1; k <= 9; ++k) m.Solid(Cuboid(4.0 * k - 0.2, 0, 9.5, 4.0 * k + 0.2, 20, 10));
  // Fifteen objects: ten pews, an altar, three machines in the aisle, an organ on the gallery.
  for (int k = 0; k < 5; ++k) {
    const double x = 10 + 1.5 * k;
    m.Solid(Cuboid(x, 2.0, 0, x + 0.6, 6.0, 0.9));
    m.Solid(Cuboid(x, 7.5, 0, x + 0.6, 11.5, 0.9));
  }
  m.Solid(Cuboid(34, 5.35, 0, 35.5, 8.35, 1.2));
  m.Solid(Cuboid(6, 16, 0, 8, 18.5, 2.0));
  m.Solid(Cuboid(18, 15.5, 0, 21, 18.5, 1.5));
  m.Solid(Cuboid(28, 17, 0, 29.5, 19.5, 2.5));
  m.Solid(Cuboid(30, 17, 5.3, 33, 19.5, 8.3));
  m.info.description =
      "chapel-like hall 40 x 20 x 10 m: nave, arcade of 20 pillars, aisle with a gallery above, "
      "26 windows, 9 roof beams, 15 objects; benchmark, optimum unknown";
  m.info.optimum_stations = 0;
  m.info.rooms = {{{0, 0, 0}, {40, 13.7, 10}}, {{0, 14.3, 0}, {40, 20, 5.0}}, {{0, 14.3, 5.3}, {40, 20, 10}}};
  m.info.floor_heights_m = {0, 5.3};
  return m;
}

struct SceneKind {
  const char* name;
  bool takes_count;
  int min_count;  // the range of K (takes_count only)
  int max_count;
  const char* summary;  // for ListScenes
  Model (*make)(int);
};

const SceneKind kScenes[] = {
    {"box", false, 0, 0, "one closed room", [](int) { return MakeBox(); }},
    {"lroom", false, 0, 0, "an L-shaped room", [](int) { return MakeLRoom(); }},
    {"comb", true, 1, kMaxCount, "comb:K, a corridor with K dead-end bays", [](int k) { return MakeComb(k); }},
    {"rooms", true, 1, kMaxCount, "rooms:N, N closed rooms off a corridor", [](int n) { return MakeRooms(n); }},
    {"hub", true, 1, kMaxCount, "hub:K, a hub hall with K small rooms on each side", [](int k) { return MakeHub(k); }},
    {"tee", false, 0, 0, "a square hall with a room on three sides", [](int) { return MakeTee(); }},
    {"court", true, 1, kMaxCount,
     "court:K, a hall with K rooms on each side behind off-centre doors and one at each end",
     [](int k) { return MakeCourt(k); }},
    {"star", true, 2, 4, "star:K, a square hub with K arms (2..4) behind doors at different positions",
     [](int k) { return MakeStar(k); }},
    {"atrium", true, 2, kMaxCount,
     "atrium:K, a square atrium with a central pier and K rooms on each of its four sides",
     [](int k) { return MakeAtrium(k); }},
    {"twofloor", false, 0, 0, "two storeys joined by a stair opening", [](int) { return MakeTwoFloor(); }},
    {"tworooms", false, 0, 0, "two rooms joined by one off-centre door", [](int) { return MakeTwoRooms(); }},
    {"stairs", false, 0, 0, "two storeys joined by a straight flight of steps", [](int) { return MakeStairs(); }},
    {"hall", false, 0, 0, "the benchmark hall", [](int) { return MakeHall(); }},
    {"slope", false, 0, 0, "an open sloping site with buildings", [](int) { return MakeSlope(); }},
    {"hillside", false, 0, 0, "a sloping site with a house whose door opens onto the slope",
     [](int) { return MakeHillside(); }},
};

constexpr char kValidSpecs[] =
    "box, lroom, comb:K, rooms:N, hub:K, court:K, tee, star:K, atrium:K, twofloor, tworooms, stairs, hall, slope, "
    "hillside (K, N in 1..50; star:K in 2..4, atrium:K in 2..50)";

Status BadSpec(std::string_view spec, std::string_view why) {
  return InvalidArgumentError("invalid scene '" + std::string(spec) + "' (" + std::string(why) +
                              "); valid scenes: " + kValidSpecs);
}

// Builds the scene `spec` in world coordinates (offset applied to info; boxes stay in design
// coordinates, the offset is added to each point).
Result<Model> BuildModel(std::string_view spec) {
  const size_t colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  for (const SceneKind& kind : kScenes) {
    if (name != kind.name) continue;
    int count = 0;
    if (kind.takes_count) {
      if (colon == std::string_view::npos) return BadSpec(spec, "it needs a count, e.g. " + std::string(name) + ":3");
      const std::string_view digits = spec.substr(colon + 1);
      const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), count);
      if (digits.empty() || ec != std::errc() || ptr != digits.data() + digits.size() || count < kind.min_count ||
          count > kind.max_count) {
        return BadSpec(spec, "the count must be an integer in " + std::to_string(kind.min_count) + ".." +
                                 std::to_string(kind.max_count));
      }
    } else if (colon != std::string_view::npos) {
      return BadSpec(spec, std::string(name) + " takes no count");
    }
    Model m = kind.make(count);
    AddCornices(m);
    SceneInfo& info = m.info;
    info.name = kind.takes_count ? std::string(name) + ":" + std::to_string(count) : std::string(name);
    WorldPoint lo = WorldPoint::Constant(1e300), hi = WorldPoint::Constant(-1e300);
    for (const Box& b : m.air) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], b.lo[a]);
        hi[a] = std::max(hi[a], b.hi[a]);
      }
    }
    info.bounds_min = lo - WorldPoint::Constant(kEnvelopeM) + kSceneOffsetM;
    info.bounds_max = hi + WorldPoint::Constant(kEnvelopeM) + kSceneOffsetM;
    for (AxisBox& r : info.rooms) {
      r.min += kSceneOffsetM;
      r.max += kSceneOffsetM;
    }
    for (double& f : info.floor_heights_m) f += kSceneOffsetM.z();
    return m;
  }
  return BadSpec(spec, "no such name");
}

// ---- Sampling ------------------------------------------------------------------------------

// Samples along one tangent axis of a face: the cell borders, and per sample its coordinate, the
// cells on either side (equal inside a cell), the border it lies on (-1 inside a cell) and its
// jitter amplitude (0 on borders).
struct AxisSamples {
  std::vector<double> borders;
  std::vector<double> coord;
  std::vector<int> cell_lo, cell_hi, border;
  std::vector<double> jitter;
  // Run-length form for counting: cell_lo, cell_hi, border, number of samples.
  std::vector<std::array<int, 4>> runs;
};

AxisSamples MakeAxisSamples(std::vector<double> borders, double spacing, bool with_coords) {
  AxisSamples s;
  std::sort(borders.begin(), borders.end());
  borders.erase(std::unique(borders.begin(), borders.end()), borders.end());
  const int cells = static_cast<int>(borders.size()) - 1;
  for (int k = 0; k <= cells; ++k) {
    const int lo = std::max(k - 1, 0), hi = std::min(k, cells - 1);
    s.runs.push_back({lo, hi, k, 1});
    if (with_coords) {
      s.coord.push_back(borders[k]);
      s.cell_lo.push_back(lo);
      s.cell_hi.push_back(hi);
      s.border.push_back(k);
      s.jitter.push_back(0);
    }
    if (k == cells) break;
    const double len = borders[k + 1] - borders[k];
    const int steps = std::max(1, static_cast<int>(std::ceil(len / spacing - 1e-6)));
    if (steps > 1) s.runs.push_back({k, k, -1, steps - 1});
    if (!with_coords) continue;
    const double step = len / steps;
    for (int i = 1; i < steps; ++i) {
      s.coord.push_back(borders[k] + i * step);
      s.cell_lo.push_back(k);
      s.cell_hi.push_back(k);
      s.border.push_back(-1);
      s.jitter.push_back(kJitterFraction * step);
    }
  }
  s.borders = std::move(borders);
  return s;
}

uint64_t SplitMix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// Uniform in [-1, 1).
double SignedUnit(uint64_t& state) { return static_cast<double>(SplitMix64(state) >> 11) * 0x1.0p-52 - 1.0; }

// Offset used to probe the cells on either side of a border; box coordinates are multiples of
// 1e-6 m (Snap), so this never crosses another border.
constexpr double kProbeM = 1e-7;

class Sampler {
 public:
  Sampler(const Model& m, double spacing) : spacing_(spacing), open_site_(m.open_site) {
    boxes_ = m.air;
    boxes_.insert(boxes_.end(), m.solid.begin(), m.solid.end());
    num_air_ = m.air.size();
    hull_ = m.air.empty() ? Box{} : m.air.front();
    for (const Box& b : m.air) {
      for (int a = 0; a < 3; ++a) {
        hull_.lo[a] = std::min(hull_.lo[a], b.lo[a]);
        hull_.hi[a] = std::max(hull_.hi[a], b.hi[a]);
      }
    }
  }

  // Visits every face; with fn == nullptr only counts.
  uint64_t Run(uint64_t seed, const std::function<void(const Eigen::Vector3f&)>* fn) const {
    uint64_t total = 0;
    for (size_t b = 0; b < boxes_.size(); ++b) {
      for (int a = 0; a < 3; ++a) {
        for (int side = 0; side < 2; ++side) total += Face(b, a, side, seed, fn);
      }
    }
    return total;
  }

 private:
  static size_t FaceIndex(size_t box, int axis, int side) { return box * 6 + axis * 2 + side; }

  static bool InBox(const Box& b, int a, double c, bool plus_side, int u, double um, int v, double vm) {
    const bool across = plus_side ? (b.lo[a] <= c && c < b.hi[a]) : (b.lo[a] < c && c <= b.hi[a]);
    return across && b.lo[u] < um && um < b.hi[u] && b.lo[v] < vm && vm < b.hi[v];
  }

  // Whether face (box, a, side) samples the point q of its plane, where q lies strictly inside one
  // of its cells: q is on the boundary of the free space (free on exactly one side of the plane)
  // and no face with a lower index lies on the same plane over q. `candidates` must hold every box
  // whose closure contains q.
  bool Samples(size_t box, int a, int side, const std::array<double, 3>& q,
               const std::vector<size_t>& candidates) const {
    const Box& f = boxes_[box];
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    const double c = q[a];
    if (!(f.lo[u] < q[u] && q[u] < f.hi[u] && f.lo[v] < q[v] && q[v] < f.hi[v])) return false;
    const size_t face_index = FaceIndex(box, a, side);
    bool air_plus = false, air_minus = false, solid_plus = false, solid_minus = false;
    for (size_t o : candidates) {
      const Box& b = boxes_[o];
      const bool plus = InBox(b, a, c, true, u, q[u], v, q[v]);
      const bool minus = InBox(b, a, c, false, u, q[u], v, q[v]);
      (o < num_air_ ? air_plus : solid_plus) |= plus;
      (o < num_air_ ? air_minus : solid_minus) |= minus;
      if (o != box && (b.lo[a] == c || b.hi[a] == c) && b.lo[u] < q[u] && q[u] < b.hi[u] && b.lo[v] < q[v] &&
          q[v] < b.hi[v] && FaceIndex(o, a, b.hi[a] == c ? 1 : 0) < face_index) {
        return false;  // an earlier coplanar face samples this part
      }
    }
    return (air_plus && !solid_plus) != (air_minus && !solid_minus);
  }

  // Whether a face with a lower index than `face_index` samples the segment of the line
  // {axis line_axis = line_at, axis a = c} whose midpoint along `run_axis` is `mid`. Such a line
  // is where two faces meet; only the lowest-indexed face that samples it keeps its points.
  bool EarlierFaceSamplesLine(size_t face_index, int a, double c, int line_axis, double line_at, int run_axis,
                              double mid, const std::vector<size_t>& near) const {
    std::array<double, 3> q{};
    q[a] = c;
    q[line_axis] = line_at;
    q[run_axis] = mid;
    for (size_t o : near) {
      const Box& y = boxes_[o];
      if (!(y.lo[run_axis] < mid && mid < y.hi[run_axis])) continue;
      // A face of y perpendicular to this one through the line, or coplanar with it and ending there.
      for (const auto& [g, across, at] : {std::tuple{line_axis, a, line_at}, std::tuple{a, line_axis, c}}) {
        for (int side = 0; side < 2; ++side) {
          if ((side ? y.hi[g] : y.lo[g]) != at || FaceIndex(o, g, side) >= face_index) continue;
          for (double d : {-kProbeM, kProbeM}) {
            std::array<double, 3> p = q;
            p[across] += d;
            if (Samples(o, g, side, p, near)) return true;
          }
        }
      }
    }
    return false;
  }

  uint64_t Face(size_t box, int a, int side, uint64_t seed,
                const std::function<void(const Eigen::Vector3f&)>* fn) const {
    const Box& f = boxes_[box];
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    const double c = side ? f.hi[a] : f.lo[a];
    if (open_site_ && (a == 2 ? c == hull_.hi[2] : c == hull_.lo[a] || c == hull_.hi[a])) return 0;
    const size_t face_index = FaceIndex(box, a, side);
    // Boxes touching this face's closed rectangle; their edges cut it into cells.
    std::vector<size_t> near;
    std::vector<double> bu = {f.lo[u], f.hi[u]}, bv = {f.lo[v], f.hi[v]};
    for (size_t o = 0; o < boxes_.size(); ++o) {
      const Box& b = boxes_[o];
      if (b.lo[a] > c || b.hi[a] < c) continue;
      if (b.lo[u] > f.hi[u] || b.hi[u] < f.lo[u] || b.lo[v] > f.hi[v] || b.hi[v] < f.lo[v]) continue;
      near.push_back(o);
      for (double x : {b.lo[u], b.hi[u]}) {
        if (x > f.lo[u] && x < f.hi[u]) bu.push_back(x);
      }
      for (double x : {b.lo[v], b.hi[v]}) {
        if (x > f.lo[v] && x < f.hi[v]) bv.push_back(x);
      }
    }
    const bool with_coords = fn != nullptr;
    const AxisSamples su = MakeAxisSamples(std::move(bu), spacing_, with_coords);
    const AxisSamples sv = MakeAxisSamples(std::move(bv), spacing_, with_coords);
    const int cu = static_cast<int>(su.borders.size()) - 1, cv = static_cast<int>(sv.borders.size()) - 1;
    // Per cell: does this face sample it?
    std::vector<uint8_t> emit(static_cast<size_t>(cu) * cv, 0);
    bool any = false;
    for (int j = 0; j < cv; ++j) {
      for (int i = 0; i < cu; ++i) {
        std::array<double, 3> q{};
        q[a] = c;
        q[u] = 0.5 * (su.borders[i] + su.borders[i + 1]);
        q[v] = 0.5 * (sv.borders[j] + sv.borders[j + 1]);
        const bool e = Samples(box, a, side, q, near);
        emit[static_cast<size_t>(j) * cu + i] = e;
        any |= e;
      }
    }
    if (!any) return 0;
    auto emits = [&](int ulo, int uhi, int vlo, int vhi) {
      return emit[static_cast<size_t>(vlo) * cu + ulo] || emit[static_cast<size_t>(vlo) * cu + uhi] ||
             emit[static_cast<size_t>(vhi) * cu + ulo] || emit[static_cast<size_t>(vhi) * cu + uhi];
    };
    // Border segments (a border crossed with a cell of the other axis) that an earlier face keeps.
    std::vector<uint8_t> skip_u(static_cast<size_t>(cu + 1) * cv, 0), skip_v(static_cast<size_t>(cv + 1) * cu, 0);
    for (int k = 0; k <= cu; ++k) {
      for (int j = 0; j < cv; ++j) {
        if (!emits(std::max(k - 1, 0), std::min(k, cu - 1), j, j)) continue;
        skip_u[static_cast<size_t>(k) * cv + j] = EarlierFaceSamplesLine(
            face_index, a, c, u, su.borders[k], v, 0.5 * (sv.borders[j] + sv.borders[j + 1]), near);
      }
    }
    for (int k = 0; k <= cv; ++k) {
      for (int i = 0; i < cu; ++i) {
        if (!emits(i, i, std::max(k - 1, 0), std::min(k, cv - 1))) continue;
        skip_v[static_cast<size_t>(k) * cu + i] = EarlierFaceSamplesLine(
            face_index, a, c, v, sv.borders[k], u, 0.5 * (su.borders[i] + su.borders[i + 1]), near);
      }
    }
    // Whether the sample with u in (ulo, uhi, border bu) and v in (vlo, vhi, border bv) is kept.
    auto keep = [&](int ulo, int uhi, int bu_k, int vlo, int vhi, int bv_k) {
      if (!emits(ulo, uhi, vlo, vhi)) return false;
      if (bu_k >= 0 && bv_k < 0) return !skip_u[static_cast<size_t>(bu_k) * cv + vlo];
      if (bv_k >= 0 && bu_k < 0) return !skip_v[static_cast<size_t>(bv_k) * cu + ulo];
      return true;
    };
    uint64_t count = 0;
    if (!with_coords) {
      for (const auto& rv : sv.runs) {
        for (const auto& ru : su.runs) {
          if (keep(ru[0], ru[1], ru[2], rv[0], rv[1], rv[2])) count += static_cast<uint64_t>(ru[3]) * rv[3];
        }
      }
      return count;
    }
    uint64_t state = seed ^ (0xD1B54A32D192ED03ULL * (face_index + 1));
    SplitMix64(state);
    Eigen::Vector3d p;
    p[a] = c + kSceneOffsetM[a];
    for (size_t j = 0; j < sv.coord.size(); ++j) {
      for (size_t i = 0; i < su.coord.size(); ++i) {
        if (!keep(su.cell_lo[i], su.cell_hi[i], su.border[i], sv.cell_lo[j], sv.cell_hi[j], sv.border[j])) {
          continue;
        }
        const double ju = SignedUnit(state) * su.jitter[i];
        const double jv = SignedUnit(state) * sv.jitter[j];
        p[u] = su.coord[i] + ju + kSceneOffsetM[u];
        p[v] = sv.coord[j] + jv + kSceneOffsetM[v];
        (*fn)(p.cast<float>());
        ++count;
      }
    }
    return count;
  }

  double spacing_;
  bool open_site_;          // Model::open_site: faces on hull_'s sky and sides are not sampled
  Box hull_;                // bounding box of the air boxes
  std::vector<Box> boxes_;  // air boxes first, then solids
  size_t num_air_ = 0;
};

Result<Model> Prepare(std::string_view spec, const SynthOptions& options) {
  VC_RETURN_IF_ERROR(options.Validate());
  return BuildModel(spec);
}

}  // namespace

Status SynthOptions::Validate() const {
  if (!std::isfinite(spacing_m) || spacing_m < 0.005 || spacing_m > 1.0) {
    return InvalidArgumentError("spacing must be a finite number of metres in [0.005, 1], got " +
                                std::to_string(spacing_m));
  }
  return Status::Ok();
}

std::string ListScenes() {
  std::string out;
  for (const char* spec : {"box", "lroom", "comb:3", "rooms:3", "hub:2", "court:2", "tee", "star:3", "atrium:2",
                           "twofloor", "tworooms", "stairs", "hall", "slope", "hillside"}) {
    Result<SceneInfo> info = DescribeScene(spec);
    if (!info.ok()) continue;
    out += info->name;
    out += std::string(std::max<size_t>(2, 10 - info->name.size()), ' ');
    out += "optimum ";
    out += info->optimum_stations > 0 ? std::to_string(info->optimum_stations) : std::string("unknown");
    out += ": " + info->description + "\n";
  }
  out += std::string("specs: ") + kValidSpecs + "\n";
  return out;
}

Result<SceneInfo> DescribeScene(std::string_view spec) {
  VC_ASSIGN_OR_RETURN(Model m, BuildModel(spec));
  return std::move(m.info);
}

Status ForEachScenePoint(std::string_view spec, const SynthOptions& options,
                         const std::function<void(const Eigen::Vector3f&)>& fn) {
  VC_ASSIGN_OR_RETURN(Model m, Prepare(spec, options));
  Sampler(m, options.spacing_m).Run(options.seed, &fn);
  return Status::Ok();
}

Result<uint64_t> CountScenePoints(std::string_view spec, const SynthOptions& options) {
  VC_ASSIGN_OR_RETURN(Model m, Prepare(spec, options));
  return Sampler(m, options.spacing_m).Run(options.seed, nullptr);
}

Result<std::vector<Eigen::Vector3f>> GenerateScene(std::string_view spec, const SynthOptions& options) {
  VC_ASSIGN_OR_RETURN(Model m, Prepare(spec, options));
  const Sampler sampler(m, options.spacing_m);
  const uint64_t count = sampler.Run(options.seed, nullptr);
  if (count > kMaxGeneratedPoints) {
    return ResourceExhaustedError("scene '" + std::string(spec) + "' at spacing " + std::to_string(options.spacing_m) +
                                  " m has " + std::to_string(count) + " points, more than the " +
                                  std::to_string(kMaxGeneratedPoints) +
                                  " GenerateScene holds in memory; use ForEachScenePoint or WritePlyBinary");
  }
  std::vector<Eigen::Vector3f> points;
  points.reserve(count);
  const std::function<void(const Eigen::Vector3f&)> fn = [&points](const Eigen::Vector3f& p) { points.push_back(p); };
  sampler.Run(options.seed, &fn);
  return points;
}

Status WritePlyBinary(const std::string& path, std::string_view spec, const SynthOptions& options) {
  VC_ASSIGN_OR_RETURN(Model m, Prepare(spec, options));
  const Sampler sampler(m, options.spacing_m);
  const uint64_t count = sampler.Run(options.seed, nullptr);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "wb"), &std::fclose);
  if (!file) {
    return FailedPreconditionError("cannot open '" + path + "' for writing: " + std::strerror(errno));
  }
  const std::string header = "ply\nformat binary_little_endian 1.0\ncomment vc synthetic scene " + std::string(spec) +
                             " spacing " + std::to_string(options.spacing_m) + " seed " + std::to_string(options.seed) +
                             "\nelement vertex " + std::to_string(count) +
                             "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  bool ok = std::fwrite(header.data(), 1, header.size(), file.get()) == header.size();
  std::vector<float> buffer;
  buffer.reserve(3 * 65536);
  auto flush = [&] {
    if (buffer.empty()) return;
    if constexpr (std::endian::native == std::endian::big) {
      for (float& x : buffer) {
        uint32_t bits = std::bit_cast<uint32_t>(x);
        bits = __builtin_bswap32(bits);
        x = std::bit_cast<float>(bits);
      }
    }
    ok = ok && std::fwrite(buffer.data(), sizeof(float), buffer.size(), file.get()) == buffer.size();
    buffer.clear();
  };
  const std::function<void(const Eigen::Vector3f&)> fn = [&](const Eigen::Vector3f& p) {
    buffer.insert(buffer.end(), {p.x(), p.y(), p.z()});
    if (buffer.size() >= 3 * 65536) flush();
  };
  sampler.Run(options.seed, &fn);
  flush();
  ok = (std::fclose(file.release()) == 0) && ok;
  if (!ok) return FailedPreconditionError("cannot write '" + path + "': " + std::strerror(errno));
  return Status::Ok();
}

}  // namespace vc
