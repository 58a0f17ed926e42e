#pragma once
// Data that cannot give a calibration: too few rows, a rank-deficient design, a non-finite value,
// sizes that do not match. It is bad user input (exit status 2 in the CLI), so it is an
// core::InputError; the message says what is wrong with the data but not which file it came from,
// which the caller (who knows) puts in front.
#include <string>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::calibration {

class FitError : public core::InputError {
 public:
  explicit FitError(const std::string& message) : core::InputError(message) {}
};

//! Relative threshold for numerical rank: a design matrix whose singular values satisfy
//! sigma_min <= kRankRelTol * sigma_max is called rank-deficient. 1e-6 is far below the relative
//! resolution of the data these fits see (the XL-80 reads 1 nm on a 10 um travel, 1e-4; a CSV
//! written with 6 decimals carries ~1e-7 relative rounding), so a design this close to singular
//! is degenerate (a point that never moved, two channels moved together, all samples at one
//! displacement), not merely noisy; a merely ill-conditioned design shows in condition_number.
inline constexpr double kRankRelTol = 1e-6;

}  // namespace piezoshift::calibration
