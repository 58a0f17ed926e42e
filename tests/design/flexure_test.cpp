#include "piezoshift/design/flexure.hpp"

#include <gtest/gtest.h>

namespace piezoshift::design {
namespace {

TEST(Flexure, PaperTablesGiveSection22Values) {
  EXPECT_NEAR(hinge_angular_stiffness_Nm_per_rad({}, {}), 274.4, 0.05);
  const double km = mechanism_stiffness_N_per_um({}, {});
  EXPECT_NEAR(km, 6.776, 0.001);
  EXPECT_NEAR(available_displacement_um({}, km), 14.587, 0.001);
}

}  // namespace
}  // namespace piezoshift::design
