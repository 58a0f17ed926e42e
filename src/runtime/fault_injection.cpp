#include "piezoshift/runtime/fault_injection.hpp"

#include <charconv>
#include <cmath>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::runtime {

namespace {
struct KindName {
  FaultKind kind;
  const char* name;
};
constexpr KindName kKinds[kFaultKinds] = {
    {FaultKind::kSgsOpen, "sgs-open"},
    {FaultKind::kSgsStuck, "sgs-stuck"},
    {FaultKind::kAdcNan, "adc-nan"},
    {FaultKind::kAdcSpike, "adc-spike"},
    {FaultKind::kAmplifierFail, "amplifier-fail"},
    {FaultKind::kActuatorCrack, "actuator-crack"},
    {FaultKind::kOverrunBurst, "overrun-burst"},
};

std::string kind_list() {
  std::string s;
  for (const auto& k : kKinds)
    s += (s.empty() ? "" : ", ") + std::string(k.name);
  return s;
}

bool parse_double(std::string_view s, double& v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(v);
}
}  // namespace

const char* to_string(FaultKind kind) noexcept {
  for (const auto& k : kKinds)
    if (k.kind == kind)
      return k.name;
  return "unknown";
}

FaultSpec parse_fault_spec(std::string_view text) {
  const auto bad = [&text](const std::string& why) {
    return core::InputError(fmt::format(
        "--fault '{}': {} (expected KIND@T_S[:CHANNEL], e.g. sgs-open@0.2:1)", text, why));
  };
  const std::size_t at = text.find('@');
  if (at == std::string_view::npos)
    throw bad("no '@'");
  const std::string_view kind_text = text.substr(0, at);
  std::string_view rest = text.substr(at + 1);
  FaultSpec spec;
  bool found = false;
  for (const auto& k : kKinds) {
    if (kind_text == k.name) {
      spec.kind = k.kind;
      found = true;
    }
  }
  if (!found)
    throw bad(fmt::format("unknown kind '{}' (kinds: {})", kind_text, kind_list()));
  std::string_view time_text = rest;
  std::string_view channel_text;
  if (const std::size_t colon = rest.find(':'); colon != std::string_view::npos) {
    time_text = rest.substr(0, colon);
    channel_text = rest.substr(colon + 1);
  }
  if (!parse_double(time_text, spec.time_s) || spec.time_s < 0.0)
    throw bad(fmt::format("time '{}' is not a number of seconds >= 0", time_text));
  if (spec.time_s > kMaxRunDurationS)
    throw bad(
        fmt::format("time {} s is beyond the longest run, {} s", spec.time_s, kMaxRunDurationS));
  if (spec.kind == FaultKind::kOverrunBurst) {
    if (!channel_text.empty())
      throw bad("overrun-burst takes no channel");
    spec.channel = -1;
    return spec;
  }
  spec.channel = 0;
  if (!channel_text.empty()) {
    if (channel_text != "1" && channel_text != "2" && channel_text != "3")
      throw bad(fmt::format("channel '{}' is not 1, 2 or 3", channel_text));
    spec.channel = channel_text[0] - '1';
  }
  return spec;
}

FaultInjectingBackend::FaultInjectingBackend(DaqBackend& inner, LoopClock& clock,
                                             std::int64_t period_ns, std::vector<FaultSpec> faults,
                                             FaultInjectionParams params, PlantFaultHooks* hooks)
    : inner_(inner),
      clock_(clock),
      period_ns_(period_ns),
      faults_(std::move(faults)),
      start_ns_(faults_.size()),
      started_(faults_.size(), kNotYet),
      emulated_(faults_.size(), false),
      params_(params),
      hooks_(hooks) {
  for (std::size_t i = 0; i < faults_.size(); ++i) {
    const FaultSpec& f = faults_[i];
    if (f.kind == FaultKind::kActuatorCrack && hooks_ == nullptr) {
      throw core::InputError(
          fmt::format("--fault {}: needs a plant model (the sim backend)", to_string(f.kind)));
    }
    if (f.kind != FaultKind::kOverrunBurst && (f.channel < 0 || f.channel > 2))
      throw core::InputError(fmt::format("--fault {}: channel must be 1..3", to_string(f.kind)));
    start_ns_[i] = static_cast<std::int64_t>(std::llround(f.time_s * 1e9));
  }
}

