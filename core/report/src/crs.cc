#include "vc/report/crs.h"

#include <proj.h>

#include <cmath>
#include <numbers>
#include <utility>

#include "vc/scene/scene_input.h"

namespace vc {
namespace {

struct ContextDeleter {
  void operator()(PJ_CONTEXT* c) const { proj_context_destroy(c); }
};
struct PjDeleter {
  void operator()(PJ* p) const { proj_destroy(p); }
};
using ContextPtr = std::unique_ptr<PJ_CONTEXT, ContextDeleter>;
using PjPtr = std::unique_ptr<PJ, PjDeleter>;

// PROJ's last error message on a context, kept instead of printed to stderr.
struct ErrorLog {
  std::string last;
};
void KeepMessage(void* log, int level, const char* message) {
  if (level <= PJ_LOG_ERROR && message != nullptr) static_cast<ErrorLog*>(log)->last = message;
}

bool IsGeographic(PJ_TYPE t) {
  return t == PJ_TYPE_GEOGRAPHIC_CRS || t == PJ_TYPE_GEOGRAPHIC_2D_CRS || t == PJ_TYPE_GEOGRAPHIC_3D_CRS;
}

// The unit `metres_per_unit` is, as vc-client --units names it; empty when it is none of them.
std::string UnitsName(double metres_per_unit) {
  for (const char* name : {"m", "cm", "mm", "ft", "us-ft"}) {
    if (std::abs(*MetresPerUnit(name) / metres_per_unit - 1) < 1e-12) return name;
  }
  return "";
}

}  // namespace

struct Crs::Proj {
  // Declared first, destroyed last: every PJ below belongs to it.
  ContextPtr context;
  std::unique_ptr<ErrorLog> log = std::make_unique<ErrorLog>();
  PjPtr horizontal;   // the projected CRS
  PjPtr to_wgs84;     // horizontal -> WGS 84 (lon, lat in degrees), axes normalised (easting first)
  PjPtr to_geodetic;  // horizontal -> its own geodetic CRS (lon, lat in degrees), for proj_factors

