#pragma once
// The flexure material, 45 steel (paper, Table 2).

namespace piezoshift::design {

struct MaterialParams {
  double elastic_modulus_Pa = 2.1e11;  //!< E, Table 2
  double poisson_ratio = 0.28;         //!< Table 2 (not used by Eqs. 1 to 3; kept for the FEA)
  double density_kg_per_m3 = 7800.0;   //!< Table 2
  double allowable_stress_Pa = 355e6;  //!< Table 2

  bool operator==(const MaterialParams&) const = default;
};

}  // namespace piezoshift::design
