#include "vc/client/did_you_mean.h"

#include <algorithm>
#include <cctype>

namespace vc::client {

size_t EditDistance(std::string_view a, std::string_view b) {
  // d[i][j]: the distance between a's first i characters and b's first j, three rows kept.
  std::vector<size_t> before(b.size() + 1), previous(b.size() + 1), current(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t substitution = previous[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, substitution});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        current[j] = std::min(current[j], before[j - 2] + 1);
      }
    }
    before.swap(previous);
    previous.swap(current);
  }
  return previous[b.size()];
}

std::string NearestName(std::string_view typed, const std::vector<std::string>& known) {
  const size_t allowed = typed.size() <= 4 ? 1 : typed.size() <= 10 ? 2 : 3;
  std::string best;
  size_t best_distance = allowed + 1;
  for (const std::string& name : known) {
    const size_t d = EditDistance(typed, name);
    if (d < best_distance) {
      best_distance = d;
      best = name;
    }
  }
  return best;
}

namespace {

// `command`'s flags and those of its parents (which it falls through to), as "--name".
std::vector<std::string> FlagNames(const CLI::App* command) {
  std::vector<std::string> names;
  for (; command != nullptr; command = command->get_parent()) {
    for (const CLI::Option* option : command->get_options()) {
      for (const std::string& name : option->get_lnames()) names.push_back("--" + name);
    }
  }
  return names;
}

// The option `flag` names for `command` or a parent, or null.
const CLI::Option* FindFlag(const CLI::App* command, const std::string& flag) {
  for (; command != nullptr; command = command->get_parent()) {
    if (const CLI::Option* option = command->get_option_no_throw(flag)) return option;
  }
  return nullptr;
}

const CLI::App* FindSubcommand(const CLI::App* command, const std::string& name) {
  for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; })) {
    if (sub->check_name(name)) return sub;
  }
  return nullptr;
}

std::vector<std::string> SubcommandNames(const CLI::App* command) {
  std::vector<std::string> names;
  for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; })) {
    names.push_back(sub->get_name());
  }
  return names;
}

}  // namespace

std::string CommandLineHint(const CLI::App& app, const std::vector<std::string>& args) {
  const CLI::App* command = &app;
  for (size_t k = 0; k < args.size(); ++k) {
    const std::string& arg = args[k];
    if (arg == "--") break;
    if (arg.starts_with("--")) {
      const size_t equals = arg.find('=');
      const std::string flag = arg.substr(0, equals);
      const CLI::Option* option = FindFlag(command, flag);
      if (option == nullptr) {
        const std::string near = NearestName(flag, FlagNames(command));
        return near.empty() ? "" : "unknown flag " + flag + "; did you mean " + near + "?";
      }
      // A flag that takes a value takes the next word unless it came with '='.
      if (equals == std::string::npos && option->get_expected_min() > 0 && option->get_type_size_max() > 0) ++k;
      continue;
    }
    if (arg.starts_with("-") && arg.size() > 1 && !std::isdigit(static_cast<unsigned char>(arg[1]))) continue;
    if (const CLI::App* sub = FindSubcommand(command, arg)) {
      command = sub;
      continue;
    }
    if (command == &app) {
      const std::string near = NearestName(arg, SubcommandNames(&app));
      return near.empty() ? "" : "unknown command '" + arg + "'; did you mean " + near + "?";
    }
  }
  return "";
}

}  // namespace vc::client