void FaultInjectingBackend::activate() {
  inner_.activate();
  for (auto& s : started_)
    s = kNotYet;
  for (std::size_t i = 0; i < emulated_.size(); ++i)
    emulated_[i] = false;
  amplifier_dead_mask_ = 0;
  frozen_V_ = Vec3{};
}

std::uint64_t FaultInjectingBackend::first_injected_tick() const noexcept {
  std::uint64_t first = kNotYet;
  for (std::uint64_t s : started_)
    if (s < first)
      first = s;
  return first;
}

DaqStatus FaultInjectingBackend::read(const CycleTime& t, Vec3& ai_V) noexcept {
  // Channel faults reach the plant before it is stepped, so this tick's samples show them.
  for (std::size_t i = 0; i < faults_.size(); ++i) {
    if (started_[i] != kNotYet || t.since_start_ns < start_ns_[i])
      continue;
    started_[i] = t.tick;
    const FaultSpec& f = faults_[i];
    if (f.kind == FaultKind::kOverrunBurst)
      continue;
    const auto ch = static_cast<std::size_t>(f.channel);
    const bool by_plant = hooks_ != nullptr && hooks_->inject(f.kind, ch, params_);
    emulated_[i] = !by_plant;
    if (emulated_[i] && f.kind == FaultKind::kAmplifierFail)
      amplifier_dead_mask_ |= std::uint64_t{1} << ch;
  }

  const DaqStatus status = inner_.read(t, ai_V);

  Vec3 healthy = ai_V;
  for (std::size_t i = 0; i < faults_.size(); ++i) {
    if (started_[i] == kNotYet)
      continue;
    const FaultSpec& f = faults_[i];
    const std::uint64_t since = t.tick - started_[i];
    if (f.kind == FaultKind::kOverrunBurst) {
      if (since < params_.overrun_burst_ticks) {
        clock_.stall_ns(static_cast<std::int64_t>(params_.overrun_stall_periods *
                                                  static_cast<double>(period_ns_)));
      }
      continue;
    }
    if (!emulated_[i])
      continue;
    const auto ch = static_cast<std::size_t>(f.channel);
    switch (f.kind) {
      case FaultKind::kSgsOpen:
        ai_V[ch] = params_.adc_full_scale_V;
        healthy[ch] = frozen_V_[ch];  // the sensor is gone: keep the value it froze at
        break;
      case FaultKind::kSgsStuck:
        ai_V[ch] = frozen_V_[ch];
        healthy[ch] = frozen_V_[ch];
        break;
      case FaultKind::kAdcNan:
        ai_V[ch] = std::numeric_limits<double>::quiet_NaN();
        healthy[ch] = frozen_V_[ch];
        break;
      case FaultKind::kAdcSpike:
        if (since == 0) {
          double v = ai_V[ch] + (ai_V[ch] < 5.0 ? params_.spike_V : -params_.spike_V);
          if (v > params_.adc_full_scale_V)
            v = params_.adc_full_scale_V;
          if (v < -params_.adc_full_scale_V)
            v = -params_.adc_full_scale_V;
          ai_V[ch] = v;
        }
        break;
      case FaultKind::kAmplifierFail:
      case FaultKind::kActuatorCrack:
      case FaultKind::kOverrunBurst:
        break;
    }
  }
  frozen_V_ = healthy;
  return status;
}

DaqStatus FaultInjectingBackend::write(const CycleTime& t, const Vec3& ao_V) noexcept {
  if (amplifier_dead_mask_ == 0)
    return inner_.write(t, ao_V);
  Vec3 v = ao_V;
  for (std::size_t i = 0; i < v.size(); ++i)
    if ((amplifier_dead_mask_ >> i) & 1U)
      v[i] = 0.0;
  return inner_.write(t, v);
}

}  // namespace piezoshift::runtime
