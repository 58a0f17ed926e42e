#pragma once
// The desired displacements Z_d of P1..P3 over time for a run:
//   step(Z)          Z_d(t) = [Z, Z, Z] for t >= 0  (the paper's Section 4.1 step, Z_d1 = Z_d2 =
//                    Z_d3 so the stage moves along z only)
//   from CSV         columns t_s and either zd_um (all three points) or zd1_um, zd2_um, zd3_um
//                    (docs/files.md; `run` and `simulate` read the same files);
//                    piecewise linear between rows, the first row's value before it, the last
//                    row's after it. Times strictly increasing.
// Every value must lie in [0, max_z_um] (default: the 16 um nominal stroke, Section 2.1): a value
// outside is refused with core::InputError naming the file and line, never clamped.
//
// at() is real-time safe (no heap; amortised O(1) for increasing t through a cursor). Loading
// allocates and throws.
#include <cstddef>
#include <string>
#include <vector>

#include "piezoshift/control/vec3.hpp"

namespace piezoshift::runtime {

using control::Vec3;

class SetpointProfile {
 public:
  static constexpr double kMaxZ_um = 16.0;  //!< nominal stroke, Section 2.1

  //! Z_d = [z, z, z] from t = 0. Throws core::InputError when z is outside [0, max_z_um].
  static SetpointProfile step(double z_um, double max_z_um = kMaxZ_um);
  static SetpointProfile load_csv(const std::string& path, double max_z_um = kMaxZ_um);
  //! From samples (tests); same checks, source names the origin in messages.
  static SetpointProfile from_samples(std::vector<double> t_s, std::vector<Vec3> z_um,
                                      const std::string& source, double max_z_um = kMaxZ_um);

  //! Z_d at time t_s. Real-time safe.
  Vec3 at(double t_s) noexcept;
  void rewind() noexcept { cursor_ = 0; }
  std::size_t size() const noexcept { return t_s_.size(); }

 private:
  std::vector<double> t_s_;
  std::vector<Vec3> z_um_;
  std::size_t cursor_ = 0;
};

}  // namespace piezoshift::runtime
