#include "piezoshift/io/plot.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::io {
namespace fs = std::filesystem;
namespace {

// A colour-blind-friendly cycle (the "tab10" palette).
constexpr const char* kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e",
                                    "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};

// Text that must stay on one line of the script or the data file: a line break (or any other
// control character) in a title or a file name would end the comment or string it is in and put
// the rest into gnuplot's command stream, where `system` runs a shell (issue 27).
std::string one_line(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char ch : s)
    out += (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ? ' ' : ch;
  return out;
}

// Text at the end of a comment line: on one line, and not ending in a backslash, which gnuplot
// reads as a line continuation that would take the next line into the comment (the fuzz target
// `plot` found a title ending in one).
std::string comment_end(std::string_view s) {
  std::string out = one_line(s);
  if (!out.empty() && out.back() == '\\')
    out += ' ';
  return out;
}

// gnuplot single-quoted string: '' stands for one quote, and nothing else is special in it
// (a backslash is a backslash); on one line.
std::string gp_quote(std::string_view s) {
  std::string out = "'";
  for (char ch : one_line(s)) {
    if (ch == '\'')
      out += "''";
    else
      out += ch;
  }
  return out + "'";
}

std::string number(double v) {
  if (std::isnan(v))
    return "NaN";
  if (std::isinf(v))
    return v > 0 ? "Inf" : "-Inf";
  return fmt::format("{}", v);
}

fs::path strip_format_extension(fs::path stem) {
  if (stem.extension() == ".png" || stem.extension() == ".svg")
    stem.replace_extension();
  return stem;
}

// The file name a figure's files are named after, or empty when the path names a folder.
bool names_a_file(const fs::path& stem) {
  const fs::path name = stem.filename();
  return !name.empty() && name != "." && name != "..";
}

// Whether a new file can be made in `dir` (an existing folder): tried, because permissions,
// read-only mounts and pseudo file systems (/proc) all say no differently, and root passes
// access(2) where open(2) fails.
std::error_code can_create_in(const fs::path& dir) {
  const fs::path probe = dir / fmt::format(".piezoshift-probe.{}", ::getpid());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0)
    return {errno, std::generic_category()};
  ::close(fd);
  ::unlink(probe.c_str());
  return {};
}

void validate(const Figure& f) {
  if (f.panels.empty())
    throw std::invalid_argument("plot: the figure has no panels");
  if (f.rows < 1 || f.cols < 1 ||
      static_cast<std::size_t>(f.rows) * static_cast<std::size_t>(f.cols) < f.panels.size())
    throw std::invalid_argument(
        fmt::format("plot: a {}x{} grid cannot hold {} panels", f.rows, f.cols, f.panels.size()));
  if (f.width_px < 16 || f.height_px < 16 || f.width_px > 20000 || f.height_px > 20000)
    throw std::invalid_argument("plot: figure size out of [16, 20000] pixels");
  for (const Panel& p : f.panels) {
    if (p.series.empty())
      throw std::invalid_argument(fmt::format("plot: panel '{}' has no series", p.title));
    // The key's position is written into the script as it is (`set key bottom right`): words
    // and numbers only, nothing that could end the command (a line break, `;`, a quote).
    if (p.key.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_"
                                " .,+-") != std::string::npos)
      throw std::invalid_argument(fmt::format("plot: key position '{}' of panel '{}' is not words",
                                              one_line(p.key), one_line(p.title)));
    for (const Series& s : p.series) {
      if (p.x_log) {
        for (const double x : s.x) {
          if (!(x > 0.0))
            throw std::invalid_argument(
                fmt::format("plot: series '{}' of panel '{}' has x = {} on a logarithmic axis",
                            s.title, p.title, x));
        }
      }
      const bool needs_w = s.style == SeriesStyle::kBoxes || s.style == SeriesStyle::kBand;
      if (s.x.empty() || s.x.size() != s.y.size() || (needs_w && s.w.size() != s.x.size()))
        throw std::invalid_argument(
            fmt::format("plot: series '{}' of panel '{}' has {} x, {} y and {} w values", s.title,
                        p.title, s.x.size(), s.y.size(), s.w.size()));
    }
  }
}

