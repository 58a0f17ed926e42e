#pragma once
// The stage as the host interface sees it (docs/gcs.md): three axes, their units, where a pose may
// go, how a pose is estimated from the strain gauges, and what the open-loop values mean.
//
//   axes       Z  piston at the plate's origin O, um
//              U  tip  theta_x (about x), urad
//              V  tilt theta_y (about y), urad
//   move       pose -> Z_d = tripod.inverse(pose) (P1..P3, Eq. 5) -> the loop's feedforward
//   position   the strain gauges through the inverted feedforward: y = SGS in um,
//              Z_S = A^-1 y, Z_i = p^-1(Z_S,i), pose = tripod.forward(Z). At rest in closed loop
//              y = S = A p(Z_d), so the estimate returns the target; its distance to the
//              interferometer is the calibration's error (the paper's linearity).
//   reachable  every Z_d,i in [0, z_max] (the cubic's calibrated domain) and every actuator
//              target S_i = (A p(Z_d))_i in [0, S_i(z_max)] (S_i(z) = (A p(z 1))_i: what
//              actuator i is asked for at the end of the calibrated piston travel, so never more
//              than the loop delivered there). z_max is the semi-closed-loop travel.
//   limits     TMN/TMX: Z in [0, z_max]; U and V the extremes reachable at Z = z_max / 2 with
//              the other angle 0. A move is checked as a whole pose, not per axis.
//   open loop  three axis values in amplifier-output volts (0-150 V), mixed into the channels as
//              v = M [v_Z, v_U, v_V], columns of M: (1,1,1); y_i / max|y| (tip-shaped);
//              -x_i / max|x| (tilt-shaped), with (x_i, y_i) the actuators in the plate frame.
//              DAQ volts = channel volts / amplifier gain.
#include <array>
#include <string>

#include <Eigen/Core>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/kinematics/tripod.hpp"
#include "piezoshift/plant/geometry.hpp"

namespace piezoshift::host {

using control::Vec3;

enum class Axis : std::uint8_t { kZ = 0, kU = 1, kV = 2 };
inline constexpr std::array<Axis, 3> kAxes{Axis::kZ, Axis::kU, Axis::kV};
//! "Z", "U", "V".
const char* axis_name(Axis axis) noexcept;
//! "um" for Z, "urad" for U and V.
const char* axis_unit(Axis axis) noexcept;

//! A pose or per-axis values, indexed by Axis: [Z um, U urad, V urad].
using AxisValues = std::array<double, 3>;

struct StageModelParams {
  control::SemiClosedLoopParams controller{};  //!< p, A and the SGS scaling (calibration file)
  std::array<kinematics::PlatePoint, 3> measurement_points{};  //!< P1..P3 in the plate frame
  std::array<kinematics::PlatePoint, 3> actuators{};           //!< legs 1..3 in the plate frame
  //! Semi-closed-loop travel: Table 4, 11.5 um, unless the calibration file measured its own.
  double z_max_um = 11.5;
  //! The lowest Z reachable from above: after a descent the stacks' hysteresis leaves them above
  //! zero at 0 V, which the 0..150 V amplifier cannot undo. 0 unless the calibration measured it.
  double z_min_um = 0.0;
  double amplifier_gain = 15.0;  //!< stack V per DAQ V, Section 4
  double channel_max_V = 150.0;  //!< amplifier output range, Section 4
};

//! The stage as the twin's geometry lays it out (measurement points and actuators, plant/
//! geometry.hpp, docs/twin.md), with the given controller's p, A and scaling. Throws
//! std::invalid_argument for a geometry that cannot be built.
StageModelParams stage_model_params(const plant::GeometryParams& geometry,
                                    const control::SemiClosedLoopParams& controller = {});

class StageModel {
 public:
  //! Throws std::invalid_argument on a singular A, collinear points, a p that is not monotonic
  //! on [0, z_max], or a non-positive z_max.
  explicit StageModel(const StageModelParams& params);

  Vec3 points_for(const AxisValues& pose) const;
  AxisValues pose_from_points(const Vec3& z_um) const;
  //! The pose the strain gauges say (see the header comment); NaN when a gauge is not finite.
  AxisValues pose_from_sgs(const Vec3& sgs_V) const;

  //! Empty when reachable, else why not (names the point or actuator and its range).
  std::string unreachable_reason(const AxisValues& pose) const;
  bool reachable(const AxisValues& pose) const { return unreachable_reason(pose).empty(); }
  const AxisValues& min_limits() const noexcept { return min_; }
  const AxisValues& max_limits() const noexcept { return max_; }

  //! Channel volts at the amplifier outputs for open-loop axis values.
  Vec3 channel_V_for(const AxisValues& open_loop_V) const;
  //! Amplifier output volts for DAQ output volts (x amplifier_gain).
  Vec3 channel_V_from_daq(const Vec3& daq_V) const;
  //! The open-loop axis values that give these channel volts (inverse of channel_V_for).
  AxisValues open_loop_for(const Vec3& channel_V) const;

  const StageModelParams& params() const noexcept { return params_; }

 private:
  StageModelParams params_;
  kinematics::TripodGeometry points_;
  control::SemiClosedLoopController feedforward_;  // its actuator_targets(): S = A p(Z_d)
  Eigen::Matrix3d a_inverse_;
  Vec3 actuator_max_um_{};
  Eigen::Matrix3d mix_;
  Eigen::Matrix3d unmix_;
  AxisValues min_{};
  AxisValues max_{};
};

}  // namespace piezoshift::host
