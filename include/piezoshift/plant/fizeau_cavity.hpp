#pragma once
// The Fizeau cavity's own drift: what a fringe lock holds is the cavity's optical path (reference
// surface on the plate to the test surface), not the plate's position in the lab. The cavity is
// an air gap L_c closed mechanically through the test piece's mount; over a hold its optical path
// changes with the air's index (the lab's temperature, the barometric pressure) and with the
// mount's thermal expansion:
//   N(t)   = n(t) - 1 = air_refractivity(lambda, T_air(t), p(t), f)     (air_index.hpp: Edlen,
//            Birch and Downs 1993/1994; T_air is the lab's air process, lab_environment.hpp)
//   p(t)   = p_0 + q(t): the barometric drift, a pressure whose rate r is a first-order
//            Gauss-Markov process of rms sigma_r and correlation time tau_r (weather moves the
//            pressure in smooth trends of hours, not in steps):
//              r <- e_r r + sigma_r sqrt(1 - e_r^2) N(0, 1),  q <- q + T r,  e_r = exp(-T / tau_r)
//            r starts in its stationary distribution (one deviate), q(0) = 0;
//              var q(t) = 2 sigma_r^2 tau_r^2 (t / tau_r - 1 + exp(-t / tau_r))
//            (defaults: 0.60 Pa rms over 60 s, 35 Pa over 1 h, 1.0 hPa over 3 h, 5.3 hPa a day)
//   dL(t)  = alpha_m L_m (T_s(t) - T_s(0)): the mount path between the test piece and the
//            reference, following the structure temperature T_s (lab_environment.hpp); L_m is
//            the net length whose expansion lengthens the gap (negative: it shortens it)
//   d_c(t) = [(N(t) - N(0)) L_c + (1 + N(t)) dL(t)] / (1 + N(0))
// d_c is the change of the cavity's optical path since the start, in lengths of the starting
// air (so a fringe's phase moves by 4 pi d_c / lambda_air, like a plate piston of d_c), positive
// when the cavity got optically longer. The plate's piston Z is taken to lengthen the cavity too
// (the reference moves away from the test piece), so the optical path the fringes see is Z + d_c
// (n(t) Z - n(0) Z, below 1e-3 nm over the stage's travel, is left out). Humidity is held at a
// constant water vapour pressure f (its drift is not modelled).
//
// The pressure process draws from its own Rng (the twin seeds it from its seed), so the rest of
// the twin draws exactly what it drew before the cavity existed.
// Real-time safe (start, update): no heap, no exceptions, no I/O.
#include <cmath>
#include <cstdint>

#include "piezoshift/plant/air_index.hpp"
#include "piezoshift/plant/lab_environment.hpp"
#include "piezoshift/plant/random.hpp"

namespace piezoshift::plant {

struct CavityParams {
  //! L_c: assumed 50 mm, mid-range of a Fizeau's test-piece gaps (10 to 100 mm)
  double gap_m = 0.05;
  double wavelength_nm = 632.991;  //!< vacuum wavelength, He-Ne (the Fizeau's source)
  double pressure_Pa = 101325.0;   //!< p_0, standard atmosphere
  //! sigma_r: assumed so that the rms change over 3 h is 1.0 hPa, the boundary between a
  //! "steady" and a "slowly" changing barometric tendency (the 3-hour pressure tendency of
  //! weather reports, AMS Glossary of Meteorology); a day then gives 5.3 hPa rms
  double pressure_rate_rms_Pa_per_s = 0.01;
  //! tau_r: assumed 6 h (weather systems pass in about a day)
  double pressure_rate_correlation_time_s = 21600.0;
  //! f: assumed 1 kPa (about 38 % relative humidity at 22 degC), constant
  double water_vapour_pressure_Pa = 1000.0;
  //! L_m: assumed 50 mm of net uncompensated mount (the test piece's holder against the stage's
  //! column on a common base)
  double mount_path_length_m = 0.05;
  double mount_cte_per_K = 11.5e-6;  //!< alpha_m, steel (assumed material)
  //! Whether d_c enters the Fizeau's fringes (Twin::fringe_piston_nm). Off by default: every
  //! measurement made before the cavity existed renders the same frames.
  bool in_fringes = false;

  bool operator==(const CavityParams&) const = default;
};

struct CavityState {
  double pressure_rate_Pa_per_s = 0.0;  //!< r
  double pressure_change_Pa = 0.0;      //!< q = p - p_0
  double refractivity = 0.0;            //!< N(t)
  double drift_nm = 0.0;                //!< d_c(t)
};

//! A seed for the cavity's own Rng from the twin's (SplitMix64's finalizer: a different stream
//! for every seed, and none equal to the twin's own).
inline std::uint64_t cavity_seed(std::uint64_t seed) noexcept {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

class FizeauCavity {
 public:
  FizeauCavity() = default;
  FizeauCavity(const CavityParams& p, double update_period_s) noexcept
      : p_(p),
        period_s_(update_period_s),
        e_r_(std::exp(-update_period_s / p.pressure_rate_correlation_time_s)),
        drive_(p.pressure_rate_rms_Pa_per_s * std::sqrt(1.0 - e_r_ * e_r_)) {}

  //! The datum: the lab's state at its start (LabEnvironment::start first), one deviate.
  void start(CavityState& s, const LabEnvironment& lab, const LabState& ls, Rng& rng) noexcept {
    s.pressure_rate_Pa_per_s = p_.pressure_rate_rms_Pa_per_s * rng.normal();
    s.pressure_change_Pa = 0.0;
    s.refractivity = refractivity(lab.air_C(ls), s.pressure_change_Pa);
    s.drift_nm = 0.0;
    start_refractivity_ = s.refractivity;
  }
  //! One update period, after the lab's own update (one deviate).
  void update(CavityState& s, const LabEnvironment& lab, const LabState& ls,
              Rng& rng) const noexcept {
    s.pressure_rate_Pa_per_s = e_r_ * s.pressure_rate_Pa_per_s + drive_ * rng.normal();
    s.pressure_change_Pa += period_s_ * s.pressure_rate_Pa_per_s;
    s.refractivity = refractivity(lab.air_C(ls), s.pressure_change_Pa);
    const double mount_m = p_.mount_cte_per_K * p_.mount_path_length_m * lab.structure_change_K(ls);
    s.drift_nm =
        1e9 *
        ((s.refractivity - start_refractivity_) * p_.gap_m + (1.0 + s.refractivity) * mount_m) /
        (1.0 + start_refractivity_);
  }

  double pressure_Pa(const CavityState& s) const noexcept {
    return p_.pressure_Pa + s.pressure_change_Pa;
  }
  const CavityParams& params() const noexcept { return p_; }

 private:
  double refractivity(double air_C, double pressure_change_Pa) const noexcept {
    return air_refractivity(p_.wavelength_nm, {air_C, p_.pressure_Pa + pressure_change_Pa,
                                               p_.water_vapour_pressure_Pa});
  }

  CavityParams p_{};
  double period_s_ = 0.0;
  double e_r_ = 1.0;
  double drive_ = 0.0;
  double start_refractivity_ = 0.0;
};

}  // namespace piezoshift::plant