std::string style_clause(const Series& s, const std::string& color) {
  const std::string lc = fmt::format("lc rgb {}", gp_quote(color));
  switch (s.style) {
    case SeriesStyle::kLines:
      return fmt::format("using 1:2 with lines lw {} {}", s.line_width, lc);
    case SeriesStyle::kPoints:
      return fmt::format("using 1:2 with points pt 7 ps 0.6 {}", lc);
    case SeriesStyle::kLinesPoints:
      return fmt::format("using 1:2 with linespoints lw {} pt 7 ps 0.6 {}", s.line_width, lc);
    case SeriesStyle::kBoxes:
      return fmt::format("using 1:2:3 with boxes fs solid 0.5 border {}", lc);
    case SeriesStyle::kBand:
      return fmt::format("using 1:2:3 with filledcurves fs transparent solid 0.2 noborder {}", lc);
  }
  return {};
}

std::string range(const std::optional<std::pair<double, double>>& r) {
  return r ? fmt::format("[{}:{}]", number(r->first), number(r->second)) : "[*:*]";
}

// The plot commands, the same for every terminal.
std::string script_body(const Figure& f) {
  std::string b;
  b += fmt::format("set multiplot layout {},{}{}\n", f.rows, f.cols,
                   f.title.empty() ? "" : " title " + gp_quote(f.title));
  int index = 0;
  for (std::size_t pi = 0; pi < f.panels.size(); ++pi) {
    const Panel& p = f.panels[pi];
    b += fmt::format("\n# panel {}\n", pi + 1);
    b += "unset arrow\nunset label\nset grid\n";
    b += fmt::format("set title {}\nset xlabel {}\nset ylabel {}\n", gp_quote(p.title),
                     gp_quote(p.x_label), gp_quote(p.y_label));
    b += p.key == "off" ? "unset key\n" : fmt::format("set key {} opaque\n", p.key);
    b += p.x_log ? "set logscale x\n" : "unset logscale x\n";
    b += fmt::format("set xrange {}\nset yrange {}\n", range(p.x_range), range(p.y_range));
    for (const Marker& m : p.markers) {
      if (m.vertical) {
        b += fmt::format(
            "set arrow from first {0}, graph 0 to first {0}, graph 1 nohead dt 2 lc rgb "
            "'#555555'\n",
            number(m.at));
        if (!m.label.empty())
          b += fmt::format("set label {} at first {}, graph 0.06 offset 0.5,0 tc rgb '#555555'\n",
                           gp_quote(m.label), number(m.at));
      } else {
        b += fmt::format(
            "set arrow from graph 0, first {0} to graph 1, first {0} nohead dt 2 lc rgb "
            "'#555555'\n",
            number(m.at));
        if (!m.label.empty())
          b += fmt::format("set label {} at graph 0.02, first {} offset 0,0.6 tc rgb '#555555'\n",
                           gp_quote(m.label), number(m.at));
      }
    }
    // Bands first so that curves are drawn over them; colours follow the series order.
    std::vector<std::string> clauses(p.series.size());
    std::size_t next_color = 0;
    for (std::size_t si = 0; si < p.series.size(); ++si) {
      const Series& s = p.series[si];
      const std::string color =
          s.color.empty() ? kPalette[next_color++ % std::size(kPalette)] : s.color;
      clauses[si] = fmt::format("datafile index {} {} {}", index + static_cast<int>(si),
                                style_clause(s, color),
                                s.title.empty() ? "notitle" : "title " + gp_quote(s.title));
    }
    std::string plot;
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t si = 0; si < p.series.size(); ++si) {
        if ((p.series[si].style == SeriesStyle::kBand) != (pass == 0))
          continue;
        plot += plot.empty() ? "plot " : ", \\\n     ";
        plot += clauses[si];
      }
    }
    b += plot + "\n";
    index += static_cast<int>(p.series.size());
  }
  b += "unset multiplot\n";
  return b;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out)
    throw PlotError(fmt::format("{}: cannot write: {}", p.string(), std::strerror(errno)));
}

bool is_executable_file(const fs::path& p) {
  struct stat st {};
  return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
}

}  // namespace

std::optional<fs::path> find_gnuplot(std::string_view program) {
  if (program.empty())
    return std::nullopt;
  if (program.find('/') != std::string_view::npos) {
    const fs::path p{std::string(program)};
    return is_executable_file(p) ? std::optional<fs::path>(fs::absolute(p)) : std::nullopt;
  }
  const char* path_env = std::getenv("PATH");
  const std::string path = path_env != nullptr ? path_env : "/usr/local/bin:/usr/bin:/bin";
  std::size_t start = 0;
  while (start <= path.size()) {
    const auto colon = path.find(':', start);
    std::string dir = path.substr(start, colon == std::string::npos ? path.npos : colon - start);
    if (dir.empty())
      dir = ".";
    const fs::path candidate = fs::path(dir) / std::string(program);
    if (is_executable_file(candidate))
      return fs::absolute(candidate);
    if (colon == std::string::npos)
      break;
    start = colon + 1;
  }
  return std::nullopt;
}

