#pragma once
// The twin's model: everything derived once from the design and twin parameters (stiffnesses,
// masses, the identified contact, the discretized components, the geometry), immutable while the
// twin runs. Built by make_twin_model(), which is also where every cross-parameter check lives.
//
// Derivations (units in the names):
//   k_m      design::mechanism_stiffness_N_per_um (Eqs. 2-3: 6.776 N/um)
//   k_a      design actuator stiffness (Table 1: 70 N/um)
//   k_c      contact.hpp: identified from the 12.931 um open-loop travel, or given
//   k_s      1 / (1 / k_a + 1 / k_c)
//   m_leg    mechanism moving mass (design, 1839 Hz fit) + stack mass k_a / (2 pi f_a)^2
//   x_nom,i  nominal stroke s_i; the stroke gain x_nom s_i / (1 + C_step(t_ref)) multiplies y + C
//   g'_i     g_i / (1 + k_m / k_c,secant)  (sgs.hpp)
//   modes    LinearMechanics of the loaded legs + plate; also the unloaded mechanism
//            sqrt(k_m / m_mech) / 2 pi (1839 Hz) and one leg with its stack, no plate
#include <array>
#include <cstddef>
#include <string>

#include "piezoshift/control/vec3.hpp"
#include "piezoshift/design/design_inputs.hpp"
#include "piezoshift/plant/amplifier.hpp"
#include "piezoshift/plant/contact.hpp"
#include "piezoshift/plant/creep.hpp"
#include "piezoshift/plant/flicker.hpp"
#include "piezoshift/plant/geometry.hpp"
#include "piezoshift/plant/hysteresis.hpp"
#include "piezoshift/plant/mechanics.hpp"
#include "piezoshift/plant/plate.hpp"
#include "piezoshift/plant/twin_params.hpp"

namespace piezoshift::plant {

struct TwinModel {
  design::DesignInputs design{};
  TwinParams params{};

  // Timing
  std::size_t substeps = 0;                       //!< physics steps per control period
  double physics_step_s = 0.0;                    //!< h
  double control_period_s = 0.0;                  //!< T_s
  std::size_t interferometer_every = 0;           //!< physics steps per dynamic sample
  std::size_t interferometer_static_samples = 0;  //!< dynamic samples per static reading

  // Stiffness and mass
  double mechanism_stiffness_N_per_um = 0.0;  //!< k_m
  double actuator_stiffness_N_per_um = 0.0;   //!< k_a
  double contact_stiffness_N_per_um = 0.0;    //!< k_c
  bool contact_identified = false;            //!< k_c from the open-loop travel (not given)
  double series_stiffness_N_per_um = 0.0;     //!< k_s
  bool contact_hertz = false;                 //!< the Hertz contact (contact.hpp)
  double contact_preload_N = 0.0;             //!< F0 (Hertz)
  bool contact_preload_identified = false;    //!< F0 from the open-loop travel (not given)
  double contact_modulus_Pa = 0.0;            //!< E* (Hertz)
  //! k_m x / (d_H(F0 + k_m x) - d_H(F0)) at x = the open-loop travel (Hertz; else k_c): the
  //! secant stiffness that sets the gauges' mean elongation per um of leg motion
  double contact_secant_N_per_um = 0.0;
  HertzResidual hertz{};  //!< r(f) (Hertz)
  double mechanism_mass_kg = 0.0;
  double stack_mass_kg = 0.0;
  double leg_mass_kg = 0.0;
  PlateInertia plate{};

  // Strokes (at t_ref after a 0 -> 150 V step)
  std::array<double, 3> free_stroke_um{};  //!< x_nom s_i
  std::array<double, 3> stroke_gain_um{};  //!< x_nom s_i / (1 + C_step(t_ref))
  double equation1_um = 0.0;               //!< Eq. 1 with the nominal stack, rigid contact
  std::array<double, 3> leg_static_um{};   //!< x_i at 150 V, t_ref (Eq. 1 generalized; Hertz)
  double open_loop_creep_factor = 0.0;     //!< (1 + C(t_m)) / (1 + C(t_ref)) at open_loop_time_s

  // Electrical
  double amplifier_current_limit_A = 0.0;
  double amplifier_slew_V_per_s = 0.0;

  // Sensors
  TwinGeometry geometry{};
  control::Vec3 sgs_gain_per_elongation{};  //!< g'_i
  double sgs_nominal_um_per_V = 0.0;        //!< k_nom = x_nom / FS

  // Dynamics
  std::array<double, 3> loaded_modes_Hz{};  //!< legs + plate
  double unloaded_mechanism_Hz = 0.0;       //!< sqrt(k_m / m_mech) / 2 pi
  double leg_with_stack_Hz = 0.0;           //!< sqrt((k_m + k_s) / m_leg) / 2 pi, no plate

  // Discretized components
  Amplifier amplifier{};
  PrandtlIshlinskii hysteresis{};
  CreepChain creep{};
  CreepChain gauge_creep{};
  FlickerNoise sgs_zero_flicker{};      //!< z_i [nm]
  FlickerNoise sgs_excitation_drift{};  //!< delta [relative]
  LinearMechanics mechanics{};
  control::Mat3 legs_to_pose{};  //!< (Z [um], theta_x [urad], theta_y [urad]) = this x
};

//! Builds the model. Throws std::invalid_argument with a message naming the parameter (in its
//! TOML spelling) for anything that cannot make a twin.
TwinModel make_twin_model(const design::DesignInputs& design, const TwinParams& params);

//! The mechanics of the legs and plate for given leg stiffnesses (k_m + k_s per leg, N/um);
//! used by make_twin_model and to re-discretize after a stiffness fault.
LinearMechanics make_leg_plate_mechanics(const TwinModel& model,
                                         const std::array<double, 3>& leg_stiffness_N_per_um);

}  // namespace piezoshift::plant
