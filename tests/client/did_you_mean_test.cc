// vc/client/did_you_mean.h: the edit distance (transpositions one edit), the nearest name within
// the slip allowance, and the hint for a command line with a misspelt flag or subcommand, from the
// app's own names (flags of the command and its parents, subcommands of the app).
#include "vc/client/did_you_mean.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace vc::client {
namespace {

TEST(EditDistanceTest, CountsInsertionsDeletionsSubstitutionsAndSwaps) {
  EXPECT_EQ(EditDistance("", ""), 0u);
  EXPECT_EQ(EditDistance("submit", "submit"), 0u);
  EXPECT_EQ(EditDistance("sumbit", "submit"), 1u);  // two neighbours swapped
  EXPECT_EQ(EditDistance("--grid-spaceing", "--grid-spacing"), 1u);
  EXPECT_EQ(EditDistance("kitten", "sitting"), 3u);
  EXPECT_EQ(EditDistance("", "abc"), 3u);
  EXPECT_EQ(EditDistance("abc", ""), 3u);
  EXPECT_EQ(EditDistance("ca", "abc"), 3u);  // the optimal string alignment distance, not Damerau's 2
}

TEST(NearestNameTest, OnlyWhatCouldBeASlip) {
  const std::vector<std::string> commands = {"submit", "evaluate", "attach",  "cancel",
                                             "health", "scanners", "inspect", "validate"};
  EXPECT_EQ(NearestName("sumbit", commands), "submit");
  EXPECT_EQ(NearestName("evalute", commands), "evaluate");
  EXPECT_EQ(NearestName("scaners", commands), "scanners");
  EXPECT_EQ(NearestName("plan", commands), "");       // 4 letters: 1 edit at most
  EXPECT_EQ(NearestName("deploy", commands), "");     // nothing near
  EXPECT_EQ(NearestName("ab", {"ac", "ab2"}), "ac");  // the first of equals
}

// A small app shaped like vc-client's: global flags, subcommands with flags and a positional.
struct App {
  CLI::App app{"test"};
  std::string server, file;
  double spacing = 1, range = 1;
  bool tls = false;
  App() {
    app.fallthrough();
    app.require_subcommand(1);
    app.add_option("--server", server);
    app.add_flag("--tls", tls);
    CLI::App* submit = app.add_subcommand("submit");
    submit->add_option("FILE", file);
    submit->add_option("--grid-spacing", spacing);
    submit->add_option("--max-range", range);
    app.add_subcommand("inspect")->add_option("FILE", file);
  }
  std::string Hint(const std::vector<std::string>& args) const { return CommandLineHint(app, args); }
};

TEST(CommandLineHintTest, AMisspeltFlagOfTheCommandOrItsParents) {
  const App a;
  EXPECT_EQ(a.Hint({"submit", "scan.ply", "--grid-spaceing", "2"}),
            "unknown flag --grid-spaceing; did you mean --grid-spacing?");
  EXPECT_EQ(a.Hint({"submit", "--grid-spacing=2", "--max-rnage=5", "scan.ply"}),
            "unknown flag --max-rnage; did you mean --max-range?");
  EXPECT_EQ(a.Hint({"submit", "scan.ply", "--severs", "h:1"}), "unknown flag --severs; did you mean --server?");
  // inspect has no --grid-spacing: nothing near among its flags and the app's.
  EXPECT_EQ(a.Hint({"inspect", "scan.ply", "--grid-spaceing", "2"}), "");
  // A flag's value is not a word to check, negative numbers included.
  EXPECT_EQ(a.Hint({"--server", "sumbit", "submit", "--max-range", "-5", "scan.ply"}), "");
}

TEST(CommandLineHintTest, AMisspeltSubcommand) {
  const App a;
  EXPECT_EQ(a.Hint({"sumbit", "scan.ply"}), "unknown command 'sumbit'; did you mean submit?");
  EXPECT_EQ(a.Hint({"--server", "h:1", "--tls", "inspct", "scan.ply"}),
            "unknown command 'inspct'; did you mean inspect?");
  EXPECT_EQ(a.Hint({"frobnicate"}), "");
  EXPECT_EQ(a.Hint({}), "");
}

}  // namespace
}  // namespace vc::client
