#include "vc/client/progress_display.h"

#include <algorithm>
#include <chrono>
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

double SteadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string FormatTimeLeft(double seconds) {
  const auto s = static_cast<long long>(std::llround(std::max(seconds, 0.0)));
  char text[48];
  if (s < 60) {
    std::snprintf(text, sizeof text, "%llds", s);
  } else if (s < 3600) {
    std::snprintf(text, sizeof text, "%lldm%02llds", s / 60, s % 60);
  } else {
    std::snprintf(text, sizeof text, "%lldh%02lldm", s / 3600, (s % 3600) / 60);
  }
  return text;
}

std::string ProgressDisplay::Describe(const ProgressEvent& e, double now) {
  std::string text(StageName(e.stage));
  char part[96];
  if (e.unit.empty()) {
    std::snprintf(part, sizeof part, " %3d%%", int(std::clamp(e.fraction, 0.0, 1.0) * 100));
    text += part;
  } else if (e.total == 0) {
    std::snprintf(part, sizeof part, " %llu %s", static_cast<unsigned long long>(e.done), e.unit.c_str());
    text += part;
  } else {
    std::snprintf(part, sizeof part, " %llu/%llu %s", static_cast<unsigned long long>(e.done),
                  static_cast<unsigned long long>(e.total), e.unit.c_str());
    text += part;
    // The rate since this count was first seen; the time left at that rate.
    const double span = now - first_seconds_;
    if (span >= kMinRateSeconds && e.done > first_done_) {
      const double rate = double(e.done - first_done_) / span;
      std::snprintf(part, sizeof part, rate < 10 ? "  %.1f/s" : "  %.0f/s", rate);
      text += part;
      if (e.done < e.total) text += "  " + FormatTimeLeft(double(e.total - e.done) / rate) + " left";
    }
  }
  if (!e.message.empty()) text += "  " + e.message;
  return text;
}

void ProgressDisplay::Update(const ProgressEvent& e) {
  const double now = now_();
  const double f = std::clamp(e.fraction, 0.0, 1.0);
  // A new stage, or a new count within it, starts a new rate measurement.
  const bool fresh = !started_ || e.stage != stage_ || e.unit != unit_ || e.total != total_ || e.done < first_done_;
  if (fresh) {
    started_ = true;
    stage_ = e.stage;
    unit_ = e.unit;
    total_ = e.total;
    first_seconds_ = now;
    first_done_ = e.done;
  }
  std::string text = Describe(e, now);
  if (tty_) {
    if (text.size() > 90) text = text.substr(0, 87) + "...";  // one line of a narrow terminal
    constexpr int kWidth = 30;
    const int filled = int(std::lround(f * kWidth));
    std::string bar(size_t(filled), '#');
    bar.append(size_t(kWidth - filled), '-');
    std::fprintf(out_, "\r\033[K[%s] %s", bar.c_str(), text.c_str());
    std::fflush(out_);
    bar_shown_ = true;
    return;
  }
  const bool moved = e.done != last_line_done_ || f != last_line_fraction_;
  if (fresh || (moved && now - last_line_seconds_ >= kPlainLineSeconds)) {
    std::fprintf(out_, "progress: %s\n", text.c_str());
    std::fflush(out_);
    last_line_seconds_ = now;
    last_line_done_ = e.done;
    last_line_fraction_ = f;
  }
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
