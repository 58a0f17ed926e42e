#include "piezoshift/psi/zernike.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/surface_metrics.hpp"
#include "piezoshift/psi/zernike_figure.hpp"

namespace piezoshift::psi {
namespace {

TEST(ZernikeTest, NollOrdering) {
  const std::vector<NollIndex> expect{{0, 0},  {1, 1}, {1, -1}, {2, 0}, {2, -2}, {2, 2},
                                      {3, -1}, {3, 1}, {3, -3}, {3, 3}, {4, 0},  {4, 2},
                                      {4, -2}, {4, 4}, {4, -4}, {5, 1}, {5, -1}, {5, 3},
                                      {5, -3}, {5, 5}, {5, -5}, {6, 0}};
  for (std::size_t k = 0; k < expect.size(); ++k) {
    const NollIndex nm = noll_index(static_cast<int>(k) + 1);
    EXPECT_EQ(nm.n, expect[k].n) << k + 1;
    EXPECT_EQ(nm.m, expect[k].m) << k + 1;
  }
  EXPECT_EQ(noll_index(37).n, 8);
  EXPECT_EQ(noll_index(37).m, 0);  // the fourth spherical term
}

TEST(ZernikeTest, KnownValuesAndUnitRms) {
  const ZernikeBasis b(11);
  std::vector<double> z(11);
  b.evaluate(1.0, 0.0, z);
  EXPECT_NEAR(z[1], 2.0, 1e-12);              // Z2 = 2 r cos t
  EXPECT_NEAR(z[3], std::sqrt(3.0), 1e-12);   // Z4 = sqrt 3 (2 r^2 - 1)
  EXPECT_NEAR(z[10], std::sqrt(5.0), 1e-12);  // Z11 = sqrt 5 (6 r^4 - 6 r^2 + 1)
  b.evaluate(0.0, 0.0, z);
  EXPECT_NEAR(z[3], -std::sqrt(3.0), 1e-12);
  // mean of Z_j^2 over a fine disk is 1 (Noll's normalisation), to the grid's accuracy
  const Mask mask = disk_mask(801, 801, 400.0);
  for (int j : {2, 4, 7, 11, 22, 37}) {
    std::vector<double> c(static_cast<std::size_t>(j), 0.0);
    c.back() = 1.0;
    const Map m = zernike_surface(c, mask);
    double s2 = 0.0;
    std::size_t n = 0;
    for (std::size_t p = 0; p < m.size(); ++p)
      if (mask.v[p]) {
        s2 += m.v[p] * m.v[p];
        ++n;
      }
    EXPECT_NEAR(s2 / static_cast<double>(n), 1.0, 0.01) << j;
  }
}

TEST(ZernikeTest, ThirtySevenTermFitReturnsItsInput) {
  const Mask mask = disk_mask(256, 256, 127.5);
  plant::Rng rng(5);
  std::vector<double> waves(37);
  for (double& c : waves)
    c = 0.2 * rng.normal();
  const Map s = zernike_surface(waves, mask);
  const std::vector<double> fit = fit_zernike(s, mask, 37);
  ASSERT_EQ(fit.size(), 37u);
  for (std::size_t k = 0; k < 37; ++k)
    EXPECT_NEAR(fit[k], waves[k], 1e-3) << "Z" << k + 1;  // 1e-3 wave
}

TEST(ZernikeTest, PvrOfAPureZernikeSurfaceIsItsPv) {
  const Mask mask = disk_mask(128, 128, 60.0);
  std::vector<double> c(11, 0.0);
  c[3] = 10.0;  // defocus, 10 nm RMS: PV = 2 sqrt 3 * 10 on the full disk
  c[10] = 3.0;
  const Map s = zernike_surface(c, mask);
  const SurfaceFigures f = surface_figures(s, mask);
  EXPECT_NEAR(f.pvr, f.pv, 1e-9);
  EXPECT_NEAR(f.rms, std::hypot(10.0, 3.0), 0.02 * std::hypot(10.0, 3.0));
  // piston, tilt and power removal leaves the spherical term alone
  const Map r = remove_terms(s, mask, Removal::kTiltAndPower);
  // (on a pixel grid Z4 and Z11 are not exactly orthogonal, so the removed power holds a little
  // of Z11: the residual is orthogonal to Z1..Z4 and keeps all of Z11's own coefficient)
  for (const double c4 : fit_zernike(r, mask, 4))
    EXPECT_NEAR(c4, 0.0, 1e-9);
  EXPECT_NEAR(fit_zernike(r, mask, 11)[10], 3.0, 1e-9);
}

// The chart `measure` and `reproduce` draw: one bar per coefficient from Z4 on, at its Noll index.
TEST(ZernikeTest, TheChartHasABarPerCoefficientFromDefocusOn) {
  const std::vector<double> c{0.5, 2.0, -3.0, 40.0, 25.0, -15.0};
  const io::Figure f = zernike_figure(c);
  ASSERT_EQ(f.panels.size(), 1u);
  ASSERT_EQ(f.panels[0].series.size(), 1u);
  const io::Series& bars = f.panels[0].series[0];
  EXPECT_EQ(bars.style, io::SeriesStyle::kBoxes);
  EXPECT_EQ(bars.x, (std::vector<double>{4.0, 5.0, 6.0}));
  EXPECT_EQ(bars.y, (std::vector<double>{40.0, 25.0, -15.0}));
  EXPECT_EQ(bars.w.size(), 3u);
  EXPECT_EQ(f.panels[0].x_label, "Noll index j");
}

}  // namespace
}  // namespace piezoshift::psi
