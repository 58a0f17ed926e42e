// The plot target: every text a figure carries into gnuplot's script (the file name, the titles,
// the axis labels, a marker's label), as a user's --data or --plot name would, through
// io::check_output_path and io::write_plot_files. The promise (a data file's name with a line
// break once ran a shell command through gnuplot's `system`): no text reaches the command
// stream. Checked against the same figure with every text "x" (an empty one empty): the script and
// the data file have the same lines, none ends in a backslash (gnuplot's line continuation), every
// quoted string ends on its line, and outside quotes and comments each line is the same.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <unistd.h>

#include "entry_points.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/plot.hpp"

namespace piezoshift::fuzz {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> lines_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  std::vector<std::string> lines;
  std::string line;
  while (std::getline(text, line))
    lines.push_back(line);
  return lines;
}

// What gnuplot reads as commands on one line: quoted strings reduced to their quotes, the
// comment dropped. An unterminated string is a finding: it would go on into the next line.
std::string commands_of(const std::string& line) {
  std::string out;
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote == '\'') {  // '' is a quote inside; nothing else is special
      if (c == '\'' && i + 1 < line.size() && line[i + 1] == '\'')
        ++i;
      else if (c == '\'')
        quote = 0, out += c;
    } else if (quote == '"') {
      if (c == '\\')
        ++i;
      else if (c == '"')
        quote = 0, out += c;
    } else if (c == '#') {
      break;
    } else {
      if (c == '\'' || c == '"')
        quote = c;
      out += c;
    }
  }
  if (quote != 0)
    throw std::logic_error("plot: a quoted string does not end on its line: " + line);
  return out;
}

io::Figure figure_of(const std::vector<std::string>& text) {
  const auto field = [&](std::size_t i) { return i < text.size() ? text[i] : std::string("x"); };
  io::Figure f;
  f.title = field(1);
  io::Panel& p = f.panels.emplace_back();
  p.title = field(2);
  p.x_label = field(3);
  p.y_label = field(4);
  const double x[] = {0.0, 1.0};
  p.series.push_back(io::line_series(field(5), x, x));
  io::Marker& m = p.markers.emplace_back();
  m.at = 0.5;
  m.label = field(6);
  return f;
}

void compare(const fs::path& fuzzed, const fs::path& benign, bool script) {
  const std::vector<std::string> a = lines_of(fuzzed);
  const std::vector<std::string> b = lines_of(benign);
  if (a.size() != b.size())
    throw std::logic_error(fmt::format("plot: {} has {} lines, {} with plain text", fuzzed.string(),
                                       a.size(), b.size()));
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!a[i].empty() && a[i].back() == '\\')
      throw std::logic_error("plot: a line ends in a backslash: " + a[i]);
    if (script && commands_of(a[i]) != commands_of(b[i]))
      throw std::logic_error(fmt::format("plot: line {} reads as other commands: {}", i + 1, a[i]));
  }
}

}  // namespace

void plot_input(std::string_view data) {
  static const fs::path dir = [] {
    const fs::path d =
        fs::temp_directory_path() / fmt::format("piezoshift-fuzz-{}-plot", ::getpid());
    fs::create_directories(d);
    return d;
  }();
  // Fields at NUL: the file name, the figure's title, the panel's title, x label, y label, the
  // series' title, the marker's label. A name stays in the scratch folder ('/' -> '_').
  std::vector<std::string> text(1);
  for (const char c : data) {
    if (c == '\0')
      text.emplace_back();
    else
      text.back() += c == '/' && text.size() == 1 ? '_' : c;
  }
  const fs::path stem = dir / text[0];
  const fs::path plain = dir / "x";
  try {
    io::check_output_path(stem, "--plot");
    const io::PlotFiles files = io::write_plot_files(figure_of(text), stem);
    // The same figure with plain texts; an empty one stays empty (it leaves out a line).
    std::vector<std::string> plain_text;
    for (const std::string& t : text)
      plain_text.push_back(t.empty() ? "" : "x");
    const io::PlotFiles reference = io::write_plot_files(figure_of(plain_text), plain);
    compare(files.script, reference.script, true);
    compare(files.data, reference.data, false);
  } catch (const core::InputError&) {
  } catch (const io::PlotError&) {  // a name the file system refuses (too long)
  }
  for (const char* ext : {".gp", ".dat"}) {
    std::error_code ignored;
    fs::remove(fs::path(stem).concat(ext), ignored);
  }
}

}  // namespace piezoshift::fuzz