  // PROJ's message for the last failure, or `fallback`.
  std::string Message(const std::string& fallback) const {
    if (!log->last.empty()) return log->last;
    const int err = proj_context_errno(context.get());
    const char* text = err != 0 ? proj_context_errno_string(context.get(), err) : nullptr;
    return text != nullptr ? text : fallback;
  }
  // `p` normalised to easting/longitude first.
  PjPtr Normalised(PjPtr p) const {
    if (!p) return p;
    PjPtr n(proj_normalize_for_visualization(context.get(), p.get()));
    return n ? std::move(n) : std::move(p);
  }
};

Crs::Crs(CrsInfo info, std::unique_ptr<Proj> proj) : info_(std::move(info)), proj_(std::move(proj)) {}
Crs::Crs(Crs&&) noexcept = default;
Crs& Crs::operator=(Crs&&) noexcept = default;
Crs::~Crs() = default;

Result<Crs> Crs::Create(std::string_view definition) {
  auto proj = std::make_unique<Proj>();
  proj->context.reset(proj_context_create());
  if (!proj->context) return InternalError("PROJ could not create a context");
  PJ_CONTEXT* ctx = proj->context.get();
  proj_log_func(ctx, proj->log.get(), KeepMessage);
  proj_log_level(ctx, PJ_LOG_ERROR);
  const std::string def(definition);
  const std::string quoted = "\"" + def + "\"";

  PjPtr crs(proj_create(ctx, def.c_str()));
  if (!crs) return InvalidArgumentError(quoted + " is not a CRS PROJ knows (" + proj->Message("unknown") + ")");
  if (!proj_is_crs(crs.get())) {
    return InvalidArgumentError(
        quoted + " is not a coordinate reference system but an operation (a PROJ string needs +type=crs)");
  }
  if (proj_get_type(crs.get()) == PJ_TYPE_BOUND_CRS) crs.reset(proj_get_source_crs(ctx, crs.get()));
  if (crs && proj_get_type(crs.get()) == PJ_TYPE_COMPOUND_CRS) crs.reset(proj_crs_get_sub_crs(ctx, crs.get(), 0));
  if (crs && proj_get_type(crs.get()) == PJ_TYPE_BOUND_CRS) crs.reset(proj_get_source_crs(ctx, crs.get()));
  if (!crs) return InvalidArgumentError(quoted + ": PROJ found no horizontal CRS in it (" + proj->Message("") + ")");
  const PJ_TYPE type = proj_get_type(crs.get());
  const char* name = proj_get_name(crs.get());
  const std::string named = quoted + " (" + (name != nullptr ? name : "unnamed") + ")";
  if (IsGeographic(type)) {
    return InvalidArgumentError(named +
                                " is a geographic CRS: its coordinates are degrees of longitude and latitude, not a "
                                "site frame in metres or feet. Give the projected CRS the scan is in (e.g. the UTM "
                                "zone, EPSG:25832 for ETRS89 / UTM zone 32N, or the national grid)");
  }
  if (type != PJ_TYPE_PROJECTED_CRS) {
    return InvalidArgumentError(named +
                                " is not a projected CRS (a geocentric, vertical or local engineering CRS has no "
                                "map projection to longitude and latitude); give the projected CRS the scan is in");
  }

  CrsInfo info;
  info.definition = def;
  info.name = name != nullptr ? name : "";
  const char* authority = proj_get_id_auth_name(crs.get(), 0);
  const char* code = proj_get_id_code(crs.get(), 0);
  if (authority != nullptr && code != nullptr && std::string(authority) == "EPSG") info.epsg = std::atoi(code);
  PjPtr cs(proj_crs_get_coordinate_system(ctx, crs.get()));
  const char* unit_name = nullptr;
  double factor = 0;
  if (!cs ||
      !proj_cs_get_axis_info(ctx, cs.get(), 0, nullptr, nullptr, nullptr, &factor, &unit_name, nullptr, nullptr) ||
      !(factor > 0)) {
    return InvalidArgumentError(named + ": PROJ gives no unit for its axes (" + proj->Message("") + ")");
  }
  info.axis_unit = unit_name != nullptr ? unit_name : "";
  info.metres_per_unit = factor;
  info.units = UnitsName(factor);

  PjPtr wgs84(proj_create(ctx, "EPSG:4326"));
  proj->to_wgs84 =
      proj->Normalised(PjPtr(proj_create_crs_to_crs_from_pj(ctx, crs.get(), wgs84.get(), nullptr, nullptr)));
  PjPtr geodetic(proj_crs_get_geodetic_crs(ctx, crs.get()));
  if (geodetic) {
    proj->to_geodetic =
        proj->Normalised(PjPtr(proj_create_crs_to_crs_from_pj(ctx, crs.get(), geodetic.get(), nullptr, nullptr)));
  }
  if (!proj->to_wgs84 || !proj->to_geodetic) {
    return InvalidArgumentError(named + ": PROJ has no transformation from it to WGS 84 longitude and latitude (" +
                                proj->Message("") + ")");
  }
  proj->horizontal = std::move(crs);
  return Crs(std::move(info), std::move(proj));
}

Result<LonLat> Crs::ToLonLat(double x_m, double y_m) const {
  proj_->log->last.clear();
  proj_errno_reset(proj_->to_wgs84.get());
  const PJ_COORD in = proj_coord(x_m / info_.metres_per_unit, y_m / info_.metres_per_unit, 0, 0);
  const PJ_COORD out = proj_trans(proj_->to_wgs84.get(), PJ_FWD, in);
  if (!std::isfinite(out.lp.lam) || !std::isfinite(out.lp.phi)) {
    return InvalidArgumentError("PROJ cannot place (" + std::to_string(x_m) + ", " + std::to_string(y_m) + ") m of " +
                                info_.name + " on the earth (" + proj_->Message("outside the CRS's area?") + ")");
  }
  return LonLat{out.xy.x, out.xy.y};
}

Result<double> Crs::TrueNorthFromGridNorthRad(double x_m, double y_m) const {
  proj_->log->last.clear();
  const PJ_COORD in = proj_coord(x_m / info_.metres_per_unit, y_m / info_.metres_per_unit, 0, 0);
  const PJ_COORD geodetic_deg = proj_trans(proj_->to_geodetic.get(), PJ_FWD, in);
  if (std::isfinite(geodetic_deg.xy.x) && std::isfinite(geodetic_deg.xy.y)) {
    constexpr double kRadPerDeg = std::numbers::pi / 180;
    const PJ_COORD lp = proj_coord(geodetic_deg.xy.x * kRadPerDeg, geodetic_deg.xy.y * kRadPerDeg, 0, 0);
    const PJ_FACTORS f = proj_factors(proj_->horizontal.get(), lp);
    if (proj_errno(proj_->horizontal.get()) == 0 && std::isfinite(f.meridian_convergence)) {
      return f.meridian_convergence;
    }
    proj_errno_reset(proj_->horizontal.get());
  }
  return InvalidArgumentError("PROJ cannot compute the meridian convergence at (" + std::to_string(x_m) + ", " +
                              std::to_string(y_m) + ") m of " + info_.name + " (" + proj_->Message("") + ")");
}

}  // namespace vc
