#include "emulated_board.hpp"

#include <sys/time.h>
#include <bit>
#include <cerrno>
#include <cmath>
#include <fstream>
#include <thread>

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
  // comedi's parse_insn, before the subdevice's handler: an unused subdevice is EIO, a channel
  // or range beyond the subdevice's (comedi_check_chanlist) EINVAL, data above maxdata EINVAL.
  if (insn.subdev >= model_.subdevices.size())
    return -EINVAL;
  const SubdeviceModel& s = model_.subdevices[insn.subdev];
  if (s.type == COMEDI_SUBD_UNUSED)
    return -EIO;
  if (insn.n > 0 && insn.data == nullptr)
    return -EFAULT;
  if (CR_CHAN(insn.chanspec) >= s.n_chan || CR_RANGE(insn.chanspec) >= s.ranges.size())
    return -EINVAL;
  if (insn.insn == INSN_WRITE) {
    for (unsigned i = 0; i < insn.n; ++i)
      if (insn.data[i] > s.maxdata)
        return -EINVAL;
  }
  return 0;
}

int EmulatedBoard::special(comedi_insn& insn) {
  switch (insn.insn) {
    case INSN_GTOD: {
      if (insn.n != 2 || insn.data == nullptr)
        return -EINVAL;
      timeval tv{};
      gettimeofday(&tv, nullptr);
      insn.data[0] = static_cast<lsampl_t>(tv.tv_sec);
      insn.data[1] = static_cast<lsampl_t>(tv.tv_usec);
      return 2;
    }
    case INSN_WAIT:  // a delay of data[0] ns, under 100 us, at microsecond resolution
      if (insn.n != 1 || insn.data == nullptr || insn.data[0] >= 100000)
        return -EINVAL;
      std::this_thread::sleep_for(std::chrono::microseconds(insn.data[0] / 1000));
      return 1;
    case INSN_INTTRIG:  // needs a command waiting for its trigger; no subdevice has commands
    default:
      return -EINVAL;
  }
}

int EmulatedBoard::execute(comedi_insn& insn) {
  if ((insn.insn & INSN_MASK_SPECIAL) != 0)
    return special(insn);
  if (const int bad = check(insn); bad < 0)
    return bad;
  const SubdeviceModel& s = model_.subdevices[insn.subdev];
  if (insn.subdev == kAiSubdevice)
    return analog_in(insn, s);
  if (insn.subdev == kAoSubdevice)
    return analog_out(insn, s);
  if (insn.subdev == kDioSubdevice)
    return digital_io(insn, s);
  // Calibration PWM, EEPROM, PFI, serial, RTSI, counters and frequency output are not emulated:
  // their instructions fail as an instruction with no handler does (the core's insn_inval).
  return -EINVAL;
}

int EmulatedBoard::analog_in(comedi_insn& insn, const SubdeviceModel& s) {
  if (insn.insn != INSN_READ)
    return -EINVAL;  // AI has no insn_write or insn_bits; its configurations are not emulated
  const unsigned ch = CR_CHAN(insn.chanspec);
  const double t = elapsed_s();
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
  ai_open_reads_ += open && insn.n > 0 ? 1 : 0;
  return static_cast<int>(insn.n);
}

int EmulatedBoard::analog_out(comedi_insn& insn, const SubdeviceModel& s) {
  const unsigned ch = CR_CHAN(insn.chanspec);
  if (insn.insn == INSN_READ) {  // comedi_readback_insn_read: the last code written
    for (unsigned i = 0; i < insn.n; ++i)
      insn.data[i] = ao_readback_[ch];
    return static_cast<int>(insn.n);
  }
  if (insn.insn != INSN_WRITE)
    return -EINVAL;
  if (settings_.ao_busy_at_s >= 0.0 && elapsed_s() >= settings_.ao_busy_at_s) {
    ++failed_ao_busy_;
    return -EBUSY;
  }
  if (insn.n == 0)
    return 0;
  const comedi_range& r = s.ranges[CR_RANGE(insn.chanspec)];
  ao_codes_[ch] = insn.data[insn.n - 1];
  ao_readback_[ch] = ao_codes_[ch];
  ao_V_[ch] = raw_volts(ao_codes_[ch], r, s.maxdata, model_.ao_raw(ch));
  twin_->write_ao(control::Vec3{ao_V_[0], ao_V_[1], ao_V_[2]});
  return static_cast<int>(insn.n);
}

void EmulatedBoard::set_dio_levels(std::uint32_t mask, std::uint32_t bits) {
  // A rising edge counts on a line made an output (a camera trigger's).
  dio_rising_edges_ +=
      static_cast<std::uint64_t>(std::popcount(mask & bits & ~dio_level_ & dio_output_));
  dio_level_ = (dio_level_ & ~mask) | (bits & mask);
}

int EmulatedBoard::digital_io(comedi_insn& insn, const SubdeviceModel& s) {
  const unsigned ch = CR_CHAN(insn.chanspec);
  const std::uint32_t bit = 1u << ch;
  switch (insn.insn) {
    case INSN_READ:  // the core emulates one line's read and write with insn_bits
      for (unsigned i = 0; i < insn.n; ++i)
        insn.data[i] = (dio_level_ & bit) != 0 ? 1 : 0;
      return static_cast<int>(insn.n);
    case INSN_WRITE:
      for (unsigned i = 0; i < insn.n; ++i)
        set_dio_levels(bit, insn.data[i] != 0 ? bit : 0);
      return static_cast<int>(insn.n);
    case INSN_BITS: {  // data[0] the lines to write, data[1] their levels, from line `ch` up
      if (insn.n != 2)
        return -EINVAL;
      const unsigned shift = s.n_chan <= 32 ? ch : 0;
      set_dio_levels(insn.data[0] << shift, insn.data[1] << shift);
      insn.data[1] = dio_level_ >> shift;
      return 2;
    }
    case INSN_CONFIG:
      return dio_config(insn, bit);
    default:
      return -EINVAL;
  }
}

int EmulatedBoard::dio_config(comedi_insn& insn, std::uint32_t bit) {
  // comedi_dio_insn_config, after check_insn_config_length
  if (insn.n < 1)
    return -EINVAL;
  switch (insn.data[0]) {
    case INSN_CONFIG_DIO_OUTPUT:
    case INSN_CONFIG_DIO_INPUT:
      if (insn.n != 1)
        return -EINVAL;
      dio_output_ =
          insn.data[0] == INSN_CONFIG_DIO_OUTPUT ? (dio_output_ | bit) : (dio_output_ & ~bit);
      return 1;
    case INSN_CONFIG_DIO_QUERY:
      if (insn.n != 2)
        return -EINVAL;
      insn.data[1] = (dio_output_ & bit) != 0 ? COMEDI_OUTPUT : COMEDI_INPUT;
      return 2;
    default:
      return -EINVAL;
  }
}

int EmulatedBoard::do_insnlist(comedi_insnlist& list) {
  const std::lock_guard lock(mutex_);
  ++transactions_;
  for (unsigned i = 0; i < list.n_insns; ++i) {
    if (list.insns[i].n > kMaxSamples) {  // do_insnlist_ioctl refuses the list before any runs
      ++failed_transactions_;
      errno = EINVAL;
      return -1;
    }
  }
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
