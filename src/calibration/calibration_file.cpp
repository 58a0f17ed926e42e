#include "piezoshift/calibration/calibration_file.hpp"

#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/core/bounds.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/config_file.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"

namespace piezoshift::calibration {

namespace {

using runtime::ListField;
using runtime::model_section;
using runtime::visit_controller_fields;
using runtime::visit_fringe_lock_fields;
using runtime::visit_improved_fields;
using runtime::visit_model_fields;
using runtime::visit_travel_fields;

[[noreturn]] void fail(const io::ConfigFile& file, std::string_view section, std::string_view key,
                       const std::string& why) {
  if (key.empty())  // a rule over the whole section
    throw core::InputError(fmt::format("{}: [{}]: {}", file.source(), section, why));
  throw core::InputError(fmt::format("{}: [{}] {}: {}", file.source(), section, key, why));
}

// Reads each number of the field list (runtime/controller_ranges.hpp) that the file holds, within
// its range; a required one must be there, a list sharing its count with another must match it.
class FieldReader {
 public:
  explicit FieldReader(const io::ConfigFile& file) : file_(file) {}

  void operator()(std::string_view section, std::string_view key, double& v, const core::Bounds& b,
                  std::string_view note) const {
    if (!file_.section(section).read(key, v, b) && note.starts_with("required"))
      fail(file_, section, key, fmt::format("missing ({})", note));
  }
  template <class Whole>
  requires std::is_unsigned_v<Whole>
  void operator()(std::string_view section, std::string_view key, Whole& v, const core::Bounds& b,
                  std::string_view) const {
    auto whole = static_cast<std::int64_t>(v);
    if (file_.section(section).read(key, whole, b))
      v = static_cast<Whole>(whole);
  }
  template <class Count>
  void operator()(std::string_view section, std::string_view key, const ListField<double, Count>& f,
                  const core::Bounds& b, std::string_view) const {
    std::vector<double> values;
    const bool present = file_.section(section).read(key, values, f.capacity, b);
    if (f.same_count_as != nullptr && values.size() != *f.count)
      fail(file_, section, key,
           fmt::format("{} {} for {} {}", values.size(), key, *f.count, f.same_count_as));
    if (!present)
      return;
    *f.count = values.size();
    for (std::size_t i = 0; i < f.capacity; ++i)
      f.values[i] = i < values.size() ? values[i] : 0.0;
  }

 private:
  const io::ConfigFile& file_;
};

void read_improved(const io::ConfigFile& file, control::ImprovedParams& im) {
  const FieldReader reader(file);
  visit_improved_fields(im, reader);
  double sum = 0.0;
  for (std::size_t i = 0; i < im.shaper.taps; ++i)
    sum += im.shaper.weight[i];
  if (std::fabs(sum - 1.0) > 1e-9)
    fail(file, "improved", "shaper_taps", fmt::format("must sum to 1 (they sum to {})", sum));
  for (std::size_t i = 0; i < control::kChannels; ++i)
    visit_model_fields(im.model[i], model_section(i), reader);
}

// [controller] outer and [fringe_lock]: the lock's parameters when outer = "fringes".
std::optional<control::FringeLockParams> read_outer_loop(const io::ConfigFile& file) {
  std::string outer = "none";
  file.section("controller").read("outer", outer);
  if (outer != "none" && outer != "fringes")
    fail(file, "controller", "outer", "expected \"none\" or \"fringes\"");
  if (outer == "none") {
    control::FringeLockParams unused;
    visit_fringe_lock_fields(unused, [&](std::string_view section, std::string_view key, auto&,
                                         const core::Bounds&, std::string_view) {
      if (file.section(section).has(key))
        fail(file, section, key, "needs [controller] outer = \"fringes\"");
    });
    return std::nullopt;
  }
  control::FringeLockParams lock;
  visit_fringe_lock_fields(lock, FieldReader(file));
  if (const char* why = control::fringe_lock_problem(lock); *why != '\0')
    fail(file, "fringe_lock", "", why);  // e.g. a total below one frame's step
  return lock;
}

std::string number_list(const double* v, std::size_t n) {
  std::string out = "[";
  for (std::size_t i = 0; i < n; ++i)
    out += fmt::format("{}{}", i == 0 ? "" : ", ", v[i]);
  return out + "]";
}

// Writes each number of the field list, in its order, with its comment (shortest round-trip
// form: the reader gets the same double back).
class FieldWriter {
 public:
  explicit FieldWriter(std::string& out) : out_(out) {}

  template <class Value>
  void operator()(std::string_view, std::string_view key, const Value& v, const core::Bounds&,
                  std::string_view note) const {
    out_ += fmt::format("{} = {}{}\n", key, v, comment(note));
  }
  template <class Count>
  void operator()(std::string_view, std::string_view key, const ListField<const double, Count>& f,
                  const core::Bounds&, std::string_view note) const {
    out_ += fmt::format("{} = {}{}\n", key, number_list(f.values, *f.count), comment(note));
  }