void check_output_path(const fs::path& path, std::string_view option) {
  const fs::path stem = strip_format_extension(path);
  const fs::path name = path.filename();
  if (name == ".png" || name == ".svg")  // an extension alone: it would draw ".png.png"
    throw core::InputError(fmt::format("{} {}: has no name before {}; give one, e.g. {}", option,
                                       path.string(), name.string(),
                                       (path.parent_path() / ("figure" + name.string())).string()));
  if (!names_a_file(stem)) {
    const fs::path folder = path.has_filename() ? path : path.parent_path();
    throw core::InputError(fmt::format("{} {}: names a folder; give a file, e.g. {}", option,
                                       path.string(), (folder / "figure.png").string()));
  }
  // The folder is created when the figure is drawn: what must exist now is the nearest folder on
  // its way, and it must take a file.
  fs::path existing = stem.parent_path();
  std::error_code ec;
  while (!existing.empty() && !fs::exists(fs::symlink_status(existing, ec)) &&
         existing != existing.parent_path())
    existing = existing.parent_path();
  if (existing.empty())
    existing = ".";
  if (!fs::is_directory(existing, ec))
    throw core::InputError(
        fmt::format("{} {}: {} is not a folder", option, path.string(), existing.string()));
  if (const std::error_code e = can_create_in(existing))
    throw core::InputError(fmt::format("{} {}: cannot create a file in {}: {}", option,
                                       path.string(), existing.string(), e.message()));
}

PlotFiles write_plot_files(const Figure& figure, const fs::path& stem_in) {
  validate(figure);
  const fs::path stem = strip_format_extension(stem_in);
  if (!names_a_file(stem))
    throw core::InputError(
        fmt::format("plot output {}: names a folder, not a file", stem_in.string()));
  const fs::path dir = stem.parent_path();
  if (!dir.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec)
      throw PlotError(fmt::format("{}: cannot create folder: {}", dir.string(), ec.message()));
  }
  const std::string name = stem.filename().string();
  PlotFiles files;
  files.data = fs::path(stem).concat(".dat");
  files.script = fs::path(stem).concat(".gp");

  std::string data = fmt::format("# piezoshift figure data for {}.gp: one index block per series\n",
                                 one_line(name));
  int index = 0;
  for (std::size_t pi = 0; pi < figure.panels.size(); ++pi) {
    for (const Series& s : figure.panels[pi].series) {
      data += fmt::format("# index {}: panel {}, '{}'\n", index++, pi + 1, one_line(s.title));
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        data += number(s.x[i]) + ' ' + number(s.y[i]);
        if (!s.w.empty())
          data += ' ' + number(s.w[i]);
        data += '\n';
      }
      data += "\n\n";
    }
  }
  write_text(files.data, data);

  const std::string body = script_body(figure);
  std::string script = fmt::format(
      "# piezoshift figure{}{}\n"
      "# Redraw after editing: run `gnuplot {}.gp` in this folder.\n"
      "datafile = {}\n"
      "set encoding utf8\n",
      figure.title.empty() ? "" : ": ", comment_end(figure.title), one_line(name),
      gp_quote(name + ".dat"));
  const std::string size = fmt::format("size {},{}", figure.width_px, figure.height_px);
  if (figure.png) {
    script += fmt::format(
        "\nset terminal pngcairo noenhanced {} font 'Sans,10' background '#ffffff'\n"
        "set output {}\n",
        size, gp_quote(name + ".png"));
    script += body + "set output\n";
  }
  if (figure.svg) {
    script += fmt::format(
        "\nset terminal svg noenhanced {} font 'Sans,10' background '#ffffff'\n"
        "set output {}\n",
        size, gp_quote(name + ".svg"));
    script += body + "set output\n";
  }
  write_text(files.script, script);
  if (figure.png)
    files.png = fs::path(stem).concat(".png");
  if (figure.svg)
    files.svg = fs::path(stem).concat(".svg");
  return files;
}

