#include "emulated_board.hpp"

#include <sys/time.h>
#include <cerrno>
#include <cmath>
#include <fstream>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace piezoshift::emulation {

namespace {

constexpr std::size_t kMaxSeriesRows = 1'000'000;

std::array<double, 3> first3(const control::Vec3& v) {
  return {v[0], v[1], v[2]};
}

}  // namespace

EmulatedBoard::EmulatedBoard(EmulationSettings settings, BoardModel model)
    : settings_(std::move(settings)), model_(std::move(model)) {
  const runtime::InstallationConfig config =
      settings_.config.empty() ? runtime::InstallationConfig{}
                               : runtime::load_installation_config(settings_.config);
  const plant::TwinParams p =
      runtime::twin_params_at_period(config.project.twin, std::llround(settings_.step_s * 1e9));
  if (const std::string problem = plant::twin_params_problem(config.project.design, p);
      !problem.empty())
    throw core::InputError(fmt::format("{}: the twin at a {} s step cannot be built: {}",
                                       settings_.source, settings_.step_s, problem));
  try {
    twin_ = std::make_unique<plant::Twin>(config.project.design, p,
                                          static_cast<std::uint64_t>(settings_.seed));
  } catch (const std::invalid_argument& e) {
    throw core::InputError(
        fmt::format("{}: the twin cannot be built: {}", settings_.source, e.what()));
  }
  // Power-up: the DACs at 0 V on their range, as ni_ao_reset leaves them.
  if (const SubdeviceModel& ao = model_.subdevices[kAoSubdevice]; ao.type == COMEDI_SUBD_AO) {
    for (unsigned ch = 0; ch < ao.n_chan && ch < ao_codes_.size(); ++ch) {
      ao_codes_[ch] = raw_code(0.0, ao.ranges[0], ao.maxdata, model_.ao_raw(ch));
      ao_V_[ch] = raw_volts(ao_codes_[ch], ao.ranges[0], ao.maxdata, model_.ao_raw(ch));
    }
  }
  twin_->write_ao(control::Vec3{ao_V_[0], ao_V_[1], ao_V_[2]});
  if (!settings_.log_folder.empty()) {
    const char* names[] = {"P1.csv", "P2.csv", "P3.csv", "centre.csv"};
    for (std::size_t i = 0; i < logs_.size(); ++i) {
      const std::string file = settings_.log_folder + "/" + names[i];
      logs_[i] = std::fopen(file.c_str(), "w");
      if (logs_[i] == nullptr)
        throw core::InputError(fmt::format("{}: [interferometer] log_folder: cannot write {}",
                                           settings_.source, file));
      std::fputs("t_s,displacement_um\n", logs_[i]);
      std::fflush(logs_[i]);
    }
  }
}

EmulatedBoard::~EmulatedBoard() {
  for (std::FILE* f : logs_)
    if (f != nullptr)
      std::fclose(f);
}

double EmulatedBoard::elapsed_s() const {
  return static_cast<double>(steps_) * settings_.step_s;
}

void EmulatedBoard::advance_to_now() {
  std::int64_t target = steps_ + 1;
  if (settings_.clock == "wall") {
    const auto now = std::chrono::steady_clock::now();
    if (!started_) {
      started_ = true;
      start_ = now;
      unix_start_s_ =
          std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
              .count();
    }
    const double since_s = std::chrono::duration<double>(now - start_).count();
    target = static_cast<std::int64_t>(std::floor(since_s / settings_.step_s));
    const auto max_steps = static_cast<std::int64_t>(kMaxCatchUp_s / settings_.step_s);
    if (target - steps_ > max_steps) {  // a host stall: the plant's time jumps ahead
      time_dropped_s_ += static_cast<double>(target - steps_ - max_steps) * settings_.step_s;
      start_ += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(static_cast<double>(target - steps_ - max_steps) *
                                        settings_.step_s));
      target = steps_ + max_steps;
    }
  }
  for (; steps_ < target; ++steps_) {
    twin_->advance();
    sample_series();
    write_interferometer_logs();
  }
}

