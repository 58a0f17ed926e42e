#pragma once
// One way to print a figure in every report and table (`reproduce`'s report and summary,
// `compare`'s report and terminal tables): to the precision it carries, with the symbols the
// docs and the dashboard use (µm, ±, λ, σ, °). By unit:
//   "s"    milliseconds, to 0.1 ms below 10 ms and to 1 ms above (the interferometer and the
//          exposures sample at 1 kHz; the 10 kHz loop's times carry 0.1 ms); "not settled"
//          when it never came (infinite)
//   "um"   µm to 0.01 (the interferometer reads 1 nm; spreads are a few nm); resolution_um
//          overrides it (the travel search steps by 0.1 µm)
//   "nm"   two significant figures (the 1 σ of 230 readings is known to about 5 %)
//   "%"    two significant figures (a linearity quantum is 1 nm of 11 µm, 0.009 %)
//   "dB"   0.1 dB; "deg": 0.1°
// Exactly 0 prints as "0" and the unit: the oracle's linearity on the paper's levels is exactly 0
// by construction (docs/compare.md), and "0.000 %" would look like a placeholder.
#include <string>
#include <string_view>

namespace piezoshift::reproduction {

//! value in unit (the FigureSpec units above); resolution > 0: the step it was measured in.
std::string format_figure(double value, std::string_view unit, double resolution = 0.0);

//! The unit as text shows it: "um" -> "µm", "deg" -> "°", others unchanged.
std::string unit_symbol(std::string_view unit);

}  // namespace piezoshift::reproduction
