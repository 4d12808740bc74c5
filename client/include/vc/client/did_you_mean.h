// "did you mean" for vc-client's command line: a misspelt flag or subcommand gets the known name
// nearest to it by edit distance (the optimal string alignment distance: insertions, deletions,
// substitutions and transpositions of two neighbours, one edit each, so `sumbit` is one edit from
// `submit`). Pure functions over the CLI11 app's own names, so a new flag or subcommand is known
// here without a list of its own.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace vc::client {

// The optimal string alignment distance between `a` and `b` (case-sensitive).
[[nodiscard]] size_t EditDistance(std::string_view a, std::string_view b);

// The name in `known` nearest to `typed`, when near enough to be a slip: at most 1 edit for a
// name of up to 4 characters, 2 up to 10, 3 beyond; the first of equals. Empty when none is.
[[nodiscard]] std::string NearestName(std::string_view typed, const std::vector<std::string>& known);

// For a command line `args` (argv without the program) that `app` refused: "did you mean
// --grid-spacing?" for the first flag unknown to the command it was given to (that command's
// flags and its parents'), "did you mean submit?" for a first word that is no subcommand of
// `app`; empty when nothing is unknown or nothing is near.
[[nodiscard]] std::string CommandLineHint(const CLI::App& app, const std::vector<std::string>& args);

}  // namespace vc::client
