#include "piezoshift/io/plot.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"

namespace piezoshift::io {
namespace fs = std::filesystem;
namespace {

// The house style (plot.hpp). Colours: the Okabe-Ito palette (M. Okabe and K. Ito, "Color
// Universal Design", 2008; https://jfly.uni-koeln.de/color/), which stays apart for the common
// colour-vision deficiencies; its yellow is left out (unreadable on white). Each series also
// takes a dash pattern and a point shape of its own, so the cycle survives greyscale printing.
constexpr const char* kPalette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                    "#E69F00", "#56B4E9", "#000000"};
constexpr const char* kDashes[] = {"solid",      "(8,4)", "(2,3)",
                                   "(10,3,2,3)", "(4,4)", "(12,3,3,3,3,3)"};
constexpr int kPointTypes[] = {7, 5, 9, 13, 11, 15};  // filled circle, square, triangles, diamond
constexpr const char* kFont = "Sans";
constexpr int kFontPt = 10;
constexpr const char* kMarkerColor = "#404040";
// Bands (tolerances) in a neutral green-grey so that they never read as one of the series.
constexpr const char* kBandColor = "#009E73";

// Text that must stay on one line of the script or the data file: a line break (or any other
// control character) in a title or a file name would end the comment or string it is in and put
// the rest into gnuplot's command stream, where `system` runs a shell.
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
  if (!(f.png_scale >= 0.25 && f.png_scale <= 8.0) ||
      f.png_scale * std::max(f.width_px, f.height_px) > 20000.0)
    throw std::invalid_argument("plot: png_scale out of [0.25, 8] or a PNG over 20000 pixels");
  for (const Panel& p : f.panels) {
    if (p.series.empty())
      throw std::invalid_argument(fmt::format("plot: panel '{}' has no series", p.title));
    for (const Label& l : p.labels) {
      if (l.align != "left" && l.align != "center" && l.align != "right")
        throw std::invalid_argument(fmt::format("plot: label '{}' of panel '{}' aligns '{}'",
                                                one_line(l.text), one_line(p.title),
                                                one_line(l.align)));
    }
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
      if (!s.dash.empty() && s.dash != "solid" &&
          s.dash.find_first_not_of("0123456789.,() ") != std::string::npos)
        throw std::invalid_argument(fmt::format("plot: dash '{}' of series '{}' is not a pattern",
                                                one_line(s.dash), s.title));
      const bool needs_w = s.style == SeriesStyle::kBoxes || s.style == SeriesStyle::kBand ||
                           s.style == SeriesStyle::kImage;
      if (s.x.empty() || s.x.size() != s.y.size() || (needs_w && s.w.size() != s.x.size()))
        throw std::invalid_argument(
            fmt::format("plot: series '{}' of panel '{}' has {} x, {} y and {} w values", s.title,
                        p.title, s.x.size(), s.y.size(), s.w.size()));
    }
  }
}

// What the cycle gives series number k of a panel: colour, dash and point shape together.
struct CycleStyle {
  std::string color;
  std::string dash;
  int point_type;
};

CycleStyle cycle_style(const Series& s, std::size_t k) {
  const std::size_t n = std::size(kPalette);
  CycleStyle c{s.color.empty() ? kPalette[k % n] : s.color,
               s.dash.empty() ? kDashes[k % std::size(kDashes)] : s.dash,
               kPointTypes[k % std::size(kPointTypes)]};
  return c;
}

std::string dash_clause(const std::string& dash) {
  return dash == "solid" ? "dt solid" : "dt " + dash;
}