void EmulatedBoard::write_interferometer_logs() {
  if (logs_[0] == nullptr)
    return;
  const double t = elapsed_s();
  if (t + 1e-12 < next_log_s_)
    return;
  next_log_s_ += settings_.log_period_s;
  const control::Vec3& z = twin_->interferometer().dynamic_um;
  const double at[] = {z[0], z[1], z[2], (z[0] + z[1] + z[2]) / 3.0};
  for (std::size_t i = 0; i < logs_.size(); ++i) {
    // Unix time of this step: the twin's time plus whatever a host stall dropped from it.
    std::fprintf(logs_[i], "%.4f,%.4f\n", unix_start_s_ + t + time_dropped_s_, at[i]);
    std::fflush(logs_[i]);  // the reader reads the whole log at each reading
  }
}

void EmulatedBoard::sample_series() {
  if (settings_.series.empty() || series_.size() >= kMaxSeriesRows)
    return;
  const double t = elapsed_s();
  if (t + 1e-12 < next_series_s_)
    return;
  next_series_s_ += settings_.series_period_s;
  series_.push_back(SeriesRow{t,
                              {ao_V_[0], ao_V_[1], ao_V_[2]},
                              first3(twin_->truth().points_um),
                              first3(twin_->interferometer().dynamic_um)});
}

int EmulatedBoard::check(const comedi_insn& insn) const {
  if (insn.subdev >= model_.subdevices.size())
    return -EINVAL;
  const SubdeviceModel& s = model_.subdevices[insn.subdev];
  if (s.type == COMEDI_SUBD_UNUSED)
    return -EIO;  // the kernel refuses instructions to an unused subdevice
  if (insn.n > 0 && insn.data == nullptr)
    return -EFAULT;
  if (insn.insn == INSN_READ || insn.insn == INSN_WRITE) {
    if (CR_CHAN(insn.chanspec) >= s.n_chan)
      return -EINVAL;
    if (!s.ranges.empty() && CR_RANGE(insn.chanspec) >= s.ranges.size())
      return -EINVAL;
  }
  if (insn.insn == INSN_WRITE) {
    for (unsigned i = 0; i < insn.n; ++i)
      if (insn.data[i] > s.maxdata)
        return -EINVAL;  // comedi's core checks written data against maxdata
  }
  return 0;
}

int EmulatedBoard::execute(comedi_insn& insn) {
  if (insn.insn == INSN_GTOD) {
    timeval tv{};
    gettimeofday(&tv, nullptr);
    if (insn.n < 2 || insn.data == nullptr)
      return -EINVAL;
    insn.data[0] = static_cast<lsampl_t>(tv.tv_sec);
    insn.data[1] = static_cast<lsampl_t>(tv.tv_usec);
    return 2;
  }
  if (const int bad = check(insn); bad < 0)
    return bad;
  const SubdeviceModel& s = model_.subdevices[insn.subdev];
  const unsigned ch = CR_CHAN(insn.chanspec);
  const double t = elapsed_s();
  if (s.type == COMEDI_SUBD_AI && insn.insn == INSN_READ) {
    if (settings_.ai_timeout_at_s >= 0.0 && t >= settings_.ai_timeout_at_s) {
      ++failed_ai_timeout_;
      return -ETIME;  // ni_ai_insn_read: the conversion did not complete
    }
    const comedi_range& r = s.ranges[CR_RANGE(insn.chanspec)];
    const bool open = settings_.ai_open_at_s >= 0.0 && t >= settings_.ai_open_at_s &&
                      ch == static_cast<unsigned>(settings_.ai_open_channel);
    const double v = ch < 3 ? twin_->read_ai()[ch] : 0.0;
    for (unsigned i = 0; i < insn.n; ++i)
      insn.data[i] = open ? s.maxdata : raw_code(v, r, s.maxdata, model_.ai_raw(ch));
    ai_open_reads_ += open ? 1 : 0;
    return static_cast<int>(insn.n);
  }
  if (s.type == COMEDI_SUBD_AO && insn.insn == INSN_WRITE) {
    if (settings_.ao_busy_at_s >= 0.0 && t >= settings_.ao_busy_at_s) {
      ++failed_ao_busy_;
      return -EBUSY;
    }
    if (insn.n == 0)
      return 0;
    const comedi_range& r = s.ranges[CR_RANGE(insn.chanspec)];
    ao_codes_[ch] = insn.data[insn.n - 1];
    ao_V_[ch] = raw_volts(ao_codes_[ch], r, s.maxdata, model_.ao_raw(ch));
    twin_->write_ao(control::Vec3{ao_V_[0], ao_V_[1], ao_V_[2]});
    return static_cast<int>(insn.n);
  }
  if (insn.subdev == kDioSubdevice && (insn.insn == INSN_WRITE || insn.insn == INSN_READ)) {
    // comedi's core emulates single-line reads and writes with the subdevice's insn_bits
    const std::uint32_t bit = 1u << ch;
    for (unsigned i = 0; i < insn.n; ++i) {
      if (insn.insn == INSN_READ) {
        insn.data[i] = (dio_level_ & bit) != 0 ? 1 : 0;
        continue;
      }
      const bool high = insn.data[i] != 0;
      if (high && (dio_level_ & bit) == 0 && (dio_output_ & bit) != 0)
        ++dio_rising_edges_;
      dio_level_ = high ? (dio_level_ | bit) : (dio_level_ & ~bit);
    }
    return static_cast<int>(insn.n);
  }
  return -EINVAL;  // not emulated: a clear refusal, never a silent success
}

