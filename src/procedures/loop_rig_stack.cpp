#include "piezoshift/procedures/loop_rig_stack.hpp"

#include <cstdio>

#include <fmt/core.h>

#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::procedures {

LoopRigStack::LoopRigStack(const LoopRigStackOptions& o,
                           const runtime::InstallationConfig& installation,
                           const control::SemiClosedLoopParams& base) {
  LoopStackOptions so;
  so.daq = o.daq == "sim-rt" ? "sim" : o.daq;
  so.rate_Hz = 1.0 / base.sample_time_s;
  so.seed = o.seed + 1;
  so.config_path = o.config_path;
  so.clock = o.free_run ? StackClock::kPaced : StackClock::kRealTime;
  stack_ = std::make_unique<LoopStack>(so, installation.project);  // names a device it cannot open
  rig::LoopRigOptions lo;
  lo.rate_Hz = so.rate_Hz;
  lo.window_s = o.window_s;
  // An interferometer log is stamped by the wall clock: real-time windows are in Unix time.
  lo.unix_time = stack_->clock().real_time();
  signals_.emplace();  // Ctrl-C ramps the stage to 0 V instead of leaving it driven
  lo.stop_signal = &g_stop_signal;
  rig_ = std::make_unique<rig::LoopRig>(
      stack_->daq(), stack_->clock(), stack_->paced(), base,
      runtime::resolve_overrun_trip(loop_safety_limits(installation.safety, std::nullopt),
                                    stack_->sim() != nullptr),
      lo);
  for (const std::string& refusal : rig_->realtime().refusals)
    fmt::print(stderr, "piezoshift: warning: the loop runs without real-time treatment: {}\n",
               refusal);
}

}  // namespace piezoshift::procedures
