// ProgressDisplay: the live progress of a job on a terminal (one redrawn bar with the stage name),
// or plain lines when the output is not a terminal (a line when a stage or its unit of count
// changes, else at most one every kPlainLineSeconds). Where the server counts the work (done of
// total units), the line says so with the rate and the time left, e.g.
// "visibility 412/858 candidates  3.1/s  2m18s left". Not thread-safe (the client calls it from
// one thread).
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "vc/base/progress.h"
#include "vc/plan/planner.h"

namespace vc::client {

// Seconds on a monotonic clock.
using SecondsClock = std::function<double()>;
double SteadySeconds();

// "45s", "2m18s", "3h05m": a time left, to the second below an hour.
std::string FormatTimeLeft(double seconds);

class ProgressDisplay {
 public:
  // Plain lines (not a terminal) come at most this often within one stage.
  static constexpr double kPlainLineSeconds = 5.0;
  // The rate is measured over at least this long before it is shown.
  static constexpr double kMinRateSeconds = 1.0;

  // `tty`: redraw one line in place (use isatty(fileno(out))). `now`: the clock (tests pass theirs).
  ProgressDisplay(std::FILE* out, bool tty, SecondsClock now = SteadySeconds)
      : out_(out), tty_(tty), now_(std::move(now)) {}
  void Uploading(const std::string& source, uint64_t bytes, const std::string& server);
  void Accepted(const std::string& job_id, uint32_t queue_position);
  void Update(const ProgressEvent& e);
  // A provisional pick of the greedy selection (`index` from 0).
  void Station(const PlannedStation& s, int index);
  // The final stations, after refinement and reduction.
  void FinalStations(const std::vector<PlannedStation>& stations);
  void Note(const std::string& line);
  // Ends the bar's line.
  void Done();

 private:
  void ClearBar();
  // The text after the bar: stage, counts, rate, time left, message.
  std::string Describe(const ProgressEvent& e, double now);
  std::FILE* out_;
  bool tty_;
  SecondsClock now_;
  bool bar_shown_ = false;
  // The count being measured: its stage, unit and total, and where it was first seen.
  Stage stage_ = Stage::kUnspecified;
  std::string unit_;
  uint64_t total_ = 0;
  bool started_ = false;
  double first_seconds_ = 0;
  uint64_t first_done_ = 0;
  // Plain lines: when the last one was printed, and what it showed.
  double last_line_seconds_ = 0;
  uint64_t last_line_done_ = 0;
  double last_line_fraction_ = -1;
};

}  // namespace vc::client