std::string style_clause(const Series& s, const CycleStyle& c) {
  const std::string lc = fmt::format("lc rgb {}", gp_quote(c.color));
  switch (s.style) {
    case SeriesStyle::kLines:
      return fmt::format("using 1:2 with lines lw {} {} {}", s.line_width, dash_clause(c.dash), lc);
    case SeriesStyle::kPoints:
      return fmt::format("using 1:2 with points pt {} ps 0.7 {}", c.point_type, lc);
    case SeriesStyle::kLinesPoints:
      return fmt::format("using 1:2 with linespoints lw {} {} pt {} ps 0.7 {}", s.line_width,
                         dash_clause(c.dash), c.point_type, lc);
    case SeriesStyle::kBoxes:
      // The colour before the fill style colours the fill, the one after it the border.
      return fmt::format("using 1:2:3 with boxes {0} fs solid 0.45 border {0}", lc);
    case SeriesStyle::kBand:
      return fmt::format("using 1:2:3 with filledcurves fs transparent solid 0.25 noborder {}", lc);
    case SeriesStyle::kImage:
      return "using 1:2:3 with image";
  }
  return {};
}

std::string range(const std::optional<std::pair<double, double>>& r) {
  return r ? fmt::format("[{}:{}]", number(r->first), number(r->second)) : "[*:*]";
}

// Dashed reference lines with their labels on an opaque box, in front of the data.
std::string marker_commands(const Panel& p) {
  std::string b;
  for (const Marker& m : p.markers) {
    const std::string at = number(m.at);
    const std::string along = number(m.label_at);
    if (m.vertical) {
      b += fmt::format(
          "set arrow from first {0}, graph 0 to first {0}, graph 1 nohead dt (6,4) lw 1.2 lc rgb "
          "'{1}' front\n",
          at, kMarkerColor);
      if (!m.label.empty())
        b +=
            fmt::format("set label {} at first {}, graph {} offset 0.6,0 tc rgb '{}' boxed front\n",
                        gp_quote(m.label), at, along, kMarkerColor);
    } else {
      b += fmt::format(
          "set arrow from graph 0, first {0} to graph 1, first {0} nohead dt (6,4) lw 1.2 lc rgb "
          "'{1}' front\n",
          at, kMarkerColor);
      if (!m.label.empty())
        b +=
            fmt::format("set label {} at graph {}, first {} offset 0,0.7 tc rgb '{}' boxed front\n",
                        gp_quote(m.label), along, at, kMarkerColor);
    }
  }
  for (const Label& l : p.labels) {
    b += fmt::format("set label {} at {} {}, {} {} {} boxed front\n", gp_quote(l.text),
                     l.data_coords ? "first" : "graph", number(l.x),
                     l.data_coords ? "first" : "graph", number(l.y), l.align);
  }
  return b;
}

// The plot command of one panel: bands first so the curves are drawn over their fill, then the
// curves, then the bands' edges over the curves (a band hidden under data is no band).
std::string plot_command(const Panel& p, int first_index) {
  std::vector<std::string> fills, curves, edges;
  std::size_t next = 0;
  for (std::size_t si = 0; si < p.series.size(); ++si) {
    const Series& s = p.series[si];
    const int index = first_index + static_cast<int>(si);
    CycleStyle c;
    if (s.style == SeriesStyle::kBand || s.style == SeriesStyle::kImage)
      c = {s.color.empty() ? kBandColor : s.color, "(4,3)", 7};
    else
      c = cycle_style(s, next++);
    const std::string clause =
        fmt::format("datafile index {} {} {}", index, style_clause(s, c),
                    s.title.empty() ? "notitle" : "title " + gp_quote(s.title));
    if (s.style == SeriesStyle::kBand) {
      fills.push_back(clause);
      for (const char* col : {"2", "3"})
        edges.push_back(
            fmt::format("datafile index {} using 1:{} with lines lw 1 dt (4,3) lc rgb {} notitle",
                        index, col, gp_quote(c.color)));
    } else {
      curves.push_back(clause);
    }
  }
  std::string plot;
  for (const auto* group : {&fills, &curves, &edges}) {
    for (const std::string& clause : *group) {
      plot += plot.empty() ? "plot " : ", \\\n     ";
      plot += clause;
    }
  }
  return plot + "\n";
}

