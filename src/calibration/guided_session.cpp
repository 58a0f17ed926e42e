#include "piezoshift/calibration/guided_session.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"

namespace piezoshift::calibration {

namespace {
constexpr const char* kFormat = "piezoshift guided calibration session 1";
constexpr std::uintmax_t kMaxBytes = 16u << 20;
}  // namespace

std::optional<GuidedSession> load_guided_session(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    return std::nullopt;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec || size > kMaxBytes)
    throw core::InputError(
        fmt::format("{}: not a readable session file of at most {} bytes", path, kMaxBytes));
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in && !in.eof())
    throw core::InputError(fmt::format("{}: cannot read the session file", path));
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    if (j.at("format").get<std::string>() != kFormat)
      throw core::InputError(fmt::format("{}: not a {}", path, kFormat));
    GuidedSession s;
    s.plan = j.at("plan").get<std::string>();
    s.steps = j.at("steps").get<std::size_t>();
    for (const auto& r : j.at("readings")) {
      SessionReading e;
      e.step = r.at("step").get<std::size_t>();
      e.optics = r.at("optics").get<std::string>();
      if (!r.at("reading_um").is_null())
        e.reading_um = r.at("reading_um").get<double>();
      const auto& sgs = r.at("sgs_um");
      if (sgs.size() != 3)
        throw core::InputError(fmt::format("{}: step {}: sgs_um needs 3 numbers", path, e.step));
      for (std::size_t i = 0; i < 3; ++i)
        e.sgs_um[i] = sgs.at(i).get<double>();
      e.window_start_s = r.at("window_start_s").get<double>();
      e.window_end_s = r.at("window_end_s").get<double>();
      e.saturated = r.at("saturated").get<bool>();
      if (e.step != s.readings.size() || e.step >= s.steps)
        throw core::InputError(
            fmt::format("{}: step {} out of order (expected {})", path, e.step, s.readings.size()));
      s.readings.push_back(e);
    }
    return s;
  } catch (const nlohmann::json::exception& e) {
    throw core::InputError(fmt::format("{}: not a session file: {}", path, e.what()));
  }
}

void save_guided_session(const std::string& path, const GuidedSession& s) {
  nlohmann::json readings = nlohmann::json::array();
  for (const SessionReading& r : s.readings) {
    nlohmann::json e;
    e["step"] = r.step;
    e["optics"] = r.optics;
    e["reading_um"] = r.reading_um ? nlohmann::json(*r.reading_um) : nlohmann::json(nullptr);
    e["sgs_um"] = {r.sgs_um[0], r.sgs_um[1], r.sgs_um[2]};
    e["window_start_s"] = r.window_start_s;
    e["window_end_s"] = r.window_end_s;
    e["saturated"] = r.saturated;
    readings.push_back(std::move(e));
  }
  const nlohmann::json j = {
      {"format", kFormat}, {"plan", s.plan}, {"steps", s.steps}, {"readings", readings}};
  io::write_file_atomically(path, j.dump(1) + "\n");
}

}  // namespace piezoshift::calibration