int EmulatedBoard::do_insnlist(comedi_insnlist& list) {
  const std::lock_guard lock(mutex_);
  ++transactions_;
  advance_to_now();
  if (settings_.io_error_at_s >= 0.0 && elapsed_s() >= settings_.io_error_at_s && failed_io_ == 0) {
    ++failed_io_;
    ++failed_transactions_;
    errno = EIO;
    return -1;
  }
  for (unsigned i = 0; i < list.n_insns; ++i) {
    const int r = execute(list.insns[i]);
    if (r < 0) {
      ++failed_transactions_;
      errno = -r;
      return -1;
    }
  }
  return static_cast<int>(list.n_insns);
}

int EmulatedBoard::dio_config(unsigned subdevice, unsigned channel, unsigned direction) {
  const std::lock_guard lock(mutex_);
  if (subdevice != kDioSubdevice || channel >= model_.subdevices[subdevice].n_chan ||
      (direction != COMEDI_INPUT && direction != COMEDI_OUTPUT)) {
    errno = EINVAL;
    return -1;
  }
  const std::uint32_t bit = 1u << channel;
  dio_output_ = direction == COMEDI_OUTPUT ? (dio_output_ | bit) : (dio_output_ & ~bit);
  return 0;
}

void EmulatedBoard::write_records() const {
  if (!settings_.record.empty()) {
    nlohmann::json j;
    j["board"] = model_.name;
    j["device"] = settings_.device;
    j["transactions"] = transactions_;
    j["failed_transactions"] = failed_transactions_;
    j["failed_ai_timeout"] = failed_ai_timeout_;
    j["failed_ao_busy"] = failed_ao_busy_;
    j["failed_io"] = failed_io_;
    j["ai_open_reads"] = ai_open_reads_;
    j["elapsed_s"] = elapsed_s();
    j["time_dropped_s"] = time_dropped_s_;
    j["ao_V"] = ao_V_;
    j["ao_codes"] = ao_codes_;
    j["points_um"] = first3(twin_->truth().points_um);
    j["interferometer_um"] = first3(twin_->interferometer().dynamic_um);
    j["dio_rising_edges"] = dio_rising_edges_;
    std::ofstream(settings_.record) << j.dump(2) << "\n";
  }
  if (!settings_.series.empty()) {
    std::ofstream out(settings_.series);
    out << "t_s,ao1_V,ao2_V,ao3_V,z1_um,z2_um,z3_um,ifm1_um,ifm2_um,ifm3_um\n";
    for (const SeriesRow& r : series_)
      out << fmt::format("{:.6f},{},{},{},{},{},{},{},{},{}\n", r.t_s, r.ao_V[0], r.ao_V[1],
                         r.ao_V[2], r.z_um[0], r.z_um[1], r.z_um[2], r.interferometer_um[0],
                         r.interferometer_um[1], r.interferometer_um[2]);
  }
}

}  // namespace piezoshift::emulation
