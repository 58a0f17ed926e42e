#include "piezoshift/calibration/interferometer_source.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <thread>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/csv_table.hpp"

namespace piezoshift::calibration {

using control::Vec3;

const char* to_string(Optics optics) noexcept {
  switch (optics) {
    case Optics::kP1:
      return "P1";
    case Optics::kP2:
      return "P2";
    case Optics::kP3:
      return "P3";
    case Optics::kCentre:
      return "centre";
  }
  return "?";
}

namespace {

constexpr std::size_t kMaxLine = 256;

// One line of at most kMaxLine characters (the rest of a longer line is consumed and the line
// refused); nothing at the end of the input.
std::optional<std::string> read_line(std::istream& in, bool& too_long) {
  std::string line;
  too_long = false;
  int c = 0;
  bool any = false;
  while ((c = in.get()) != std::char_traits<char>::eof()) {
    any = true;
    if (c == '\n')
      return line;
    if (line.size() < kMaxLine)
      line.push_back(static_cast<char>(c));
    else
      too_long = true;
  }
  if (!any)
    return std::nullopt;
  return line;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

}  // namespace

std::optional<double> PromptSource::read(const ReadingRequest& r) {
  for (;;) {
    say_(fmt::format("reading {} of {}: {}; interferometer at {} [um]: ", r.index + 1, r.total,
                     r.what, to_string(r.optics)));
    bool too_long = false;
    const std::optional<std::string> line = read_line(in_, too_long);
    if (!line) {
      say_("\n");
      return std::nullopt;
    }
    std::string_view text = trim(*line);
    if (text.size() >= 2 && text.substr(text.size() - 2) == "um")
      text = trim(text.substr(0, text.size() - 2));
    double v = 0.0;
    if (!too_long && io::parse_finite_double(text, v))
      return v;
    say_(
        fmt::format("standard input: '{}' is not a displacement in um (a number such as 7.012); "
                    "enter it again\n",
                    too_long ? std::string(line->substr(0, 40)) + "..." : std::string(text)));
  }
}

void PromptSource::refuse(const std::string& why) {
  say_(fmt::format("refused: {}; enter it again\n", why));
}

std::optional<double> LogFileSource::read(const ReadingRequest& r) {
  // The interferometer software appends and flushes in its own rhythm: a log that does not yet
  // reach the window's end is read again until it does or wait_s has passed.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s_);
  for (;;) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path_, ec);
    if (!ec && size > max_bytes_)
      throw core::InputError(fmt::format("{}: the log is larger than {} bytes", path_, max_bytes_));
    const io::CsvTable t = io::CsvTable::load(path_);
    t.require_columns({"t_s", "displacement_um"});
    const std::vector<double> time = t.column("t_s");
    const std::vector<double> z = t.column("displacement_um");
    double sum = 0.0, last = -std::numeric_limits<double>::infinity();
    std::size_t n = 0;
    for (std::size_t i = 0; i < time.size(); ++i) {
      last = std::max(last, time[i]);
      if (time[i] >= r.window.start_s && time[i] <= r.window.end_s) {
        sum += z[i];
        ++n;
      }
    }
    if (last < r.window.end_s) {
      if (std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        continue;
      }
      throw core::InputError(fmt::format(
          "{}: the log ends at t_s {:.3f}, before the end of the window {:.3f} s ({}), after "
          "waiting {:g} s for it",
          path_, last, r.window.end_s, r.what, wait_s_));
    }
    if (n == 0)
      throw core::InputError(fmt::format("{}: no row with t_s between {:.3f} and {:.3f} s ({})",
                                         path_, r.window.start_s, r.window.end_s, r.what));
    return sum / static_cast<double>(n);
  }
}

std::optional<double> TwinSource::read(const ReadingRequest& r) {
  if (!r.window.twin_points_um)
    throw std::logic_error("the twin's interferometer needs the twin (--daq sim)");
  const Vec3& p = *r.window.twin_points_um;
  switch (r.optics) {
    case Optics::kP1:
      return p[0];
    case Optics::kP2:
      return p[1];
    case Optics::kP3:
      return p[2];
    case Optics::kCentre:
      return (p[0] + p[1] + p[2]) / 3.0;
  }
  return std::nullopt;
}

}  // namespace piezoshift::calibration
