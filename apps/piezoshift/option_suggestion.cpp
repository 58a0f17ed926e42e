#include "option_suggestion.hpp"

#include <algorithm>
#include <limits>
#include <string_view>
#include <vector>

#include <fmt/core.h>

namespace piezoshift::app {
namespace {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// "cfg" abbreviates "config": same first letter, every letter in order.
bool abbreviates(std::string_view shorter, std::string_view name) {
  if (shorter.empty() || shorter.size() >= name.size() || shorter[0] != name[0])
    return false;
  std::size_t at = 0;
  for (char c : shorter) {
    at = name.find(c, at);
    if (at == std::string_view::npos)
      return false;
    ++at;
  }
  return true;
}

}  // namespace

std::string option_suggestion(const CLI::App& app, int argc, const char* const* argv) {
  const CLI::App* command = &app;
  for (const CLI::App* s : app.get_subcommands())
    command = s;
  std::vector<std::string> names;
  for (const CLI::Option* o : command->get_options())
    for (const std::string& n : o->get_lnames())
      names.push_back(n);
  for (int i = 1; i < argc; ++i) {
    std::string_view arg = argv[i];
    if (!arg.starts_with("--") || arg.size() == 2)
      continue;
    arg.remove_prefix(2);
    arg = arg.substr(0, arg.find('='));
    if (std::find(names.begin(), names.end(), arg) != names.end())
      continue;
    std::string best;
    std::size_t best_distance = std::numeric_limits<std::size_t>::max();
    for (const std::string& n : names) {
      const std::size_t d = abbreviates(arg, n) ? 1 : edit_distance(arg, n);
      if (d <= 2 && d < best_distance) {
        best = n;
        best_distance = d;
      }
    }
    const std::string where = command == &app ? "piezoshift" : command->get_name();
    if (best.empty())
      return fmt::format("--{} is not an option of {}", arg, where);
    return fmt::format("--{} is not an option of {}: did you mean --{}?", arg, where, best);
  }
  return "";
}

}  // namespace piezoshift::app