// The settings one panel changes, reset for each panel of a multiplot.
std::string panel_settings(const Panel& p) {
  std::string b = "unset arrow\nunset label\n";
  b += fmt::format("set title {}\nset xlabel {}\nset ylabel {}\n", gp_quote(p.title),
                   gp_quote(p.x_label), gp_quote(p.y_label));
  // A key inside the data gets an opaque box; one outside must not (its box would cover the
  // axis label next to it).
  const bool outside = p.key.find("below") != std::string::npos ||
                       p.key.find("outside") != std::string::npos ||
                       p.key.find("above") != std::string::npos;
  b += p.key == "off" ? "unset key\n"
                      : fmt::format("set key {}{} noautotitle\n", p.key, outside ? "" : " opaque");
  b += p.x_log ? "set logscale x\n" : "unset logscale x\n";
  b += fmt::format("set xrange {}\nset yrange {}\n", range(p.x_range), range(p.y_range));
  // An autoscaled axis keeps a margin so that no point sits on the frame (offsets apply to
  // autoscaled ranges only); x only for discrete data (points, bars), where a curve's ends
  // would otherwise leave a gap.
  const bool discrete = std::all_of(p.series.begin(), p.series.end(), [](const Series& s) {
    return s.style != SeriesStyle::kLines && s.style != SeriesStyle::kBand &&
           s.style != SeriesStyle::kImage;
  });
  b += fmt::format("set offsets graph {0}, graph {0}, graph 0.06, graph 0.06\n",
                   discrete ? "0.04" : "0");
  const bool image = std::any_of(p.series.begin(), p.series.end(),
                                 [](const Series& s) { return s.style == SeriesStyle::kImage; });
  if (image) {
    b += fmt::format("set cblabel {}\nset cbrange {}\nset colorbox\n", gp_quote(p.cb_label),
                     range(p.cb_range));
  } else {
    b += "unset colorbox\n";
  }
  b += p.equal_axes ? "set size ratio -1\n" : "set size noratio\n";
  return b + marker_commands(p);
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
    b += panel_settings(p);
    b += plot_command(p, index);
    index += static_cast<int>(p.series.size());
  }
  b += "unset multiplot\n";
  return b;
}

// The style every terminal shares (plot.hpp): grid, ticks, text boxes, the maps' palette.
std::string style_preamble() {
  return "set grid lt 1 lw 0.5 lc rgb '#d0d0d0'\n"
         "set border lw 1 lc rgb '#000000'\n"
         "set tics out nomirror\n"
         "set style textbox opaque noborder margins 1,1\n"
         "set key noenhanced samplen 3 spacing 1.1\n"
         // Maps: Paul Tol's diverging BuRd scheme (https://personal.sron.nl/~pault/), white at the
         // middle, readable in greyscale as dark-light-dark.
         "set palette defined (0 '#2166AC', 0.25 '#6EA6CD', 0.5 '#F7F7F7', 0.75 '#F4A582', "
         "1 '#B2182B')\n";
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

bool has_control_character(std::string_view s) {
  return std::any_of(s.begin(), s.end(),
                     [](char ch) { return static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f; });
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
  // A line break in the name would split the script's lines (exit 1 from gnuplot): refused.
  if (has_control_character(path.string()))
    throw core::InputError(fmt::format(
        "{} {}: holds a control character (a line break, a tab ...); give a name without", option,
        one_line(path.string())));
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
  // The figure goes into a folder that exists and takes a file: a folder is never created (a
  // mistyped --plot /nonexistent/x.png made /nonexistent).
  const fs::path folder = stem.parent_path().empty() ? fs::path(".") : stem.parent_path();
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(folder, ec)))
    throw core::InputError(fmt::format("{} {}: the folder {} does not exist (it is not created)",
                                       option, path.string(), folder.string()));
  if (!fs::is_directory(folder, ec))
    throw core::InputError(
        fmt::format("{} {}: {} is not a folder", option, path.string(), folder.string()));
  if (const std::error_code e = can_create_in(folder))
    throw core::InputError(fmt::format("{} {}: cannot create a file in {}: {}", option,
                                       path.string(), folder.string(), e.message()));
}

