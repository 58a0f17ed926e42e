#pragma once
// `compare --lock`: the Fizeau's hold beside the comparison's columns. Per seed s,
// the paper's controller (the `paper` column's, calibrated with the XL-80) and the improved one
// (the `improved` column's) each run instrument::twin_hold twice, on the semi-closed loop alone
// and with the fringe lock: what
//   piezoshift measure --free-run --config C --calibration CAL --averages 10 --hold-s H
//                      [--lock] --seed s
// gives, with C compare's configuration plus a 96 px camera and the cavity's drift in the fringes
// ([twin.cavity] in_fringes = true) and CAL that column's controller. Figures per run (twin
// truth): the RMS of the cavity's optical path from its set point over the hold's exposures, and
// the RMS of its means over whole seconds; a run that fails (or a controller not calibrated) is
// not valid with its reason, never a number. The lock's target: the improved controller's
// locked median within kHoldTarget_nm, reported beside the semi-closed loop's on the same seeds.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::reproduction {

//! The four holds of a seed: a controller, unlocked or locked.
enum class HoldVariant {
  kPaperUnlocked = 0,
  kPaperLocked = 1,
  kImprovedUnlocked = 2,
  kImprovedLocked = 3,
};
inline constexpr std::array<HoldVariant, 4> kHoldVariants{
    HoldVariant::kPaperUnlocked, HoldVariant::kPaperLocked, HoldVariant::kImprovedUnlocked,
    HoldVariant::kImprovedLocked};
//! "paper_unlocked", ...: the JSON keys' middle (hold_<key>_<figure>).
const char* hold_key(HoldVariant v);
//! The improved or the paper's controller's.
bool hold_of_improved(HoldVariant v);
bool hold_locked(HoldVariant v);

//! The lock's target: the cavity's path within 0.2 nm RMS of its set point over the hold, with
//! the lock (the improved controller's median over seeds).
inline constexpr double kHoldTarget_nm = 0.2;
//! The hold's default length: a minute, a measurement's worth of holding.
inline constexpr double kDefaultHold_s = 60.0;
//! Measurements before the hold (the first is the lock's reference).
inline constexpr int kHoldAverages = 10;

//! One hold's figures [nm], or not valid with its reason.
struct HoldRun {
  rig::Validity validity;
  double path_error_rms_nm = std::numeric_limits<double>::quiet_NaN();
  double path_error_1s_means_rms_nm = std::numeric_limits<double>::quiet_NaN();
  std::size_t frames = 0;         //!< the hold's exposures
  double simulated_time_s = 0.0;  //!< the loop's ticks x its period
  double wall_time_s = 0.0;
};

//! The hold's figures, in the table's order: JSON key (after hold_<variant>_), label (of the
//! cavity's path from its set point) and the member.
struct HoldFigure {
  const char* key;
  const char* label;
  double HoldRun::*member;
};
inline constexpr std::array<HoldFigure, 2> kHoldFigures{
    HoldFigure{"path_error_rms_nm", "RMS", &HoldRun::path_error_rms_nm},
    HoldFigure{"path_error_1s_means_rms_nm", "1 s means RMS",
               &HoldRun::path_error_1s_means_rms_nm}};

//! compare's configuration as the holds run it: a 96 x 96 px camera and the cavity's drift in
//! the fringes; [safety] at the installation's defaults.
camera::InstrumentConfig hold_instrument_config(const config::ProjectConfig& config);

//! One hold on seed of a controller whose calibration is `calibrated` (not valid: nothing runs,
//! the hold is not valid with that reason). Bad input to the hold (core::InputError) is a
//! hold not valid with its reason too: compare's own options are checked before it runs.
HoldRun run_hold(const config::ProjectConfig& config,
                 const control::SemiClosedLoopParams& controller, const rig::Validity& calibrated,
                 std::uint64_t seed, bool lock, double hold_s);

}  // namespace piezoshift::reproduction
