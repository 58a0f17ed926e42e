#pragma once
// The settle criterion of a phase-shifting step (psi::OnTarget), judged on the controller's own
// estimate, never on the twin's truth: on every channel i the tracking error of the strain
// gauges, e_i = S_i - feedback_i (nm), averaged over the last hold ticks;
//
//   settled  <=>  the window is full and max_i |mean(e_i)| <= band_nm
//
// with hold = max(1, round(hold_s / T)). Both drivers of a sequence use it: run_sequence, which
// ticks the loop itself (sequence.hpp), and SampleSequence, which reads `serve`'s HostSamples
// (sample_sequence.hpp). Fixed size after construction; add() allocates nothing.
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "piezoshift/psi/stage.hpp"

namespace piezoshift::instrument {

class SettleWindow {
 public:
  //! hold_s and the loop's period T [s] give the window's length in ticks.
  SettleWindow(const psi::OnTarget& criterion, double period_s);

  //! Forgets every tick (a new step, or a gap in the samples).
  void reset() noexcept;
  //! One tick's S - feedback per channel [nm]; true once the criterion holds.
  bool add(const std::array<double, 3>& error_nm) noexcept;
  //! max_i |mean(e_i)| over the window [nm] (over the ticks held when not full).
  double worst_mean_nm() const noexcept;
  std::size_t length() const noexcept { return window_.size(); }
  //! Why a step that has not settled within the criterion's timeout fails, at loop time t_s.
  std::string timeout_reason(double t_s) const;

 private:
  psi::OnTarget criterion_;
  std::vector<std::array<double, 3>> window_;
  std::size_t filled_ = 0;
  std::size_t next_ = 0;
};

}  // namespace piezoshift::instrument