PlotFiles render(const Figure& figure, const fs::path& stem_in, const PlotOptions& options) {
  const std::optional<fs::path> gnuplot = find_gnuplot(options.gnuplot);
  if (!gnuplot) {
    throw PlotError(fmt::format(
        "cannot draw figures: '{}' not found on PATH (install Debian's gnuplot-nox, e.g. with "
        "scripts/install-deps)",
        options.gnuplot));
  }
  const PlotFiles files = write_plot_files(figure, stem_in);
  const fs::path stem = strip_format_extension(stem_in);
  const fs::path dir = stem.parent_path().empty() ? fs::path(".") : stem.parent_path();
  const std::string name = stem.filename().string();
  const std::string script_name = name + ".gp";
  const std::string log_name = name + ".gnuplot.log";
  for (const auto& out : {files.png, files.svg}) {
    if (out)
      fs::remove(*out);
  }

  // gnuplot runs in the figure's folder so the script's relative names resolve as they will
  // when a user reruns it; its output goes to a log that ends up in the error on failure.
  const std::string dir_s = dir.string();
  const std::string gp_s = gnuplot->string();
  const pid_t pid = ::fork();
  if (pid < 0)
    throw PlotError(fmt::format("cannot start gnuplot: {}", std::strerror(errno)));
  if (pid == 0) {
    if (::chdir(dir_s.c_str()) != 0)
      ::_exit(126);
    const int log = ::open(log_name.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null_in = ::open("/dev/null", O_RDONLY);
    if (log < 0 || null_in < 0)
      ::_exit(126);
    ::dup2(null_in, 0);
    ::dup2(log, 1);
    ::dup2(log, 2);
    ::execl(gp_s.c_str(), gp_s.c_str(), script_name.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR)
      throw PlotError(fmt::format("waiting for gnuplot: {}", std::strerror(errno)));
  }
  const fs::path log_path = dir / log_name;
  const std::string log = read_text(log_path);
  const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!ok) {
    throw PlotError(fmt::format("gnuplot failed on {} ({}):\n{}", (dir / script_name).string(),
                                WIFEXITED(status)
                                    ? fmt::format("exit status {}", WEXITSTATUS(status))
                                    : std::string("killed by a signal"),
                                log));
  }
  for (const auto& out : {files.png, files.svg}) {
    std::error_code ec;
    if (out && (!fs::exists(*out) || fs::file_size(*out, ec) == 0 || ec)) {
      throw PlotError(fmt::format("gnuplot left no output in {} (script {}):\n{}", out->string(),
                                  (dir / script_name).string(), log));
    }
  }
  if (log.empty())
    fs::remove(log_path);  // keep it only when gnuplot had something to say
  return files;
}

Series line_series(std::string title, std::span<const double> x, std::span<const double> y,
                   std::string color) {
  return Series{
      std::move(title), SeriesStyle::kLines, {x.begin(), x.end()}, {y.begin(), y.end()}, {},
      std::move(color)};
}

Series point_series(std::string title, std::span<const double> x, std::span<const double> y,
                    std::string color) {
  return Series{
      std::move(title), SeriesStyle::kPoints, {x.begin(), x.end()}, {y.begin(), y.end()}, {},
      std::move(color)};
}

Series band_series(std::string title, double x_lo, double x_hi, double y_lo, double y_hi,
                   std::string color) {
  return Series{std::move(title), SeriesStyle::kBand, {x_lo, x_hi},
                {y_lo, y_lo},     {y_hi, y_hi},       color.empty() ? "#2ca02c" : std::move(color)};
}

Series histogram_series(std::string title, std::span<const double> values, double bin_width,
                        std::string color) {
  if (values.empty())
    throw std::invalid_argument("histogram: no values");
  if (!(bin_width > 0.0) || !std::isfinite(bin_width))
    throw std::invalid_argument("histogram: bin width must be > 0");
  std::map<long long, double> counts;
  double lo = values[0], hi = values[0];
  for (double v : values) {
    if (!std::isfinite(v))
      throw std::invalid_argument("histogram: non-finite value");
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if ((hi - lo) / bin_width > 10000.0)
    throw std::invalid_argument("histogram: more than 10000 bins; choose a wider bin");
  for (double v : values)
    counts[static_cast<long long>(std::floor(v / bin_width))] += 1.0;
  Series s{std::move(title), SeriesStyle::kBoxes, {}, {}, {}, std::move(color)};
  const long long first = counts.begin()->first;
  const long long last = counts.rbegin()->first;
  for (long long k = first; k <= last; ++k) {
    const auto it = counts.find(k);
    s.x.push_back((static_cast<double>(k) + 0.5) * bin_width);
    s.y.push_back(it == counts.end() ? 0.0 : it->second);
    s.w.push_back(bin_width);
  }
  return s;
}

}  // namespace piezoshift::io