 private:
  static std::string comment(std::string_view note) {
    return note.empty() || note.starts_with("required") ? std::string()
                                                        : fmt::format("  # {}", note);
  }
  std::string& out_;
};

std::string format_improved(const control::ImprovedParams& im) {
  std::string out =
      "\n[improved]  # the improved controller (docs/control.md), for one loop rate\n";
  const FieldWriter writer(out);
  visit_improved_fields(im, writer);
  for (std::size_t i = 0; i < control::kChannels; ++i) {
    out += fmt::format("\n[{}]  # gauge um from command um\n", model_section(i));
    visit_model_fields(im.model[i], model_section(i), writer);
  }
  return out;
}

}  // namespace

void read_controller_section(const io::ConfigFile& file, control::SemiClosedLoopParams& params) {
  visit_controller_fields(params, FieldReader(file));
  const io::ConfigSection c = file.section("controller");
  std::array<double, 4> p{params.polynomial.p3, params.polynomial.p2, params.polynomial.p1,
                          params.polynomial.p0};
  if (c.read("p", p))
    params.polynomial = control::CubicPolynomial{p[0], p[1], p[2], p[3]};
  c.read("A", params.matrix.a, runtime::kMatrixEntry);
  std::string kind = "paper";
  if (c.read("kind", kind)) {
    if (kind == "improved")
      params.kind = control::ControllerKind::kImproved;
    else if (kind == "paper")
      params.kind = control::ControllerKind::kPaper;
    else
      fail(file, "controller", "kind", "expected \"paper\" or \"improved\"");
  }
  if (params.kind == control::ControllerKind::kImproved)
    read_improved(file, params.improved);
}

control::SemiClosedLoopParams load_calibration_file(
    const std::string& path, std::optional<double>* travel_z_max_um,
    std::optional<double>* travel_z_min_um, std::optional<control::FringeLockParams>* fringe_lock) {
  const io::ConfigFile file = io::ConfigFile::load(path);
  control::SemiClosedLoopParams params;
  read_controller_section(file, params);
  const std::optional<control::FringeLockParams> lock = read_outer_loop(file);
  if (lock && fringe_lock == nullptr)
    throw core::InputError(fmt::format(
        "{}: [controller] outer = \"fringes\": the fringe lock runs in `piezoshift measure` only "
        "(this command runs the semi-closed loop alone)",
        path));
  if (fringe_lock != nullptr)
    *fringe_lock = lock;
  double z_max_um = 0.0, z_min_um = 0.0;
  const io::ConfigSection travel = file.section("travel");
  const bool has_max = travel.has("z_max_um");
  const bool has_min = travel.has("z_min_um");
  visit_travel_fields(z_max_um, z_min_um, FieldReader(file));
  file.reject_unknown();
  // The checks over a whole set name the key's line when the file has it.
  const auto refuse = [&file](const runtime::FieldProblem& why) {
    throw core::InputError(
        fmt::format("{}: {}", file.section(why.section).location(why.key), why.why));
  };
  if (const runtime::FieldProblem why =
          runtime::controller_field_problem(params, runtime::own_sample_time_s(params));
      !why.empty())
    refuse(why);
  if (const runtime::FieldProblem why =
          runtime::travel_problem(has_max ? std::optional<double>(z_max_um) : std::nullopt,
                                  has_min ? std::optional<double>(z_min_um) : std::nullopt);
      !why.empty())
    refuse(why);
  if (travel_z_max_um != nullptr)
    *travel_z_max_um = has_max ? std::optional<double>(z_max_um) : std::nullopt;
  if (travel_z_min_um != nullptr)
    *travel_z_min_um = has_min ? std::optional<double>(z_min_um) : std::nullopt;
  return params;
}

std::string format_calibration(const control::SemiClosedLoopParams& params,
                               const std::string& header, std::optional<double> travel_z_max_um,
                               std::optional<double> travel_z_min_um) {
  // A travel the loader would refuse is not written (Python and calibrate on a stage beyond this
  // one's stroke both end here, naming the key).
  if (const runtime::FieldProblem why = runtime::travel_problem(travel_z_max_um, travel_z_min_um);
      !why.empty())
    throw core::InputError(fmt::format("the calibration to write: {}", why.why));
  std::string out;
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);)
    out += "# " + line + "\n";
  const auto& p = params.polynomial;
  const auto& a = params.matrix.a;
  out += "\n[controller]\n";
  visit_controller_fields(params, FieldWriter(out));
  out +=
      fmt::format("p = [{}, {}, {}, {}]  # [p3, p2, p1, p0], Eq. 8, um\n", p.p3, p.p2, p.p1, p.p0);
  out += "A = [";
  for (std::size_t r = 0; r < 3; ++r) {
    out += fmt::format("{}[{}, {}, {}]{}", r == 0 ? "" : "     ", a[r][0], a[r][1], a[r][2],
                       r == 2 ? "]  # S = A Z_S, Eq. 8\n" : ",\n");
  }
  if (params.kind == control::ControllerKind::kImproved) {
    out += "kind = \"improved\"\n";
    out += format_improved(params.improved);
  }
  if (travel_z_max_um) {
    out += "\n[travel]\n";
    out += fmt::format(
        "z_max_um = {}  # the travel one move from rest reaches (Section 4.1's search, then "
        "single moves)\n",
        *travel_z_max_um);
    if (travel_z_min_um)
      out += fmt::format("z_min_um = {}  # the lowest Z a move from the top reaches\n",
                         *travel_z_min_um);
  }
  return out;
}

void write_calibration_file(const std::string& path, const control::SemiClosedLoopParams& params,
                            const std::string& header, std::optional<double> travel_z_max_um,
                            std::optional<double> travel_z_min_um) {
  io::write_file_atomically(path,
                            format_calibration(params, header, travel_z_max_um, travel_z_min_um));
}

}  // namespace piezoshift::calibration