PlotFiles write_plot_files(const Figure& figure, const fs::path& stem_in) {
  validate(figure);
  const fs::path stem = strip_format_extension(stem_in);
  if (!names_a_file(stem))
    throw core::InputError(
        fmt::format("plot output {}: names a folder, not a file", stem_in.string()));
  if (has_control_character(stem.string()))
    throw core::InputError(
        fmt::format("plot output {}: holds a control character", one_line(stem_in.string())));
  // Into a folder that exists, never created; each file replaced whole through a fresh
  // temporary (atomic_file.hpp: O_EXCL | O_NOFOLLOW, then rename), so a link planted at a
  // side file's name is replaced, not followed.
  const fs::path dir = stem.parent_path().empty() ? fs::path(".") : stem.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw core::InputError(fmt::format("plot output {}: the folder {} does not exist",
                                       stem_in.string(), dir.string()));
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
        if (s.style == SeriesStyle::kImage && i > 0 && s.y[i] != s.y[i - 1])
          data += '\n';  // a map's rows are scan lines, one blank line apart
        data += number(s.x[i]) + ' ' + number(s.y[i]);
        if (!s.w.empty())
          data += ' ' + number(s.w[i]);
        data += '\n';
      }
      data += "\n\n";
    }
  }
  write_file_atomically(files.data.string(), data);

  const std::string body = script_body(figure);
  std::string script = fmt::format(
      "# piezoshift figure{}{}\n"
      "# Redraw after editing: run `gnuplot {}.gp` in this folder.\n"
      "datafile = {}\n"
      "set encoding utf8\n",
      figure.title.empty() ? "" : ": ", comment_end(figure.title), one_line(name),
      gp_quote(name + ".dat"));
  script += style_preamble();
  if (figure.png) {
    const double k = figure.png_scale;
    script += fmt::format(
        "\nset terminal pngcairo noenhanced size {},{} fontscale {} linewidth {} pointscale {} "
        "font '{},{}' background '#ffffff'\n"
        "set output {}\n",
        static_cast<int>(std::lround(k * figure.width_px)),
        static_cast<int>(std::lround(k * figure.height_px)), number(k), number(k), number(k), kFont,
        kFontPt, gp_quote(name + ".png"));
    script += body + "set output\n";
  }
  if (figure.svg) {
    script += fmt::format(
        "\nset terminal svg noenhanced size {},{} font '{},{}' background '#ffffff'\n"
        "set output {}\n",
        figure.width_px, figure.height_px, kFont, kFontPt, gp_quote(name + ".svg"));
    script += body + "set output\n";
  }
  write_file_atomically(files.script.string(), script);
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
  // gnuplot opens its outputs and log by name: whatever is at those names now (an old figure, a
  // planted link) is removed first, and the log is created afresh without following a link.
  for (const auto& out : {files.png, files.svg}) {
    if (out)
      fs::remove(*out);
  }
  std::error_code gone;
  fs::remove(dir / log_name, gone);

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
    const int log =
        ::open(log_name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
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
  Series s;
  s.title = std::move(title);
  s.x.assign(x.begin(), x.end());
  s.y.assign(y.begin(), y.end());
  s.color = std::move(color);
  return s;
}

Series point_series(std::string title, std::span<const double> x, std::span<const double> y,
                    std::string color) {
  Series s = line_series(std::move(title), x, y, std::move(color));
  s.style = SeriesStyle::kPoints;
  return s;
}

Series band_series(std::string title, double x_lo, double x_hi, double y_lo, double y_hi,
                   std::string color) {
  Series s;
  s.title = std::move(title);
  s.style = SeriesStyle::kBand;
  s.x = {x_lo, x_hi};
  s.y = {y_lo, y_lo};
  s.w = {y_hi, y_hi};
  s.color = color.empty() ? kBandColor : std::move(color);
  return s;
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
  Series s;
  s.title = std::move(title);
  s.style = SeriesStyle::kBoxes;
  s.color = std::move(color);
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
