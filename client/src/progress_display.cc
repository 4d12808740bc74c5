#include "vc/client/progress_display.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace vc::client {

void ProgressDisplay::ClearBar() {
  if (tty_ && bar_shown_) {
    std::fputs("\r\033[K", out_);
    bar_shown_ = false;
  }
}

void ProgressDisplay::Uploading(const std::string& source, uint64_t bytes, const std::string& server) {
  Note("uploading " + source + " (" + std::to_string(bytes) + " bytes) to " + server);
}

void ProgressDisplay::Accepted(const std::string& job_id, uint32_t queue_position) {
  Note("job " + job_id + (queue_position == 0 ? " started" : " queued at position " + std::to_string(queue_position)));
}

void ProgressDisplay::Update(const ProgressEvent& e) {
  const double f = std::clamp(e.fraction, 0.0, 1.0);
  if (tty_) {
    constexpr int kWidth = 30;
    const int filled = int(std::lround(f * kWidth));
    std::string bar(size_t(filled), '#');
    bar.append(size_t(kWidth - filled), '-');
    std::string msg = e.message.size() > 40 ? e.message.substr(0, 37) + "..." : e.message;
    std::fprintf(out_, "\r\033[K[%s] %3d%% %-12s %s", bar.c_str(), int(f * 100),
                 std::string(StageName(e.stage)).c_str(), msg.c_str());
    std::fflush(out_);
    bar_shown_ = true;
    return;
  }
  const int quarter = int(f * 4);
  if (e.stage != stage_ || quarter > last_quarter_) {
    std::fprintf(out_, "progress: %-12s %3d%%%s%s\n", std::string(StageName(e.stage)).c_str(), int(f * 100),
                 e.message.empty() ? "" : "  ", e.message.c_str());
    std::fflush(out_);
  }
  if (e.stage != stage_) last_quarter_ = -1;
  stage_ = e.stage;
  last_quarter_ = std::max(last_quarter_, quarter);
}

void ProgressDisplay::Station(const PlannedStation& s, int index) {
  char line[160];
  std::snprintf(line, sizeof line, "%s station %d %s at (%.2f, %.2f, %.2f): +%llu voxels, coverage %.1f%%",
                s.fixed ? "fixed" : "picked", index + 1, s.fixed ? "(already placed)" : "(provisional)", s.position.x(),
                s.position.y(), s.position.z(), static_cast<unsigned long long>(s.marginal_gain),
                100.0 * s.cumulative_coverage);
  Note(line);
}

void ProgressDisplay::FinalStations(const std::vector<PlannedStation>& stations) {
  const double coverage = stations.empty() ? 0.0 : stations.back().cumulative_coverage;
  char line[160];
  size_t fixed = 0;
  for (const PlannedStation& s : stations) fixed += s.fixed ? 1 : 0;
  std::snprintf(line, sizeof line, "final stations: %zu after refinement and reduction, coverage %.1f%%",
                stations.size(), 100.0 * coverage);
  if (fixed > 0) {
    std::snprintf(line + std::strlen(line), sizeof line - std::strlen(line), " (%zu fixed, %zu added)", fixed,
                  stations.size() - fixed);
  }
  Note(line);
}

void ProgressDisplay::Note(const std::string& line) {
  ClearBar();
  std::fprintf(out_, "%s\n", line.c_str());
  std::fflush(out_);
}

void ProgressDisplay::Done() { ClearBar(); }

}  // namespace vc::client
