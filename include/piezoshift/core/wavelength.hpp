#pragma once
// The Fizeau's source: the helium-neon line every phase-shifting figure of the project is in
// (the sequence's steps, the analysis, the twin camera's fringes, the lock's quarter wave, the
// calibration from fringes). It lives in the lowest module so that each of them, and the
// experiments' lambda/8 step, take it from here.
namespace piezoshift::core {

//! HeNe, 632.8 nm [nm].
inline constexpr double kHeNeWavelength_nm = 632.8;
//! The same line in micrometres, written out so that it is the double 0.6328 exactly as the
//! figures of the calibration from fringes were computed (632.8 / 1000 rounds to another one).
inline constexpr double kHeNeWavelength_um = 632.8e-3;

}  // namespace piezoshift::core
