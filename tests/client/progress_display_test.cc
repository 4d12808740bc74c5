// ProgressDisplay: counts, rate and time left from the server's counted progress; plain lines at
// most every few seconds off a terminal; one redrawn bar on a terminal. A fake clock drives time.
#include "vc/client/progress_display.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace vc::client {
namespace {

// Everything written to a FILE*, read back as a string.
class Captured {
 public:
  Captured() : file_(open_memstream(&buffer_, &size_)) {}
  ~Captured() {
    std::fclose(file_);
    std::free(buffer_);
  }
  std::FILE* file() { return file_; }
  std::string text() {
    std::fflush(file_);
    return std::string(buffer_, size_);
  }

 private:
  char* buffer_ = nullptr;
  size_t size_ = 0;
  std::FILE* file_;
};

ProgressEvent Counted(Stage stage, uint64_t done, uint64_t total, const std::string& unit) {
  return {stage, total > 0 ? double(done) / double(total) : 0.0, "", done, total, unit};
}

TEST(FormatTimeLeft, SecondsMinutesHours) {
  EXPECT_EQ(FormatTimeLeft(0), "0s");
  EXPECT_EQ(FormatTimeLeft(44.6), "45s");
  EXPECT_EQ(FormatTimeLeft(138), "2m18s");
  EXPECT_EQ(FormatTimeLeft(3599.4), "59m59s");
  EXPECT_EQ(FormatTimeLeft(3 * 3600 + 5 * 60 + 59), "3h05m");
  EXPECT_EQ(FormatTimeLeft(-5), "0s");
}

TEST(ProgressDisplay, PlainLinesShowCountsRateAndTimeLeftAtMostEveryFewSeconds) {
  Captured out;
  double now = 100;
  ProgressDisplay d(out.file(), false, [&] { return now; });
  d.Update(Counted(Stage::kVisibility, 0, 858, "candidates"));  // the stage starts: a line
  now += 2;
  d.Update(Counted(Stage::kVisibility, 10, 858, "candidates"));  // 2 s later: too soon
  now += 4;
  d.Update(Counted(Stage::kVisibility, 30, 858, "candidates"));  // 6 s: 5/s, 828 left
  now += 1;
  d.Update(Counted(Stage::kVisibility, 40, 858, "candidates"));  // 1 s after the last line
  EXPECT_EQ(out.text(),
            "progress: visibility 0/858 candidates\n"
            "progress: visibility 30/858 candidates  5.0/s  2m46s left\n");
}

TEST(ProgressDisplay, ANewStageOrCountStartsAFreshRateAndALine) {
  Captured out;
  double now = 0;
  ProgressDisplay d(out.file(), false, [&] { return now; });
  d.Update(Counted(Stage::kVisibility, 0, 100, "candidates"));
  now = 10;
  d.Update(Counted(Stage::kVisibility, 50, 100, "candidates"));  // 5/s, 10 s left
  now = 10.5;
  d.Update(Counted(Stage::kEvaluation, 0, 12, "stations"));  // a new stage: a line at once, no rate yet
  now = 11;
  d.Update(ProgressEvent{Stage::kSelection, 0.5, "coverage 50.0 %", 3, 0, "stations"});  // total unknown
  now = 12;
  d.Update(ProgressEvent{Stage::kRoute, 0.25, "", 0, 0, ""});  // not counted: a percentage
  EXPECT_EQ(out.text(),
            "progress: visibility 0/100 candidates\n"
            "progress: visibility 50/100 candidates  5.0/s  10s left\n"
            "progress: evaluation 0/12 stations\n"
            "progress: selection 3 stations  coverage 50.0 %\n"
            "progress: route  25%\n");
}

TEST(ProgressDisplay, NoRateBeforeASecondOrWithoutProgress) {
  Captured out;
  double now = 0;
  ProgressDisplay d(out.file(), false, [&] { return now; });
  d.Update(Counted(Stage::kVisibility, 5, 100, "candidates"));
  now = 6;
  d.Update(Counted(Stage::kVisibility, 5, 100, "candidates"));  // nothing moved: no line
  now = 7;
  d.Update(ProgressEvent{Stage::kVisibility, 0.06, "", 5, 100, "candidates"});  // the fraction moved, not the count
  EXPECT_EQ(out.text(),
            "progress: visibility 5/100 candidates\n"
            "progress: visibility 5/100 candidates\n");
}

TEST(ProgressDisplay, TerminalRedrawsOneBarWithTheSameText) {
  Captured out;
  double now = 0;
  ProgressDisplay d(out.file(), true, [&] { return now; });
  d.Update(Counted(Stage::kVisibility, 0, 40, "candidates"));
  now = 2;
  d.Update(Counted(Stage::kVisibility, 20, 40, "candidates"));
  d.Note("picked station 1");
  const std::string text = out.text();
  EXPECT_NE(text.find("\r\033[K[###############---------------] visibility 20/40 candidates  10/s  2s left"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("\r\033[Kpicked station 1\n"), std::string::npos) << text;  // the bar is cleared first
}

}  // namespace
}  // namespace vc::client
